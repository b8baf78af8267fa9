"""One depth curve over the whole velocity range: rigid, deforming and eroding projectiles.

Regimes of a projectile of dynamic yield stress Y_p striking a target of resistance R_t at U_s:

* ``rigid``      U_s < U_y: the projectile stays elastic; Part I's rigid/elastic projectile
                 (eq. (11); eqs. (26), (29)/(30')) gives the depth.  U_y is the critical impact
                 velocity U_sC of Part I, eqs. (33)/(36): the axial stress at the start reaches Y_p.
* ``deforming``  U_y <= U_s < U_e: the nose yields (mushrooms, bends, the rod may turn round)
                 but the projectile is not consumed.  No model of the band is claimed: the depth
                 lies between the eroding rod's (a projectile that loses mass as it penetrates)
                 and the Part I one (a nose that keeps its shape penetrates deepest).  The
                 regime-aware depth reports the Part I depth, the upper bound (the safe side for
                 a protection designer), flagged outside its validity; the eroding depth is
                 reported beside it as the lower bound.
* ``eroding``    U_s >= U_e: the Alekseevskii-Tate eroding rod (below) gives the depth.

Erosion onset U_e.  The Alekseevskii-Tate rod of the projectile's mass erodes to a residual
length L_r(U_s) that falls as U_s grows.  The projectile counts as eroding once the model
consumes it down to less than its nose length l_n: the whole shank has flowed away and what is
left is a stub, not a penetrator that keeps its identity.  U_e is the lowest U_s >= U_y with
L_r(U_s) <= l_n (erosion needs a yielding nose, so never below U_y):

    L_r(U_*) = l_n,   U_e = max(U_y, U_*).

This criterion is this project's own, not the paper's (``nose_length`` of
:data:`EROSION_CRITERIA`); on the bundled VAR 4340 shots it puts the depth drop between the last
deep shot (1493 m/s, 277 mm) and the first shallow one (1585 m/s, 105 mm); the transfer between
steels does not choose it (reports/validation_regimes.md).

Alekseevskii-Tate (Alekseevskii 1966, Tate 1967; Part IV, eq. (1) for the rigid phase):
rho_p L dv/dt = -Y_p, dL/dt = -(v - u), dP/dt = u,
(1/2) rho_p (v - u)^2 + Y_p = (1/2) rho_t u^2 + R_t.  With v as the independent variable
(dt = -rho_p L dv / Y_p) it is a quadrature, used here for all striking velocities and strengths at once:

    ln(L_0 / L(v)) = k [I(U_s) - I(v)],    I(v) = int (w - u(w)) dw,   k = rho_p / Y_p
    P_erosion(U_s) = k L_0 int_{v_e}^{U_s} u(w) exp(-k [I(U_s) - I(w)]) dw

where v_e ends erosion: u = v at v_e = sqrt(2 (Y_p - R_t)/rho_t) if Y_p > R_t (the residual
rod then penetrates rigidly, P += rho_p L_r / rho_t ln(1 + rho_t v_e^2 / (2 R_t)), Part IV
eq. (3)), or u = 0 at v_e = sqrt(2 (R_t - Y_p)/rho_p) if Y_p < R_t (the rest erodes on the
crater floor).  I(v) has a closed form (:func:`tate_integral`); the depth integral is Gauss-Legendre
in s, w = v_e + (U_s - v_e) s^2 (8 panels of 16 points; u(w) ~ sqrt(w - v_e) near v_e becomes smooth
in s).  The rod is the cylinder of the projectile's mass and diameter (mass is what
erodes; for the Piekutowski ogive this is 65.6 mm against the 71.1 mm overall length).
The one home of the Alekseevskii-Tate equations (issue 39): :func:`.peers.tate_penetration` returns this
quadrature; the independent check is a time integration in tests/tate_reference.py.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from semianalytic.ballistic_limit.theory import stop_time
from semianalytic.errors import InputError

__all__ = [
    "REGIMES",
    "ErodingDepth",
    "eroding_rod_length",
    "eroding_depth",
    "eroding_depth_per_length",
    "tate_integral",
    "erosion_onset_velocity",
    "classify_regimes",
    "regime_depth",
]

REGIMES = ("rigid", "deforming", "eroding")

_GX, _GW = np.polynomial.legendre.leggauss(16)


@dataclass(frozen=True)
class ErodingDepth:
    """Alekseevskii-Tate outcome per striking velocity (arrays, SI): depth [m], residual rod
    length [m], the velocity v_e at which erosion ends [m/s] and whether the rod eroded."""

    depth: np.ndarray
    residual_length: np.ndarray
    erosion_end_velocity: float
    eroded: np.ndarray


def tate_interface_velocity(v, rho_p, Y_p, rho_t, R_t):
    """Penetration velocity u of the eroding rod from (1/2) rho_p (v-u)^2 + Y_p = (1/2) rho_t u^2 + R_t
    (Tate 1967; the root with u <= v; 0 where the target does not yield).  The one home of the
    interface balance (:func:`.peers.tate_penetration` and the quadrature below use it)."""
    v = np.asarray(v, float)
    if math.isclose(rho_p, rho_t, rel_tol=1e-12):
        u = 0.5 * v + (Y_p - R_t) / (rho_p * v)
    else:
        disc = rho_p * rho_t * v**2 + 2.0 * (rho_p - rho_t) * (R_t - Y_p)
        u = (rho_p * v - np.sqrt(np.maximum(disc, 0.0))) / (rho_p - rho_t)
    return np.clip(u, 0.0, v)[()]


def eroding_rod_length(length: float, nose_length: float, diameter: float, density: float, mass: float | None = None) -> float:
    """Length [m] of the eroding cylinder: the projectile's mass on its diameter, m / (rho_p pi d^2/4);
    without a mass, the overall length.  Raises InputError if the rod is not longer than its nose."""
    for key, val in (("length", length), ("diameter", diameter), ("density", density)):
        if not (math.isfinite(val) and val > 0):
            raise InputError(f"projectile.{key}", f"must be positive; got {val!r}")
    if not nose_length < length:
        raise InputError("projectile.length", f"the rod ({length * 1e3:.4g} mm) must be longer than its nose "
                                              f"({nose_length * 1e3:.4g} mm)")
    if mass is None:
        return float(length)
    if not (math.isfinite(mass) and mass > 0):
        raise InputError("projectile.mass", f"must be positive; got {mass!r}")
    return float(mass / (density * math.pi * diameter**2 / 4.0))


def _erosion_end(rho_p: float, Y_p: float, rho_t: float, R_t: float) -> float:
    """v_e: u = v (Y_p > R_t) or u = 0 (Y_p < R_t) (module docstring; scalar :func:`_erosion_end_array`)."""
    return float(_erosion_end_array(rho_p, Y_p, rho_t, R_t))


def _check_strengths(target_resistance: float, rod_strength: float, target_density: float, density: float):
    for key, val in (("target.resistance.eroding_resistance", target_resistance),
                     ("projectile.dynamic_yield_stress", rod_strength),
                     ("target.density", target_density), ("projectile.density", density)):
        if not (math.isfinite(val) and val > 0):
            raise InputError(key, f"must be positive; got {val!r}")


def tate_integral(v, v_e, rho_p, Y_p, rho_t, R_t):
    """I(v) = int_{v_e}^{v} (w - u(w)) dw of the Alekseevskii-Tate rod in closed form (module
    docstring; u(w) from (1/2) rho_p (w - u)^2 + Y_p = (1/2) rho_t u^2 + R_t).  With
    a = rho_p rho_t, c = 2 (rho_p - rho_t)(R_t - Y_p), S(w) = sqrt(a w^2 + c):
    w - u = (S - rho_t w)/(rho_p - rho_t) and int S dw = w S/2 + c/(2 sqrt a) ln(sqrt a w + S);
    for rho_p = rho_t, w - u = w/2 - (Y_p - R_t)/(rho_p w).  Arrays broadcast (v, v_e, Y_p, R_t)."""
    v, v_e, Y_p, R_t = (np.asarray(x, float) for x in (v, v_e, Y_p, R_t))
    dr = rho_p - rho_t
    if abs(dr) <= 1e-12 * rho_p:
        with np.errstate(divide="ignore", invalid="ignore"):
            log = np.where(v_e > 0, np.log(np.maximum(v, v_e) / v_e), 0.0)
        return 0.25 * (v**2 - v_e**2) - (Y_p - R_t) / rho_p * log
    a = rho_p * rho_t
    sa = math.sqrt(a)
    c = 2.0 * dr * (R_t - Y_p)
    S = np.sqrt(np.maximum(a * v**2 + c, 0.0))
    S_e = np.sqrt(np.maximum(a * v_e**2 + c, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        log = np.where(c != 0.0, np.log((sa * v + S) / (sa * v_e + S_e)), 0.0)
    return (0.5 * (v * S - v_e * S_e) + c / (2.0 * sa) * log - 0.5 * rho_t * (v**2 - v_e**2)) / dr


def _erosion_end_array(rho_p, Y_p, rho_t, R_t):
    """v_e for arrays of Y_p and R_t: sqrt(2 (Y_p - R_t)/rho_t) if Y_p > R_t (u = v), else
    sqrt(2 (R_t - Y_p)/rho_p) (u = 0) (module docstring; Tate 1967)."""
    return np.where(Y_p > R_t, np.sqrt(2.0 * np.abs(Y_p - R_t) / rho_t), np.sqrt(2.0 * np.abs(R_t - Y_p) / rho_p))


# Gauss-Legendre in s on [0, 1] (w = v_e + (U - v_e) s^2), 8 panels of 16 points
_EDGES = np.linspace(0.0, 1.0, 9)
_S = (_EDGES[:-1, None] + 0.5 * (_EDGES[1:] - _EDGES[:-1])[:, None] * (_GX + 1.0)[None, :]).ravel()
_WS = (0.5 * (_EDGES[1:] - _EDGES[:-1])[:, None] * _GW[None, :]).ravel()
_CHUNK = 1 << 20  # quadrature values per block: bounds the memory of a vectorised call (~50 MB)


def eroding_depth_per_length(striking_velocity, *, density: float, target_density: float, target_resistance,
                             rod_strength) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Alekseevskii-Tate depth and residual length per unit rod length L_0 (module docstring),
    vectorised over striking velocities U_s AND strengths: ``striking_velocity``,
    ``target_resistance`` (R_t) and ``rod_strength`` (Y_p) broadcast against each other (the
    depth is proportional to L_0).  Returns (P / L_0, L_r / L_0, eroded) of the broadcast shape.
    The calibration evaluates thousands of (R_t, Y_p) draws at once with it; no check of the
    inputs (see :func:`eroding_depth`).  Accuracy: 1e-8 relative against the time integration for
    k U_s^2 = rho_p U_s^2 / Y_p up to about 500 (a steel rod of Y_p >= 0.15 GPa at 3 km/s); for a much
    weaker rod the erosion is concentrated near U_s and the 128 nodes no longer resolve it (1e-3 at
    k U_s^2 ~ 5000, 0.5 at 5e5)."""
    rho_p, rho_t = float(density), float(target_density)
    U, R, Y = np.broadcast_arrays(*(np.asarray(x, float) for x in (striking_velocity, target_resistance, rod_strength)))
    shape = U.shape
    U, R, Y = U.ravel(), R.ravel(), Y.ravel()
    k = rho_p / Y
    v_e = _erosion_end_array(rho_p, Y, rho_t, R)
    depth = np.zeros(U.shape)
    residual = np.ones(U.shape)
    eroded = U > v_e
    stronger = Y > R
    low = ~eroded & stronger  # rigid rod below v_e, Part IV eq. (3)
    depth[low] = rho_p / rho_t * np.log1p(rho_t * U[low] ** 2 / (2.0 * R[low]))
    low = ~eroded & ~stronger  # u = 0: the rod erodes on the surface without penetrating, L = L0 exp(-k U^2/2)
    residual[low] = np.exp(-0.5 * k[low] * U[low] ** 2)
    idx = np.flatnonzero(eroded)
    step = max(1, _CHUNK // len(_S))
    for b in range(0, len(idx), step):
        j = idx[b : b + step]
        Uj, Rj, Yj, kj, vj = U[j], R[j], Y[j], k[j], v_e[j]
        IU = tate_integral(Uj, vj, rho_p, Yj, rho_t, Rj)
        # P/L0 = k int_{v_e}^{U} u(w) exp(-k (I(U) - I(w))) dw, w = v_e + (U - v_e) s^2
        span = (Uj - vj)[:, None]
        w = vj[:, None] + span * _S[None, :] ** 2
        u = tate_interface_velocity(np.maximum(w, 1e-9 * Uj[:, None]), rho_p, Yj[:, None], rho_t, Rj[:, None])
        Iw = tate_integral(w, vj[:, None], rho_p, Yj[:, None], rho_t, Rj[:, None])
        integrand = u * np.exp(-kj[:, None] * (IU[:, None] - Iw)) * 2.0 * span * _S[None, :]
        d = kj * (integrand @ _WS)
        lr = np.exp(-kj * IU)
        s_ = Yj > Rj  # the residual rod penetrates rigidly from v_e (Part IV eqs. (2)-(3))
        d[s_] += rho_p * lr[s_] / rho_t * np.log1p(rho_t * vj[s_] ** 2 / (2.0 * Rj[s_]))
        depth[j], residual[j] = d, lr
    return depth.reshape(shape), residual.reshape(shape), eroded.reshape(shape)


def eroding_time_per_length(striking_velocity, *, density: float, target_density: float, target_resistance: float,
                            rod_strength: float):
    """Duration of the Alekseevskii-Tate penetration per unit rod length [s/m] (scalar U_s): from
    dt = -rho_p L dv / Y_p, t / L_0 = (rho_p / Y_p) int_{v_e}^{U} exp(-k (I(U) - I(w))) dw, plus the
    rigid phase of the residual rod of length L_r (Y_p > R_t): Part IV eq. (3)'s stop time from v_e
    (:func:`semianalytic.ballistic_limit.theory.stop_time`).  Below v_e the rod is rigid throughout; with u = 0 (Y_p < R_t, U below the
    stall velocity) the rod erodes on the surface in rho_p U / Y_p."""
    rho_p, rho_t, Y, R = float(density), float(target_density), float(rod_strength), float(target_resistance)
    U = float(striking_velocity)
    k = rho_p / Y
    v_e = float(_erosion_end_array(rho_p, Y, rho_t, R))
    if U <= v_e:
        return stop_time(U, R, rho_t, rho_p, 1.0) if Y > R else rho_p * U / Y  # rigid rod: Part IV eq. (3)
    IU = float(tate_integral(U, v_e, rho_p, Y, rho_t, R))
    w = v_e + (U - v_e) * _S**2
    Iw = tate_integral(w, v_e, rho_p, Y, rho_t, R)
    t = k * float(np.exp(-k * (IU - Iw)) * 2.0 * (U - v_e) * _S @ _WS)
    if Y > R:
        t += stop_time(v_e, R, rho_t, rho_p, math.exp(-k * IU))  # the residual rod, rigid: Part IV eq. (3)
    return t


def eroding_depth(striking_velocity, *, length: float, nose_length: float, diameter: float, density: float,
                  target_density: float, target_resistance: float, rod_strength: float,
                  mass: float | None = None) -> ErodingDepth:
    """Alekseevskii-Tate depth of penetration of an eroding rod (module docstring), vectorised.

    Inputs (SI): striking velocities U_s [m/s]; the projectile's overall length, nose length,
    diameter, density rho_p and optionally its mass (the rod is the cylinder of that mass); the
    target's density rho_t and eroding resistance R_t [Pa]; the rod's dynamic yield stress
    Y_p [Pa].  Below v_e (Y_p > R_t) the rod does not erode: rigid penetration, Part IV eq. (3).
    """
    _check_strengths(target_resistance, rod_strength, target_density, density)
    U = np.atleast_1d(np.asarray(striking_velocity, float))
    if U.size == 0 or np.any(~np.isfinite(U)) or np.any(U <= 0):
        raise InputError("impact.striking_velocities", "must be positive (m/s)")
    L0 = eroding_rod_length(length, nose_length, diameter, density, mass)
    d, r, eroded = eroding_depth_per_length(U, density=density, target_density=target_density,
                                            target_resistance=target_resistance, rod_strength=rod_strength)
    return ErodingDepth(L0 * d, L0 * r, _erosion_end(density, rod_strength, target_density, target_resistance), eroded)


def erosion_onset_velocity(yield_velocity: float, *, length: float, nose_length: float, diameter: float,
                           density: float, target_density: float, target_resistance: float, rod_strength: float,
                           mass: float | None = None) -> float:
    """U_e [m/s] (Alekseevskii-Tate rod equations, with U_y from Part I, eqs. (33)/(36)): the
    lowest U_s >= U_y at which the eroding rod is consumed down to its nose
    length, or to its radius where the nose is shorter (module docstring).  NaN if U_y is not
    finite (no yielding predicted)."""
    from scipy.optimize import brentq

    _check_strengths(target_resistance, rod_strength, target_density, density)
    if not math.isfinite(yield_velocity):
        return math.nan
    L0 = eroding_rod_length(length, nose_length, diameter, density, mass)
    rho_p, Y_p, rho_t, R_t = density, rod_strength, target_density, target_resistance
    v_e = _erosion_end(rho_p, Y_p, rho_t, R_t)
    # L_r(U) = L0 exp(-k I(U)) = l_n  <=>  I(U) = ln(L0 / l_n) / k, I increasing
    # a nose shorter than the radius (flat, blunted) counts as one radius long: the rod has lost
    # its nose region once consumed to within a radius of its end (sphere and ogives unchanged)
    l_n = max(nose_length, 0.5 * diameter)
    if not l_n < L0:
        return math.inf
    target = math.log(L0 / l_n) * Y_p / rho_p

    def gap(v):
        return float(tate_integral(v, v_e, rho_p, Y_p, rho_t, R_t)) - target

    v_hi = max(2.0 * v_e, 4000.0)
    while gap(v_hi) < 0:
        v_hi *= 2.0
        if v_hi > 1e6:
            return math.inf
    onset = brentq(gap, v_e, v_hi, xtol=1e-10, rtol=1e-14)
    return float(max(onset, yield_velocity))


def classify_regimes(striking_velocity, yield_velocity: float, erosion_velocity: float) -> list[str]:
    """Regime per striking velocity: rigid below U_y (Part I, eqs. (33)/(36)), eroding from U_e
    (Alekseevskii-Tate), deforming between."""
    U = np.atleast_1d(np.asarray(striking_velocity, float))
    out = []
    for v in U:
        if not (math.isfinite(yield_velocity) and v >= yield_velocity):
            out.append("rigid")
        elif math.isfinite(erosion_velocity) and v >= erosion_velocity:
            out.append("eroding")
        else:
            out.append("deforming")
    return out


def regime_depth(regimes, part1_depth, eroding_depth_m) -> np.ndarray:
    """The regime-aware depth: Part I's in the rigid regime and (as the upper bound) in the
    deforming band, the eroding rod's in the eroding regime."""
    p1 = np.asarray(part1_depth, float)
    er = np.asarray(eroding_depth_m, float)
    return np.where(np.asarray(regimes) == "eroding", er, p1)


# --- published transition criteria and target resistance (issue 22) -------------------------

TABOR_CONSTRAINT = 3.0
"""Constraint factor C of a plastically indented solid: mean contact pressure = C x flow stress,
C ~ 3 for metals (Tabor 1951, The Hardness of Metals, Oxford, ch. 4-5)."""

ONSET_CRITERIA = ("nose_meyer", "part1_usc", "tate_tip", "meyer_tip")
"""Rigid -> deforming.  ``part1_usc``: Part I, eqs. (33)/(36) (the mean axial stress of the
shank reaches Y_p).  ``tate_tip``: Tate's criterion (Tate 1967, J. Mech. Phys. Solids 15:387:
a rod deforms and erodes once the interface pressure (1/2) rho_t U^2 + R_t exceeds its strength)
applied to the nose tip, whose strength as a constrained indenter is C Y_p (Tabor 1951,
C = 3): U_y = sqrt(2 (C Y_p - R_t)/rho_t).  The combination (Tate's pressure against Tabor's
constrained strength of the tip) is this project's reading of the two published relations.
``meyer_tip`` (the default, chosen by transfer): the same pressure against the rod's static Meyer
hardness H_M (:func:`.hardness.meyer_hardness_from_vickers`), the mean pressure at which the tip
indents plastically (Tabor 1951): U_y = sqrt(2 (H_M - R_t)/rho_t), no fitted constant; again this
project's reading of Tate's and Tabor's relations.  ``nose_meyer`` (the default): the dynamic load
of the actual nose reaches kappa (H_M - s_0) (:mod:`.nose_load`, this project's own reading of
Part I's eq. (36) with one fitted kappa for every nose)."""

EROSION_CRITERIA = ("nose_meyer", "tate", "tate_tip_uts", "nose_length")
"""Deforming -> eroding.  ``tate`` (published): Tate (1967): a flat-ended rod of strength Y_p
erodes once (1/2) rho_t U^2 + R_t > Y_p, from U_T = sqrt(2 (Y_p - R_t)/rho_t) (0 if
Y_p <= R_t).  ``tate_tip_uts``: the same pressure against the tip's constrained ultimate
strength C sigma_u (the tip breaks up, not only yields; Tabor 1951, C = 3; sigma_u from the
hardness, Pavlina & Van Tyne 2008, eq. (5)) -- this project's reading, as ``tate_tip``.
``nose_length``: this project's own (:func:`erosion_onset_velocity`: the Alekseevskii-Tate rod
consumed down to its nose length).  ``nose_meyer`` (the default): the nose's dynamic load reaches
kappa (e H_M - s_0) (:mod:`.nose_load`; e fitted, this project's own).  Every criterion starts the eroding regime at
max(U_y, U_e): a nose that does not yield does not erode."""

RESISTANCE_RELATIONS = ("part1", "tate1986")
"""R_t of the eroding rod from the target's properties: ``part1`` = the case's Part I R_t (eq.
(16) for the elastic-plastic target); ``tate1986`` = Tate (1986), Int. J. Mech. Sci. 28:599,
R_t = Y_t (2/3 + ln(0.57 E_t / Y_t)) (:func:`tate_resistance`)."""

ROD_STRENGTHS = ("static_ultimate", "static_yield", "yield", "ultimate")
"""Y_p of the Alekseevskii-Tate rod.  ``static_ultimate`` (default) and ``static_yield``: the rod's
static ultimate strength or yield stress from its hardness (Pavlina & Van Tyne 2008, eqs. (5), (4))
times the eroding rod's own stated factor :data:`ROD_FLOW_FACTOR` (no constant shared with the
transitions).  ``yield`` and ``ultimate``: the dynamic factor f of the legacy onsets times the same
static values (the earlier reading, one constant for two mechanisms)."""

ROD_FLOW_FACTOR = 1.0
"""Y_p / static strength of the eroding rod: 1 (the static strength from the hardness, as Tate
(1967, 1986) takes Y_p from the rod's quasi-static flow stress; no fitted constant)."""

DEFORMING_MODELS = ("part1_upper", "eroding", "breakup", "two_stage")
"""Depth in the deforming band (``two_stage``, the default: the Part I depth of a bent rod that
keeps its nose until the tip pressure reaches b H_M, the eroding rod's beyond; b fitted, this
project's own, :data:`DEFAULT_BREAKUP_FACTOR`): ``part1_upper`` (this project's own reading: the Part I depth of a
nose that keeps its shape, an upper bound); ``eroding`` (the Alekseevskii-Tate rod with its
rigid-rod phase, Tate 1967 / Part IV eqs. (2)-(3), which covers a rod that erodes while it
decelerates and penetrates rigidly below v_e); ``breakup`` (this project's own combination of
the two: the Part I depth while the tip's pressure stays below its constrained ultimate strength,
the tip-UTS velocity of :data:`EROSION_CRITERIA` ``tate_tip_uts``, the eroding rod's above it: a
nose that has yielded keeps penetrating as a slightly bent rigid body until it breaks up)."""


DEFAULT_BREAKUP_FACTOR = 1.15
"""b of the breakup (``deforming = "two_stage"``): the depth drops from Part I's to the eroding rod's
once the tip pressure reaches b x the rod's static Meyer hardness (this project's own criterion;
the onset is b = 1).  1.15: between the posterior medians fitted on each steel of Piekutowski et
al. (1999), each transferring to the other (reports/validation_regimes.md)."""


def tate_erosion_velocity(rod_strength, target_resistance, target_density: float, constraint: float = 1.0):
    """U_T = sqrt(2 (C Y - R_t)/rho_t), 0 where C Y <= R_t: Tate's (1967) criterion
    (1/2) rho_t U^2 + R_t > C Y (C = 1: the flat-ended rod; C = :data:`TABOR_CONSTRAINT`: the
    nose tip as a constrained indenter, see :data:`ONSET_CRITERIA`); vectorised."""
    Y, R = np.asarray(rod_strength, float), np.asarray(target_resistance, float)
    return np.sqrt(np.maximum(2.0 * (constraint * Y - R) / target_density, 0.0))[()]


def breakup_velocity(breakup_factor, meyer_hardness, target_resistance, target_density: float, onset, erosion):
    """U_b [m/s] of ``deforming = "two_stage"`` (this project's own, :data:`DEFORMING_MODELS`): where
    Tate's (1967) tip pressure (1/2) rho_t U^2 + R_t reaches b H_M, kept between the onset U_y and
    the erosion U_e (U_y <= U_b <= U_e); vectorised (b, H_M, R_t, U_y, U_e broadcast)."""
    b, H = np.asarray(breakup_factor, float), np.asarray(meyer_hardness, float)
    return np.clip(tate_erosion_velocity(b * H, target_resistance, target_density), onset, erosion)[()]


def tate_resistance(yield_stress: float, youngs_modulus: float) -> float:
    """R_t [Pa] of Tate (1986), Int. J. Mech. Sci. 28:599-612: R_t = Y_t (2/3 + ln(0.57 E_t/Y_t))
    from the target's yield stress Y_t and Young's modulus E_t."""
    if not (yield_stress > 0 and youngs_modulus > yield_stress):
        raise InputError("target.resistance.yield_stress", "Tate's R_t needs 0 < Y_t < E_t")
    return float(yield_stress * (2.0 / 3.0 + math.log(0.57 * youngs_modulus / yield_stress)))


def regime_codes(striking_velocity, yield_velocity, erosion_velocity) -> np.ndarray:
    """Regime index (0 rigid, 1 deforming, 2 eroding; :data:`REGIMES`) for broadcast arrays of
    U_s, U_y (:data:`ONSET_CRITERIA`) and U_e (:data:`EROSION_CRITERIA`); the vectorised
    :func:`classify_regimes` (NaN or inf U_y: rigid)."""
    U, Uy, Ue = np.broadcast_arrays(*(np.asarray(x, float) for x in (striking_velocity, yield_velocity, erosion_velocity)))
    with np.errstate(invalid="ignore"):
        yields = np.isfinite(Uy) & (U >= Uy)
        erodes = yields & np.isfinite(Ue) & (U >= Ue)
    return np.where(erodes, 2, np.where(yields, 1, 0))
