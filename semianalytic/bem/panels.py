"""Panels on a meridian: layouts (with grading) and node geometry.

A panel is a parameter interval [ta, tb] of one analytic segment of the meridian, mapped
from the reference interval u in [-1, 1].  Geometry is always evaluated on the exact curve
(no interpolation of the shape).  A panel may be *mirrored* in the plane x = 0 (the
image body S' of Part I, eqs. (21)-(22), Fig. 3): its x is negated and its parameter
runs backwards so that the closed chain S + S' keeps one orientation.

Layouts grade panels geometrically towards points where the solution is singular
(conical tips, corners, the edge where a nose crosses the free surface) and grow them
geometrically along a long shank, so that accuracy is uniform with few unknowns.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.optimize import brentq

from semianalytic.bem.quadrature import gauss_legendre
from semianalytic.geometry import Arc, EllipseArc, Line, Meridian, Nose, Segment, SplineCurve

GRADING_RATIO = 0.2  # size ratio between successive graded panels (hp-type grading)


@dataclass(frozen=True)
class PanelSet:
    """Panels over one or more segments.

    ``segment_index[k]``, ``ta[k]``, ``tb[k]`` locate panel k; ``sign[k]`` is +1, or -1
    for a mirrored panel (x -> -x); ``offset`` shifts x before mirroring (the target
    frame puts the tip of a nose at x = P).  The first ``n_primary`` panels are the
    physical surface; the rest (if any) are the mirror images, in reverse order.
    """

    segments: tuple[Segment, ...]
    segment_index: np.ndarray
    ta: np.ndarray
    tb: np.ndarray
    sign: np.ndarray
    offset: float
    order: int
    n_primary: int

    @property
    def n_panels(self) -> int:
        return len(self.ta)

    def evaluate(self, panel: np.ndarray, u: np.ndarray, second: bool = False):
        """Points and derivatives d/du at reference coordinates ``u`` of panels ``panel``.

        ``panel`` and ``u`` broadcast together; returns x, r, x_u, r_u (and x_uu, r_uu
        with ``second=True``).
        """
        panel, u = np.broadcast_arrays(np.asarray(panel), np.asarray(u, dtype=float))
        out = [np.empty(u.shape) for _ in range(6 if second else 4)]
        seg_of = self.segment_index[panel]
        for s, seg in enumerate(self.segments):
            mask = seg_of == s
            if not mask.any():
                continue
            pk = panel[mask]
            ta, tb, sg = self.ta[pk], self.tb[pk], self.sign[pk]
            half = 0.5 * (tb - ta)
            t = ta + half * (u[mask] + 1.0)
            px, pr = seg.point(t)
            dx, dr = seg.derivative(t)
            out[0][mask] = sg * (px + self.offset)
            out[1][mask] = pr
            out[2][mask] = sg * dx * half
            out[3][mask] = dr * half
            if second:
                ddx, ddr = seg.second_derivative(t)
                out[4][mask] = sg * ddx * half * half
                out[5][mask] = ddr * half * half
        return tuple(out)

    @cached_property
    def nodes(self) -> "NodeGeometry":
        u, w = gauss_legendre(self.order)
        panel = np.repeat(np.arange(self.n_panels), self.order).reshape(self.n_panels, self.order)
        x, r, xu, ru = self.evaluate(panel, np.broadcast_to(u, panel.shape))
        J = np.hypot(xu, ru)
        return NodeGeometry(x=x, r=r, tx=xu / J, tr=ru / J, J=J, w=w * J)

    @cached_property
    def centers(self) -> tuple[np.ndarray, np.ndarray]:
        """(x, r) of each panel's midpoint u = 0."""
        x, r, _, _ = self.evaluate(np.arange(self.n_panels), np.zeros(self.n_panels))
        return x, r

    @cached_property
    def lengths(self) -> np.ndarray:
        """Arc length of each panel."""
        return self.nodes.w.sum(axis=1)

    def mirror_node_index(self) -> np.ndarray:
        """Flat index of the mirror image of each primary node (for folding columns)."""
        p, n = self.order, self.n_primary
        if self.n_panels == n:
            return np.empty(0, dtype=int)
        k = np.arange(n)
        mirror_panel = 2 * n - 1 - k
        return (mirror_panel[:, None] * p + (p - 1 - np.arange(p))[None, :]).ravel()


@dataclass(frozen=True)
class NodeGeometry:
    """Geometry at the Gauss nodes, arrays of shape (n_panels, p).

    ``w`` is the arc-length quadrature weight (Gauss weight times |dy/du|); the surface
    element of the ring is 2 pi r w.  The unit normal out of the body is (tr, -tx).
    """

    x: np.ndarray
    r: np.ndarray
    tx: np.ndarray
    tr: np.ndarray
    J: np.ndarray
    w: np.ndarray

    @property
    def nx(self) -> np.ndarray:
        return self.tr

    @property
    def nr(self) -> np.ndarray:
        return -self.tx


# ------------------------------------------------------------------------------------
# breakpoints


def _graded(t0: float, t1: float, n: int, grade0: int, grade1: int, ratio: float = GRADING_RATIO) -> np.ndarray:
    """n uniform panels on [t0, t1]; the first/last subdivided geometrically ``grade*`` times."""
    edges = np.linspace(t0, t1, n + 1)
    h = edges[1] - edges[0]
    head = [t0 + h * ratio**k for k in range(grade0, 0, -1)] if grade0 else []
    tail = [t1 - h * ratio**k for k in range(1, grade1 + 1)] if grade1 else []
    return np.concatenate([[t0], head, edges[1:-1], tail[::-1], [t1]])


def _segment_arc_length(seg: Segment, ta: float, tb: float) -> float:
    u, w = gauss_legendre(24)
    t = 0.5 * (ta + tb) + 0.5 * (tb - ta) * u
    dx, dr = seg.derivative(t)
    return float(0.5 * abs(tb - ta) * np.sum(w * np.hypot(dx, dr)))


def _count(arc: float, scale: float, refinement: float, per_scale: float, minimum: int = 2) -> int:
    return max(minimum, int(math.ceil(refinement * per_scale * arc / scale)))


# ------------------------------------------------------------------------------------
# layouts


@dataclass(frozen=True)
class LayoutOptions:
    """Resolution of a layout: ``order`` Gauss points per panel; ``refinement`` scales
    panel counts; ``levels`` graded panels towards singular points."""

    order: int = 8
    refinement: float = 1.0
    levels: int = 8


def body_panels(meridian: Meridian, options: LayoutOptions = LayoutOptions()) -> PanelSet:
    """Panels on a closed meridian in unbounded fluid (sphere, spheroid, projectile, table)."""
    segs = meridian.segments
    corners = meridian.corners()
    tip0, tip1 = meridian.axis_angles()
    scale = max(float(np.max(np.abs(s.point(np.linspace(s.t0, s.t1, 33))[1]))) for s in segs)
    idx, ta, tb = [], [], []
    for k, seg in enumerate(segs):
        arc = _segment_arc_length(seg, seg.t0, seg.t1)
        n = _count(arc, scale, options.refinement, 1.6)
        if isinstance(seg, EllipseArc):
            # a slender ellipse needs panels in proportion to its length in the parameter
            n = max(n, _count(math.pi * max(seg.a, seg.b), math.pi * min(seg.a, seg.b), options.refinement, 1.2, 4))
        if isinstance(seg, SplineCurve):
            n = max(n, len(seg.knots) - 1)
        g0 = options.levels if (k == 0 and tip0 > 1e-6) or (k > 0 and corners[k - 1]) else 0
        g1 = options.levels if (k == len(segs) - 1 and tip1 > 1e-6) or (k < len(segs) - 1 and corners[k]) else 0
        edges = _graded(seg.t0, seg.t1, n, g0, g1)
        idx += [k] * (len(edges) - 1)
        ta += list(edges[:-1])
        tb += list(edges[1:])
    n = len(ta)
    return PanelSet(
        segments=tuple(segs),
        segment_index=np.array(idx),
        ta=np.array(ta),
        tb=np.array(tb),
        sign=np.ones(n),
        offset=0.0,
        order=options.order,
        n_primary=n,
    )


def param_at_x(seg: Segment, x: float) -> float:
    """Parameter where a nose segment reaches body-frame abscissa ``x`` (x decreases along it)."""
    if isinstance(seg, Line):
        (x0, _), (x1, _) = seg.p0, seg.p1
        return (x - x0) / (x1 - x0)
    if isinstance(seg, Arc):
        c = np.clip((x - seg.center[0]) / seg.radius, -1.0, 1.0)
        return float(np.arccos(c))
    f = lambda t: float(seg.point(t)[0]) - x  # noqa: E731
    return brentq(f, seg.t0, seg.t1, xtol=1e-15 * max(1.0, abs(x)), rtol=4e-16)


@dataclass(frozen=True)
class HalfspaceLayout:
    """Breakpoints of the submerged surface of a nose at depth P (body frame).

    ``pieces`` are (segment, normalised breakpoints in [0, 1], t_start, t_end): the last
    piece ends at the free surface.  Re-evaluating the same layout at a nearby depth with
    :meth:`at_depth` keeps the panel topology and moves only the last piece's end (the
    frozen topology that differentiation in P needs).
    """

    nose: Nose
    depth: float
    pieces: tuple[tuple[Segment, np.ndarray, float, float], ...]
    options: LayoutOptions

    def at_depth(self, depth: float) -> "HalfspaceLayout":
        *head, (seg, tau, t0, _) = self.pieces
        if isinstance(seg, Line) and seg.p0[0] == -self.nose.length and seg.p1[1] == seg.p0[1]:
            if depth <= self.nose.length:
                raise ValueError("depth moved across the nose-shank junction; use a smaller step")
            new_last = (Line(seg.p0, (-depth, seg.p0[1])), tau, 0.0, 1.0)
        else:
            if depth > self.nose.length:
                raise ValueError("depth moved across the nose-shank junction; use a smaller step")
            new_last = (seg, tau, t0, param_at_x(seg, -depth))
        return HalfspaceLayout(self.nose, depth, (*head, new_last), self.options)

    def panels(self) -> PanelSet:
        """Primary panels (target frame, tip at x = P) followed by their mirror images."""
        segs, idx, ta, tb = [], [], [], []
        for seg, tau, t0, t1 in self.pieces:
            edges = t0 + (t1 - t0) * tau
            segs.append(seg)
            idx += [len(segs) - 1] * (len(edges) - 1)
            ta += list(edges[:-1])
            tb += list(edges[1:])
        idx, ta, tb = np.array(idx), np.array(ta), np.array(tb)
        n = len(ta)
        return PanelSet(
            segments=tuple(segs),
            segment_index=np.concatenate([idx, idx[::-1]]),
            ta=np.concatenate([ta, tb[::-1]]),
            tb=np.concatenate([tb, ta[::-1]]),
            sign=np.concatenate([np.ones(n), -np.ones(n)]),
            offset=self.depth,
            order=self.options.order,
            n_primary=n,
        )


def halfspace_layout(nose: Nose, depth: float, options: LayoutOptions = LayoutOptions()) -> HalfspaceLayout:
    """Layout of the submerged nose (and shank, and entry-hole wall) at depth P > 0.

    For P <= L_h the nose is cut by the free surface x = 0, where the surface and its
    mirror image meet at an edge: panels are graded towards it.  For P > L_h the shank
    and the hole wall form one cylinder r = d/2 from the shoulder to x = 0 (n_x = 0 there,
    so A, B, C depend only on the nose and P: errata item 1b); its panels grow
    geometrically away from the shoulder, and it meets its mirror image smoothly.
    """
    if not depth > 0:
        raise ValueError("depth must be positive")
    R, Lh = nose.radius, nose.length
    lev, ref = options.levels, options.refinement
    segs = nose.segments
    submerged = min(depth, Lh)
    # local length scale of the submerged nose part
    scale = max(min(R, submerged if depth < Lh else R), 1e-300)
    pieces = []
    # conical tip (ogive psi > 1/2, cone, table): grade towards it
    tip_conical = nose.tip_half_angle() < 0.5 * math.pi - 1e-9
    turning = Meridian(segs, closed=False).corners() if len(segs) > 1 else []
    for k, seg in enumerate(segs):
        x_end = float(seg.point(seg.t1)[0])
        cut_here = depth < Lh and -depth >= x_end - 1e-15 * max(Lh, R)
        t1 = param_at_x(seg, -depth) if cut_here else seg.t1
        arc = _segment_arc_length(seg, seg.t0, t1)
        if arc <= 0:
            continue
        n = _count(arc, scale, ref, 1.6)
        if isinstance(seg, SplineCurve):
            n = max(n, int(np.sum((seg.knots > seg.t0) & (seg.knots < t1))) + 1)
        g0 = lev if (k == 0 and tip_conical) or (k > 0 and turning[k - 1]) else 0
        if k > 0 and not turning[k - 1]:
            g0 = 2  # curvature jump between tangent segments: mild grading
        if cut_here:
            g1 = lev
        elif k < len(segs) - 1:
            g1 = lev if turning[k] else 2
        else:
            # shoulder: corner if the nose does not meet the shank tangentially
            dx, dr = (float(v) for v in seg.derivative(seg.t1))
            g1 = lev if abs(dr) > 1e-9 * math.hypot(dx, dr) else 2
        edges = _graded(seg.t0, t1, n, g0, g1)
        pieces.append((seg, (edges - seg.t0) / (t1 - seg.t0), seg.t0, t1))
        if cut_here:
            break
    if depth > Lh:
        length = depth - Lh
        shoulder_corner = pieces[-1][1].size and _shoulder_is_corner(nose)
        h0 = R / max(ref, 1e-9) * 0.8
        grade = options.levels if shoulder_corner else 2
        edges = [0.0]
        # graded start at the shoulder, then geometric growth by a factor 2
        h = min(h0, 0.5 * length)
        for k in range(grade, 0, -1):
            edges.append(h * GRADING_RATIO**k)
        pos = h
        while pos < length:
            edges.append(pos)
            h *= 2.0 if ref <= 1 else 2.0 ** (1.0 / ref)
            pos += h
        if length - edges[-1] < 0.5 * (edges[-1] - edges[-2]) and len(edges) > 2:
            edges[-1] = length
        else:
            edges.append(length)
        tau = np.array(edges) / length
        pieces.append((Line((-Lh, R), (-depth, R)), tau, 0.0, 1.0))
    return HalfspaceLayout(nose, depth, tuple(pieces), options)


def _shoulder_is_corner(nose: Nose) -> bool:
    seg = nose.segments[-1]
    dx, dr = (float(v) for v in seg.derivative(seg.t1))
    return abs(dr) > 1e-9 * math.hypot(dx, dr)
