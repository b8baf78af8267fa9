"""Energy of plastic deformation around the penetration channel (Part IV, section 6, eqs. (15)-(17)).

A target section is split into regions i of nearly constant hardness H_i (the maps of Figs. 2,
4, 5).  Region i, of meridian area S_i whose centroid lies at distance R_i from the channel
axis, is a ring of volume 2 pi R_i S_i (Pappus); with the plastic work per unit volume U_i:

    w_i = 2 pi R_i S_i U_i                      (15)
    U_i = H_i eps_pi / 3                        (16)   (mean hardness and plastic strain)
    w_p = sum_i w_i                             (17)

and the projectile's kinetic energy w_k = m v^2 / 2 (Table 5).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

__all__ = ["Region", "plastic_work_density", "region_energy", "plastic_energy", "kinetic_energy"]


@dataclass(frozen=True)
class Region:
    """One region of a hardness map: centroid distance R [m] from the axis, meridian area
    S [m^2], mean hardness H [Pa] and mean plastic strain eps_p [-]."""

    centroid_radius: float
    area: float
    hardness: float
    plastic_strain: float


def plastic_work_density(H, eps_p):
    """U = H eps_p / 3 [J/m^3] (Part IV, eq. (16))."""
    return H * eps_p / 3.0


def region_energy(region: Region) -> float:
    """w_i = 2 pi R_i S_i U_i [J] (Part IV, eq. (15))."""
    return 2.0 * math.pi * region.centroid_radius * region.area * plastic_work_density(
        region.hardness, region.plastic_strain)


def plastic_energy(regions: Iterable[Region]) -> float:
    """w_p = sum of w_i over the regions [J] (Part IV, eq. (17))."""
    return float(sum(region_energy(r) for r in regions))


def kinetic_energy(mass, velocity):
    """w_k = m v^2 / 2 [J] (Part IV, Table 5)."""
    return 0.5 * mass * velocity**2
