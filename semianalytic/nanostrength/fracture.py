"""Surface energy, critical energy release rate and fracture toughness: Part III, eqs. (15)-(16)
and Table 3.

Eq. (15) defines the surface energy of the crack as the work of the interlayer stress up to
its peak,  gamma = int_{d_0}^{d_max} sigma(u) du.  With sigma = (1/d) dPhi/de and du = d_0 de
this is Delta Phi = Phi(d_max) - Phi(d_0) (exactly so for the reference-spacing measure).
Eq. (16) as printed,  gamma = (Delta Phi / e**) * 7.78605e2 N/m,  divides by the critical
strain as well (7.78605e2 N/m is the rydberg/bohr^2 -> J/m^2 conversion): it is larger than
eq. (15) by 1/e** ~ 6.9 in tension and 1/e* ~ 10 in compression.  Table 3 was computed with
eq. (16).  Both are offered: ``form="eq15"`` (the integral the paper defines; default) and
``form="eq16"`` (the printed ratio, which reproduces Table 3).

Y_1c = 2 gamma and K_1c = sqrt(Y_1c E) (Part III, text before Table 3).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from semianalytic.nanostrength.crystal import Crystal
from semianalytic.nanostrength.interplanar import Law

Form = Literal["eq15", "eq16"]
FORMS = ("eq15", "eq16")
EnergySource = Literal["printed", "law"]
SIDES = ("tension", "compression")


def surface_energy_eq16(delta_phi: float, critical_strain: float) -> float:
    """gamma = Delta Phi / e [J/m^2]; Part III, eq. (16) as printed (Delta Phi in J/m^2, so the
    printed factor 7.78605e2 N/m, i.e. Ry/bohr^2, is already applied)."""
    if not critical_strain > 0:
        raise ValueError("critical strain must be positive")
    return delta_phi / critical_strain


def surface_energy_eq15(law: Law, strain: float) -> float:
    """gamma = int_{d_0}^{d_max} sigma(u) du [J/m^2]; Part III, eq. (15), with d_max = d_0 (1 + e)
    at the stress peak (e < 0 in compression; the result is positive on both sides)."""
    return abs(law.work_to(strain))


def energy_release_rate(gamma: float) -> float:
    """Y_1c = 2 gamma [J/m^2] (Part III, text after eq. (16))."""
    return 2.0 * gamma


def fracture_toughness(Y1c: float, E: float) -> float:
    """K_1c = sqrt(Y_1c E) [Pa m^1/2] (Part III, text before Table 3, after [51])."""
    return math.sqrt(Y1c * E)


@dataclass(frozen=True)
class FractureResult:
    """One side (tension or compression) of Table 3.  SI: gamma, Y_1c in J/m^2, K_1c in Pa m^1/2."""

    side: str
    form: str
    energy_source: str
    delta_phi: float
    critical_strain: float
    gamma: float
    Y1c: float
    K1c: float


def fracture(crystal: Crystal, law: Law | None, side: str, form: Form = "eq15",
             energy_source: EnergySource = "law") -> FractureResult:
    """Y_1c and K_1c on one side (``tension``: e**, sigma_2; ``compression``: e*, sigma_1).

    form = "eq15": gamma from the integral of the law's stress up to its peak (needs ``law``).
    form = "eq16": gamma = Delta Phi / e with Delta Phi and e printed (after eq. (16) and in
    Table 2; ``energy_source="printed"``) or from the law and its own peak (``"law"``).
    K_1c uses the crystal's E (Table 2).
    """
    if side not in SIDES:
        raise ValueError(f"side must be one of {SIDES}")
    tension = side == "tension"
    if form == "eq15":
        energy_source = "law"
    if energy_source == "law":
        if law is None:
            raise ValueError(f"form {form} with Delta Phi from the law needs the law")
        peaks = law.strength()
        e = peaks.e_t if tension else peaks.e_c  # the law's own peak (= Table 2 when calibrated)
        if not math.isfinite(e):
            raise ValueError(f"{crystal.name}: the law has no {side} peak")
        signed = e if tension else -e
        delta = law.deformation_energy(signed)
    elif energy_source == "printed":
        e = crystal.e_t if tension else crystal.e_c
        delta = crystal.dphi_t if tension else crystal.dphi_c
        if delta is None:
            raise ValueError(f"{crystal.name}: no printed Delta Phi for {side}")
    else:
        raise ValueError("energy_source must be 'printed' or 'law'")
    if form == "eq15":
        gamma = surface_energy_eq15(law, signed)
    elif form == "eq16":
        gamma = surface_energy_eq16(delta, e)
    else:
        raise ValueError(f"form must be one of {FORMS}")
    Y = energy_release_rate(gamma)
    return FractureResult(side, form, energy_source, delta, e, gamma, Y, fracture_toughness(Y, crystal.E))
