"""Transition criteria in terms of the nose's own load: the stress the nose puts into the rod.

The mean axial stress a rigid nose puts into its shank at striking velocity U is the nose force
over the shank area, sigma_n(U) = F(U) / (pi a^2) = s_0 + q(U), a static part s_0 (the target's
quasi-static resistance) and a dynamic part q(U) that carries the nose geometry:

* ``part1`` -- Part I, eq. (11) with the deep-limit coefficients of the actual nose (eq. (32)):
  s_0 = Cbar R_t and q(U) = rho_t Bbar U^2 / 2, Bbar = 4B/(pi d^2) (the seed quotes Bbar = 0.58
  for the hemisphere and 0.11 for the 3-CRH ogive, section 2 after eq. (36)).  This is the load of
  the critical velocity U_sC of Part I, eqs. (33)/(36), where the rod yields once
  rho_t Bbar U^2 / 2 = Ybar_p - Rbar_t.
* ``forrestal`` -- the spherical cavity-expansion law of Forrestal's model (Warren & Forrestal
  1998, three-term; Forrestal et al. 1995 two-term) integrated over the nose with the nose factors
  N_1 = int n_x^2 dS/(pi a^2) and N_2 = int n_x^3 dS/(pi a^2) (:func:`.peers.nose_factors`; N_2 is
  Chen & Li's (2002) nose factor N*): s_0 = A Y and q(U) = B N_1 sqrt(rho_t Y) U + C N_2 rho_t U^2.
  Chen & Li (2002, Int. J. Impact Eng. 27:619) use this load over the shank area to state when
  the rigid-projectile assumption holds (the nose force must stay below the rod's strength).
* ``tip`` -- Tate's (1967) interface pressure of a flat-ended rod, q(U) = rho_t U^2 / 2: the same
  for every nose (no geometry; the earlier ``meyer_tip`` onset).  Kept for comparison: it cannot
  order the noses.

Criterion (this project's own reading of Part I's eq. (36) and of Tate's criterion; labelled
``nose_meyer``): the rod passes a transition when the dynamic load of its nose reaches a fixed
fraction kappa of the rod's strength surplus over the target's static resistance,

    q(U_j) = kappa (S_j - s_0),   S_y = H_M (onset),  S_b = b H_M (breakup),  S_e = e H_M (erosion)

with H_M the rod's static Meyer hardness (:func:`.hardness.meyer_hardness_from_vickers`).  In
Part I's terms (q = rho_t Bbar U^2/2, s_0 = Rbar_t) the onset is eq. (36) with the reduced
strength Ybar_p = Rbar_t + kappa (H_M - Rbar_t); for the ``tip`` load and kappa = 1 it is Tate's
tip pressure against the Meyer hardness.  One kappa for every nose: a blunter nose (larger
Bbar, or N_1 and N_2) reaches the same load at a lower U, so its transitions come earlier,
monotone in the nose load.  kappa, b and e are fitted on the ogive shots.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["NOSE_LOADS", "NoseLoad", "load_velocity", "nose_load_of"]

NOSE_LOADS = ("part1", "forrestal", "tip")


@dataclass(frozen=True)
class NoseLoad:
    """sigma_n(U) = static + linear U + quadratic U^2 [Pa] (module docstring), one nose and target."""

    kind: str
    static: float
    linear: float
    quadratic: float

    def dynamic(self, U):
        """q(U) = linear U + quadratic U^2 [Pa]."""
        U = np.asarray(U, float)
        return (self.linear * U + self.quadratic * U**2)[()]

    def stress(self, U):
        """sigma_n(U) = static + q(U) [Pa]: the mean axial stress the nose puts into the shank."""
        return (self.static + self.dynamic(U))[()]


def load_velocity(level, linear, quadratic):
    """U >= 0 with linear U + quadratic U^2 = level (closed form, vectorised; 0 where level <= 0,
    inf where the load never grows).  The root is written as 2 level / (linear + sqrt(...)), free
    of cancellation when the linear term dominates."""
    lv, l1, q2 = np.broadcast_arrays(*(np.asarray(x, float) for x in (level, linear, quadratic)))
    disc = np.sqrt(l1**2 + 4.0 * q2 * np.maximum(lv, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        U = np.where(lv > 0, 2.0 * lv / (l1 + disc), 0.0)
    U = np.where((lv > 0) & (l1 + disc <= 0), np.inf, U)
    return U[()]


def nose_load_of(kind: str, *, Bbar: float, Cbar: float, resistance: float, target_density: float,
                 cavity=None, N1: float | None = None, N2: float | None = None) -> NoseLoad:
    """The nose load of ``kind`` (:data:`NOSE_LOADS`) from Part I's deep-limit coefficients (Bbar,
    Cbar, R_t) or the cavity-expansion law ``cavity`` (a :class:`.peers.CavityLaw`) with the nose
    factors N_1, N_2."""
    rho = float(target_density)
    if kind == "part1":
        return NoseLoad(kind, float(Cbar) * float(resistance), 0.0, rho * float(Bbar) / 2.0)
    if kind == "forrestal":
        if cavity is None or N1 is None or N2 is None:
            raise ValueError("the forrestal nose load needs the cavity law and N1, N2")
        Y = cavity.yield_stress
        return NoseLoad(kind, cavity.A * Y, cavity.B * N1 * math.sqrt(rho * Y), cavity.C * N2 * rho)
    if kind == "tip":
        return NoseLoad(kind, float(resistance), 0.0, rho / 2.0)
    raise ValueError(f"unknown nose load {kind!r}")


def transition_velocity(kappa, strength, load_static, load_linear, load_quadratic):
    """U_j of the ``nose_meyer`` criterion: q(U_j) = kappa (S_j - s_0) (module docstring);
    vectorised (kappa, S_j and the load coefficients broadcast)."""
    level = np.asarray(kappa, float) * (np.asarray(strength, float) - np.asarray(load_static, float))
    return load_velocity(level, load_linear, load_quadratic)
