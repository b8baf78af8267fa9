"""The potential problem of Part I in a plate: a nose in the slab 0 <= x <= H (issue 23, item 2).

Boundary conditions.  On the front face x = 0 the condition of Part I, eq. (7) is kept
(dphi/dn = 0, the half-space model of today, so that H -> infinity gives today's
coefficients).  On the back face x = H the target is free to move and is taken as a free
surface of the impulsive (linearised) flow, phi = 0 (this project's own choice, argued here):
with dphi/dn = 0 on both faces the flux C that the nose pushes into the plate could only
leave radially through the slab, phi would grow like ln r and the added mass would be
infinite; phi = 0 on the back face lets it out, and phi decays exponentially in r.

Green's function: images.  Reflecting in x = 0 with the same sign (Neumann) and in x = H
with the opposite sign (Dirichlet) gives sources at 2kH +- y with the sign (-1)^k:

    G_slab(x, y) = sum_k (-1)^k [G(x - 2kH, y) + G(x - 2kH, y')],   y' = y mirrored in x = 0,

the k = 0 term being today's half-space kernel (Part I, eqs. (21)-(22)).  It satisfies both
face conditions term by term in pairs, so Green's representation over the wetted surface alone
(the faces drop out: both phi and G obey the same homogeneous conditions there) gives the
second-kind equation of :mod:`semianalytic.bem.solve` with this kernel.

Why images and not a meshed back face: the image copies reuse the half-space quadrature
unchanged (a copy is the half-space panel set seen from targets shifted by 2kH), the k = 0
block *is* the half-space matrix (so the limit H -> infinity is exact term by term, and the
half-space path is untouched), and the back face, an infinite plane, needs no truncation.
The series converges only conditionally (like 1 - 1/2 + 1/3 ...), so it is cut at |k| = K
with 2 K H >= TAIL_SEPARATION times the body radius and the rest is summed in closed form:
for |k| > K every copy is far, the ring kernels are expanded in 1/s (s the axial distance;
the azimuthal means of 1/R up to s^-5 and of its derivatives up to s^-6) and the alternating
sums of |s0 - 2kH|^-p are alternating Hurwitz zeta functions (digamma for p = 1).  The
truncation error of the tail is ~ (r_max/s_K)^6 of the tail, which is itself ~ r_max/s_K of
phi: below 1e-9 relative at TAIL_SEPARATION = 12.

The tip past the back face (P > H): the wetted surface is the band of the body inside the
slab, cut at x = H as well (:func:`slab_layout`); there it meets its odd image (the k = 1
copy) at a ring where phi = 0.  The wedge of fluid between the body and the face has an angle
beta <= pi/2, so phi ~ s^(pi/(2 beta)) with exponent >= 1 there: a benign edge.  The
row-sum identity of the half-space assembly (double layer of 1 = -1/2 on the closed surface
S + S') is kept by closing the open band with two discs (its end caps at x = +-H), whose
double layer is integrated here and moved to the diagonal.

Not slab-aware: :meth:`SurfaceSolution.potential` / ``gradient`` (the field off the surface)
sum the half-space kernel only; the surface values (phi, dphi/ds), and so A, B, C, are exact.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from scipy.special import digamma, zeta

from semianalytic.bem.kernels import single_double
from semianalytic.bem.panels import (
    GRADING_RATIO,
    HalfspaceLayout,
    LayoutOptions,
    PanelSet,
    Piece,
    graded_panels,
    halfspace_layout,
    panel_set,
    param_at_x,
)
from semianalytic.bem.solve import (
    AssemblyPlan,
    SurfaceSolution,
    _flat_nodes,
    _layers,
    assemble,
    near_pairs,
    near_quadrature,
    solve_assembled,
)
from semianalytic.geometry import Line, Nose

TAIL_SEPARATION = 12.0  # copies beyond 2 K H >= this many body radii are summed in closed form
MAX_COPIES = 400  # explicit copies on either side at most (plates thinner than ~0.03 radii refused)
CAP_PANELS = 6  # panels on each end cap (graded towards the rim)


# --------------------------------------------------------------------------------------
# layout


@dataclass(frozen=True)
class SlabLayout:
    """Panels of the wetted surface of a nose at depth P in the plate 0 <= x <= H.

    For P <= H the half-space layout (the tip inside the plate), its first panel graded
    towards the tip when the back face is near; for P > H the same layout cut at the back
    face x = H (body frame x_b = H - P): the first piece starts at the cut.  ``at_depth``
    keeps the topology (both cuts stretch) for differences in P.
    """

    half: HalfspaceLayout
    thickness: float
    pieces: tuple[Piece, ...]

    @property
    def depth(self) -> float:
        return self.half.depth

    @property
    def nose(self) -> Nose:
        return self.half.nose

    @property
    def through(self) -> bool:
        """The tip has passed the back face (the wetted surface is an open band)."""
        return self.depth > self.thickness

    def at_depth(self, depth: float) -> SlabLayout:
        half = self.half.at_depth(depth)
        if not self.through:
            if depth > self.thickness:
                raise ValueError("depth moved across the back face; use a smaller step")
            first = half.pieces[0]
            pieces = (Piece(first.segment, first.t0, first.t1, first.p0, first.p1, self.pieces[0].panels, first.powers),
                      *half.pieces[1:])
            return SlabLayout(half, self.thickness, pieces)
        if not depth > self.thickness:
            raise ValueError("depth moved across the back face; use a smaller step")
        skip = len(half.pieces) - len(self.pieces)
        first = half.pieces[skip]
        x_cut = self.thickness - depth
        t_cut = param_at_x(first.segment, x_cut)
        if not min(first.t0, first.t1) <= t_cut <= max(first.t0, first.t1):
            raise ValueError("the back-face cut moved across a joint; use a smaller step")
        cut = Piece(first.segment, t_cut, first.t1, (x_cut, float(first.segment.point(t_cut)[1])), first.p1,
                    self.pieces[0].panels, (1.0, first.powers[1]))
        return SlabLayout(half, self.thickness, (cut, *half.pieces[skip + 1:]))

    def panels(self) -> PanelSet:
        """Primary panels (tip at x = P) followed by their mirror images in x = 0."""
        return panel_set(self.pieces, self.half.options.order, offset=self.depth, mirror=True,
                         label=f"{self.nose.kind} nose")

    def cap_radius(self) -> float:
        """Radius of the body where it crosses the back face (P > H), else 0."""
        return float(self.pieces[0].p0[1]) if self.through else 0.0


def _split_first(rows: np.ndarray, levels: int) -> np.ndarray:
    """Subdivide the first panel of a piece geometrically ``levels`` times towards t0."""
    if levels <= 0:
        return rows
    anchor, a, b = rows[0]
    if anchor != 0 or a != 0.0:
        return rows
    edges = [0.0] + [b * GRADING_RATIO**k for k in range(levels, 0, -1)] + [b]
    new = [(0, lo, hi) for lo, hi in zip(edges[:-1], edges[1:])]
    return np.vstack([np.array(new, float), rows[1:]])


def _first_panel_length(piece: Piece) -> float:
    from semianalytic.geometry import segment_arc_length

    anchor, a, b = piece.panels[0]
    span = piece.t1 - piece.t0
    return segment_arc_length(piece.segment, piece.t0 + a * span, piece.t0 + b * span)


def _need(gap: float, h: float) -> int:
    """Geometric levels (ratio GRADING_RATIO) that bring a panel of length h down to gap."""
    if not (0 < gap < h):
        return 0
    return min(int(math.ceil(math.log(gap / h) / math.log(GRADING_RATIO))), 22)


def slab_layout(nose: Nose, depth: float, thickness: float, options: LayoutOptions = LayoutOptions()) -> SlabLayout:
    """Layout of the wetted surface at depth P in a plate of thickness H (0 < P < H + L_h).

    P <= H: the half-space layout; where the tip is closer to the back face than its first
    panel is long, that panel is graded towards the tip down to the gap H - P (the tip and
    its image in the back face are 2 (H - P) apart).  P > H: the layout cut at the back face,
    the cut graded like a corner (``options.junction_levels + 2`` levels: phi ~ s^lambda,
    lambda >= 1, there)."""
    if not (depth > 0 and thickness > 0):
        raise ValueError("depth and thickness must be positive")
    if depth >= thickness + nose.length:
        raise ValueError("the nose has left the plate (P >= H + L_h): A = B = C = 0, nothing to solve")
    half = halfspace_layout(nose, depth, options)
    pieces = list(half.pieces)
    if depth <= thickness:
        gap = thickness - depth
        first = pieces[0]
        lev = _need(gap, _first_panel_length(first)) if options.levels else 0
        pieces[0] = Piece(first.segment, first.t0, first.t1, first.p0, first.p1, _split_first(first.panels, lev), first.powers)
        return SlabLayout(half, thickness, tuple(pieces))
    x_cut = thickness - depth  # body frame, < 0
    for k, piece in enumerate(pieces):  # noqa: B007
        if float(piece.p1[0]) < x_cut:
            break
    else:  # pragma: no cover - excluded by the check on depth above
        raise ValueError("the back face does not cut the nose")
    t_cut = param_at_x(piece.segment, x_cut)
    p_cut = (x_cut, float(piece.segment.point(t_cut)[1]))
    # re-grade the piece from the cut: panels no longer than the piece's uniform ones, graded
    # geometrically towards the cut (phi'_P at the moving cut goes like s^(lambda - 1): graded as
    # a tip; clipping the old rows instead left a sliver beside a long panel, and B off by 2e-4
    # of pi R^2), and as before towards the far end
    rows = piece.panels
    frac_cut = (t_cut - piece.t0) / (piece.t1 - piece.t0)
    sizes = rows[:, 2] - rows[:, 1]
    h_u = float(np.max(sizes))
    g1 = int(np.sum((rows[:, 0] == 1) & (sizes < 0.99 * h_u)))
    g1 = max(g1 - 1, 0)
    n = max(2, int(math.ceil((1.0 - frac_cut) / h_u - 1e-9)))
    lev = options.levels + 2 if options.levels else 0
    arr = graded_panels(n, lev, g1)
    cut = Piece(piece.segment, t_cut, piece.t1, p_cut, piece.p1, arr, (1.0, piece.powers[1]))
    return SlabLayout(half, thickness, (cut, *pieces[k + 1:]))


# --------------------------------------------------------------------------------------
# assembly


def copies(thickness: float, r_max: float) -> int:
    """K: copies |k| <= K are summed explicitly, the rest in closed form (module docstring)."""
    K = max(1, int(math.ceil(0.5 * TAIL_SEPARATION * r_max / thickness)))
    if K > MAX_COPIES:
        raise ValueError(f"the plate is too thin for the image series (H/r = {thickness / r_max:.3g})")
    return K


def _eta(p: int, z):
    """Alternating Hurwitz sum sum_{n >= 0} (-1)^n (n + z)^-p (z > 0)."""
    if p == 1:
        return 0.5 * (digamma(0.5 * (z + 1.0)) - digamma(0.5 * z))
    return 2.0**-p * (zeta(p, 0.5 * z) - zeta(p, 0.5 * (z + 1.0)))


@functools.cache
def _eta_interpolant(p: int, K: int):
    """:func:`_eta` on z in [K, K + 2] (where the tail needs it) as a Chebyshev interpolant of
    degree 32: the nearest singularity (the pole at z = 0) is at least one half-width from the
    interval (measured: 2e-12 relative at K = 1, 1e-14 for K >= 2; the tail itself is below
    1e-2 of phi), and an
    assembly evaluates polynomials instead of scipy's zeta (85% of a solve's time)."""
    from numpy.polynomial import Chebyshev

    return Chebyshev.interpolate(lambda z: _eta(p, z), 32, domain=[K, K + 2.0])


def _tail_kernels(xt, rt, xs, rs, nxs, nrs, thickness: float, K: int):
    """sum_{|k| > K} (-1)^k of the ring kernels (S, Dl) between targets (xt, rt) and sources
    (xs, rs) shifted by 2kH, from the expansion of the ring mean of 1/R in 1/s (module
    docstring).  Arrays broadcast; target-frame abscissae."""
    s0 = xt - xs  # |s0| < 2H for the surface and its mirror image
    c = s0 / (2.0 * thickness)
    q1 = rt * rt + rs * rs
    q2 = q1 * q1 + 2.0 * rt * rt * rs * rs
    sign = (-1.0) ** (K + 1)
    S = np.zeros(np.broadcast(xt, xs).shape)
    Dl = np.zeros_like(S)
    # k > K: s = s0 - 2kH < 0;  k < -K: s > 0.  |s| = 2H (k -+ c)
    for side, z in ((-1.0, K + 1.0 - c), (1.0, K + 1.0 + c)):
        z = np.clip(z, K, K + 2.0)
        T = {p: sign * (2.0 * thickness) ** -p * _eta_interpolant(p, K)(z) for p in range(1, 7)}
        mean = T[1] - 0.5 * q1 * T[3] + 0.375 * q2 * T[5]  # <1/R>
        # d<1/R>/dx1 = sign(s) [u^2 - 3/2 q1 u^4 + 15/8 q2 u^6]; d<1/R>/dr1 = -r1 u^3 + 3/2 r1 (2 r^2 + r1^2) u^5
        dx1 = side * (T[2] - 1.5 * q1 * T[4] + 1.875 * q2 * T[6])
        dr1 = -rs * T[3] + 1.5 * rs * (2.0 * rt * rt + rs * rs) * T[5]
        S += 0.5 * rs * mean
        Dl += 0.5 * rs * (nxs * dx1 + nrs * dr1)
    return S, Dl


@dataclass(frozen=True)
class SlabPlan:
    """The quadrature rules of a slab solve, frozen for the stencil of a difference in P (as
    :class:`~semianalytic.bem.solve.AssemblyPlan` for the half-space part): the half-space
    plan, the near rules of each copy, the number K of explicit copies and the caps' rules."""

    base: AssemblyPlan
    copies: dict
    K: int
    caps: tuple


def _cap_panels(ps: PanelSet, x_cap: float, radius: float, normal: float, levels: int) -> PanelSet:
    """The disc x = x_cap (computational frame), 0 <= r <= radius, normal (normal, 0), with
    panels graded towards its rim."""
    seg = Line((x_cap, 0.0), (x_cap, radius)) if normal > 0 else Line((x_cap, radius), (x_cap, 0.0))
    rows = graded_panels(CAP_PANELS, 0, levels) if normal > 0 else graded_panels(CAP_PANELS, levels, 0)
    return panel_set([Piece(seg, 0.0, 1.0, seg.p0, seg.p1, rows)], ps.order, label="cap")


def _targets(ps: PanelSet):
    X, R, _, _, _ = _flat_nodes(ps)
    N = ps.n_primary * ps.order
    return X[:N], R[:N]


def _caps(ps: PanelSet, thickness: float, cap_radius: float, levels: int):
    P = ps.offset
    return (_cap_panels(ps, thickness - P, cap_radius, 1.0, levels),
            _cap_panels(ps, -thickness - P, cap_radius, -1.0, levels))


def plan_slab(ps: PanelSet, thickness: float, cap_radius: float = 0.0, cap_levels: int = 12) -> SlabPlan:
    """Choose every rule of :func:`assemble_slab` for the panel set ``ps`` (see SlabPlan)."""
    from semianalytic.bem.solve import plan_assembly

    xt, rt = _targets(ps)
    K = copies(thickness, float(np.max(ps.nodes.r)))
    rules = {}
    for k in range(1, K + 1):
        for kk in (k, -k):
            tgt, pan, ustar, du = near_pairs(ps, xt - 2.0 * kk * thickness, rt)
            rules[kk] = near_quadrature(tgt, pan, ustar, du, ps.order) if tgt.size else None
    caps = ()
    if cap_radius > 0:
        for cap in _caps(ps, thickness, cap_radius, cap_levels):
            tgt, pan, ustar, du = near_pairs(cap, xt, rt)
            caps += (near_quadrature(tgt, pan, ustar, du, cap.order) if tgt.size else None,)
    return SlabPlan(plan_assembly(ps), rules, K, caps)


def _matrices(src: PanelSet, xt, rt, rule, both: bool = True):
    """Single- and double-layer matrices of the panel set ``src`` (not folded) at targets
    (xt, rt): plain Gauss rules, and ``rule`` (graded) for the near pairs."""
    p = src.order
    X, R, NX, NR, W = _flat_nodes(src)
    with np.errstate(divide="ignore", invalid="ignore"):
        S, D = single_double(xt[:, None], rt[:, None], X[None, :], R[None, :], NX[None, :], NR[None, :])
    S *= W[None, :]
    D *= W[None, :]
    if rule is not None:
        Sb, Db = rule.integrate(src, xt, rt, _layers)
        rows = rule.target[:, None]
        cols = rule.panel[:, None] * p + np.arange(p)[None, :]
        S[rows, cols] = Sb
        D[rows, cols] = Db
    return S, D




def assemble_slab(ps: PanelSet, thickness: float, plan: SlabPlan | None = None, cap_radius: float = 0.0,
                  cap_levels: int = 12) -> tuple[np.ndarray, np.ndarray]:
    """(Smat, Dmat) of the slab kernel at the primary nodes; (I/2 - Dmat) phi = -Smat g.

    k = 0: :func:`semianalytic.bem.solve.assemble` unchanged (the half-space matrices, with
    their row-sum correction); ``cap_radius`` > 0 (the band of a nose through the back face):
    the row sums are moved from -1/2 to -1/2 minus the double layer of 1 of the two end caps.
    |k| = 1..K: copies with the graded near rules; |k| > K: the closed-form tail."""
    plan = plan or plan_slab(ps, thickness, cap_radius, cap_levels)
    S, D = assemble(ps, plan.base)
    N = S.shape[0]
    H = thickness
    P = ps.offset
    xt, rt = _targets(ps)
    if cap_radius > 0:  # the band S + S' is open at x = +-H: close it with discs there
        capw = sum(_matrices(cap, xt, rt, rule)[1].sum(axis=1)
                   for cap, rule in zip(_caps(ps, H, cap_radius, cap_levels), plan.caps))
        D[np.arange(N), np.arange(N)] -= capw
    K = plan.K
    for k in range(1, K + 1):
        for kk in (k, -k):
            Sk, Dk = _matrices(ps, xt - 2.0 * kk * H, rt, plan.copies[kk])
            sgn = (-1.0) ** k
            S += sgn * ps.fold_mirror(Sk)
            D += sgn * ps.fold_mirror(Dk)
    X, R, NX, NR, W = _flat_nodes(ps)
    St, Dt = _tail_kernels(xt[:, None] + P, rt[:, None], X[None, :] + P, R[None, :], NX[None, :], NR[None, :], H, K)
    S += ps.fold_mirror(St * W[None, :])
    D += ps.fold_mirror(Dt * W[None, :])
    return S, D


def cap_levels(layout: SlabLayout) -> int:
    """Grading of the end caps towards their rim: as the cut of the band."""
    return max(layout.half.options.levels, 2)


def plan_for(layout: SlabLayout) -> SlabPlan:
    """The rules of :func:`solve_slab` at this layout (reusable on ``layout.at_depth``)."""
    return plan_slab(layout.panels(), layout.thickness, layout.cap_radius(), cap_levels(layout))


def solve_slab(layout: SlabLayout, *, neumann=None, plan: SlabPlan | None = None) -> SurfaceSolution:
    """phi on the wetted surface of a nose at depth P in the plate (unit speed, +x).

    ``neumann(x, r, nx, nr) -> g`` replaces the datum g = -n_x of Part I, eq. (7) (for
    checks against exact solutions); ``plan`` reuses the quadrature rules of a layout of the
    same topology (the stencil of a difference in P)."""
    ps = layout.panels()
    S, D = assemble_slab(ps, layout.thickness, plan, layout.cap_radius(), cap_levels(layout))
    phi, g = solve_assembled(ps, S, D, neumann, layout.depth)  # the half-space's solve step
    return SurfaceSolution(ps, phi, g, "slab", depth=layout.depth)
