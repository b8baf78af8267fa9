"""Critical impact velocity of an elastic projectile, Part I, eqs. (31)-(36), longitudinal
buckling (Fig. 4) and the inverse problem (Appendix).

The projectile starts to yield when the peak axial stress sigma_0 = 4N/(pi d^2) reaches its
dynamic yield stress Y_p (eq. (31)).  With constant (deep-limit) A, B, C and the largest
velocity U_s - Y_p c_0/E_p at the start (eq. (26)):

    U_sC = Y_p c_0/E_p + sqrt( (2/(rho Bbar)) (Ybar_p - Rbar_t) )   if Ybar_p >= Rbar_t   (33)/(36)
    U_sC = Y_p c_0/E_p                                              otherwise             (34)
    U_sC = inf (no real root)                     if Ybar_p >= Rbar_t and Bbar <= 0
    Ybar_p = (1 + rho A/m) Y_p,  Rbar_t = Cbar R_t,  Bbar = 4B/(pi d^2)                   (35)

With loss of stability, Y_p is replaced everywhere by Y_c = phi(lambda) Y_p, lambda = 4L/d
(section 2, Fig. 4).  phi: "none" (phi = 1), "johnson-euler" (a standard column curve,
below) or a user table [[lambda, phi], ...] (linear interpolation, constant beyond the ends).

Johnson-Euler column curve (J. B. Johnson's parabola joined tangentially to Euler's
hyperbola; e.g. Timoshenko & Gere, Theory of Elastic Stability, or any machine-design text),
for a pin-ended column of slenderness lambda = L/r_g (r_g = d/4 for a solid circular rod,
so lambda = 4L/d):
    phi = 1 - Y_p lambda^2 / (4 pi^2 E_p)      for lambda <= lambda_e = pi sqrt(2 E_p / Y_p)
    phi = pi^2 E_p / (lambda^2 Y_p)            for lambda >  lambda_e  (Euler)
phi = 1/2 at lambda_e, where both branches and their slopes meet.

No real root.  Eq. (33) needs Bbar > 0: the axial stress grows with the velocity only through
the velocity term rho B u^2 of eq. (11).  The ``bernoulli`` reading of B (B = dA/dP) vanishes
at depth (the table's deep B is round-off, |Bbar| ~ 1e-9, of either sign): then the stress at
the start never exceeds Rbar_t, and with Ybar_p >= Rbar_t the projectile yields at no striking
velocity.  :func:`critical_velocity` returns ``math.inf`` (stated by
:func:`no_real_root_reason`, which ``penetrate`` prints on stderr); the inverse problem has no
solution and raises InputError naming ``coefficients.reading``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from semianalytic.errors import InputError

__all__ = [
    "slenderness",
    "johnson_euler_phi",
    "table_phi",
    "buckling_factor",
    "reduced_strengths",
    "critical_velocity",
    "yield_stress_from_critical_velocity",
    "CriticalInputs",
    "no_real_root_reason",
]


def slenderness(length: float, diameter: float) -> float:
    """lambda = 4L/d (Part I, section 2: L/r_g of a solid rod, r_g = d/4)."""
    return 4.0 * length / diameter


def johnson_euler_phi(lam, youngs_modulus: float, yield_stress: float):
    """Buckling factor phi = Y_c / Y_p of the Johnson-Euler column curve (module docstring)."""
    lam = np.asarray(lam, float)
    lam_e = math.pi * math.sqrt(2.0 * youngs_modulus / yield_stress)
    johnson = 1.0 - yield_stress * lam**2 / (4.0 * math.pi**2 * youngs_modulus)
    with np.errstate(divide="ignore"):
        euler = math.pi**2 * youngs_modulus / (lam**2 * yield_stress)
    return np.where(lam <= lam_e, johnson, euler)[()]


def table_phi(lam, table) -> float:
    """phi(lambda) from a user table [[lambda, phi], ...] (linear, constant beyond the ends)."""
    tab = np.asarray(table, float)
    if tab.ndim != 2 or tab.shape[1] != 2 or len(tab) < 2:
        raise InputError("projectile.buckling_table", "needs at least two [lambda, phi] pairs")
    if np.any(np.diff(tab[:, 0]) <= 0):
        raise InputError("projectile.buckling_table", "lambda must increase strictly")
    if np.any(tab[:, 1] <= 0) or np.any(tab[:, 1] > 1):
        raise InputError("projectile.buckling_table", "phi must lie in (0, 1]")
    return np.interp(lam, tab[:, 0], tab[:, 1])[()]


def buckling_factor(kind: str, lam: float, youngs_modulus: float, yield_stress: float, table=None) -> float:
    """phi for ``kind`` in {"none", "johnson-euler", "table"} (Part I, section 2, Fig. 4)."""
    if kind == "none":
        return 1.0
    if kind == "johnson-euler":
        return float(johnson_euler_phi(lam, youngs_modulus, yield_stress))
    if kind == "table":
        if table is None:
            raise InputError("projectile.buckling_table", "buckling = 'table' needs buckling_table = [[lambda, phi], ...]")
        return float(table_phi(lam, table))
    raise InputError("projectile.buckling", f"must be 'none', 'johnson-euler' or 'table'; got {kind!r}")


def reduced_strengths(Y_p: float, R_t: float, *, A: float, C: float, mass: float, diameter: float, target_density: float):
    """(Ybar_p, Rbar_t) of Part I, eq. (35): Ybar_p = (1 + rho A / m) Y_p, Rbar_t = Cbar R_t.

    The paper writes rho A/m = rho Abar/(rho_p L) for a cylinder; the projectile's actual mass
    is used here (pass m = rho_p pi d^2 L / 4 to reproduce the paper's cylinder).
    """
    area = math.pi * diameter**2 / 4.0
    return (1.0 + target_density * A / mass) * Y_p, (C / area) * R_t


@dataclass(frozen=True)
class CriticalInputs:
    """Everything eq. (33) needs besides Y_p (SI): E_p, rho_p, mass, d, A, B, C (deep limit),
    target density rho and resistance R_t."""

    youngs_modulus: float
    density: float
    mass: float
    diameter: float
    A: float
    B: float
    C: float
    target_density: float
    resistance_pa: float

    @property
    def c0(self) -> float:
        return math.sqrt(self.youngs_modulus / self.density)


def critical_velocity(Y_p: float, inputs: CriticalInputs, phi: float = 1.0) -> float:
    """U_sC of Part I, eqs. (33)/(36) [m/s], with Y_p -> phi Y_p under loss of stability."""
    Yc = phi * Y_p
    c = inputs
    area = math.pi * c.diameter**2 / 4.0
    Ybar, Rbar = reduced_strengths(Yc, c.resistance_pa, A=c.A, C=c.C, mass=c.mass, diameter=c.diameter, target_density=c.target_density)
    elastic = Yc * c.c0 / c.youngs_modulus
    if Ybar < Rbar:  # eq. (34): the target is as strong as the projectile or stronger
        return elastic
    Bbar = c.B / area
    if not Bbar > 0:  # no velocity term: the stress never reaches Ybar_p (module docstring, "No real root")
        return math.inf
    return elastic + math.sqrt(2.0 / (c.target_density * Bbar) * (Ybar - Rbar))


def no_real_root_reason(inputs: CriticalInputs) -> str | None:
    """Why eq. (33) has no real root for these inputs (deep Bbar <= 0), or None when it has one."""
    Bbar = inputs.B / (math.pi * inputs.diameter**2 / 4.0)
    if Bbar > 0:
        return None
    return (f"eq. (33) has no real root: the deep drag coefficient Bbar = {Bbar:.2g} is not positive (the "
            "'bernoulli' reading B = dA/dP vanishes at depth), so the axial stress never grows with the velocity and "
            "no yielding is predicted at any striking velocity (U_sC = inf); use [coefficients] reading = 'body' "
            "or 'literal' for U_sC")


def yield_stress_from_critical_velocity(U_sC: float, inputs: CriticalInputs, phi=1.0) -> float:
    """The inverse problem of the Appendix: the dynamic yield stress Y_p [Pa] for which
    eq. (33) gives the measured U_sC.  ``phi`` is a number or a callable phi(Y_p) (the
    Johnson-Euler factor depends on Y_p).  U_sC increases with Y_p wherever phi Y_p does."""
    if not (np.isfinite(U_sC) and U_sC > 0):
        raise InputError("critical_velocity", f"must be positive; got {U_sC!r}")
    reason = no_real_root_reason(inputs)
    if reason is not None:
        raise InputError("coefficients.reading", f"the dynamic yield stress cannot be found from U_sC: {reason}")
    def phif(Y):
        return phi(Y) if callable(phi) else phi

    def f(Y):
        return critical_velocity(Y, inputs, phif(Y)) - U_sC
    lo, hi = 1e3, 1e8
    while f(hi) < 0:
        lo, hi = hi, hi * 2.0
        if hi > 1e13:
            raise InputError("critical_velocity", f"{U_sC:g} m/s is not reached by eq. (33) for any yield stress")
    from scipy.optimize import brentq  # only the inverse problem needs it (start-up time)

    return brentq(f, lo, hi, xtol=1e-6, rtol=1e-14)
