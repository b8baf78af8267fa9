"""Pure pieces of the nose-shape optimisation: constraints and objectives (SI floats).

A design changes the nose; the shank then follows the constraint:

- fixed mass m0 (density rho_p given): pi R^2 L_c rho_p + V_nose rho_p = m0, so
  L_c = (m0 / rho_p - V_nose) / (pi R^2); infeasible when the nose alone is heavier than m0;
- fixed total length L0: L_c = L0 - L_h; infeasible when the nose is longer than L0;
- both: L_c = L0 - L_h and the mass is held at m0 (the projectile's density follows);
- none: the starting design's shank length L_c is kept.

Objectives (minimised): ``depth``: minus the mean final depth over the striking velocities
(Part I, eq. (11); rigid, or the elastic projectile with the exact-rod energy, errata item 5);
``deep_drag``: the deep-penetration drag Bbar = 4 B / (pi d^2) (Part I, eq. (13), deep limit),
from :func:`deep_limit` alone (a few BEM solves at depth, not a table from first contact);
``ballistic_limit``: the plate's ballistic limit V_bl (minimised); ``residual_velocity``: minus
the mean residual velocity over the striking velocities (both by Part I, eq. (11) through the
plate: :mod:`semianalytic.perforation`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

OBJECTIVES = ("depth", "deep_drag", "ballistic_limit", "residual_velocity")
PLATE_OBJECTIVES = ("ballistic_limit", "residual_velocity")  # need a plate ([target] thickness or layers)
CONSTRAINTS = ("mass", "length", "caliber")
DEPTH_MODELS = ("rigid", "exact-rod")


class Infeasible(ValueError):
    """The design cannot meet a constraint (the message says which and why)."""

    def __init__(self, constraint: str, message: str):
        super().__init__(message)
        self.constraint = constraint


@dataclass(frozen=True)
class ShankChoice:
    """The cylindrical length L_c [m] and the mass override [kg] (None: density x volume)."""

    shank_length: float
    mass: float | None


def shank_for_constraints(
    nose_volume: float,
    nose_length: float,
    diameter: float,
    *,
    start_shank: float,
    density: float | None,
    mass: float | None = None,
    length: float | None = None,
) -> ShankChoice:
    """The shank that meets the constraints (see the module docstring).

    ``mass``: fixed total mass m0 [kg] (needs ``density`` unless ``length`` is fixed too);
    ``length``: fixed total length L0 [m].  Raises :class:`Infeasible`.
    """
    area = math.pi * (0.5 * diameter) ** 2
    if length is not None:
        shank = length - nose_length
        if shank < -1e-12 * length:
            raise Infeasible("length", f"the nose (L_h = {nose_length * 1e3:.4g} mm) is longer than the fixed length "
                                       f"{length * 1e3:.4g} mm")
        return ShankChoice(max(shank, 0.0), mass)
    if mass is not None:
        if density is None:
            raise Infeasible("mass", "a fixed mass with a free length needs projectile.density")
        shank = (mass / density - nose_volume) / area
        if shank < 0:
            raise Infeasible("mass", f"the nose alone weighs {density * nose_volume * 1e3:.4g} g, more than the fixed "
                                     f"mass {mass * 1e3:.4g} g")
        return ShankChoice(shank, None)
    return ShankChoice(start_shank, None)


@dataclass(frozen=True)
class DeepLimit:
    """A, B (three readings), C of the deep-penetration limit P -> infinity (SI), with the
    extrapolation's error estimate per coefficient and the depths solved."""

    values: dict
    errors: dict
    depths: tuple[float, ...]

    @property
    def solves(self) -> int:
        return len(self.depths)


def deep_limit(nose, *, order: int = 8, refinement: float = 0.3, levels: int = 6, tolerance: float = 1e-5,
               max_depth_nose_lengths: float = 300.0, max_solves: int = 24, strict: bool = True) -> DeepLimit:
    """The deep-penetration limit of A, B, C alone (Part I, eqs. (12)-(14) as P -> infinity).

    The same rule as the deep piece of a certified table
    (:mod:`semianalytic.coefficients.table`): direct solves at P = b / v past the last
    breakpoint b, for v = 2^-3 .. 2^-6 (the table's four deepest initial knots, fewer when
    ``max_depth_nose_lengths`` is shallower than 64 b), the limit
    extrapolated to v = 0 by the polynomial through them, its error the change from dropping
    the farthest point; deeper solves (v halved) until that error is within half the
    tolerance of each coefficient's magnitude over these solves (the three readings of B
    share one scale: B_bernoulli = dA/dP vanishes at depth).  Only these depths are solved (the objective
    ``deep_drag`` reads nothing else); raises ValueError past ``max_depth_nose_lengths``
    (``strict=False``, the case's fixed depth grid: stops there, the error estimate kept).
    """
    from semianalytic.bem.panels import LayoutOptions
    from semianalytic.coefficients.table import CONTROLLED, _extrapolate_to_zero, depth_pieces, solve_depth

    pieces, kinks = depth_pieces(nose)
    deep = pieces[-1]
    opts = LayoutOptions(order, refinement, levels)
    P_max = max_depth_nose_lengths * nose.depth_unit
    names = CONTROLLED + ("phi_tip",)
    vs, rows = [], []

    def solve(v: float) -> None:
        P = float(deep.P(v))
        if P > P_max * (1 + 1e-12):
            raise ValueError(f"the deep limit needs solves to {P / nose.depth_unit:.4g} nose lengths, beyond "
                             f"max_depth_nose_lengths = {max_depth_nose_lengths:g}")
        d = solve_depth(nose, P, opts, kinks)
        vs.append(v)
        rows.append({k: getattr(d, k) for k in names})

    # the table's initial deep knots: v = 1, 1/2, .., 2^-n with n = min(6, log2(P_max / b)); the four deepest
    n = int(min(6, math.floor(math.log2(P_max / deep.P_lo)))) if P_max > deep.P_lo else 0
    for k in range(max(n - 3, 0), n + 1):
        solve(2.0**-k)
    while True:
        v = np.array(vs[-4:])
        values, errors = {}, {}
        for name in names:
            val, err, _, _ = _extrapolate_to_zero(v, np.array([r[name] for r in rows[-4:]]))
            values[name], errors[name] = val, err
        values["C"], errors["C"] = math.pi * nose.radius**2, 0.0  # exact once the nose is in
        scale = {q: max([abs(values[q])] + [abs(r[q]) for r in rows]) or 1.0 for q in CONTROLLED}
        b_scale = max(scale[q] for q in CONTROLLED if q.startswith("B_"))  # B_bernoulli = dA/dP -> 0 at depth
        scale.update({q: b_scale for q in CONTROLLED if q.startswith("B_")})
        if all(errors[q] <= 0.5 * tolerance * scale[q] for q in CONTROLLED) or len(vs) >= max_solves:
            break
        if not strict and float(deep.P(0.5 * vs[-1])) > P_max * (1 + 1e-12):
            break  # a fixed depth range (``strict=False``): the limit with its error estimate, as the table does
        solve(0.5 * vs[-1])
    return DeepLimit(values, errors, tuple(float(deep.P(v)) for v in vs))


# The depth objective's tables (this project's own rule): knots per smooth piece of the depth axis
# while searching, and on the finer table that confirms the optimum.  Measured on the power-law
# noses n = 0.5, 0.74, 0.9 of cases/optimize_power_into_fig15a.toml against a certified table at
# tolerance 1e-6 (2026-11-26): 4 knots per piece: rigid depths within 1e-5 relative (15 depth
# solves); 8 knots per piece: within 4e-7 (the fixed 40-depth table of the case to 60 nose lengths: 3e-6).
SEARCH_KNOTS_PER_PIECE = 4
CONFIRM_KNOTS_PER_PIECE = 8
# range of the depth objective's table: P_max = DEPTH_MARGIN x (deep-limit estimate of the deepest
# final depth) + DEPTH_MARGIN_NOSES x L_h.  The deep-limit coefficients overstate the drag while the
# nose enters, so the estimate falls short by less than one nose length (measured: 0.5-0.65 L_h on
# the noses above); P_max is then past every final depth, checked after the solve.
DEPTH_MARGIN = 1.1
DEPTH_MARGIN_NOSES = 2.0


def depth_range(deep_estimate: float, nose_length: float) -> float:
    """P_max [m] of the depth objective's table from the deepest final depth [m] computed with
    the deep-limit coefficients (Part I, eq. (11) with A, B, C constant): this project's own margin
    (:data:`DEPTH_MARGIN`, :data:`DEPTH_MARGIN_NOSES`)."""
    return DEPTH_MARGIN * float(deep_estimate) + DEPTH_MARGIN_NOSES * float(nose_length)


def depth_knots(nose, P_max: float, per_piece: int) -> list[float]:
    """The depths [m] of a coefficient table over [0, P_max] alone (this project's own rule): on
    every smooth piece of the depth axis of :func:`semianalytic.coefficients.table.depth_pieces`
    (cut at the nose's breakpoints, each in its own interpolation variable v), ``per_piece``
    depths equally spaced in v inside the piece (its ends are the table's own knots); on the deep
    piece (v = l/P) ``per_piece`` depths equally spaced in v from v(P_max) to 1, nothing deeper
    (the depth objective reads A, B, C only down to the final depth, below P_max)."""
    from semianalytic.coefficients.table import depth_pieces

    if per_piece < 2:
        raise ValueError("per_piece must be at least 2")
    pieces, _ = depth_pieces(nose)
    out: list[float] = []
    for p in pieces[:-1]:
        hi = min(p.P_hi, P_max)
        if hi <= p.P_lo:
            continue
        vs = np.linspace(float(p.v(p.P_lo)), float(p.v(hi)), per_piece + 2)[1:-1]
        out += [float(p.P(v)) for v in vs]
    deep = pieces[-1]
    if P_max > deep.P_lo:
        vs = np.linspace(1.0, float(deep.v(P_max)), per_piece + 1)[1:]
        out += [float(deep.P(v)) for v in vs]
    return sorted(set(out))


# The known result the power-law and spline designs are compared with: the minimum-drag body of
# revolution of given length and base diameter under Newtonian impact theory (no friction) is
# close to the power law r ~ x^(3/4) (Eggers, Resnikoff & Dennis 1957, "Bodies of revolution
# having minimum drag at high supersonic airspeeds", NACA Report 1306; the exact Newtonian optimum
# has a small flat tip and lies within a few per cent of the 3/4-power body).
NEWTONIAN_MIN_DRAG_EXPONENT = 0.75
NEWTONIAN_SOURCE = ("Eggers, Resnikoff & Dennis (1957), NACA Report 1306: the Newtonian minimum-drag body of given "
                    "length and base diameter, close to the 3/4-power law")


def fitted_exponent(xi, r, nose_length: float, radius: float) -> float:
    """The exponent n of the power law r = R (xi/L_h)^n nearest a nose meridian in the least-squares
    sense over the points (xi, r) [m] (this project's own comparison measure: the power law a free-form
    nose is closest to, compared with the known optimum exponents)."""
    from scipy.optimize import minimize_scalar

    xi, r = np.asarray(xi, float) / nose_length, np.asarray(r, float) / radius
    keep = (xi > 0) & (xi <= 1)
    xi, r = xi[keep], r[keep]
    res = minimize_scalar(lambda n: float(np.sum((r - xi**n) ** 2)), bounds=(0.05, 1.5), method="bounded",
                          options={"xatol": 1e-8})
    return float(res.x)


def depth_objective(depths) -> float:
    """Minus the mean final depth [m] over the striking velocities (minimised = deepest on average)."""
    d = np.asarray(depths, float)
    if d.size == 0 or not np.all(np.isfinite(d)):
        return math.inf
    return -float(np.mean(d))


def deep_drag(B_deep: float, diameter: float) -> float:
    """Bbar = 4 B / (pi d^2) of the deep-penetration limit (Part I, eq. (13) normalised as in Fig. 8)."""
    return float(B_deep) / (math.pi * 0.25 * diameter**2)


def quantise(x, low, high, resolution: float):
    """Round each design variable to ``resolution`` of its range (repeat designs hit the caches)."""
    x, low, high = (np.asarray(v, float) for v in (x, low, high))
    step = resolution * (high - low)
    q = low + np.round((x - low) / step) * step
    return np.clip(q, low, high)


def confirmation_grid(best, low, high, n: int, half_width: float):
    """A grid of n points per variable over best +- half_width x range (clipped to the bounds):
    list of points and the grid spacing per variable."""
    best, low, high = (np.asarray(v, float) for v in (best, low, high))
    h = half_width * (high - low)
    lo, hi = np.maximum(best - h, low), np.minimum(best + h, high)
    axes = [np.linspace(a, b, n) for a, b in zip(lo, hi)]
    mesh = np.meshgrid(*axes, indexing="ij")
    pts = np.column_stack([m.ravel() for m in mesh])
    spacing = (hi - lo) / max(n - 1, 1)
    return pts, spacing
