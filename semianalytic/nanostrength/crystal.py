"""Input description of one diamond-like crystal for Part III (SI units throughout).

The four crystals of Tables 1-2 (C, BN, SiC, AlN) are built from :mod:`.data`; a case file
may define others with the same quantities (``[[nanostrength.crystal]]``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from semianalytic.nanostrength import data


@dataclass(frozen=True)
class Crystal:
    """What the bulk interplanar law is calibrated to.

    phi0        Phi_0 [J/m^2], energy of interaction of the weakest pair of {111} planes per unit
                area at equilibrium (negative: bound); Part III, Table 1.
    d0          d_0 = c_0 / 4 [m], their equilibrium spacing.
    E           Young's modulus along [111] [Pa] (Table 2, E_1 = E_2).
    sigma_c     theoretical strength in compression sigma_1^max [Pa] (positive number).
    e_c         its strain -e*_111 (positive number).
    sigma_t     theoretical strength in tension sigma_2^max [Pa].
    e_t         its strain e**_111.
    dphi_t, dphi_c  Delta Phi = Phi(d_max) - Phi(d_0) [J/m^2] quoted after eq. (16), if known.
    """

    name: str
    phi0: float
    d0: float
    E: float
    sigma_c: float
    e_c: float
    sigma_t: float
    e_t: float
    dphi_t: float | None = None
    dphi_c: float | None = None

    def __post_init__(self):
        checks = {
            "phi0": self.phi0 < 0,
            "d0": self.d0 > 0,
            "E": self.E > 0,
            "sigma_c": self.sigma_c > 0,
            "e_c": 0 < self.e_c < 1,
            "sigma_t": self.sigma_t > 0,
            "e_t": 0 < self.e_t < 1,
        }
        for name, ok in checks.items():
            value = getattr(self, name)
            if not (ok and math.isfinite(value)):
                raise ValueError(f"{self.name}: {name} = {value!r} is out of range")

    @property
    def c0(self) -> float:
        """Lattice parameter c_0 = 4 d_0 [m]."""
        return 4 * self.d0


def paper_crystal(name: str) -> Crystal:
    """One of the crystals of Part III, Tables 1-2 (with Delta Phi from the text after eq. 16)."""
    t1, t2 = data.TABLE1[name], data.TABLE2[name]
    dt, dc = data.DEFORMATION_ENERGY[name]
    return Crystal(
        name=name,
        phi0=t1.phi0,
        d0=t1.d0,
        E=t2.E2 * data.GPa,
        sigma_c=t2.sigma1 * data.GPa,
        e_c=t2.e1,
        sigma_t=t2.sigma2 * data.GPa,
        e_t=t2.e2,
        dphi_t=dt * data.RY_PER_BOHR2,
        dphi_c=dc * data.RY_PER_BOHR2,
    )
