"""Certified tables of A(P), B(P), C(P) from first contact to P -> infinity (Part I, eqs. (12)-(15), Fig. 8).

The depth axis is cut at the geometric breakpoints, where the coefficients have kinks: P = L_h
(the shoulder reaches the free surface) and the axial positions of the nose's corners and
segment junctions.  Each smooth piece is interpolated in its own variable:

- from first contact to the first breakpoint in v = sqrt(P/l): the coefficients start like
  powers of P (A ~ P^3/2, B ~ P^1/2, C ~ P on a rounded tip, A ~ P^3 on a pointed one), which
  are polynomials in sqrt(P);
- between breakpoints in v = P/l;
- past a breakpoint b where a corner of the meridian enters the target (a cone's shoulder at
  P = L_h) or where two of the nose's segments join, in v = ((P - b)/l)^(1/3) (``graded``; up
  to 2 b past the last breakpoint): there the coefficients change like non-integer powers of
  P - b over many decades (B jumps at a shoulder corner; the corner and its mirror image, or
  the joint and the free-surface edge, are P - b apart and interact), which are smooth in
  that v (the knots crowd b like P - b ~ v^3); in l/P they took about 100 knots;
- beyond the last breakpoint (or the graded piece) in v = l/P, down to v = 0: the deep-penetration limit, which
  the free-surface image approaches like 1/P (errata item 2b), so the coefficients are
  smooth in 1/P there.  The limit is extrapolated from the deepest solves by polynomials in
  1/P, with the difference of two orders as its error estimate; the table is extended
  (deeper solves) until that estimate is within the tolerance; the default range
  (DEFAULT_MAX_DEPTH nose lengths) extends itself as far as that needs (with a warning), a range
  the user set stops with an error naming ``coefficients.max_depth_nose_lengths``.

A is interpolated by cubic Hermite splines using dA/dP (= B_bernoulli) at the knots, the
others by not-a-knot cubic splines.  Knots are placed adaptively: every interval is tested
by a direct BEM solve at its midpoint and bisected until the interpolant agrees with it
within ``tolerance`` times the coefficient's largest magnitude over the table.  The
discrepancy found when an interval is accepted (before its midpoint became a knot) is kept
as that interval's interpolation-error estimate.  The BEM discretisation error is estimated
by solving two depths again at a lower order (the difference bounds the error of the table's
order, which converges spectrally) and by the residual of the identity B_bernoulli = dA/dP.

Breakpoints (also a table spline's knots where its third derivative jumps): the knots nearest a breakpoint b are at b (1 -+ BREAK_OFFSET) (the BEM layout
changes topology at b itself), solved with a fourth-order difference in P whose step is a
hundredth of the distance to b; across the gap the table is linear.
"""  # noqa: E501

from __future__ import annotations

import bisect
import functools
import io
import json
import math
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np

from semianalytic.coefficients import READINGS
from semianalytic.errors import InputError
from semianalytic.geometry import Nose, SplineCurve

if TYPE_CHECKING:
    from semianalytic.bem.panels import LayoutOptions
    from semianalytic.coefficients.depth import DepthCoefficients

TABLE_VERSION = 9  # (5: certified tables; 6-7: with the corner-aware BEM; 8: graded pieces past corners; 9: flat tips to 1e-6 R, near-hemispheres in sqrt(P), bounded shallow layouts) bump when the numerics change, to invalidate caches  # noqa: E501

DEFAULT_TOLERANCE = 1e-5  # relative to each coefficient's largest magnitude over the table
# the default depth range (nose lengths, Nose.depth_unit); when the tolerance needs deeper solves
# (the deep limit to 1e-8 needs about 1000) it extends itself up to AUTO_MAX_DEPTH and says so;
# any other range the user sets is a hard bound (this project's own rule)
DEFAULT_MAX_DEPTH = 300.0
AUTO_MAX_DEPTH = 1e5
CONTROLLED = ("A", "B_body", "B_literal", "B_bernoulli", "C")  # error-controlled coefficients
INTERPOLATED = CONTROLLED + ("phi_tip",)
BREAK_OFFSET = 1e-6  # knots at b (1 -+ BREAK_OFFSET) beside a breakpoint b (relative)
NEAR_BREAK = 1e-3  # closer than this (relative) to a breakpoint: fourth-order difference in P
FLAT_TIP_DEPTH = 1e-2  # a flat tip's first solve, in radii (the coefficients jump at P = 0+; constant below)
# A flat tip's coefficients start as X0 + c P^alpha (measured on the flat nose: alpha ~ 0.7-0.8 for B,
# from 0.68 at 1e-7 R to 1.8 at 1e-2 R): below the first knot P_1 the table holds X(P_1), with the
# estimate 2 |X(4 P_1) - X(P_1)| (a bound for any alpha >= 0.3), and P_1 is quartered (a knot at v/2)
# until that estimate is within half the tolerance, down to FLAT_TIP_FLOOR radii (this project's own
# rule; below about 1e-6 R the BEM's own noise in P, ~1e-5 of max |B| at 1e-7 R, exceeds what the
# quartering would gain: measured on the flat nose)
FLAT_TIP_FLOOR = 1e-6
MAX_ROUNDS = 40  # bisection rounds (each halves the failing intervals)
MAX_SOLVES = 400  # bisection stops (estimates kept) once this many depths are solved
NOISE_RATIO = 0.7  # bisection that shrinks a discrepancy by less than this is noise-limited
# floor of every error estimate, relative to the coefficient's largest magnitude: phi at P is the
# mean of the difference stencil's solves (error O(h^2), about 1e-8; coefficients/depth.py)
ROUND_OFF = 1e-8
# past a corner breakpoint b the coefficients go like non-integer powers of P - b (B jumps at b,
# then changes over many decades of P - b: the corner and its mirror image, 2 (P - b) apart,
# interact); interpolated in v = ((P - b)/l)^(1/GRADED_POWER) up to b (1 + GRADED_SPAN)
GRADED_POWER = 3.0
GRADED_SPAN = 1.0
_KINDS = {"root": 0, "mid": 1, "deep": 2, "graded": 3}


# --------------------------------------------------------------------------------------
# geometry of the depth axis


def breakpoints(nose: Nose) -> list[float]:
    """Depths P (> 0) where the coefficients have kinks: the axial positions (from the tip)
    of the joints between the nose's meridian segments and of its corners, and P = L_h."""
    out: list[float] = []
    L = nose.length
    for seg in nose.segments[:-1]:
        x, _ = seg.point(seg.t1)
        out.append(-float(x))
    for seg in nose.segments:
        out.extend(_spline_jumps(seg))
    for name in ("corner_depths", "corner_positions"):  # exposed by cornered-nose geometries
        extra = getattr(nose, name, None)
        if extra is not None:
            out.extend(float(abs(v)) for v in (extra() if callable(extra) else extra))
    if L > 0:
        out.append(L)
    tol = 1e-9 * max(L, nose.radius)
    pts: list[float] = []
    for P in sorted(out):
        if P > tol and P <= L + tol and (not pts or P - pts[-1] > tol):
            pts.append(P)
    return pts


def _spline_jumps(seg) -> list[float]:
    """Axial distances from the tip of a table spline's knots where its third derivative
    jumps (the not-a-knot spline's other interior knots are C^3): the coefficients have a
    weak singularity there, which a spline across it spreads over the whole piece."""
    if not isinstance(seg, SplineCurve) or seg.lo is not None:
        return []
    knots, xs, rs = seg._splines
    out = []
    for spl in (xs, rs):
        c3 = np.asarray(spl.c[0], float)  # cubic coefficient per interval
        big = float(np.max(np.abs(c3))) or 1.0
        for i in range(1, len(knots) - 1):
            if abs(c3[i] - c3[i - 1]) > 1e-8 * big:
                out.append(-float(xs(knots[i])))  # the knot's axial position
    return sorted(set(out))


def flat_tip(nose: Nose) -> bool:
    """True when the tip is a flat disk (C(0+) > 0: the coefficients jump at first contact)."""
    s = nose.segments[0]
    for t in (s.t0, 0.5 * (s.t0 + s.t1)):  # a disk: x constant along the first segment
        dx, dr = (float(v) for v in s.derivative(t))
        if abs(dx) > 1e-12 * max(abs(dr), 1e-300):
            return False
    return True


NEAR_ROUND_ANGLE = 1e-2  # rad: a curved tip this close to 90 deg is tabulated as a rounded one


def near_round_tip(nose: Nose) -> bool:
    """True for a curved tip whose half-angle is within NEAR_ROUND_ANGLE of 90 deg (an ogive of
    crh 0.5 + epsilon: a hemisphere but for a cone of radius ~ (s - d/2) at the tip).

    Its coefficients follow the hemisphere's powers of sqrt(P) down to P ~ (s - d/2)^2 / (2 s)
    (7e-11 m at crh 0.5001, d = 7.11 mm) and the cone's below, which are polynomial in sqrt(P)
    as well: interpolated in P they took ~250 knots against the hemisphere's ~50 (this
    project's own rule)."""
    from semianalytic.geometry import Arc

    return isinstance(nose.segments[0], Arc) and 0.5 * math.pi - nose.tip_half_angle() < NEAR_ROUND_ANGLE


@dataclass(frozen=True)
class Piece:
    """A smooth piece of the depth axis, [P_lo, P_hi] (P_hi = inf for the deep piece), with
    its interpolation variable v: ``root`` v = sqrt(P/l), ``mid`` v = P/l, ``deep`` v = l/P,
    ``graded`` v = ((P - b)/l)^(1/m) past a corner breakpoint b (``origin``; m = ``power``)."""

    kind: str
    P_lo: float
    P_hi: float
    scale: float
    origin: float = 0.0
    power: float = 1.0

    def v(self, P):
        P = np.asarray(P, float)
        if self.kind == "root":
            return np.sqrt(P / self.scale)
        if self.kind == "mid":
            return P / self.scale
        if self.kind == "graded":
            return np.maximum((P - self.origin) / self.scale, 0.0) ** (1.0 / self.power)
        with np.errstate(divide="ignore"):
            return np.where(np.isinf(P), 0.0, self.scale / P)

    def P(self, v):
        # one knot (a Python or numpy float) stays a float: the same double operations without numpy's
        # 0-d arrays; the graded power always takes numpy's (the C library's pow may differ by an ulp)
        one = isinstance(v, float)
        if not one or self.kind == "graded":
            v = np.asarray(v, float)
        if self.kind == "root":
            return self.scale * v * v
        if self.kind == "mid":
            return self.scale * v
        if self.kind == "graded":
            return self.origin + self.scale * v**self.power
        if one:
            return math.inf if v == 0 else self.scale / v
        with np.errstate(divide="ignore"):
            return np.where(v == 0, np.inf, self.scale / np.where(v == 0, 1.0, v))

    def dP_dv(self, v):
        v = np.asarray(v, float)
        if self.kind == "root":
            return 2.0 * self.scale * v
        if self.kind == "mid":
            return np.full_like(v, self.scale)
        if self.kind == "graded":
            return self.power * self.scale * v ** (self.power - 1.0)
        with np.errstate(divide="ignore"):
            return -self.scale / (v * v)

    def d2P_dv2(self, v):
        v = np.asarray(v, float)
        if self.kind == "root":
            return np.full_like(v, 2.0 * self.scale)
        if self.kind == "mid":
            return np.zeros_like(v)
        if self.kind == "graded":
            return self.power * (self.power - 1.0) * self.scale * v ** (self.power - 2.0)
        with np.errstate(divide="ignore"):
            return 2.0 * self.scale / (v * v * v)


def depth_pieces(nose: Nose) -> tuple[list[Piece], list[float]]:
    """The smooth pieces of the depth axis and the kinks between them."""
    bps = breakpoints(nose)
    ends = [0.0] + bps
    kinks = list(bps)
    if len(ends) == 1:  # no breakpoint (a flat nose with a sharp edge): split at the radius
        ends.append(nose.radius)
    # from first contact: in sqrt(P) on a rounded or flat tip (A ~ P^3/2, B ~ P^1/2), in P on a
    # pointed one (A ~ P^3, B ~ P^2: polynomial in P; exactly so on a cone)
    pointed = nose.tip_half_angle() < 0.5 * math.pi - 1e-9 and not flat_tip(nose) and not near_round_tip(nose)
    pieces = [Piece("mid" if pointed else "root", 0.0, ends[1], ends[1])]
    n = nose.parameters.get("exponent", 1.0) if nose.kind == "power" else 1.0
    if n < 1.0:  # a power-law tip: the wetted radius (P/L_h)^n L_h-scaled is linear in v = (P/l)^n
        pieces[0] = Piece("graded", 0.0, ends[1], ends[1], 0.0, 1.0 / n)
    corners = graded_breakpoints(nose, kinks)
    for a, b in zip(ends[1:-1], ends[2:]):
        pieces.append(Piece("graded", a, b, b - a, a, GRADED_POWER) if a in corners else Piece("mid", a, b, a))
    last = ends[-1]
    if last in corners:  # past a corner: graded up to GRADED_SPAN times the depth, then 1/P
        pieces.append(Piece("graded", last, last * (1 + GRADED_SPAN), last * GRADED_SPAN, last, GRADED_POWER))
        last *= 1 + GRADED_SPAN
    pieces.append(Piece("deep", last, math.inf, last))
    return pieces, kinks


def graded_breakpoints(nose: Nose, kinks) -> set:
    """The breakpoints past which the table is graded: where a corner of the meridian (off
    the axis) enters the target, and the joints between the nose's segments (a tangent joint
    with a curvature jump: past it the free-surface edge, itself a corner of the mirrored
    surface, lies P - b from the joint).  Not P = L_h of a tangent shoulder (the shank meets
    its mirror image smoothly) nor a table spline's C^2 knots (measured: grading there costs
    knots)."""
    tol = 1e-9 * max(nose.length, nose.radius)
    at = [-x for x, r, _ in nose.corners() if r > tol]
    at += [-float(seg.point(seg.t1)[0]) for seg in nose.segments[:-1]]
    return {b for b in kinks if any(abs(b - c) <= tol for c in at)}


def solve_depth(nose: Nose, depth: float, options: LayoutOptions, kinks=None, cache=None) -> DepthCoefficients:
    """One direct BEM solve at depth P (Part I, eqs. (12)-(14)); beside a breakpoint the
    difference in P is of fourth order with a step of a hundredth of the distance to it.
    ``cache``: an :class:`~semianalytic.bem.solve.AssemblyCache` shared by the depths of a table."""
    from semianalytic.coefficients.depth import coefficients_at_depth  # the BEM: not on a cached table's path

    kinks = breakpoints(nose) if kinks is None else kinks
    scale = max(nose.length, nose.radius)
    dist = min((abs(depth - b) for b in kinks), default=math.inf)
    if dist < NEAR_BREAK * scale:
        if dist == 0.0:
            raise ValueError("a breakpoint itself has no layout; use direct_coefficients")
        return coefficients_at_depth(nose, depth, options, fd_order=4, step=1e-2 * dist / 3.0, cache=cache)
    return coefficients_at_depth(nose, depth, options, cache=cache)


def _row(d: DepthCoefficients) -> dict:
    return {k: getattr(d, k) for k in INTERPOLATED + ("dA_dP", "dphi_tip_dP")}


def direct_coefficients(nose: Nose, depths, order: int = 8, refinement: float = 0.3, levels: int = 6) -> list[dict]:
    """Direct BEM solves at exactly the given depths (not interpolated): per depth a dict of
    A, B_body, B_literal, B_bernoulli, C, phi_tip, dA_dP, unknowns (SI).  Within BREAK_OFFSET
    of a breakpoint (no layout exists there) the value is the linear interpolation between
    the solves at b (1 -+ BREAK_OFFSET), as in the table."""
    from semianalytic.bem.panels import LayoutOptions

    opts = LayoutOptions(order, refinement, levels)
    kinks = breakpoints(nose)
    out = []
    for P in np.atleast_1d(np.asarray(depths, float)):
        P = float(P)
        if not (math.isfinite(P) and P > 0):
            raise ValueError("depths must be finite and > 0")
        near = [b for b in kinks if abs(P - b) <= BREAK_OFFSET * b]
        if near:
            b = near[0]
            lo, hi = b * (1 - BREAK_OFFSET), b * (1 + BREAK_OFFSET)
            r0, r1 = solve_depth(nose, lo, opts, kinks), solve_depth(nose, hi, opts, kinks)
            w = (P - lo) / (hi - lo)
            row = {k: (1 - w) * v + w * _row(r1)[k] for k, v in _row(r0).items()}
            row["unknowns"] = r1.unknowns
        else:
            r = solve_depth(nose, P, opts, kinks)
            row = _row(r) | {"unknowns": r.unknowns}
        row["depth"] = P
        out.append(row)
    return out


def coefficients_at(nose: Nose, depths, order: int = 8, refinement: float = 1.0, levels: int = 12) -> dict:
    """A, B (three readings), C, phi_tip, dA/dP at the given depths (arrays, SI)."""
    rows = direct_coefficients(nose, depths, order, refinement, levels)
    keys = ("depth",) + INTERPOLATED + ("dA_dP", "unknowns")
    return {k: np.array([r[k] for r in rows]) for k in keys}


# --------------------------------------------------------------------------------------
# interpolation on one piece


def _extrapolate_to_zero(v: np.ndarray, y: np.ndarray) -> tuple[float, float, float, float]:
    """(value at v = 0, its error estimate, slope at 0) from the polynomial through the given
    points (deep limit in v = l/P); the estimate is the change from dropping the farthest point."""
    order = np.argsort(v)
    v, y = v[order], y[order]
    n = len(v)
    if n < 2:
        return float(y[0]), math.inf, 0.0, 0.0
    p_hi = np.polyfit(v, y, n - 1)
    p_lo = np.polyfit(v[:-1], y[:-1], n - 2) if n > 2 else np.array([y[0]])
    val, low = float(p_hi[-1]), float(p_lo[-1])
    slope = float(p_hi[-2])
    curv = 2.0 * float(p_hi[-3]) if n > 2 else 0.0
    return val, abs(val - low), slope, curv


def _spline(v: np.ndarray, y: np.ndarray, derivs=None):
    """Interpolant as a PPoly in v: quintic Hermite through values and the given first and
    second derivatives (``derivs`` = (dy, d2y)), else an interpolating spline of degree 5
    (3 or 1 when there are too few knots)."""
    from scipy.interpolate import BPoly, PPoly, make_interp_spline  # building only: not on a cached table's path

    n = len(v)
    if n == 1:
        return None
    if derivs is not None:
        dy, d2y = derivs
        return PPoly.from_bernstein_basis(BPoly(_quintic_bernstein(np.asarray(v, float), np.column_stack([y, dy, d2y])), v))
    return make_interp_spline(v, y, k=_degree(n))


def _quintic_bernstein(x: np.ndarray, Y: np.ndarray) -> np.ndarray:
    """Bernstein coefficients (6, n - 1) of the quintic Hermite interpolant through the values, first and
    second derivatives ``Y`` (n, 3) at the knots ``x``: scipy's ``BPoly.from_derivatives`` (its
    ``_construct_from_derivatives``), the same operations in the same order, on all the intervals at
    once instead of one Python call per interval (the same numbers; this project's own speed-up)."""
    comb, poch = _bernstein_numbers()
    ya, yb = Y[:-1], Y[1:]
    # (xb - xa)**q as scipy takes it: a float64 scalar power per interval (numpy's array power may round
    # differently from the C library's pow)
    dxq = [np.array([d**q for d in x[1:] - x[:-1]]) for q in range(3)]
    c = np.empty((6, len(x) - 1))
    for q in range(3):  # from the left end
        c[q] = ya[:, q] / poch[q] * dxq[q]
        for j in range(q):
            c[q] -= (-1) ** (j + q) * comb[q, j] * c[j]
    for q in range(3):  # from the right end
        c[-q - 1] = yb[:, q] / poch[q] * (-1) ** q * dxq[q]
        for j in range(q):
            c[-q - 1] -= (-1) ** (j + 1) * comb[q, j + 1] * c[-q + j]
    return c


@functools.cache
def _bernstein_numbers() -> tuple[dict, list]:
    """scipy's comb(q, j) (q, j <= 2) and poch(6 - q, q) (q <= 2) that :func:`_quintic_bernstein` reads,
    worked out once by scipy itself (the same numpy floats; a scalar call of scipy.special costs
    several microseconds, and a table made about 450 of them)."""
    from scipy.special import comb, poch

    return {(q, j): comb(q, j) for q in range(3) for j in range(3)}, [poch(6 - q, q) for q in range(3)]


def _degree(n: int) -> int:
    """Degree of the interpolating spline through n knots: 5, or 3 or 1 when there are too few."""
    return 5 if n >= 6 else (3 if n >= 4 else 1)


def _splines(v: np.ndarray, Y: np.ndarray) -> list:
    """:func:`_spline` of each column of ``Y`` (n, m) without derivatives: one fit of all the
    columns (the banded system factorised once; the same coefficients column by column)."""
    from scipy.interpolate import BSpline, make_interp_spline  # building only: not on a cached table's path

    n = len(v)
    if n == 1:
        return [None] * Y.shape[1]
    both = make_interp_spline(v, Y, k=_degree(n))
    # construct_fast: the knots are both's, checked once by make_interp_spline (BSpline's own checks cost
    # ~20 us a column; the same spline objects)
    return [BSpline.construct_fast(both.t, np.ascontiguousarray(both.c[:, j]), both.k) for j in range(Y.shape[1])]


def _coef6(f, v0: float, fallback: float) -> list:
    """The 6 Taylor coefficients (highest power first) at v0 of a piecewise polynomial of
    degree <= 5 whose pieces break only at knots (so one piece spans the interval from v0)."""
    if f is None:
        return [0.0] * 5 + [fallback]
    return [float(f(v0, nu=i)) / math.factorial(i) for i in range(5, -1, -1)]


def _coef6_all(f, v0: np.ndarray, fallback: float) -> list:
    """:func:`_coef6` at every v0 at once (one evaluation per derivative order: the same numbers)."""
    if f is None:
        return [[0.0] * 5 + [fallback] for _ in v0]
    cols = [np.asarray(f(v0, nu=i), float) / math.factorial(i) for i in range(5, -1, -1)]
    return [[float(c[k]) for c in cols] for k in range(len(v0))]


@dataclass
class _PieceKnots:
    """Knots of one piece while the table is built (v ascending)."""

    piece: Piece
    v: list = field(default_factory=list)
    rows: list = field(default_factory=list)  # dict per knot (None for the deep limit at v = 0)
    nodes: list = field(default_factory=list)
    unknowns: list = field(default_factory=list)
    err: dict = field(default_factory=dict)  # (v_a, v_b) -> {name: estimate}

    def add(self, v: float, row: dict, nodes=None, unknowns: int = 0):
        k = bisect.bisect_left(self.v, v)
        self.v.insert(k, v)
        self.rows.insert(k, row)
        self.nodes.insert(k, nodes)
        self.unknowns.insert(k, unknowns)

    def splines(self) -> dict:
        v = np.array(self.v)
        p = self.piece
        out = {}
        names = [name for name in INTERPOLATED if name != "A"] + ["dA_dP"]
        # one interpolating spline per column, fitted together (the same coefficients as one by one)
        fitted = _splines(v, np.array([[r[name] for name in names] for r in self.rows]))
        out.update(zip(names, fitted))
        # A: quintic Hermite with dA/dP (= B_bernoulli) and d2A/dP2 from the spline of dA/dP
        y = np.array([r["A"] for r in self.rows])
        dA = np.array([r["dA_dP"] for r in self.rows])
        with np.errstate(divide="ignore", invalid="ignore"):
            Pv, Pvv = p.dP_dv(v), p.d2P_dv2(v)
            ddA = out.pop("dA_dP")
            ddA_dv = ddA.derivative()(v) if ddA is not None else np.zeros_like(v)
            dy = np.where(np.isfinite(Pv), dA * Pv, 0.0)
            d2y = np.where(np.isfinite(Pvv), ddA_dv * Pv + dA * Pvv, 0.0)
        if p.kind == "deep" and v[0] == 0.0:
            dy[0], d2y[0] = self.rows[0]["dA_dv"], self.rows[0]["d2A_dv2"]
        if p.kind == "root" and v[0] == 0.0:
            dy[0], d2y[0] = 0.0, 2.0 * p.scale * dA[0]
        out["A"] = _spline(v, y, (dy, d2y))
        return {k: out[k] for k in INTERPOLATED}


def _evaluate_splines(splines: dict, v: np.ndarray) -> dict:
    return {k: (s(v) if s is not None else np.full_like(v, np.nan)) for k, s in splines.items()}


# --------------------------------------------------------------------------------------
# the table


def table_npz_bytes(table, meta: dict) -> bytes:
    """A coefficient table (half-space or plate) as the bytes of an ``.npz`` archive: ``meta`` (its
    own keys) with the keys both tables share, the depths, unknowns, knot values, intervals and the
    surface nodes of every knot concatenated (``counts`` per knot)."""
    keys = list(table.nodes[0]) if table.nodes else []
    counts = np.array([len(n["x"]) for n in table.nodes], int)
    meta = {"nose_kind": table.nose_kind, "diameter": table.diameter, "nose_length": table.nose_length,
            "options": table.options, "node_keys": keys, "bem_errors": table.bem_errors,
            "tolerance": table.tolerance, "kinks": list(table.kinks), **meta}
    buf = io.BytesIO()
    np.savez(
        buf, meta=json.dumps(meta), depth=table.depth, unknowns=table.unknowns, counts=counts,
        **{f"v_{k}": v for k, v in table.values.items()},
        **{f"i_{k}": np.asarray(v) for k, v in table.intervals.items()},
        **{f"n_{k}": np.concatenate([n[k] for n in table.nodes]) for k in keys},
    )
    return buf.getvalue()


def read_table_npz(z, version: int, what: str) -> tuple[dict, tuple, dict, dict]:
    """(meta, nodes per knot, values, intervals) of an archive of :func:`table_npz_bytes`; ValueError
    if it holds another ``version`` (the cache then rebuilds the table)."""
    meta = json.loads(str(z["meta"]))
    if meta.get("version") != version:
        raise ValueError(f"{what} cache has another version")
    bounds = np.concatenate([[0], np.cumsum(z["counts"])])
    arrays = {k: z[f"n_{k}"] for k in meta["node_keys"]}
    nodes = tuple({k: v[a:b] for k, v in arrays.items()} for a, b in zip(bounds[:-1], bounds[1:]))
    values = {k[2:]: z[k] for k in z.files if k.startswith("v_")}
    intervals = {k[2:]: z[k] for k in z.files if k.startswith("i_")}
    return meta, nodes, values, intervals


class CoefficientAccessors:
    """A(P), B(P), C(P) and phi at the tip of a table that interpolates by ``self._eval(name, P)``
    (the half-space :class:`CoefficientTable` and the plate table of
    :mod:`semianalytic.coefficients.plate`); ``self.reading`` is the default B reading."""

    def _init_intervals(self) -> None:
        """Check the default reading and keep the interval breaks and the per-interval quintic
        coefficients as Python lists (the scalar path of ``_eval`` reads them without numpy)."""
        if self.reading not in READINGS:
            raise ValueError(f"reading must be one of {READINGS}")
        iv = self.intervals
        object.__setattr__(self, "_breaks", list(map(float, iv["P_lo"])))
        object.__setattr__(self, "_coef", {k: np.asarray(iv[f"coef_{k}"]).tolist() for k in INTERPOLATED})

    @staticmethod
    def _quintic(c, h: float) -> float:
        """sum_i c_i h^(5-i) by Horner (c = (c5, .., c0), the local polynomial of an interval)."""
        c5, c4, c3, c2, c1, c0 = c
        return ((((c5 * h + c4) * h + c3) * h + c2) * h + c1) * h + c0

    def A(self, P):
        """Added-mass volume A(P) = integral phi n_x dS [m^3] (Part I, eq. (12))."""
        return self._eval("A", P)

    def B(self, P, reading: str | None = None):
        """Drag area B(P) [m^2] in the given reading (Part I, eq. (12); errata item 2a)."""
        reading = reading or self.reading
        if reading not in READINGS:
            raise ValueError(f"reading must be one of {READINGS}; got {reading!r}")
        return self._eval(f"B_{reading}", P)

    def C(self, P):
        """Contact area C(P) = integral n_x dS [m^2] over the wetted surface (Part I, eq. (12))."""
        return self._eval("C", P)

    def phi_tip(self, P):
        """phi at the nose tip [m] (Fig. 6; 0 once a plate's back face is passed)."""
        return self._eval("phi_tip", P)

    # --- normalised (Part I, after eq. (34); errata item 2) --------------------------

    @property
    def area(self) -> float:
        """pi d^2 / 4 [m^2], the shank's cross-section (``self.diameter``)."""
        return math.pi * self.diameter**2 / 4

    def A_bar(self, P):
        """Abar = 4A/(pi d^2), a length [m]."""
        return self.A(P) / self.area

    def B_bar(self, P, reading: str | None = None):
        """Bbar = 4B/(pi d^2) (dimensionless)."""
        return self.B(P, reading) / self.area

    def C_bar(self, P):
        """Cbar = 4C/(pi d^2) (dimensionless)."""
        return self.C(P) / self.area


@dataclass(frozen=True, eq=False)
class CoefficientTable(CoefficientAccessors):
    """A(P) [m^3], B(P) [m^2] in three readings, C(P) [m^2] and phi at the tip [m], with
    error estimates.

    Call ``A(P)``, ``B(P)``, ``C(P)`` with floats or arrays (P >= 0, SI; any depth, the deep
    limit included); ``reading`` selects the B of errata item 2a (default ``body``).
    ``error(name, P)`` is the estimated absolute error of the value at P (interpolation plus
    BEM discretisation plus, in the deep piece, the extrapolated limit).

    ``depth``/``values``: the solved knots (ascending) and the coefficients there;
    ``intervals``: the interpolant, one row per interval of the depth axis (see
    :meth:`_build`); ``errors``: interpolation-error estimate per interval and coefficient.
    """

    nose_kind: str
    diameter: float
    nose_length: float
    depth: np.ndarray
    values: dict  # name -> array over depth: A, B_body, B_literal, B_bernoulli, C, phi_tip, dA_dP, dphi_tip_dP
    limits: dict  # name -> deep-penetration limit
    unknowns: np.ndarray
    nodes: tuple = field(repr=False)  # per depth: dict of surface arrays (see DepthCoefficients)
    options: dict = field(default_factory=dict)
    reading: str = "body"
    intervals: dict = field(default_factory=dict, repr=False)  # P_lo, kind, scale, v0, coef_<name>, err_<name>
    limit_errors: dict = field(default_factory=dict)
    bem_errors: dict = field(default_factory=dict)
    tolerance: float | None = None
    kinks: tuple = ()

    def __post_init__(self):
        self._init_intervals()
        iv = self.intervals
        object.__setattr__(self, "_kind", list(map(int, iv["kind"])))
        object.__setattr__(self, "_scale", list(map(float, iv["scale"])))
        object.__setattr__(self, "_v0", list(map(float, iv["v0"])))
        n = len(iv["P_lo"])  # graded intervals: v = ((P - origin)/scale)^(1/power)
        object.__setattr__(self, "_origin", np.asarray(iv.get("origin", np.zeros(n)), float))
        object.__setattr__(self, "_power", np.asarray(iv.get("power", np.ones(n)), float))
        object.__setattr__(self, "_graded", bool(np.any(np.asarray(iv["kind"]) == _KINDS["graded"])))

    # --- evaluation -----------------------------------------------------------------

    def _index(self, P: np.ndarray) -> np.ndarray:
        return np.clip(np.searchsorted(np.asarray(self._breaks), P, side="right") - 1, 0, len(self._breaks) - 1)

    def _local(self, P: np.ndarray, j: np.ndarray) -> np.ndarray:
        kind = np.asarray(self.intervals["kind"])[j]
        sc = np.asarray(self.intervals["scale"])[j]
        with np.errstate(divide="ignore", invalid="ignore"):
            v = np.where(kind == 0, np.sqrt(P / sc), np.where(kind == 1, P / sc, np.where(np.isinf(P), 0.0, sc / P)))
            if self._graded:
                graded = np.maximum((P - self._origin[j]) / sc, 0.0) ** (1.0 / self._power[j])
                v = np.where(kind == 3, graded, v)
        return v - np.asarray(self.intervals["v0"])[j]

    def _eval(self, name: str, P):
        if isinstance(P, float) and P >= 0.0:
            j = max(bisect.bisect_right(self._breaks, P) - 1, 0)
            kind, sc = self._kind[j], self._scale[j]
            if kind == 3:
                v = max((P - float(self._origin[j])) / sc, 0.0) ** (1.0 / float(self._power[j]))
            else:
                v = math.sqrt(P / sc) if kind == 0 else (P / sc if kind == 1 else sc / P)
            return self._quintic(self._coef[name][j], v - self._v0[j])
        P = np.asarray(P, dtype=float)
        if np.any(np.isnan(P)) or np.any(P < 0):
            raise ValueError("depth P must be >= 0")
        j = self._index(P)
        h = self._local(P, j)
        c = np.asarray(self.intervals[f"coef_{name}"])[j]
        out = c[..., 0]
        for i in range(1, 6):
            out = out * h + c[..., i]
        return out[()]

    def dA_dP(self, P):
        """dA/dP [m^2]: the derivative of the interpolant of A (equals B_bernoulli)."""
        P = np.asarray(P, dtype=float)
        j = self._index(P)
        h = self._local(P, j)
        c = np.asarray(self.intervals["coef_A"])[j]
        dA_dv = c[..., 0] * 5
        for i in range(1, 5):
            dA_dv = dA_dv * h + (5 - i) * c[..., i]
        kind = np.asarray(self.intervals["kind"])[j]
        sc = np.asarray(self.intervals["scale"])[j]
        with np.errstate(divide="ignore", invalid="ignore"):
            dv_dP = np.where(kind == 0, 0.5 / np.sqrt(P * sc), np.where(kind == 1, 1.0 / sc, -sc / P**2))
            if self._graded:
                m = self._power[j]
                graded = np.maximum((P - self._origin[j]) / sc, 0.0) ** (1.0 / m - 1.0) / (m * sc)
                dv_dP = np.where(kind == 3, graded, dv_dP)
            out = np.where(np.isfinite(dv_dP), dA_dv * dv_dP, 0.0)
        return np.where(np.isinf(P), 0.0, out)[()]

    def error(self, name: str, P):
        """Estimated absolute error of coefficient ``name`` (A, B_body, B_literal,
        B_bernoulli, C, phi_tip) at depth P: interpolation (the interval's estimate) plus
        BEM discretisation."""
        P = np.asarray(P, dtype=float)
        j = self._index(P)
        return (np.asarray(self.intervals[f"err_{name}"])[j] + self.bem_errors.get(name, 0.0))[()]

    def with_reading(self, reading: str) -> CoefficientTable:
        """The same table with another default B reading."""
        return replace(self, reading=reading)

    def deep_limit(self, reading: str | None = None) -> tuple[float, float, float]:
        """(A_inf, B_inf, C_inf) as P -> infinity."""
        reading = reading or self.reading
        return self.limits["A"], self.limits[f"B_{reading}"], self.limits["C"]

    @property
    def max_abs(self) -> dict:
        """Largest magnitude of each coefficient over the table (the tolerance's reference)."""
        return {k: float(max(np.max(np.abs(self.values[k])), abs(self.limits.get(k, 0.0)))) for k in INTERPOLATED}

    # --- contact pressure and region (Part I, eqs. (9), (13), (15)) ------------------

    def _nearest(self, P: float) -> dict:
        k = int(np.argmin(np.abs(self.depth - P)))
        return self.nodes[k]

    def pressure_profile(self, P: float, rho: float, u: float, du_dt: float, R_t: float, reading: str | None = None):
        """Contact pressure p_c of Part I, eq. (9) at the surface nodes (tabulated depth nearest P).

        p_c = rho phi du/dt + (|grad phi|^2 + 2 phi'_P) rho u^2/2 + R_t; in the ``bernoulli``
        reading the sign of |grad phi|^2 is corrected (errata item 2a).  Returns (x, p_c):
        target-frame abscissae of the nodes (0 <= x <= P) and pressures [Pa].
        """
        from semianalytic.coefficients.contact import pressure_terms

        reading = reading or self.reading
        n = self._nearest(P)
        phi, q = pressure_terms(n, reading)
        return n["x"], rho * phi * du_dt + q * rho * u * u / 2 + R_t

    def contact_intervals(self, P: float, rho: float, u: float, du_dt: float, R_t: float, reading: str | None = None):
        """Separated intervals [(x0, x1), ...] of the nose, where p_c <= 0 (eq. (15)); [] if none."""
        n = self._nearest(P)
        x, p = self.pressure_profile(P, rho, u, du_dt, R_t, reading)
        on_nose = n["nx"] > 1e-12
        sep = (p <= 0) & on_nose
        out = []
        k = 0
        while k < len(sep):
            if sep[k]:
                j = k
                while j + 1 < len(sep) and sep[j + 1]:
                    j += 1
                out.append((float(min(x[k], x[j])), float(max(x[k], x[j]))))
                k = j + 1
            else:
                k += 1
        return out

    # --- persistence ------------------------------------------------------------------

    def to_npz_bytes(self) -> bytes:
        """The table as the bytes of an ``.npz`` archive (persisted by :mod:`semianalytic.cache`)."""
        return table_npz_bytes(self, {"limits": self.limits, "version": TABLE_VERSION,
                                      "limit_errors": self.limit_errors})

    @classmethod
    def from_npz(cls, source) -> CoefficientTable:
        """The table from an ``.npz`` archive (a path or a binary file object)."""
        with np.load(source, allow_pickle=False) as z:
            meta, nodes, values, intervals = read_table_npz(z, TABLE_VERSION, "coefficient table")
            return cls(meta["nose_kind"], meta["diameter"], meta["nose_length"], z["depth"], values,
                       meta["limits"], z["unknowns"], nodes, meta["options"], intervals=intervals,
                       limit_errors=meta["limit_errors"], bem_errors=meta["bem_errors"],
                       tolerance=meta["tolerance"], kinks=tuple(meta["kinks"]))


# --------------------------------------------------------------------------------------
# building



def settle_interval(pk, a: float, m: float, b: float, disc: dict, worst: float, up) -> int:
    """Accept the halves (a, m) and (m, b) of an interval of the adaptive refinement, each with the
    midpoint discrepancy ``disc`` as its error estimate.  An interval still above the tolerance
    (``worst`` > 1: noise-limited, or out of solves) keeps the larger of its and its parent's
    discrepancy (``up`` = (worst, disc) of the parent, or None).  Returns 1 if noise-limited, else 0
    (the half-space and the plate tables share it)."""
    noisy = worst > 1.0
    if noisy and up is not None:
        disc = {q: max(disc[q], up[1][q]) for q in INTERPOLATED}
    pk.err[(a, m)] = pk.err[(m, b)] = disc
    return int(noisy)


def settle_unfinished(knots, pending: dict, parent: dict) -> int:
    """Intervals still pending when the rounds run out: each keeps its parent's discrepancy as its
    estimate (infinite without a parent).  Returns how many (all count as noise-limited)."""
    n = 0
    for i, ivs in pending.items():
        for a, b in ivs:
            up = parent.get((i, a, b))
            knots[i].err[(a, b)] = up[1] if up else {q: math.inf for q in INTERPOLATED}
            n += 1
    return n

class _Builder:
    """Adaptive construction of a table (see the module docstring)."""

    def __init__(self, nose: Nose, opts: LayoutOptions, tolerance: float, P_max: float, progress=None):
        self.nose, self.opts, self.tol, self.P_max = nose, opts, tolerance, P_max
        # the default depth range extends itself as far as the tolerance needs (too_shallow)
        self.extendable = abs(P_max / nose.depth_unit - DEFAULT_MAX_DEPTH) <= 1e-9 * DEFAULT_MAX_DEPTH
        self.extended = False
        self.pieces, self.kinks = depth_pieces(nose)
        self.flat = flat_tip(nose)
        self.knots = [_PieceKnots(p) for p in self.pieces]
        self.progress = progress
        self.solves = 0
        self.noise_limited = 0
        self.limit_err: dict = {}
        self.solved: dict = {}  # depth -> (row, nodes, unknowns)
        self._extrapolated: dict = {}  # (v, y) bytes -> _extrapolate_to_zero(v, y), see update_limit
        from semianalytic.bem.solve import AssemblyCache  # the BEM: imported when a table is built

        self.cache = AssemblyCache()  # blocks of the panels that stay in place from depth to depth

    # one solve
    def solve(self, P: float):
        if P in self.solved:  # a knot shared by two pieces
            row, nodes, n = self.solved[P]
            return dict(row), nodes, n
        r = solve_depth(self.nose, P, self.opts, self.kinks, self.cache)
        self.solves += 1
        if self.progress is not None:
            self.progress.update(1)
        self.solved[P] = (_row(r), r.nodes, r.unknowns)
        return self.solved[P]

    def _add_solved(self, pk: _PieceKnots, vs):
        for v, (row, nodes, n) in zip(vs, [self.solve(float(pk.piece.P(v))) for v in vs]):
            pk.add(float(v), row, nodes, n)

    def initial(self, fixed_depths=None):
        """Initial knots of every piece (or the given depths, for a fixed table)."""
        d = BREAK_OFFSET
        for pk in self.knots:
            p = pk.piece
            if fixed_depths is not None:
                lo = p.P_lo * (1 + d) if p.P_lo in self.kinks else p.P_lo
                hi = p.P_hi * (1 - d) if p.P_hi in self.kinks else p.P_hi
                Ps = [P for P in fixed_depths if lo < P < hi]
                ends = [P for P in (lo, hi) if 0 < P < math.inf and P not in Ps]
                Ps = sorted(Ps + ends)
                if p.kind == "root" and self.flat:
                    Ps = sorted(set(Ps) | {FLAT_TIP_DEPTH * self.nose.radius})
                self._add_solved(pk, [float(p.v(P)) for P in Ps])
            else:
                if p.kind == "deep":
                    v_hi = float(p.v(p.P_lo * (1 + d))) if p.P_lo in self.kinks else 1.0
                    n = int(min(6, math.floor(math.log2(self.P_max / p.P_lo)))) if self.P_max > p.P_lo else 0
                    vs = [v_hi] + [2.0**-k for k in range(1, n + 1)]
                else:
                    v_lo = float(p.v(p.P_lo * (1 + d))) if p.P_lo in self.kinks else float(p.v(p.P_lo))
                    v_hi = float(p.v(p.P_hi * (1 - d))) if p.P_hi in self.kinks else float(p.v(p.P_hi))
                    vs = list(np.linspace(v_lo, v_hi, 6))
                    if p.P_lo == 0.0:
                        vs = vs[1:]
                        if self.flat:
                            vs.insert(0, float(p.v(FLAT_TIP_DEPTH * self.nose.radius)))
                self._add_solved(pk, vs)
            if p.P_lo == 0.0 and not self.flat:  # first contact: everything vanishes
                pk.add(0.0, {k: 0.0 for k in INTERPOLATED + ("dA_dP", "dphi_tip_dP")}, None, 0)
        self.update_limit()

    def update_limit(self):
        """Deep limit (v = 0 of the deep piece) extrapolated from its four deepest solves."""
        pk = self.knots[-1]
        if pk.v and pk.v[0] == 0.0:
            pk.v.pop(0), pk.rows.pop(0), pk.nodes.pop(0), pk.unknowns.pop(0)
        v = np.array(pk.v[:4])
        row, err = {}, {}
        for name in INTERPOLATED + ("dA_dP", "dphi_tip_dP"):
            y = np.array([r[name] for r in pk.rows[:4]])
            # the same four knots are extrapolated again after most rounds: each fit once (keyed by
            # the bits of its inputs; this project's own shortcut, the same numbers)
            key = (v.tobytes(), y.tobytes())
            got = self._extrapolated.get(key)
            if got is None:
                got = self._extrapolated[key] = _extrapolate_to_zero(v, y)
            val, e, slope, curv = got
            row[name], err[name] = val, e
            if name == "A":
                row["dA_dv"], row["d2A_dv2"] = slope, curv
        for name in list(err):  # too few deep solves to extrapolate: the value itself
            if not math.isfinite(err[name]):
                err[name] = abs(row[name])
        row["C"], err["C"] = math.pi * self.nose.radius**2, 0.0  # exact once the nose is in
        row["dA_dP"] = row["dphi_tip_dP"] = 0.0
        pk.add(0.0, row, None, 0)
        self.limit_err = err

    def scales(self) -> dict:
        out = {}
        for name in INTERPOLATED:
            out[name] = max(abs(r[name]) for pk in self.knots for r in pk.rows) or 1.0
        return out

    def refine(self, max_rounds: int = MAX_ROUNDS, max_solves: int = MAX_SOLVES):
        """Bisect every interval until the interpolant and a direct solve at its midpoint agree.

        An interval whose discrepancy no longer shrinks under bisection (less than a factor
        1/NOISE_RATIO per halving) is limited by the BEM's own noise in P, not by the
        interpolation: it is accepted with its discrepancy as the estimate (above the
        tolerance; counted in ``noise_limited``)."""
        pending = {i: list(zip(pk.v[:-1], pk.v[1:])) for i, pk in enumerate(self.knots)}
        parent: dict = {}
        for _ in range(max_rounds):
            if not any(pending.values()):
                break
            splines = {i: self.knots[i].splines() for i in pending if pending[i]}
            tests = {i: [0.5 * (a + b) for a, b in ivs] for i, ivs in pending.items() if ivs}
            deepest = max((float(self.knots[i].piece.P(v)) for i, vs in tests.items() for v in vs), default=0.0)
            if deepest > self.P_max * (1 + 1e-12):
                self.too_shallow("the interpolant toward the deep limit", deepest)
            solved = {i: [self.solve(float(self.knots[i].piece.P(v))) for v in vs] for i, vs in tests.items()}
            for i, vs in tests.items():
                pred = _evaluate_splines(splines[i], np.array(vs))
                for v, (row, nodes, n) in zip(vs, solved[i]):
                    self.knots[i].add(v, row, nodes, n)
                solved[i] = (pred, [s[0] for s in solved[i]])
            scale = self.scales()
            new = {}
            budget = self.solves < max_solves
            for i, vs in tests.items():
                pred, rows = solved[i]
                pk = self.knots[i]
                nxt = []
                for k, ((a, b), m) in enumerate(zip(pending[i], vs)):
                    disc = {q: abs(float(pred[q][k]) - rows[k][q]) for q in INTERPOLATED}
                    worst = max(disc[q] / (self.tol * scale[q]) for q in CONTROLLED)
                    tiny = (b - a) <= 1e-7 * max(abs(b), 1e-300) if pk.piece.kind != "deep" or a > 0 else False
                    up = parent.get((i, a, b))
                    # an interval at a piece end may hold a singularity (log-like at a corner): never noise
                    # (not so the first interval of a flat tip: the constant below it holds the jump)
                    inner = (a > pk.v[0] or (i == 0 and self.flat)) and b < pk.v[-1]
                    stalled = inner and up is not None and worst > NOISE_RATIO * up[0]
                    if worst > 1.0 and not tiny and not stalled and budget:
                        nxt += [(a, m), (m, b)]
                        parent[(i, a, m)] = parent[(i, m, b)] = (worst, disc)
                    else:
                        self.noise_limited += settle_interval(pk, a, m, b, disc, worst, up)
                new[i] = nxt
            self.update_limit()
            self.extend_deep(new, scale)
            self.extend_shallow(new, scale)
            pending = new
        else:
            self.noise_limited += settle_unfinished(self.knots, pending, parent)

    @staticmethod
    def shallow_estimate(pk: _PieceKnots) -> dict:
        """Error of the constant X(P_1) below a flat tip's first knot: 2 |X(4 P_1) - X(P_1)|
        (the knot at v = 2 v_1 of the root piece, v = sqrt(P/l))."""
        v0 = pk.v[0]
        k2 = int(np.argmin(np.abs(np.array(pk.v) - 2.0 * v0)))
        if k2 == 0 or abs(pk.v[k2] - 2.0 * v0) > 1e-9 * v0:  # no knot at 4 P_1: the change to the next, quadrupled
            k2 = min(1, len(pk.v) - 1)
            factor = 2.0 * max(2.0 * v0 / max(pk.v[k2] - v0, 1e-300), 1.0) if k2 else math.inf
        else:
            factor = 2.0
        return {q: factor * abs(pk.rows[k2][q] - pk.rows[0][q]) for q in INTERPOLATED}

    def extend_shallow(self, pending: dict, scale: dict):
        """Shallower first knots of a flat tip (quartering P_1) until the constant below it is
        within half the tolerance, or P_1 reaches FLAT_TIP_FLOOR radii."""
        if not self.flat:
            return
        pk = self.knots[0]
        for _ in range(40):
            est = _Builder.shallow_estimate(pk)
            if all(est[q] <= 0.5 * self.tol * scale[q] for q in CONTROLLED):
                return
            v_new = 0.5 * pk.v[0]
            if float(pk.piece.P(v_new)) < FLAT_TIP_FLOOR * self.nose.radius:
                return
            self._add_solved(pk, [v_new])
            pending[0] = pending.get(0, []) + [(v_new, pk.v[1])]

    def extend_deep(self, pending: dict, scale: dict):
        """Deeper solves until the extrapolated deep limit is within half the tolerance."""
        i = len(self.knots) - 1
        pk = self.knots[i]
        for _ in range(30):
            bad = [q for q in CONTROLLED if self.limit_err[q] > 0.5 * self.tol * scale[q]]
            if not bad:
                return
            v_new = 0.5 * pk.v[1]
            P_new = float(pk.piece.P(v_new))
            if P_new > self.P_max * (1 + 1e-12):
                self.too_shallow(f"the deep limit of {bad[0]} (extrapolation error "
                                 f"{self.limit_err[bad[0]] / scale[bad[0]]:.1e} of its largest magnitude)", P_new)
            self._add_solved(pk, [v_new])
            pending[i] = [iv for iv in pending.get(i, []) if iv[0] > 0.0] + [(0.0, v_new), (v_new, pk.v[2])]
            pk.err = {k: e for k, e in pk.err.items() if k[0] > 0.0}
            self.update_limit()

    def too_shallow(self, what: str, P_needed: float):
        """Extend the depth range to ``P_needed`` when it is the default one (up to
        AUTO_MAX_DEPTH nose lengths; recorded and reported), else stop with an error naming
        the key that bounds it."""
        unit = self.nose.depth_unit
        if self.extendable and P_needed <= AUTO_MAX_DEPTH * unit:
            self.P_max = max(self.P_max, P_needed * (1 + 1e-9))
            self.extended = True
            return
        raise InputError(
            "coefficients.max_depth_nose_lengths",
            f"{self.P_max / unit:g} nose lengths is too shallow: {what} needs solves to {P_needed / unit:.4g} nose "
            f"lengths for the tolerance {self.tol:g}; raise it (default 300) or the tolerance",
        )

    def bem_errors(self) -> dict:
        """BEM discretisation error per coefficient: two depths solved again at a lower order
        (the difference bounds the error of the table's order), and the residual of the
        identity B_bernoulli = dA/dP at every knot (errata item 2a)."""
        from semianalytic.bem.panels import LayoutOptions

        lower = LayoutOptions(max(self.opts.order - 2, 2), self.opts.refinement, self.opts.levels)
        probes = []
        root = self.knots[0]
        probes.append(float(root.piece.P(0.5 * (root.v[0] + root.v[-1]))))
        deep = self.knots[-1]
        probes.append(float(deep.piece.P(deep.v[-1] / 3.0)))
        out = {q: 0.0 for q in INTERPOLATED}
        for P in probes:
            a = _row(solve_depth(self.nose, P, self.opts, self.kinks))
            b = _row(solve_depth(self.nose, P, lower, self.kinks))
            self.solves += 2
            for q in INTERPOLATED:
                out[q] = max(out[q], abs(a[q] - b[q]))
        resid = max(abs(r["B_bernoulli"] - r["dA_dP"]) for pk in self.knots for r in pk.rows if r is not None)
        for q in ("B_body", "B_literal", "B_bernoulli"):
            out[q] = max(out[q], resid)
        scale = self.scales()
        return {q: max(e, ROUND_OFF * scale[q]) for q, e in out.items()}  # no estimate below round-off

    def table(self, options: dict, bem_err: dict) -> CoefficientTable:
        return assemble_table(self.nose, self.knots, self.kinks, self.limit_err, bem_err, options, self.tol)


def assemble_table(nose, knots, kinks, limit_err, bem_err, options, tolerance) -> CoefficientTable:
    """The evaluation structure of a table from the knots of its pieces: one row per interval
    of the depth axis with its variable and cubic coefficients, gaps at breakpoints linear."""
    rows: list[dict] = []
    errs = {q: [] for q in INTERPOLATED}
    for n, pk in enumerate(knots):
        p = pk.piece
        v = np.array(pk.v)
        sp = pk.splines()
        deep = p.kind == "deep"
        order = range(len(v) - 1)
        taylor = {q: _coef6_all(sp[q], v[:-1], pk.rows[0][q]) for q in INTERPOLATED}
        for k in order:
            a, b = v[k], v[k + 1]
            P_lo = float(p.P(b)) if deep else float(p.P(a))
            if not deep and k == 0 and a > 0 and p.kind == "root":  # flat tip: constant below the first solve
                rows.append({"P_lo": 0.0, "kind": 1, "scale": 1.0, "v0": 0.0, "origin": 0.0, "power": 1.0,
                             **{f"coef_{q}": [0.0] * 5 + [pk.rows[0][q]] for q in INTERPOLATED}})
                shallow = _Builder.shallow_estimate(pk)  # X0 + c P^alpha, alpha >= 0.3: see FLAT_TIP_FLOOR
                for q in INTERPOLATED:
                    errs[q].append(shallow[q])
            rows.append({"P_lo": P_lo, "kind": _KINDS[p.kind], "scale": p.scale, "v0": float(a),
                         "origin": p.origin, "power": p.power,
                         **{f"coef_{q}": taylor[q][k] for q in INTERPOLATED}})
            e = pk.err.get((float(a), float(b)), {})
            for q in INTERPOLATED:
                extra = limit_err.get(q, 0.0) if deep else 0.0
                errs[q].append(e.get(q, math.inf) + extra)
        if n + 1 < len(knots):  # linear across the breakpoint gap
            nxt = knots[n + 1]
            P0 = float(p.P(v[-1]))
            P1 = float(nxt.piece.P(nxt.v[-1] if nxt.piece.kind == "deep" else nxt.v[0]))
            if P1 > P0:
                r0 = pk.rows[-1]
                r1 = nxt.rows[-1] if nxt.piece.kind == "deep" else nxt.rows[0]
                rows.append({"P_lo": P0, "kind": 1, "scale": 1.0, "v0": P0, "origin": 0.0, "power": 1.0,
                             **{f"coef_{q}": [0.0] * 4 + [(r1[q] - r0[q]) / (P1 - P0), r0[q]] for q in INTERPOLATED}})
                for q in INTERPOLATED:  # slope of the neighbouring intervals times the gap
                    slope = max(abs(r0[q] - pk.rows[-2][q]) / abs(P0 - float(p.P(v[-2]))) if len(v) > 1 else 0.0, 0.0)
                    errs[q].append(abs(r1[q] - r0[q]) + slope * (P1 - P0))
    # deep piece rows were appended in increasing v = decreasing P: sort by P_lo
    order = np.argsort([r["P_lo"] for r in rows], kind="stable")
    rows = [rows[i] for i in order]
    intervals = {k: np.array([r[k] for r in rows]) for k in ("P_lo", "kind", "scale", "v0", "origin", "power")}
    for q in INTERPOLATED:
        intervals[f"coef_{q}"] = np.array([r[f"coef_{q}"] for r in rows], float)
        intervals[f"err_{q}"] = np.array(errs[q], float)[order]
    # the solved knots, ascending
    solved = [(float(pk.piece.P(v)), r, nd, u) for pk in knots for v, r, nd, u in zip(pk.v, pk.rows, pk.nodes, pk.unknowns)
              if nd is not None]
    solved.sort(key=lambda t: t[0])
    names = INTERPOLATED + ("dA_dP", "dphi_tip_dP")
    deep = knots[-1]
    limits = {q: float(deep.rows[0][q]) for q in INTERPOLATED}
    return CoefficientTable(
        nose_kind=nose.kind,
        diameter=nose.diameter,
        nose_length=nose.length,
        depth=np.array([s[0] for s in solved]),
        values={k: np.array([s[1][k] for s in solved]) for k in names},
        limits=limits,
        unknowns=np.array([s[3] for s in solved]),
        nodes=tuple(s[2] for s in solved),
        options=options,
        intervals=intervals,
        limit_errors={q: float(limit_err.get(q, 0.0)) for q in INTERPOLATED},
        bem_errors={q: float(bem_err.get(q, 0.0)) for q in INTERPOLATED},
        tolerance=tolerance,
        kinks=tuple(kinks),
    )


def check_tolerance(tolerance, field_name: str = "coefficients.tolerance") -> float:
    """The relative tolerance of a table: a number in (0, 0.1)."""
    try:
        tol = float(tolerance)
    except (TypeError, ValueError):
        raise InputError(field_name, f"expected a number in (0, 0.1), e.g. 1e-5; got {tolerance!r}") from None
    if not (math.isfinite(tol) and 0 < tol < 0.1):
        raise InputError(field_name, f"expected a number in (0, 0.1), e.g. 1e-5; got {tolerance!r}")
    return tol


def coefficient_table(
    nose: Nose,
    *,
    order: int = 8,
    refinement: float = 0.3,
    levels: int = 6,
    tolerance: float | None = None,
    n_depths: int | None = None,
    max_depth_nose_lengths: float = 300.0,
    depths=None,
    progress: bool = False,
    bem_error: bool = True,
) -> CoefficientTable:
    """Tabulate A, B, C of a nose from first contact to the deep limit (Fig. 8).

    Default: knots placed adaptively until the interpolation error is within ``tolerance``
    (default 1e-5) of each coefficient's largest magnitude (see the module docstring).
    With ``depths`` (or ``n_depths``, the legacy geometric grid) the knots are those depths
    and the error estimates come from dropping every other knot.  ``max_depth_nose_lengths``
    bounds the deepest solve (in nose lengths L_h, or radii for a nose shorter than its radius: ``Nose.depth_unit``).
    """
    tol = check_tolerance(DEFAULT_TOLERANCE if tolerance is None else tolerance)
    P_max = max_depth_nose_lengths * nose.depth_unit
    from semianalytic.bem.panels import LayoutOptions  # the BEM: imported when a table is built

    opts = LayoutOptions(order, refinement, levels)
    bar = None
    if progress:
        from semianalytic.progress import counter

        # the adaptive knots: about 70 (ogive) to 140 (cornered noses), bench_bem.md
        bar = counter(len(depths) if depths is not None else 90, "BEM depths of the coefficient table", "depth")
    import contextlib

    from semianalytic.bem.solve import _single_threaded_blas

    blas = contextlib.ExitStack()
    try:
        blas.enter_context(_single_threaded_blas())  # once for all the table's solves
        b = _Builder(nose, opts, tol, P_max, bar)
        options = {"order": order, "refinement": refinement, "levels": levels}
        if depths is None and n_depths is not None:
            depths = default_depths(nose, n_depths, max_depth_nose_lengths)
        if depths is not None:
            b.initial(fixed_depths=np.asarray(depths, float))
            _fixed_errors(b)
            options["depths"] = [float(P) for P in depths]
        else:
            b.initial()
            b.refine()
            options["tolerance"] = tol
            options["noise_limited_intervals"] = b.noise_limited
            if b.extended:
                deepest = b.P_max / nose.depth_unit
                options["max_depth_nose_lengths"] = deepest
                import warnings

                warnings.warn(f"coefficients: the depth range extended itself from {max_depth_nose_lengths:g} to "
                              f"{deepest:.4g} nose lengths, as the tolerance {tol:g} needs (deep limit)", stacklevel=2)
        bem_err = b.bem_errors() if bem_error else {}
        return b.table(options, bem_err)
    finally:
        blas.close()
        if bar is not None:
            bar.close()


def _fixed_errors(b: _Builder):
    """Error estimates of a fixed-knot table: interpolants through every other knot compared
    with the knots left out (the interval estimate is that discrepancy)."""
    for pk in b.knots:
        n = len(pk.v)
        for k in range(n - 1):  # at least the change across the interval
            pk.err[(pk.v[k], pk.v[k + 1])] = {q: abs(pk.rows[k + 1][q] - pk.rows[k][q]) for q in INTERPOLATED}
        if n < 3:
            continue
        keep = list(range(0, n, 2)) + ([n - 1] if (n - 1) % 2 else [])
        sub = _PieceKnots(pk.piece, [pk.v[i] for i in keep], [pk.rows[i] for i in keep])
        sp = sub.splines()
        for k in range(1, n - 1, 2):
            pred = _evaluate_splines(sp, np.array([pk.v[k]]))
            for key in ((pk.v[k - 1], pk.v[k]), (pk.v[k], pk.v[k + 1])):
                pk.err[key] = {q: max(pk.err[key][q], abs(float(pred[q][0]) - pk.rows[k][q])) for q in INTERPOLATED}


def default_depths(nose: Nose, n_depths: int = 60, max_depth_nose_lengths: float = 300.0) -> np.ndarray:
    """The legacy fixed grid: half of the depths while the nose enters (geometric from 1% of
    L_h, then linear), half beyond, geometric up to ``max_depth_nose_lengths``."""
    Lh = nose.length
    scale = nose.depth_unit
    P_max = max_depth_nose_lengths * scale
    if Lh > 0.05 * nose.radius:  # a nose to enter (not a flat face): half the depths while it enters
        n_in = n_depths // 2
        n_geo = n_in // 3
        entry = np.concatenate(
            [np.geomspace(0.01, 0.2, n_geo, endpoint=False), np.linspace(0.2, 0.985, n_in - n_geo)]
        ) * Lh
        deep = np.geomspace(1.015 * Lh, P_max, n_depths - n_in)
        return np.concatenate([entry, deep])
    return np.geomspace(0.01 * scale + Lh, P_max, n_depths)
