"""A(P), B(P), C(P) of a nose perforating a plate 0 <= x <= H (Part I, eqs. (11)-(14); issue 23, item 2).

The potential problem is Part I's with a back face: dphi/dn = 0 on the front face x = 0
(Part I, eq. (7), as in the half-space tables) and phi = 0 on the back face x = H (this
project's own choice, argued in :mod:`semianalytic.bem.slab`: with dphi/dn = 0 there as well
the added mass of a nose in a plate would be infinite).  The BEM is the half-space one with
the slab's image series (:mod:`semianalytic.bem.slab`).  The wetted surface is the part of
the body inside the plate: for P > H (the tip through the back face) a band cut at x = H;
for P >= H + L_h the nose has left the plate, n_x = 0 on what remains and A = B = C = 0.

Coefficients are defined as in Part I, eq. (12) over the wetted surface, with phi'_P by
differences in P on a frozen panel topology (both cuts stretch), in the three readings of
errata item 2a.  The identity B_bernoulli = dA/dP of the half-space (energy conservation)
still holds in a plate: on the back face phi = 0 at all times, so there p + rho |v|^2/2 =
-rho dPhi/dt = 0 (the corrected Lagrange-Cauchy integral) and the energy flux through it
(pressure work plus the kinetic energy carried out) vanishes.  Its residual at every knot is
part of the BEM error estimate, as in the half-space tables.

Far from the back face the plate differs from the half-space by the image of the monopole
(the nose pushes a flux C into the target, errata item 2f): phi on the nose is shifted by
delta = -C ln 2 / (2 pi H) + O(H^-3) (the alternating image sum sum_{k != 0} (-1)^k C/(2 pi |2kH|)),
so (:func:`far_field_correction`)

    A_plate = A_half - C^2 ln 2 / (2 pi H),   B_plate = B_half - C C' ln 2 / (pi H),   C_plate = C_half,

each + O(H^-3) relative (the field of the images is uniform over the nose up to O(x^2/H^3): the
+-k copies cancel its gradient).  The plate therefore converges to today's half-space like
1/H, not faster: 7e-3 relative at H = 50 nose lengths for the 3-CRH ogive.

Tables (:func:`plate_coefficient_table`): the depth axis 0 < P < H + L_h is cut where the
coefficients have kinks (a joint or corner of the nose, or the shoulder, crossing the front
face at P = b or the back face at P = H + b; the tip reaching the back face at P = H); each
piece is interpolated in a variable v in [0, 1] clustered at its singular end (P - a ~ v^m,
m = 2 from first contact and after the tip's exit, 3 past a corner; the approach of the tip to
the back face is clustered at its end), knots placed adaptively by midpoint solves until
the interpolant agrees within ``tolerance`` times each coefficient's largest magnitude; the
discrepancy at acceptance is the interval's error estimate, plus the BEM discretisation
error (two depths solved again at order - 2), as in :mod:`semianalytic.coefficients.table`.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass, field, replace

import numpy as np

from semianalytic.coefficients import READINGS
from semianalytic.coefficients.table import (
    BREAK_OFFSET,
    FLAT_TIP_DEPTH,
    NEAR_BREAK,
    ROUND_OFF,
    CoefficientAccessors,
    _coef6,
    _PieceKnots,
    breakpoints,
    check_tolerance,
    flat_tip,
    graded_breakpoints,
    read_table_npz,
    settle_interval,
    settle_unfinished,
    table_npz_bytes,
)
from semianalytic.geometry import Nose

PLATE_VERSION = 2  # bump when the numerics change, to invalidate cached plate tables (2: the back-face cut re-graded)
DEFAULT_TOLERANCE = 1e-5
CONTROLLED = ("A", "B_body", "B_literal", "B_bernoulli", "C")
INTERPOLATED = CONTROLLED + ("phi_tip",)
ROW_KEYS = INTERPOLATED + ("dA_dP", "dphi_tip_dP")
MAX_SOLVES = 300
MAX_ROUNDS = 30
STEP = 1e-4  # relative step of the difference in P (as coefficients/depth.py)


# --------------------------------------------------------------------------------------
# the depth axis


def plate_breakpoints(nose: Nose, thickness: float) -> list[float]:
    """Depths 0 < P < H + L_h where the plate coefficients have kinks: a breakpoint b of the
    half-space (:func:`semianalytic.coefficients.table.breakpoints`) crossing the front face
    (P = b < H + L_h) or the back face (P = H + b), and the tip reaching the back face (P = H)."""
    H, L = thickness, nose.length
    end = H + L
    tol = 1e-9 * max(L, nose.radius, H)
    bps = breakpoints(nose)
    pts = sorted([b for b in bps] + [H] + [H + b for b in bps])
    out: list[float] = []
    for P in pts:
        if tol < P < end - tol and (not out or P - out[-1] > tol):
            out.append(P)
    return out


def check_thickness(nose: Nose, thickness) -> float:
    """The plate thickness H [m] as a float, or InputError naming ``target.thickness``: a finite
    length > 0, and at least MIN_THICKNESS_RADII nose radii (thinner plates need more image copies
    than the series allows: :data:`semianalytic.bem.slab.MAX_COPIES`)."""
    from semianalytic.bem.slab import MAX_COPIES, TAIL_SEPARATION
    from semianalytic.errors import InputError

    try:
        H = float(thickness)
    except (TypeError, ValueError):
        raise InputError("target.thickness", f"expected a length in m; got {thickness!r}") from None
    if not (math.isfinite(H) and H > 0):
        raise InputError("target.thickness", f"must be a finite length > 0 (m); got {thickness!r}")
    H_min = 0.5 * TAIL_SEPARATION * nose.radius / MAX_COPIES
    if H < H_min:
        raise InputError("target.thickness", f"{H * 1e3:.4g} mm is below the plate BEM's reach "
                         f"({H_min * 1e3:.3g} mm = {H_min / nose.radius:.3g} nose radii); use a thicker plate")
    return H


def plate_end(nose: Nose, thickness: float) -> float:
    """H + L_h: beyond it the nose has left the plate (A = B = C = 0)."""
    return thickness + nose.length


@dataclass(frozen=True)
class PlatePiece:
    """A smooth piece [a, b] of the depth axis with its variable v in [0, 1]:
    P = a + (b - a) v^m (``side`` 0, clustered at a) or P = b - (b - a) (1 - v)^m (``side`` 1)."""

    a: float
    b: float
    m: float = 1.0
    side: int = 0

    def P(self, v):
        v = np.asarray(v, float)
        if self.side == 0:
            return self.a + (self.b - self.a) * v**self.m
        return self.b - (self.b - self.a) * (1.0 - v) ** self.m

    def v(self, P):
        w = (np.asarray(P, float) - self.a) / (self.b - self.a)
        w = np.clip(w, 0.0, 1.0)
        if self.side == 0:
            return w ** (1.0 / self.m)
        return 1.0 - (1.0 - w) ** (1.0 / self.m)

    def dP_dv(self, v):
        v = np.asarray(v, float)
        if self.side == 0:
            return (self.b - self.a) * self.m * v ** (self.m - 1.0)
        return (self.b - self.a) * self.m * (1.0 - v) ** (self.m - 1.0)


def plate_pieces(nose: Nose, thickness: float) -> tuple[list[PlatePiece], list[float]]:
    """The smooth pieces of 0 < P < H + L_h and the kinks between them."""
    H = thickness
    kinks = plate_breakpoints(nose, H)
    ends = [0.0] + kinks + [plate_end(nose, H)]
    corners = graded_breakpoints(nose, breakpoints(nose))
    tol = 1e-9 * max(nose.length, nose.radius, H)
    pointed = nose.tip_half_angle() < 0.5 * math.pi - 1e-9 and not flat_tip(nose)
    pieces = []
    for a, b in zip(ends[:-1], ends[1:]):
        after_corner = any(abs(a - c) <= tol or abs(a - H - c) <= tol for c in corners)
        if a == 0.0:
            m = 1.0 if pointed else 2.0
        elif after_corner:
            m = 3.0
        elif abs(a - H) <= tol:
            m = 2.0  # the tip has just left: the band grows from the tip
        else:
            m = 1.0
        if abs(b - H) <= tol:  # the tip approaches the back face: cluster that end too
            mid = 0.5 * (a + b)
            pieces += [PlatePiece(a, mid, m, 0), PlatePiece(mid, b, 2.0, 1)]
        else:
            pieces.append(PlatePiece(a, b, m, 0))
    return pieces, kinks


# --------------------------------------------------------------------------------------
# direct solves


def _step(nose: Nose, depth: float, kinks, end: float) -> float:
    scale = min(depth, nose.radius)
    for b in list(kinks) + [end]:
        if b != depth:
            scale = min(scale, abs(depth - b) / 3.0)
    return STEP * scale


def _zero_row() -> dict:
    return {k: 0.0 for k in ROW_KEYS}


def plate_depth_coefficients(nose: Nose, thickness: float, depth: float, options=None, kinks=None):
    """One direct slab solve at depth P (0 < P < H + L_h, not at a kink): Part I, eqs. (9), (12)
    on the wetted surface, phi'_P by a central difference in P (fourth order within NEAR_BREAK
    of a kink, with a step of a hundredth of the distance to it).  Returns
    :class:`semianalytic.coefficients.depth.DepthCoefficients`."""
    from semianalytic.bem.panels import LayoutOptions
    from semianalytic.bem.slab import plan_for, slab_layout, solve_slab
    from semianalytic.bem.solve import SurfaceSolution
    from semianalytic.coefficients.depth import STENCILS, _combine

    options = options or LayoutOptions(8, 0.3, 6)
    kinks = plate_breakpoints(nose, thickness) if kinks is None else kinks
    end = plate_end(nose, thickness)
    scale = max(nose.length, nose.radius)
    dist = min((abs(depth - b) for b in list(kinks) + [end]), default=math.inf)
    if dist == 0.0:
        raise ValueError("a kink of the depth axis has no layout; use plate_coefficients_at")
    if dist < NEAR_BREAK * scale:
        fd_order, h = 4, 1e-2 * dist / 3.0
    else:
        fd_order, h = 2, _step(nose, depth, kinks, end)
    offsets, weights, interp = STENCILS[fd_order]
    layout = slab_layout(nose, depth, thickness, options)
    panels = layout.panels()
    plan = plan_for(layout)
    sols = [solve_slab(layout.at_depth(depth + k * h), plan=plan) for k in offsets]
    center = SurfaceSolution(panels, sum(c * s.phi_nodes for c, s in zip(interp, sols)),
                             -panels.nodes.tr[: panels.n_primary], "slab", depth=depth)
    return _combine(center, sols, weights, h)


def _row(d, thickness: float = math.inf) -> dict:
    row = {k: float(getattr(d, k)) for k in ROW_KEYS}
    if d.depth > thickness:  # the tip has left the plate: its phi is not a coefficient of the plate
        row["phi_tip"] = row["dphi_tip_dP"] = 0.0
    return row


def plate_coefficients_at(nose: Nose, thickness: float, depths, order: int = 8, refinement: float = 0.3,
                          levels: int = 6) -> dict:
    """Direct slab solves at exactly the given depths (not interpolated): arrays of A [m^3],
    B_body, B_literal, B_bernoulli, C [m^2], phi_tip [m], dA_dP [m^2] and unknowns, with
    ``depth``.  P = 0 and P >= H + L_h give zeros (a flat tip: P = 0 is its first contact,
    solved at FLAT_TIP_DEPTH radii); within BREAK_OFFSET of a kink the value is the linear
    interpolation between the solves at b (1 -+ BREAK_OFFSET)."""
    from semianalytic.bem.panels import LayoutOptions

    thickness = check_thickness(nose, thickness)
    opts = LayoutOptions(order, refinement, levels)
    kinks = plate_breakpoints(nose, thickness)
    end = plate_end(nose, thickness)
    out = {k: [] for k in ("depth",) + ROW_KEYS + ("unknowns",)}
    for P in np.atleast_1d(np.asarray(depths, float)):
        P = float(P)
        if not (math.isfinite(P) and P >= 0):
            raise ValueError("depths must be finite and >= 0")
        n = 0
        if P >= end * (1 - BREAK_OFFSET) or (P == 0.0 and not flat_tip(nose)):
            row = _zero_row()
        else:
            if P < FLAT_TIP_DEPTH * nose.radius and flat_tip(nose):
                P_solve = FLAT_TIP_DEPTH * nose.radius
            else:
                P_solve = P
            near = [b for b in kinks if abs(P_solve - b) <= BREAK_OFFSET * b]
            if near:
                b = near[0]
                lo, hi = b * (1 - BREAK_OFFSET), b * (1 + BREAK_OFFSET)
                r0 = plate_depth_coefficients(nose, thickness, lo, opts, kinks)
                r1 = plate_depth_coefficients(nose, thickness, hi, opts, kinks)
                w = (P_solve - lo) / (hi - lo)
                row = {k: (1 - w) * v + w * _row(r1, thickness)[k] for k, v in _row(r0, thickness).items()}
                n = r1.unknowns
            else:
                r = plate_depth_coefficients(nose, thickness, P_solve, opts, kinks)
                row, n = _row(r, thickness), r.unknowns
        out["depth"].append(P)
        for k in ROW_KEYS:
            out[k].append(row[k])
        out["unknowns"].append(n)
    return {k: np.array(v) for k, v in out.items()}


def far_field_correction(C: float, dC_dP: float, thickness: float) -> tuple[float, float]:
    """(Delta A, Delta B) of a plate of thickness H against the half-space at the same depth,
    to leading order in 1/H (module docstring; this project's own derivation): the images of
    the monopole 2C in the back face shift phi on the nose by -C ln 2/(2 pi H), so
    Delta A = -C^2 ln 2/(2 pi H) and Delta B = -C C' ln 2/(pi H) (all three readings)."""
    return -C * C * math.log(2.0) / (2.0 * math.pi * thickness), -C * dC_dP * math.log(2.0) / (math.pi * thickness)


# --------------------------------------------------------------------------------------
# the table


def _spline(v: np.ndarray, y: np.ndarray, dy=None):
    """Interpolant in v: cubic Hermite with the derivatives ``dy``, else an interpolating
    spline of degree 5 (3 or 1 with fewer knots); returned as a scipy PPoly."""
    from scipy.interpolate import CubicHermiteSpline, PPoly, make_interp_spline

    if len(v) == 1:
        return None
    if dy is not None:
        return CubicHermiteSpline(v, y, dy)
    k = 5 if len(v) >= 6 else (3 if len(v) >= 4 else 1)
    return PPoly.from_spline(make_interp_spline(v, y, k=k))


class _Knots(_PieceKnots):
    """Knots of one plate piece while the table is built (the half-space table's, with A by a
    Hermite spline of dA/dP only: a plate piece has no deep limit)."""

    def splines(self) -> dict:
        v = np.array(self.v)
        out = {}
        for name in INTERPOLATED:
            if name != "A":
                out[name] = _spline(v, np.array([r[name] for r in self.rows]))
        dA = np.array([r["dA_dP"] for r in self.rows]) * self.piece.dP_dv(v)
        out["A"] = _spline(v, np.array([r["A"] for r in self.rows]), np.where(np.isfinite(dA), dA, 0.0))
        return out


@dataclass(frozen=True, eq=False)
class PlateCoefficientTable(CoefficientAccessors):
    """A(P) [m^3], B(P) [m^2] (three readings), C(P) [m^2], phi_tip [m] of a nose in a plate of
    thickness H, 0 <= P < infinity (zero for P >= H + L_h), with error estimates; the interface
    of :class:`semianalytic.coefficients.table.CoefficientTable` (no deep limit: a plate has none).

    ``intervals``: one row per interval of the depth axis: P_lo, the piece's a, b, m, side,
    the local origin v0 and degree-5 coefficients in v - v0 per coefficient, err_<name>."""

    nose_kind: str
    diameter: float
    nose_length: float
    thickness: float
    depth: np.ndarray
    values: dict
    unknowns: np.ndarray
    nodes: tuple = field(repr=False)
    intervals: dict = field(repr=False)
    bem_errors: dict = field(default_factory=dict)
    options: dict = field(default_factory=dict)
    reading: str = "body"
    tolerance: float | None = None
    kinks: tuple = ()

    def __post_init__(self):
        self._init_intervals()
        iv = self.intervals
        object.__setattr__(self, "_geo", [tuple(map(float, t)) for t in zip(iv["a"], iv["b"], iv["m"], iv["side"], iv["v0"])])
        object.__setattr__(self, "_end", self.thickness + self.nose_length)

    @property
    def end(self) -> float:
        """H + L_h: the coefficients are zero beyond."""
        return self._end

    def _eval1(self, name: str, P: float, deriv: bool = False) -> float:
        if not P >= 0.0:
            raise ValueError("depth P must be >= 0")
        if P >= self._end:
            return 0.0
        j = max(bisect.bisect_right(self._breaks, P) - 1, 0)
        a, b, m, side, v0 = self._geo[j]
        w = min(max((P - a) / (b - a), 0.0), 1.0)
        v = w ** (1.0 / m) if side == 0 else 1.0 - (1.0 - w) ** (1.0 / m)
        h = v - v0
        c5, c4, c3, c2, c1, c0 = self._coef[name][j]
        if not deriv:
            return self._quintic(self._coef[name][j], h)
        if m > 1.0 and (v < 1e-6 if side == 0 else v > 1.0 - 1e-6):
            # dP/dv = 0 at the clustered end: the limit of dy/dv / dP/dv, taken 1e-6 inside
            v = 1e-6 if side == 0 else 1.0 - 1e-6
            h = v - v0
        dy_dv = (((5 * c5 * h + 4 * c4) * h + 3 * c3) * h + 2 * c2) * h + c1
        dP_dv = (b - a) * m * (v ** (m - 1.0) if side == 0 else (1.0 - v) ** (m - 1.0))
        return dy_dv / dP_dv

    def _eval(self, name: str, P, deriv: bool = False):
        if isinstance(P, float):
            return self._eval1(name, P, deriv)
        arr = np.asarray(P, dtype=float)
        if np.any(np.isnan(arr)) or np.any(arr < 0):
            raise ValueError("depth P must be >= 0")
        out = np.array([self._eval1(name, float(p), deriv) for p in arr.ravel()]).reshape(arr.shape)
        return out[()]

    def dA_dP(self, P):
        """dA/dP [m^2]: the derivative of the interpolant of A."""
        return self._eval("A", P, deriv=True)

    def error(self, name: str, P):
        """Estimated absolute error of coefficient ``name`` at depth P: the interval's
        interpolation estimate plus the BEM discretisation estimate (0 beyond H + L_h)."""
        P = np.asarray(P, dtype=float)
        j = np.clip(np.searchsorted(np.asarray(self._breaks), P, side="right") - 1, 0, len(self._breaks) - 1)
        e = np.asarray(self.intervals[f"err_{name}"])[j] + self.bem_errors.get(name, 0.0)
        return np.where(P >= self._end, 0.0, e)[()]

    def with_reading(self, reading: str) -> PlateCoefficientTable:
        return replace(self, reading=reading)

    @property
    def max_abs(self) -> dict:
        return {k: float(np.max(np.abs(self.values[k]))) if len(self.depth) else 0.0 for k in INTERPOLATED}

    # --- persistence ------------------------------------------------------------------

    def to_npz_bytes(self) -> bytes:
        return table_npz_bytes(self, {"thickness": self.thickness, "version": PLATE_VERSION})

    @classmethod
    def from_npz(cls, source) -> PlateCoefficientTable:
        with np.load(source, allow_pickle=False) as z:
            meta, nodes, values, intervals = read_table_npz(z, PLATE_VERSION, "plate coefficient table")
            return cls(meta["nose_kind"], meta["diameter"], meta["nose_length"], meta["thickness"], z["depth"],
                       values, z["unknowns"], nodes, intervals, meta["bem_errors"], meta["options"],
                       tolerance=meta["tolerance"], kinks=tuple(meta["kinks"]))


SCALE_POWERS = {"A": 3, "B": 2, "C": 2, "phi_tip": 1, "dA_dP": 2}
"""Powers of the length scale of each coefficient (A [m^3], B and C [m^2], phi_tip [m])."""


class ScaledPlateTable:
    """The plate table of a nose scaled by ``scale`` s (lengths x s): the potential problem has no
    length of its own, so X(P) = s^k X_1(P / s) with k of :data:`SCALE_POWERS` (A: 3, B, C: 2,
    phi_tip: 1), errors alike.  One table per nose shape and thickness ratio H/d serves every
    calibre (the cache holds the table of the nose of unit diameter)."""

    def __init__(self, table, scale: float):
        self.table, self.scale = table, float(scale)
        s = self.scale
        self.diameter = table.diameter * s
        self.nose_length = table.nose_length * s
        self.thickness = table.thickness * s
        self.depth = np.asarray(table.depth) * s
        self.reading = table.reading
        self.tolerance = table.tolerance
        self.options = dict(table.options, scale=s)
        self.bem_errors = {k: v * s ** SCALE_POWERS.get(k.split("_")[0] if k.startswith("B_") else k, 2)
                           for k, v in table.bem_errors.items()}
        self.kinks = tuple(k * s for k in table.kinks)

    @property
    def end(self) -> float:
        return self.table.end * self.scale

    def _p(self, P):
        return np.asarray(P, float) / self.scale if not isinstance(P, float) else P / self.scale

    def A(self, P):
        return self.table.A(self._p(P)) * self.scale**3

    def B(self, P, reading: str | None = None):
        return self.table.B(self._p(P), reading) * self.scale**2

    def C(self, P):
        return self.table.C(self._p(P)) * self.scale**2

    def phi_tip(self, P):
        return self.table.phi_tip(self._p(P)) * self.scale

    def dA_dP(self, P):
        return self.table.dA_dP(self._p(P)) * self.scale**2

    def error(self, name: str, P):
        k = SCALE_POWERS["B"] if name.startswith("B") else SCALE_POWERS.get(name, 2)
        return self.table.error(name, self._p(P)) * self.scale**k

    def with_reading(self, reading: str) -> ScaledPlateTable:
        return ScaledPlateTable(self.table.with_reading(reading), self.scale)


class _Builder:
    def __init__(self, nose: Nose, thickness: float, opts, tol: float, max_solves: int):
        self.nose, self.H, self.opts, self.tol, self.max_solves = nose, thickness, opts, tol, max_solves
        self.pieces, self.kinks = plate_pieces(nose, thickness)
        self.end = plate_end(nose, thickness)
        self.flat = flat_tip(nose)
        self.knots = [_Knots(p) for p in self.pieces]
        self.solved: dict = {}
        self.solves = 0
        self.noise_limited = 0
        self.bar = None  # a tqdm bar of the depths solved (progress = True)

    def solve(self, P: float):
        if P not in self.solved:
            r = plate_depth_coefficients(self.nose, self.H, P, self.opts, self.kinks)
            self.solves += 1
            if self.bar is not None:
                self.bar.update(1)
            self.solved[P] = (_row(r, self.H), r.nodes, r.unknowns)
        row, nodes, n = self.solved[P]
        return dict(row), nodes, n

    def _is_kink(self, P: float) -> bool:
        tol = 1e-12 * self.end
        return any(abs(P - b) <= tol for b in self.kinks) or abs(P - self.end) <= tol

    def _solve_v(self, pk: _Knots, v: float):
        P = float(pk.piece.P(v))
        if P <= 0.0 and not self.flat:
            return _zero_row(), None, 0
        if abs(P - self.end) <= 1e-12 * self.end:
            return _zero_row(), None, 0
        if self._is_kink(P):
            P = P * (1 + BREAK_OFFSET) if v == 0.0 else P * (1 - BREAK_OFFSET)
        if self.flat and P < FLAT_TIP_DEPTH * self.nose.radius:
            P = FLAT_TIP_DEPTH * self.nose.radius
        return self.solve(P)

    def initial(self):
        for pk in self.knots:
            for v in np.linspace(0.0, 1.0, 5):
                pk.add(float(v), *self._solve_v(pk, float(v)))

    def scales(self) -> dict:
        return {q: max(abs(r[q]) for pk in self.knots for r in pk.rows) or 1.0 for q in INTERPOLATED}

    def refine(self):
        pending = {i: list(zip(pk.v[:-1], pk.v[1:])) for i, pk in enumerate(self.knots)}
        parent: dict = {}
        for _ in range(MAX_ROUNDS):
            if not any(pending.values()):
                break
            tests = {i: [0.5 * (a + b) for a, b in ivs] for i, ivs in pending.items() if ivs}
            preds = {}
            for i, vs in tests.items():
                sp = self.knots[i].splines()
                preds[i] = {q: (sp[q](np.array(vs)) if sp[q] is not None else np.zeros(len(vs))) for q in INTERPOLATED}
            rows = {i: [self._solve_v(self.knots[i], v) for v in vs] for i, vs in tests.items()}
            for i, vs in tests.items():
                for v, (row, nodes, n) in zip(vs, rows[i]):
                    self.knots[i].add(v, row, nodes, n)
            scale = self.scales()
            budget = self.solves < self.max_solves
            new = {}
            for i, vs in tests.items():
                pk, nxt = self.knots[i], []
                for k, ((a, b), m) in enumerate(zip(pending[i], vs)):
                    disc = {q: abs(float(preds[i][q][k]) - rows[i][k][0][q]) for q in INTERPOLATED}
                    worst = max(disc[q] / (self.tol * scale[q]) for q in CONTROLLED)
                    up = parent.get((i, a, b))
                    stalled = up is not None and worst > 0.7 * up[0] and a > 0.0 and b < 1.0
                    if worst > 1.0 and budget and not stalled and (b - a) > 1e-6:
                        nxt += [(a, m), (m, b)]
                        parent[(i, a, m)] = parent[(i, m, b)] = (worst, disc)
                    else:
                        self.noise_limited += settle_interval(pk, a, m, b, disc, worst, up)
                new[i] = nxt
            pending = new
        self.noise_limited += settle_unfinished(self.knots, pending, parent)  # out of rounds

    def fixed_errors(self):
        """Fixed knots (``depths``): every other knot left out and predicted (as the table)."""
        for pk in self.knots:
            n = len(pk.v)
            for k in range(n - 1):
                pk.err[(pk.v[k], pk.v[k + 1])] = {q: abs(pk.rows[k + 1][q] - pk.rows[k][q]) for q in INTERPOLATED}
            if n < 3:
                continue
            keep = list(range(0, n, 2)) + ([n - 1] if (n - 1) % 2 else [])
            sub = _Knots(pk.piece, [pk.v[i] for i in keep], [pk.rows[i] for i in keep])
            sp = sub.splines()
            for k in range(1, n - 1, 2):
                for key in ((pk.v[k - 1], pk.v[k]), (pk.v[k], pk.v[k + 1])):
                    pk.err[key] = {q: max(pk.err[key][q], abs(float(sp[q](pk.v[k])) - pk.rows[k][q]) if sp[q] is not None else 0.0)
                                   for q in INTERPOLATED}

    def bem_errors(self) -> dict:
        """Two depths (in the first and the last piece) solved again at order - 2."""
        from semianalytic.bem.panels import LayoutOptions

        lower = LayoutOptions(max(self.opts.order - 2, 2), self.opts.refinement, self.opts.levels)
        out = {q: 0.0 for q in INTERPOLATED}
        for pk in (self.knots[0], self.knots[-1]):
            P = float(pk.piece.P(0.5))
            if self._is_kink(P):
                P *= 1 + 1e-3
            a = _row(plate_depth_coefficients(self.nose, self.H, P, self.opts, self.kinks))
            b = _row(plate_depth_coefficients(self.nose, self.H, P, lower, self.kinks))
            self.solves += 2
            for q in INTERPOLATED:
                out[q] = max(out[q], abs(a[q] - b[q]))
        resid = max(abs(r["B_bernoulli"] - r["dA_dP"]) for pk in self.knots for r in pk.rows)
        for q in ("B_body", "B_literal", "B_bernoulli"):
            out[q] = max(out[q], resid)
        scale = self.scales()
        return {q: max(e, ROUND_OFF * scale[q]) for q, e in out.items()}

    def table(self, options: dict, bem_err: dict, tolerance) -> PlateCoefficientTable:
        rows, errs = [], {q: [] for q in INTERPOLATED}
        for pk in self.knots:
            p = pk.piece
            sp = pk.splines()
            for k in range(len(pk.v) - 1):
                a, b = pk.v[k], pk.v[k + 1]
                P_lo = float(p.P(a))
                if k == 0 and self.flat and p.a == 0.0:  # flat tip: constant below the first solve
                    P_lo = 0.0
                rows.append({"P_lo": P_lo, "a": p.a, "b": p.b, "m": p.m, "side": p.side, "v0": a,
                             **{f"coef_{q}": _coef6(sp[q], a, pk.rows[0][q]) for q in INTERPOLATED}})
                e = pk.err.get((a, b), {})
                for q in INTERPOLATED:
                    errs[q].append(e.get(q, math.inf))
        intervals = {k: np.array([r[k] for r in rows], float) for k in ("P_lo", "a", "b", "m", "side", "v0")}
        for q in INTERPOLATED:
            intervals[f"coef_{q}"] = np.array([r[f"coef_{q}"] for r in rows], float)
            intervals[f"err_{q}"] = np.array(errs[q], float)
        solved = sorted((P, r, nd, n) for P, (r, nd, n) in self.solved.items())
        return PlateCoefficientTable(
            nose_kind=self.nose.kind, diameter=self.nose.diameter, nose_length=self.nose.length, thickness=self.H,
            depth=np.array([s[0] for s in solved]),
            values={k: np.array([s[1][k] for s in solved]) for k in ROW_KEYS},
            unknowns=np.array([s[3] for s in solved], int), nodes=tuple(s[2] for s in solved),
            intervals=intervals, bem_errors=bem_err, options=options, tolerance=tolerance, kinks=tuple(self.kinks),
        )


def plate_coefficient_table(
    nose: Nose,
    thickness: float,
    *,
    tolerance: float | None = None,
    reading: str = "body",
    order: int = 8,
    refinement: float = 0.3,
    levels: int = 6,
    depths=None,
    max_solves: int = MAX_SOLVES,
    bem_error: bool = True,
    progress: bool = False,
) -> PlateCoefficientTable:
    """Tabulate A, B, C of a nose perforating a plate of thickness H [m], 0 <= P <= H + L_h
    (zero beyond), with error estimates (module docstring).  ``tolerance``: relative
    interpolation tolerance (default 1e-5 of each coefficient's largest magnitude);
    ``depths``: fixed knots instead (error estimates from dropping every other knot); ``progress``:
    a progress line of the depths solved on stderr (when it is a terminal)."""
    from semianalytic.bem.panels import LayoutOptions

    thickness = check_thickness(nose, thickness)
    if reading not in READINGS:
        raise ValueError(f"reading must be one of {READINGS}")
    tol = check_tolerance(DEFAULT_TOLERANCE if tolerance is None else tolerance)
    opts = LayoutOptions(order, refinement, levels)
    b = _Builder(nose, float(thickness), opts, tol, max_solves)
    if progress:
        import sys

        from tqdm import tqdm

        b.bar = tqdm(desc=f"plate BEM depths (H = {thickness * 1e3:.4g} mm)", unit="depth", leave=False, file=sys.stderr,
                     disable=not sys.stderr.isatty())
    options = {"order": order, "refinement": refinement, "levels": levels}
    if depths is not None:
        for pk in b.knots:
            p = pk.piece
            vs = {0.0, 1.0} | {float(p.v(P)) for P in np.asarray(depths, float) if p.a < P < p.b}
            for v in sorted(vs):
                pk.add(v, *b._solve_v(pk, v))
        b.fixed_errors()
        options["depths"] = [float(P) for P in depths]
    else:
        b.initial()
        b.refine()
        options["tolerance"] = tol
        options["noise_limited_intervals"] = b.noise_limited
    bem_err = b.bem_errors() if bem_error else {}
    if b.bar is not None:
        b.bar.close()
    return b.table(options, bem_err, tol).with_reading(reading)
