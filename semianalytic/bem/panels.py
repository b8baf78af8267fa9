"""Panels on a meridian: layouts (with grading) and node geometry.

A panel is a parameter interval of one analytic segment of the meridian, mapped from the
reference interval u in [-1, 1].  Geometry is always evaluated on the exact curve (no
interpolation of the shape), and *relative to an anchor*: each panel stores the exact
coordinates of the nearer end of its segment (a nose tip, a corner, the free-surface cut)
and its parameter offsets from it, so that panels graded down to 1e-9 of the body size
keep full relative precision.

A panel may be *mirrored* in the plane x = 0 (the image body S' of Part I, eqs. (21)-(22),
Fig. 3): its x is negated and its parameter runs backwards so that the closed chain S + S'
keeps one orientation.

Layouts grade panels geometrically towards points where the solution is singular (conical
tips, corners, the edge where a nose crosses the free surface) and grow them geometrically
along a long shank, so that accuracy is uniform with few unknowns.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property, lru_cache

import numpy as np

from semianalytic.bem.quadrature import gauss_legendre
from semianalytic.geometry import Arc, EllipseArc, Line, Meridian, Nose, Segment, SplineCurve, segment_arc_length
from semianalytic.native import address

GRADING_RATIO = 0.35  # size ratio between successive graded panels (hp-type grading)



_UINTP = np.dtype(np.uintp)
_MAX = np.maximum.reduce
_ANY = np.logical_or.reduce
_KERNELS = []


def _kernels():
    """The module :mod:`semianalytic.bem.kernels`, imported on first use (it imports scipy.special:
    not at start-up) and then kept (an import statement costs a microsecond per call, and the
    geometry asks for the compiled library about 1000 times per table).  Its ``compiled`` is
    looked up at each call, as tests replace it."""
    if not _KERNELS:
        from semianalytic.bem import kernels

        _KERNELS.append(kernels)
    return _KERNELS[0]


def _outputs(k: int, shape) -> tuple[tuple, list]:
    """k float64 output arrays of ``shape`` for a compiled call, rows of one block (one allocation
    and one address instead of k: this project's own shortcut), and their addresses."""
    block = np.empty((k,) + tuple(shape))
    at, step = address(block), block.nbytes // k
    rows = tuple(block) if block.ndim > 1 else tuple(block[i, ...] for i in range(k))  # [i, ...]: 0-d arrays
    return rows, list(range(at, at + k * step, step)) if step else [at] * k


@lru_cache(maxsize=64)
def _node_grid(n_panels: int, order: int) -> tuple:
    """The panel index (intp) and the Gauss coordinate u of every node of ``n_panels`` panels of
    ``order`` nodes, panel by panel, as flat read-only arrays and their addresses (this project's
    own shortcut: the node grid of a size is built once, not for each of the three panel sets of a
    depth, nor for each plan, which reads the primary panels' grid).  The cache keeps them alive."""
    u, _ = gauss_legendre(order)
    pk = np.repeat(np.arange(n_panels, dtype=np.intp), order)
    uu = np.tile(u, n_panels)
    at = address(pk), address(uu)
    for a in (pk, uu):
        a.setflags(write=False)
    return pk, uu, *at


def _curve_row(seg):
    """The compiled geometry's kind of a segment's curve and its two numbers (see
    :attr:`PanelSet._compiled_curves`), or None for a curve it does not evaluate."""
    k = {Line: 0, Arc: 1, EllipseArc: 2, SplineCurve: 3}.get(type(seg))
    if k is None:
        return None
    return ((k, seg.p1[0] - seg.p0[0], seg.p1[1] - seg.p0[1]) if k == 0 else
            (k, seg.radius, 0.0) if k == 1 else (k, seg.a, seg.b) if k == 2 else (k, 0.0, 0.0))


@dataclass(frozen=True)
class PanelSet:
    """Panels over one or more segments.

    Panel k lies on ``segments[segment_index[k]]`` between parameters
    ``base[k] + da[k]`` and ``base[k] + db[k]``; ``(anchor_x[k], anchor_r[k])`` is the exact
    point at parameter ``base[k]``.  ``sign[k]`` is +1, or -1 for a mirrored panel.
    Coordinates are returned in a computational frame whose origin is at x = ``offset``
    (the tip of a penetrating nose): add ``offset`` for target-frame abscissae.  The first
    ``n_primary`` panels are the physical surface; the rest are their mirror images, in
    reverse order.
    """

    segments: tuple[Segment, ...]
    segment_index: np.ndarray
    base: np.ndarray
    anchor_x: np.ndarray
    anchor_r: np.ndarray
    da: np.ndarray
    db: np.ndarray
    sign: np.ndarray
    offset: float
    order: int
    n_primary: int
    # corner panels: the parameter is substituted t - t_corner ~ ((1 +- u)/2)^power, so that
    # the nodes crowd the corner and phi ~ s^lambda becomes smooth in u; cluster[k] is -1
    # (corner at u = -1), +1 (corner at u = +1) or 0 (no substitution)
    power: np.ndarray | None = None
    cluster: np.ndarray | None = None
    label: str = "body"  # what the panels cover, for error messages ("cone nose", "body")

    @property
    def n_panels(self) -> int:
        return len(self.da)


    @cached_property
    def _half(self) -> np.ndarray:
        """Half the parameter span of each panel (d dt/du of a plain panel)."""
        return 0.5 * (self.db - self.da)

    @cached_property
    def _span(self) -> np.ndarray:
        """Parameter span db - da of each panel."""
        return self.db - self.da

    @cached_property
    def _clustered(self) -> np.ndarray:
        """Panels with a corner substitution (a mask)."""
        return np.zeros(self.n_panels, bool) if self.cluster is None else self.cluster != 0

    def _param(self, pk, u, second: bool = False):
        """Offset of the segment parameter from the anchor, dt(u), and its derivatives.

        Plain panels: dt = da + (db - da)(u + 1)/2.  Corner panels (Part I's BEM refined
        at corners): dt = da + (db - da) w(u), w = ((1 + u)/2)^q, or dt = db - (db - da)
        ((1 - u)/2)^q at the other end; the corner end is the anchor, so tiny offsets keep
        their relative precision."""
        da = self.da[pk]
        half = self._half[pk]
        dt = da + half * (u + 1.0)
        d2 = np.zeros_like(dt) if second else None
        if self.cluster is None:
            return dt, half, d2
        on = np.nonzero(self._clustered[pk])  # the few nodes on corner panels
        if on[0].size == 0:
            return dt, half, d2
        dtdu = half.copy() if half.shape == dt.shape else np.array(np.broadcast_to(half, dt.shape), dtype=float)
        so, c, q, _, dt[on], (_, w1, w2) = self._corner(pk[on], u[on], second)
        dtdu[on] = 0.5 * so * q * w1  # both ends: the sign of span
        if second:
            d2w = 0.25 * q * (q - 1.0) * w2
            d2[on] = np.where(c > 0, -so * d2w, so * d2w)
        return dt, dtdu, d2

    def _corner(self, pko, uo, second: bool = False):
        """The corner substitution of :meth:`_param` at points on corner panels (panels ``pko``,
        coordinates ``uo``): the span db - da, c, q, lo = (1 - c u)/2 (the distance from the
        corner end: (1 + u)/2 for c = -1, (1 - u)/2 for c = +1), the offset dt and the powers
        (lo^q, lo^(q - 1), lo^max(q - 2, 0) with ``second``, else None).  One home for
        :meth:`_param`, :meth:`param_distance` and the numpy powers the compiled second
        derivatives take (:meth:`_numpy_powers`)."""
        so = self._span[pko]
        c, q, lo, powers = self._corner_powers(pko, uo, second)
        sw = so * powers[0]
        dt = np.where(c > 0, self.db[pko] - sw, self.da[pko] + sw)
        return so, c, q, lo, dt, powers

    def _corner_powers(self, pko, uo, second: bool = False):
        """c, q, lo and the powers of :meth:`_corner`, without its offset (what
        :meth:`_numpy_powers` needs)."""
        c, q = self.cluster[pko], self.power[pko]
        lo = 0.5 * (1.0 - c * uo)
        return c, q, lo, (lo**q, lo ** (q - 1.0), lo ** np.maximum(q - 2.0, 0.0) if second else None)

    def evaluate(self, panel: np.ndarray, u: np.ndarray, second: bool = False, split: bool = False):
        """Points and derivatives d/du at reference coordinates ``u`` of panels ``panel``.

        ``panel`` and ``u`` broadcast together; returns x, r, x_u, r_u (and x_uu, r_uu
        with ``second=True``; and then the four arrays of :meth:`split` with ``split=True``,
        from the same evaluation of the curve).
        """
        panel = np.asarray(panel)
        u = np.asarray(u, dtype=float)
        if panel.shape != u.shape:
            panel, u = np.broadcast_arrays(panel, u)
        if u.size and not (second and split) and self._compiled_curves is not None:
            got = self._evaluate_compiled(panel, u, split, second)
            if got is not None:
                return got
        curves, group = self._curves
        if len(curves) == 1:
            return self._evaluate_segment(curves[0], panel, u, second, split)
        out = [np.empty(u.shape) for _ in range((6 if second else 4) + (4 if split else 0))]
        for seg, mask, pk in self._by_segment(panel):
            for o, v in zip(out, self._evaluate_segment(seg, pk, u[mask], second, split)):
                o[mask] = v
        return tuple(out)

    @cached_property
    def _compiled_curves(self):
        """The per-panel arrays ``ring_panel_points`` and ``ring_panel_relative`` of ``_ring.c``
        read (their addresses, kept alive here): the curve kind of each panel (0 line,
        1 circular arc, 2 ellipse arc) and its two numbers (p1 - p0; the radius; the
        semi-axes; 3 a table nose's cubic spline, whose knots and coefficients are passed once),
        the anchors, parameters, signs and corner substitutions; None when a panel lies on
        another curve (a power law, a Bezier nose, two different splines: the numpy path)."""
        return self._compiled_with(self._compiled_segments(self.__dict__.get("_like")))

    def _compiled_segments(self, like: PanelSet | None = None):
        """The curve part of :attr:`_compiled_curves` (kind, c0, c1 per panel; the spline's knots
        and coefficients) as (addresses, arrays), or None.  ``like``: a panel set of the same
        topology whose part is reused when its segments are these, or when only the last
        differs, a line as before (a layout stretched by :meth:`HalfspaceLayout.at_depth`:
        only that segment's rows are computed again; the same numbers)."""
        if like is not None and like.n_panels == self.n_panels and len(like.segments) == len(self.segments) \
                and all(a is b for a, b in zip(like.segments[:-1], self.segments)):
            got = like._compiled_curves
            if got is None:
                return None
            addr, keep = got
            old, seg = like.segments[-1], self.segments[-1]
            if seg is old:
                return ({k: addr[k] for k in ("kind", "c0", "c1", "nk", "knots", "cx", "cr")},
                        {k: keep[k] for k in ("kind", "c0", "c1", "knots", "cx", "cr") if k in keep})
            if type(seg) is Line and type(old) is Line:
                rows = np.nonzero(self.segment_index == len(self.segments) - 1)[0]
                c0, c1 = keep["c0"].copy(), keep["c1"].copy()
                c0[rows], c1[rows] = _curve_row(seg)[1:]
                part = {k: keep[k] for k in ("kind", "knots", "cx", "cr") if k in keep} | {"c0": c0, "c1": c1}
                return {k: addr[k] for k in ("kind", "nk", "knots", "cx", "cr")} | {"c0": address(c0), "c1": address(c1)}, part
        rows = []
        splines = None
        for seg in self.segments:
            row = _curve_row(seg)
            if row is None:
                return None
            if row[0] == 3:
                if splines is not None and seg._splines is not splines:
                    return None
                splines = seg._splines
            rows.append(row)
        keep = {"kind": np.ascontiguousarray(np.array([r[0] for r in rows], dtype=np.intp)[self.segment_index])}
        for j, name in ((1, "c0"), (2, "c1")):
            keep[name] = np.ascontiguousarray(np.array([r[j] for r in rows], dtype=float)[self.segment_index])
        if splines is not None:  # scipy CubicSpline's knots and (4, n - 1) coefficients, as its evaluation reads them
            knots, sx, sr = splines
            keep["knots"] = np.ascontiguousarray(sx.x, dtype=float)
            keep["cx"], keep["cr"] = (np.ascontiguousarray(f.c, dtype=float) for f in (sx, sr))
            if keep["cx"].shape != (4, keep["knots"].size - 1) or keep["cr"].shape != keep["cx"].shape:
                return None
        addr = {name: address(a) for name, a in keep.items()}
        addr["nk"] = 0 if splines is None else int(keep["knots"].size)
        if splines is None:
            addr["knots"] = addr["cx"] = addr["cr"] = None
        return addr, keep

    def _compiled_with(self, curves):
        """:attr:`_compiled_curves` from its curve part ``curves`` (:meth:`_compiled_segments`)
        and this panel set's parameters, anchors, signs and corner substitutions."""
        if curves is None:
            return None
        keep = {name: np.ascontiguousarray(a, dtype=float) for name, a in (
            ("base", self.base), ("da", self.da), ("db", self.db), ("half", self._half), ("sign", self.sign),
            ("ax", self.anchor_x), ("ar", self.anchor_r))}
        corner = self.cluster is not None and bool(self._clustered.any())
        if corner:
            keep["cluster"], keep["power"] = (np.ascontiguousarray(a, dtype=float) for a in (self.cluster, self.power))
        addr = {name: address(a) for name, a in keep.items()} | curves[0]
        if not corner:
            addr["cluster"] = addr["power"] = None
        # the geometry arguments of ring_panel_points in its order, once (read by every evaluation)
        addr["points"] = tuple(addr[k] for k in ("base", "da", "db", "half", "sign", "ax", "ar")) + (float(self.offset),) \
            + tuple(addr[k] for k in ("cluster", "power", "kind", "c0", "c1", "nk", "knots", "cx", "cr"))
        return addr, keep | curves[1]

    def _compiled_lib(self, panel):
        """The compiled library and the panel indices as a flat intp array when the compiled
        geometry applies (lines, arcs and a table's spline; indices in range), else None."""
        if self._compiled_curves is None:
            return None
        lib = _kernels().compiled()
        if lib is None:
            return None
        pk = np.ascontiguousarray(panel, dtype=np.intp).reshape(-1)
        # numpy's negative indices: its own path (seen unsigned they exceed every panel index)
        if pk.size and _MAX(pk.view(_UINTP)) >= self.n_panels:
            return None
        return lib, pk

    def _evaluate_compiled(self, panel, u, split, second=False):
        """:meth:`evaluate` by ``ring_panel_points`` of ``_ring.c`` (with ``second``:
        ``ring_panel_second``, without ``split``) (the same formulas, this project's own
        speed-up), or None."""
        got = self._compiled_lib(panel)
        if got is None:
            return None
        lib, pk = got
        c = self._compiled_curves[0]
        uu = np.ascontiguousarray(u, dtype=float).reshape(-1)
        if second:
            fn = lib.ring_panel_second
            out = [np.empty(u.shape) for _ in range(6)]
            pw = self._numpy_powers(pk, uu)
            fn(pk.size, address(pk), address(uu), c["base"], c["da"], c["db"], c["half"], c["sign"], c["ax"],
               c["ar"], float(self.offset), c["cluster"], c["power"], c["kind"], c["c0"], c["c1"], c["nk"],
               c["knots"], c["cx"], c["cr"], None if pw is None else address(pw), *(address(a) for a in out))
            return tuple(out)
        return self._points_compiled(lib, pk.size, address(pk), address(uu), u.shape, split)

    def _points_compiled(self, lib, n: int, pk_at: int, u_at: int, shape, split: bool):
        """``ring_panel_points`` at ``n`` points (panel indices and coordinates at the addresses
        ``pk_at`` and ``u_at``, checked by the caller): x, r, x_u, r_u (and the four arrays of
        :meth:`split` with ``split``), of ``shape``."""
        out, ptr = _outputs(8 if split else 4, shape)
        lib.ring_panel_points(n, pk_at, u_at, *self._compiled_curves[0]["points"], *ptr, *(None,) * (8 - len(ptr)))
        return out

    def _numpy_powers(self, pk, u):
        """numpy's lo^q, lo^(q - 1), lo^max(q - 2, 0) of :meth:`_param` at the
        points on corner panels, (n, 3) (other rows unset), for ``ring_panel_second``; None
        without corner points.  numpy's power differs from the C library's pow by an ulp at
        times: these keep the compiled second derivatives equal to numpy's bit for bit."""
        if self.cluster is None:
            return None
        on = np.nonzero(self._clustered[pk])[0]
        if on.size == 0:
            return None
        pw = np.empty((pk.size, 3))
        pw[on, 0], pw[on, 1], pw[on, 2] = self._corner_powers(pk[on], u[on], second=True)[3]
        return pw

    def _evaluate_segment(self, seg, pk, u, second, split=False):
        base, sg = self.base[pk], self.sign[pk]
        dt, half, d2t = self._param(pk, u, second)
        ex, er = seg.displacement(base, dt)
        dx, dr = seg.derivative(base + dt)
        # computational frame: x_b for primary panels, -x_b - 2 offset for mirrored ones
        out = [sg * (self.anchor_x[pk] + ex) + (sg - 1.0) * self.offset, self.anchor_r[pk] + er, sg * dx * half, dr * half]
        if second:
            ddx, ddr = seg.second_derivative(base + dt)
            out += [sg * (ddx * half * half + dx * d2t), ddr * half * half + dr * d2t]
        if split:  # as split() computes them
            out += [sg * self.anchor_x[pk] + (sg - 1.0) * self.offset, self.anchor_r[pk], sg * ex, er]
        return tuple(out)

    @cached_property
    def _curves(self) -> tuple[tuple[Segment, ...], np.ndarray]:
        """Segments that evaluate alike, merged (this project's own shortcut): the pieces of one
        table spline between its knots share its fitted splines, and their points, derivatives
        and displacements depend on the parameter only, so one call evaluates all of them (the
        same numbers, a fifth of the spline calls on a table nose).  Returns the distinct
        curves and the curve of each panel."""
        curves: list = []
        of_segment = []
        for seg in self.segments:
            for k, c in enumerate(curves):
                if c is seg or (isinstance(seg, SplineCurve) and isinstance(c, SplineCurve) and seg.lo is not None
                                and c.lo is not None and c._splines is seg._splines):
                    of_segment.append(k)
                    break
            else:
                of_segment.append(len(curves))
                curves.append(seg)
        return tuple(curves), np.asarray(of_segment, dtype=int)[self.segment_index]

    def _by_segment(self, panel: np.ndarray):
        """(curve, mask into ``panel``, the panels on that curve) for each curve used."""
        curves, group = self._curves
        if len(curves) == 1:
            yield curves[0], slice(None), panel  # every point: a view, not a masked copy
            return
        seg_of = group[panel]
        for s, seg in enumerate(curves):
            mask = seg_of == s
            if mask.any():
                yield seg, mask, panel[mask]

    def split(self, panel: np.ndarray, u: np.ndarray):
        """Points as (anchor + offset) in the computational frame: returns (ax, ar, ex, er)
        with x = ax + ex, r = ar + er.  Differences between points near one anchor (a
        corner) taken as (ax1 - ax2) + (ex1 - ex2) keep their digits however small."""
        panel, u = np.broadcast_arrays(np.asarray(panel), np.asarray(u, dtype=float))
        ex = np.empty(u.shape)
        er = np.empty(u.shape)
        for seg, mask, pk in self._by_segment(panel):
            dt = self._param(pk, u[mask])[0]
            e_x, e_r = seg.displacement(self.base[pk], dt)
            ex[mask] = self.sign[pk] * e_x
            er[mask] = e_r
        sg = self.sign[panel]
        return sg * self.anchor_x[panel] + (sg - 1.0) * self.offset, self.anchor_r[panel], ex, er

    @cached_property
    def tiny_panels(self) -> np.ndarray:
        """Panels shorter than 1e-4 of their distance from the computational origin (deep
        grading at a corner): there coordinate differences lose digits."""
        size = np.abs(self.anchor_x) + np.abs(self.anchor_r) + abs(self.offset) * (self.sign < 0)
        return self.lengths < 1e-4 * size

    @cached_property
    def node_split(self):
        """:meth:`split` at the Gauss nodes of every panel, flat arrays."""
        u, _ = gauss_legendre(self.order)
        panel = np.repeat(np.arange(self.n_panels), self.order)
        return tuple(a.ravel() for a in self.split(panel, np.tile(u, self.n_panels)))

    def relative(self, panel: np.ndarray, u_from: np.ndarray, u_to: np.ndarray):
        """point(u_to) - point(u_from) on the same panel, free of cancellation: the
        segment's displacement over the parameter difference (needed where the two points
        are far closer to each other than to the origin)."""
        panel, u_from, u_to = np.asarray(panel), np.asarray(u_from, float), np.asarray(u_to, float)
        if not panel.shape == u_from.shape == u_to.shape:
            panel, u_from, u_to = np.broadcast_arrays(panel, u_from, u_to)
        got = self._compiled_lib(panel) if u_from.size else None
        if got is not None:  # lines, arcs, a table's spline: ring_panel_relative of _ring.c, the same formulas
            lib, pk = got
            c = self._compiled_curves[0]
            uf, ut = (np.ascontiguousarray(v, dtype=float).reshape(-1) for v in (u_from, u_to))
            (dx, dr), ptr = _outputs(2, u_from.shape)
            lib.ring_panel_relative(pk.size, address(pk), address(uf), address(ut), c["base"], c["da"], c["db"],
                                    c["half"], c["sign"], c["cluster"], c["power"], c["kind"], c["c0"], c["c1"],
                                    c["nk"], c["knots"], c["cx"], c["cr"], *ptr)
            return dx, dr
        dx = np.empty(u_from.shape)
        dr = np.empty(u_from.shape)
        for seg, mask, pk in self._by_segment(panel):
            half = 0.5 * (self.db[pk] - self.da[pk])
            uf, ut = u_from[mask], u_to[mask]
            base = self.base[pk]
            t_from = base + self.da[pk] + half * (uf + 1.0)
            step = half * (ut - uf)  # exact for plain panels
            if self.cluster is not None:
                on = np.nonzero(self._clustered[pk])[0]  # corner panels: through the substitution
                if on.size:
                    pko = pk[on]
                    dt_from = self._param(pko, uf[on])[0]
                    t_from[on] = base[on] + dt_from
                    step[on] = self._param(pko, ut[on])[0] - dt_from
            ex, er = seg.displacement(t_from, step)
            dx[mask] = self.sign[pk] * ex
            dr[mask] = er
        return dx, dr

    def param_distance(self, panel: np.ndarray, u: np.ndarray, dist: np.ndarray, du: np.ndarray) -> np.ndarray:
        """A distance ``dist`` from the point u of ``panel`` expressed in the panel
        coordinate: ``du`` (= dist/|dy/du|) on plain panels; on corner panels, where
        |dy/du| -> 0 at the corner, the u-step that covers ``dist`` along the curve."""
        if self.cluster is None:
            return du
        on = np.nonzero(self._clustered[panel])[0]
        if on.size == 0:
            return du
        du = np.array(du, dtype=float, copy=True)
        pk, uk, dk = panel[on], u[on], dist[on]
        # lo: corner-end coordinate in [0, 1]; w = lo^q: the fraction of the panel's parameter span from the corner
        so, c, q, lo, dt, (w, _, _) = self._corner(pk, uk)
        span = np.abs(so)
        speed = np.empty(on.size)
        for seg, m, pkm in self._by_segment(pk):
            dx, dr = seg.derivative(self.base[pkm] + dt[m])
            speed[m] = np.hypot(dx, dr)
        dw = dk / np.maximum(speed * span, 1e-300)
        up = np.minimum(w + dw, 1.0) ** (1.0 / q) - lo
        down = lo - np.maximum(w - dw, 0.0) ** (1.0 / q)
        step = np.where(w + dw <= 1.0, up, np.where(w - dw >= 0.0, down, np.maximum(up, down)))
        # the substitution puts the kernel's near singularity off the real u axis at an
        # angle ~pi/q from the corner, about one step away: pieces four times shorter
        du[on] = np.minimum(du[on], 0.5 * step)
        return du

    @cached_property
    def nodes(self) -> NodeGeometry:
        u, w = gauss_legendre(self.order)
        shape = (self.n_panels, self.order)
        pk, uu, pk_at, u_at = _node_grid(*shape)
        lib = self._compiled_curves is not None and shape[0] and _kernels().compiled()
        if lib:  # the compiled geometry on the node grid, its indices in range by construction
            x, r, xu, ru, *parts = self._points_compiled(lib, pk.size, pk_at, u_at, shape, True)
        else:
            x, r, xu, ru, *parts = self.evaluate(pk.reshape(shape), uu.reshape(shape), split=True)
        self.__dict__["node_split"] = tuple(a.ravel() for a in parts)  # the same points: node_split for free
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

    def fold_mirror(self, M: np.ndarray) -> np.ndarray:
        """Columns of the mirror nodes added onto those of their primary nodes: (rows, N) from
        (rows, 2N), N = n_primary * order; ``M`` itself without mirror panels.  The mirror
        panels follow the primary ones in reverse order (panel 2n - 1 - k mirrors panel k, its
        nodes reversed), so the mirror of primary node i is node 2N - 1 - i: a reversed view,
        no gathered copy."""
        if self.n_panels == self.n_primary:
            return M
        N = self.n_primary * self.order
        return M[:, :N] + M[:, :N - 1:-1]


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
# pieces: one segment between two parameters, with panels anchored at either end


@dataclass(frozen=True)
class Piece:
    """Panels on ``segment`` between parameters t0 and t1 (exact end points p0, p1).

    ``panels`` rows are (anchor, a, b): anchor 0 measures the offsets a < b from t0 in units
    of (t1 - t0), anchor 1 from t1 (a < b <= 0).  Offsets are kept normalised so that the
    piece can be stretched to a new end parameter without changing its topology.
    """

    segment: Segment
    t0: float
    t1: float
    p0: tuple[float, float]
    p1: tuple[float, float]
    panels: np.ndarray  # (n, 3)
    # substitution power of the panel touching t0 / t1 (1: none; > 1 at a corner or a
    # conical tip, see corner_power)
    powers: tuple[float, float] = (1.0, 1.0)

    def stretched(self, t1: float, p1: tuple[float, float]) -> Piece:
        return Piece(self.segment, self.t0, t1, self.p0, p1, self.panels, self.powers)


def graded_panels(n: int, grade0: int, grade1: int, ratio: float = GRADING_RATIO) -> np.ndarray:
    """n uniform panels on [0, 1]; the first/last subdivided geometrically ``grade*`` times.

    Returns rows (anchor, a, b) as in :class:`Piece`: graded panels are anchored at the
    end they crowd, so their offsets are exact.
    """
    h = 1.0 / n
    rows = []
    if grade0:
        edges = [0.0] + [h * ratio**k for k in range(grade0, 0, -1)] + [h]
        rows += [(0, a, b) for a, b in zip(edges[:-1], edges[1:])]
    else:
        rows.append((0, 0.0, h))
    for k in range(1, n - 1):
        a, b = k * h, (k + 1) * h
        rows.append((0, a, b) if a + b <= 1.0 else (1, a - 1.0, b - 1.0))
    if n > 1:
        if grade1:
            edges = [-h] + [-h * ratio**k for k in range(1, grade1 + 1)] + [0.0]
            rows += [(1, a, b) for a, b in zip(edges[:-1], edges[1:])]
        else:
            rows.append((1, -h, 0.0))
    elif grade1:  # a single panel graded at its end too
        rows.pop()
        if grade0:
            raise ValueError("use n >= 2 to grade both ends")
        edges = [-1.0] + [-ratio**k for k in range(1, grade1 + 1)] + [0.0]
        rows += [(1, a, b) for a, b in zip(edges[:-1], edges[1:])]
    return np.array(rows, dtype=float)


@lru_cache(maxsize=256)
def _graded_rows(n: int, grade0: int, grade1: int) -> np.ndarray:
    """:func:`graded_panels` at the default ratio, made once per (n, grade0, grade1) and read-only:
    :func:`halfspace_layout` asks for the same few at every depth of a table."""
    rows = graded_panels(n, grade0, grade1)
    rows.setflags(write=False)
    return rows


def panel_set(pieces: list[Piece] | tuple[Piece, ...], order: int, offset: float = 0.0, mirror: bool = False,
              label: str = "body") -> PanelSet:
    """Assemble pieces (and optionally their mirror images) into a :class:`PanelSet`.

    Vectorised over each piece's panels (the same numbers as a loop over them, element by
    element: a table builds about 700 panel sets)."""
    segs = [piece.segment for piece in pieces]
    rows = [np.asarray(piece.panels, dtype=float).reshape(-1, 3) for piece in pieces]
    counts = [len(r) for r in rows]
    n = sum(counts)
    block = np.empty((5, 2 * n if mirror else n))  # base, anchor x, anchor r, da, db (see _anchored)
    if n == 0:
        idx, power, cluster = np.array([]), np.empty(0), np.empty(0)
    else:
        rows = np.concatenate(rows) if len(rows) > 1 else rows[0]
        # per piece: t0, x0, r0, t1, x1, r1, span and the end powers, repeated over its panels
        per = np.array([[float(pc.t0), float(pc.p0[0]), float(pc.p0[1]), float(pc.t1), float(pc.p1[0]),
                         float(pc.p1[1]), float(pc.t1 - pc.t0), float(pc.powers[0]), float(pc.powers[1])]
                        for pc in pieces]).T
        per = per.repeat(counts, axis=1) if len(pieces) > 1 else per
        idx = np.repeat(np.arange(len(pieces)), counts)
        start = _anchored(block[:, :n], rows, per[:3], per[3:6], per[6])
        anchor, a, b = rows.T
        q0, q1 = per[7], per[8]
        # corner panels: anchored at the end of the piece that has a substitution power
        at0 = start & (a == 0.0) & (q0 > 1.0)
        at1 = ~at0 & (anchor == 1) & (b == 0.0) & (q1 > 1.0)
        power = np.where(at0, q0, np.where(at1, q1, 1.0))
        cluster = np.where(at0, -1.0, np.where(at1, 1.0, 0.0))
    sign = np.ones(len(block[0]))
    if mirror:
        # reversed order, reversed parameter direction
        idx = np.concatenate([idx, idx[::-1]])
        _mirror_rows(block, 0, n)
        sign[n:] = -1.0
        power = np.concatenate([power, power[::-1]])
        cluster = np.concatenate([cluster, -cluster[::-1]])  # the parameter runs backwards
    power_arr, cluster_arr = power, cluster
    if not _ANY(cluster_arr != 0.0, axis=None):
        power_arr = cluster_arr = None
    ps = PanelSet(tuple(segs), idx, *block, sign, offset, order, n, power_arr, cluster_arr, label)
    ps.__dict__["_block"] = block
    return ps


def _anchored(out, rows, at0, at1, span) -> np.ndarray:
    """base, anchor x, anchor r, da, db of panels (rows: anchor end 0 or 1, a, b of the piece's
    span) of pieces running from ``at0`` = (t0, x0, r0) to ``at1`` = (t1, x1, r1) over ``span``
    (per panel, or one piece's numbers), written into the rows of ``out`` (5, n); returns the
    mask of panels anchored at t0.  One home for :func:`panel_set` and :func:`restretched`."""
    start = rows[:, 0] == 0
    out[:3] = np.where(start, at0, at1)
    np.multiply(rows[:, 1:].T, span, out=out[3:])
    return start


def _mirror_rows(block, k: int, m: int) -> None:
    """The mirror images of panels k .. k + m - 1 of ``block`` (5, 2n: base, anchor x, anchor r,
    da, db) written into their places among the mirror panels n + (n - k - m) .. 2n - 1 - k
    (reversed order, the parameter running backwards: da and db swapped)."""
    n = block.shape[1] // 2
    lo, hi = 2 * n - k - m, 2 * n - k
    src = slice(k + m - 1, k - 1 if k else None, -1)
    block[:3, lo:hi] = block[:3, src]
    block[3, lo:hi] = block[4, src]
    block[4, lo:hi] = block[3, src]


def restretched(like: PanelSet, pieces, offset: float) -> PanelSet:
    """:func:`panel_set` of ``pieces`` (mirrored as ``like``) from ``like``, the panel set of pieces
    that differ only in the last piece's end parameter, end point and segment (a layout and its
    :meth:`HalfspaceLayout.at_depth`): only the last piece's rows are computed again, by
    :func:`panel_set`'s formulas, the other arrays are shared (this project's own shortcut, the
    same numbers; the two sets of a difference in P per depth)."""
    last = pieces[-1]
    rows = np.asarray(last.panels, dtype=float).reshape(-1, 3)
    m, n = len(rows), like.n_primary
    mirrored = like.n_panels > n
    if len(like.segments) != len(pieces) or like.n_panels != (2 * n if mirrored else n) or m > n:
        raise ValueError("restretched: pieces of another topology than the panel set's")
    old = like.__dict__.get("_block")
    block = old.copy() if old is not None else np.array([like.base, like.anchor_x, like.anchor_r, like.da, like.db])
    _anchored(block[:, n - m:n], rows, np.array([float(last.t0), float(last.p0[0]), float(last.p0[1])])[:, None],
              np.array([float(last.t1), float(last.p1[0]), float(last.p1[1])])[:, None], float(last.t1 - last.t0))
    if mirrored:  # the mirror panels of the last piece (the first m mirror panels)
        _mirror_rows(block, n - m, m)
    ps = PanelSet(like.segments[:-1] + (last.segment,), like.segment_index, *block, like.sign, offset, like.order,
                  n, like.power, like.cluster, like.label)
    ps.__dict__["_like"] = like  # for the curve part of the compiled geometry (PanelSet._compiled_segments)
    ps.__dict__["_block"] = block
    return ps


TIP_POWER = 2.0  # substitution at a conical tip (axisymmetric point exponent nu in (1/2, 1))
MAX_POWER = 6.0


def corner_exponent(turning: float) -> float:
    """Exponent lambda of the leading corner solution phi ~ s^lambda at a ring corner where
    the meridian's tangent turns by ``turning`` rad (> 0: convex, the fluid angle is
    alpha = pi + turning): lambda = pi/alpha (locally the 2-D Neumann corner problem)."""
    return math.pi / (math.pi + turning)


def corner_power(turning: float) -> float:
    """Substitution power q on the panels touching a corner (1: no corner).

    With s ~ ((1 + u)/2)^q the leading corner term phi ~ s^lambda becomes (1 + u)^(q lambda)
    and the B integrand |grad phi|^2 ds ~ s^(2 lambda - 2) ds becomes
    (1 + u)^(q (2 lambda - 1) - 1).  q = k/lambda with k the smallest integer >= 2 that keeps
    the latter bounded (k (2 - 1/lambda) >= 1): phi's leading term is then the polynomial
    (1 + u)^k, which the panel's Lagrange basis represents exactly (the 90 deg edge of a
    flat face: lambda = 2/3, q = 3)."""
    if abs(turning) <= 1e-9:
        return 1.0
    lam = corner_exponent(turning)
    if lam <= 0.5 + 1e-6:  # a cusp (turning ~ 180 deg): strongest grading allowed
        return MAX_POWER
    k = max(2, math.ceil(lam / (2.0 * lam - 1.0) - 1e-9))
    return float(min(max(k / lam, 1.0), MAX_POWER))




def _count(arc: float, scale: float, refinement: float, per_scale: float, minimum: int = 2) -> int:
    return max(minimum, int(math.ceil(refinement * per_scale * arc / scale)))


def _point(seg: Segment, t: float) -> tuple[float, float]:
    x, r = seg.point(t)
    return float(x), float(r)


# ------------------------------------------------------------------------------------
# layouts


@dataclass(frozen=True)
class LayoutOptions:
    """Resolution of a layout: ``order`` Gauss points per panel; ``refinement`` scales
    panel counts; ``levels`` graded panels towards singular points (each GRADING_RATIO
    times the next: 12 levels reach 3e-6 of the ungraded panel size)."""

    order: int = 8
    refinement: float = 1.0
    levels: int = 12

    def corner_grading(self, turning: float) -> int:
        """Graded panels at a corner of the meridian (a tangent jump of ``turning`` rad).

        Where the substitution power q (:func:`corner_power`) is an integer, the corner
        series phi = a + b s^lambda + c s + ... is polynomial in the panel coordinate
        (the 90 deg edge of a flat face, lambda = 2/3, q = 3): two levels suffice, and
        more only add panels whose own error (~0.35-graded intervals, ~2e-6 relative at
        order 8) does not shrink.  Otherwise the s^1 term is not polynomial: four levels
        more than at a tip (measured at the 15 deg shoulder of a 30 deg cone: 6 -> 10
        levels take B from 8e-6 to 3e-7 relative)."""
        if not self.levels:
            return 0
        q = corner_power(turning)
        if abs(q - round(q)) < 1e-9:
            return min(self.levels, 2)
        return min(self.levels + 4, 22)

    @property
    def junction_levels(self) -> int:
        """Grading at a curvature jump between tangent segments (nose-shank): milder than
        at corners and tips, where the solution itself is singular."""
        return self.levels // 3

    def __post_init__(self):
        if not 2 <= self.order <= 16:
            raise ValueError("order must lie between 2 and 16")
        if not 0 < self.refinement <= 16:
            raise ValueError("refinement must lie in (0, 16]")
        if not 0 <= self.levels <= 18:
            # below ~0.35^18 of the panel size the geometry runs out of digits
            raise ValueError("levels must lie between 0 and 18")


def body_panels(meridian: Meridian, options: LayoutOptions = LayoutOptions()) -> PanelSet:
    """Panels on a closed meridian in unbounded fluid (sphere, spheroid, projectile, table)."""
    segs = meridian.segments
    corners = meridian.corners()
    tip0, tip1 = meridian.axis_angles()
    scale = max(float(np.max(np.abs(s.point(np.linspace(s.t0, s.t1, 33))[1]))) for s in segs)
    joints = _joints(segs)
    joints[0] = (joints[0][0], 0.0)  # on the axis exactly
    joints[-1] = (joints[-1][0], 0.0)
    pieces = []
    for k, seg in enumerate(segs):
        arc = segment_arc_length(seg, seg.t0, seg.t1)
        n = _count(arc, scale, options.refinement, 1.6)
        if isinstance(seg, EllipseArc):
            # a slender ellipse needs panels in proportion to its length in the parameter
            n = max(n, _count(math.pi * max(seg.a, seg.b), math.pi * min(seg.a, seg.b), options.refinement, 1.2, 4))
        if isinstance(seg, SplineCurve):
            n = max(n, len(seg.knots) - 1)
        g0 = options.levels if (k == 0 and tip0 > 1e-6) else (options.corner_grading(corners[k - 1]) if k > 0 and corners[k - 1] else 0)
        g1 = options.levels if (k == len(segs) - 1 and tip1 > 1e-6) else (options.corner_grading(corners[k]) if k < len(segs) - 1 and corners[k] else 0)  # noqa: E501
        q0 = (TIP_POWER if tip0 > 1e-6 else 1.0) if k == 0 else corner_power(corners[k - 1])
        q1 = (TIP_POWER if tip1 > 1e-6 else 1.0) if k == len(segs) - 1 else corner_power(corners[k])
        p0, p1 = joints[k], joints[k + 1]
        pieces.append(Piece(seg, seg.t0, seg.t1, p0, p1, graded_panels(max(n, 2), g0, g1), (q0, q1)))
    return panel_set(pieces, options.order)


def _joints(segs) -> list[tuple[float, float]]:
    """End points of a chain of segments, each joint computed once (so that the panels on
    either side of a corner share one exact anchor)."""
    pts = [_point(segs[0], segs[0].t0)] + [_point(s, s.t1) for s in segs]
    return pts


def param_at_x(seg: Segment, x: float) -> float:
    """Parameter where a nose segment reaches body-frame abscissa ``x`` (x decreases along it)."""
    if isinstance(seg, Line):
        (x0, _), (x1, _) = seg.p0, seg.p1
        return (x - x0) / (x1 - x0)
    if isinstance(seg, Arc):
        c = min(max((x - seg.center[0]) / seg.radius, -1.0), 1.0)  # np.clip's numbers, without its wrappers
        return float(np.arccos(c))
    from scipy.optimize import brentq  # here, not at start-up (scipy.optimize: ~0.5 s to import)

    f = lambda t: float(seg.point(t)[0]) - x  # noqa: E731
    if isinstance(seg, SplineCurve):
        # a table nose is cut at its knots into segments; the free surface of a nearby
        # depth (a difference in P) may lie just past the segment's end, on the next
        # interval of the same (C^2) spline: search the whole spline
        knots = seg.knots
        return brentq(f, float(knots[0]), float(knots[-1]), xtol=1e-15 * float(knots[-1]), rtol=4.5 * np.finfo(float).eps)
    # scipy requires rtol >= 4 eps; xtol is absolute in the parameter (arc length of a spline)
    span = abs(seg.t1 - seg.t0)
    return brentq(f, seg.t0, seg.t1, xtol=1e-15 * max(span, 1e-300), rtol=4.5 * np.finfo(float).eps)


@dataclass(frozen=True)
class HalfspaceLayout:
    """Panels of the submerged surface of a nose at depth P (body frame), as pieces.

    The last piece ends at the free surface x_b = -P.  Re-evaluating the layout at a
    nearby depth with :meth:`at_depth` keeps the panel topology and stretches only the
    last piece (the frozen topology that differentiation in P needs).
    """

    nose: Nose
    depth: float
    pieces: tuple[Piece, ...]
    options: LayoutOptions
    shank: bool  # the last piece is the cylinder r = d/2 from the shoulder to x = 0

    def at_depth(self, depth: float) -> HalfspaceLayout:
        *head, last = self.pieces
        R, Lh = self.nose.radius, self.nose.length
        if self.shank:
            if not depth > Lh:
                raise ValueError("depth moved across the nose-shank junction; use a smaller step")
            seg = Line((-Lh, R), (-depth, R))
            new = Piece(seg, 0.0, 1.0, (-Lh, R), (-depth, R), last.panels, last.powers)
        else:
            if not depth < Lh:
                raise ValueError("depth moved across the nose-shank junction; use a smaller step")
            t1 = param_at_x(last.segment, -depth)
            new = last.stretched(t1, (-depth, float(last.segment.point(t1)[1])))
        return HalfspaceLayout(self.nose, depth, (*head, new), self.options, self.shank)

    def panels(self, like: PanelSet | None = None) -> PanelSet:
        """Primary panels (tip at x = P in the target frame) followed by their mirror images.
        ``like``: the panel set of a layout that this one is :meth:`at_depth` of (or the reverse),
        whose arrays are reused (:func:`restretched`, the same numbers)."""
        if like is not None:
            return restretched(like, self.pieces, self.depth)
        return panel_set(self.pieces, self.options.order, offset=self.depth, mirror=True, label=f"{self.nose.kind} nose")


@dataclass(frozen=True)
class _LayoutFrame:
    """What :func:`halfspace_layout` reads of a nose at every depth and that does not depend on
    the depth: the segments (a table's spline cut at its knots, so that panels never straddle
    one), whether the tip is conical, the turning angles at the joints and at the shoulder, the
    joints, and per segment its end abscissae, its arc length and its number of inner knots."""

    segs: tuple
    tip_conical: bool
    turning: tuple
    joints: tuple
    shoulder_turning: float
    shoulder_corner: bool
    x_start: tuple
    x_end: tuple
    arc: tuple
    inner_knots: tuple


def _layout_frame(nose: Nose) -> _LayoutFrame:
    """The :class:`_LayoutFrame` of ``nose``, worked out once and kept on the nose (this project's
    own shortcut: the same numbers; a table lays out about 75 depths of one nose, and on a table
    nose these were a tenth of its layout time)."""
    got = nose.__dict__.get("_layout_frame")
    if got is None:
        segs = tuple(p for seg in nose.segments for p in (seg.between_knots() if isinstance(seg, SplineCurve) else (seg,)))
        tip_conical = nose.tip_half_angle() < 0.5 * math.pi - 1e-9
        tip_conical = tip_conical or getattr(segs[0], "singular_at_t0", False)  # a power-law tip, 1/n not an integer
        got = _LayoutFrame(
            segs, tip_conical, tuple(Meridian(segs, closed=False).corners()) if len(segs) > 1 else (),
            tuple(_joints(segs)),
            _shoulder_turning(nose), _shoulder_is_corner(nose),
            tuple(float(seg.point(seg.t0)[0]) for seg in segs), tuple(float(seg.point(seg.t1)[0]) for seg in segs),
            tuple(segment_arc_length(seg, seg.t0, seg.t1) for seg in segs),
            tuple(int(np.sum((seg.knots > seg.t0) & (seg.knots < seg.t1))) if isinstance(seg, SplineCurve) else 0
                  for seg in segs))
        nose.__dict__["_layout_frame"] = got
    return got


def halfspace_layout(nose: Nose, depth: float, options: LayoutOptions = LayoutOptions()) -> HalfspaceLayout:
    """Layout of the submerged nose (and shank, and entry-hole wall) at depth P > 0.

    For P < L_h the nose is cut by the free surface x = 0, where the surface and its mirror
    image meet at an edge: panels are graded towards it.  For P > L_h the shank and the
    hole wall form one cylinder r = d/2 from the shoulder to x = 0 (n_x = 0 there, so A, B,
    C depend only on the nose and P: errata item 1b); its panels grow geometrically away
    from the shoulder, and it meets its mirror image smoothly.
    """
    if not depth > 0:
        raise ValueError("depth must be positive")
    R, Lh = nose.radius, nose.length
    lev, ref = options.levels, options.refinement
    frame = _layout_frame(nose)
    segs, tip_conical, turning, joints = frame.segs, frame.tip_conical, frame.turning, frame.joints
    shoulder_turning, shoulder_corner = frame.shoulder_turning, frame.shoulder_corner
    cut_on_nose = depth < Lh
    scale = R if not cut_on_nose else max(min(R, depth), 1e-300)

    def junction(k: int) -> int:
        # a knot of a table's spline (C^2: only the third derivative jumps) needs no grading
        a, b = segs[k], segs[k + 1]
        same_spline = isinstance(a, SplineCurve) and isinstance(b, SplineCurve) and a.xs == b.xs and a.rs == b.rs
        # between two analytic segments of a nose (a sphere cap on a cone): two levels more
        # than at the nose-shank junction (measured on the blunted cone: B from 5e-6 to 5e-7)
        return 0 if same_spline else options.junction_levels + (2 if options.levels else 0)

    pieces = []
    for k, seg in enumerate(segs):
        cut_here = cut_on_nose and -depth >= frame.x_end[k] - 1e-15 * max(Lh, R)
        t1 = param_at_x(seg, -depth) if cut_here else seg.t1
        arc = segment_arc_length(seg, seg.t0, t1) if cut_here else frame.arc[k]
        if arc <= 0:
            continue
        # a straight segment next to a corner whose s^1 term is not polynomial in the substituted
        # panel (q not an integer: a cone's shoulder): three times the panels (measured on the
        # 30 deg cone at depth: identity error 1.8e-6 -> 7e-7 for 32 more unknowns; on curved
        # segments the gain does not pay for its cost)
        ends = [turning[k - 1] if k > 0 else 0.0, turning[k] if k < len(segs) - 1 else shoulder_turning]
        rough = isinstance(seg, Line) and any(abs(corner_power(a) - round(corner_power(a))) > 1e-9 for a in ends)
        # a segment wholly in the target (a flat face at a shallow depth) is counted on its own
        # length, not on the depth: its solution varies on the depth's scale only next to the
        # segment that the free surface cuts, where it is graded (below); counted on the depth,
        # a flat face took (face radius)/P panels (this project's own bound)
        # The cut segment itself is counted on the depth, but on no less than 1/30 of its wetted
        # length (at most ~15 panels at refinement 1 beside the grading at the cut): on a
        # shallow cap (a thin lens with its mirror image) the solution varies on the lens's
        # size except at the cut, where it is graded; counted on P alone the panels grew like
        # P^-1/2 (measured: a 1 mm corner radius at 1e-9 m, 3000 unknowns and growing)
        seg_scale = max(scale, min(R, arc) / 30.0) if cut_here else max(scale, min(R, arc))
        # a segment ending in a corner (a flat face, a meplat) has at least 2 panels per 0.3 of
        # refinement: the clamp of 2 panels made --refinement a no-op on a flat nose, whose face
        # is one radius long (this project's own rule; 2 at the tables' default 0.3)
        at_corner = any(a and abs(corner_power(a) - 1.0) > 1e-9 for a in ends) or (
            k == len(segs) - 1 and not cut_here and shoulder_corner)
        minimum = 1 if isinstance(seg, SplineCurve) else (max(2, math.ceil(2.0 * ref / 0.3 - 1e-9)) if at_corner else 2)
        n = _count(arc, seg_scale, ref, 4.8 if rough else 1.6, minimum=minimum)
        if isinstance(seg, SplineCurve):
            inside = int(np.sum((seg.knots > seg.t0) & (seg.knots < t1))) if cut_here else frame.inner_knots[k]
            n = max(n, inside + 1)
        if k == 0:
            g0 = lev if tip_conical else 0
        else:
            g0 = options.corner_grading(turning[k - 1]) if turning[k - 1] else junction(k - 1)  # curvature jump between tangent segments
        if cut_here:
            g1 = lev
        elif k < len(segs) - 1:
            g1 = options.corner_grading(turning[k]) if turning[k] else junction(k)
            if cut_on_nose and options.levels and -depth >= frame.x_end[k + 1] - 1e-15 * max(Lh, R):
                # the free surface cuts the next segment: grade towards the joint down to the
                # length left between the joint and the cut
                gap = abs(frame.x_start[k + 1] + depth)
                need = math.ceil(math.log(gap / (arc / n)) / math.log(GRADING_RATIO)) if 0 < gap < arc / n else 0
                g1 = max(g1, min(need, 22))
        else:
            g1 = options.corner_grading(shoulder_turning) if shoulder_corner else options.junction_levels
            if shoulder_corner and depth > Lh and options.levels:
                # the shoulder's mirror image lies 2 (P - L_h) away: grade down to that scale
                gap = 0.5 * (depth - Lh)
                need = math.ceil(math.log(gap / (arc / n)) / math.log(GRADING_RATIO)) if gap < arc / n else 0
                g1 = max(g1, min(need, 22))
        p0 = (0.0, 0.0) if k == 0 else joints[k]
        if cut_here:
            p1 = (-depth, float(seg.point(t1)[1]))
        elif k == len(segs) - 1:
            p1 = (-Lh, R)
        else:
            p1 = joints[k + 1]
        q0 = (TIP_POWER if tip_conical else 1.0) if k == 0 else corner_power(turning[k - 1])
        if cut_here:
            q1 = 1.0  # the free-surface edge is regular for the even (mirrored) potential
        elif k < len(segs) - 1:
            q1 = corner_power(turning[k])
        else:
            q1 = corner_power(shoulder_turning)
        if n == 1 and g0 and g1:
            n = 2
        pieces.append(Piece(seg, seg.t0, t1, p0, p1, _graded_rows(n, g0, g1), (q0, q1)))
        if cut_here:
            break
    shank = depth > Lh
    if shank:
        pieces.append(_shank_piece(nose, depth, options))
    return HalfspaceLayout(nose, depth, tuple(pieces), options, shank=shank)


def _shank_piece(nose: Nose, depth: float, options: LayoutOptions) -> Piece:
    """Cylinder from the shoulder (-L_h, R) to the free surface (-P, R): graded at the
    shoulder, then panels growing geometrically (by 2 at refinement 1) towards x = 0,
    where phi varies ever more slowly."""
    R, Lh = nose.radius, nose.length
    length = depth - Lh
    frame = _layout_frame(nose)  # the shoulder's turning and corner, worked out once per nose
    grade = options.corner_grading(frame.shoulder_turning) if frame.shoulder_corner else options.junction_levels
    growth = min(3.0, 2.0 ** (1.0 / options.refinement))  # 2 at refinement 1
    h = min(0.8 * R / max(options.refinement, 1e-9), 0.5 * length)
    edges = [0.0] + [h * GRADING_RATIO**k for k in range(grade, 0, -1)]
    pos = h
    while pos < length:
        edges.append(pos)
        h *= growth
        pos += h
    if len(edges) > 2 and length - edges[-1] < 0.5 * (edges[-1] - edges[-2]):
        edges[-1] = length
    else:
        edges.append(length)
    tau = np.array(edges) / length
    # rows (0, a, b), or (1, a - 1, b - 1) anchored at the free surface past the middle, for all at once
    rows = np.empty((len(tau) - 1, 3))
    rows[:, 1], rows[:, 2] = tau[:-1], tau[1:]
    far = rows[:, 1] + rows[:, 2] > 1.0
    rows[:, 0] = far
    rows[far, 1:] -= 1.0
    powers = (corner_power(frame.shoulder_turning), 1.0)
    return Piece(Line((-Lh, R), (-depth, R)), 0.0, 1.0, (-Lh, R), (-depth, R), rows, powers)


def _shoulder_turning(nose: Nose) -> float:
    """Turning angle (rad, > 0 convex) of the meridian at the shoulder, from the nose's last
    tangent to the shank direction (-1, 0)."""
    seg = nose.segments[-1]
    dx, dr = (float(v) for v in seg.derivative(seg.t1))
    ang = math.atan2(dx * 0.0 - dr * -1.0, -dx)  # cross(t, (-1, 0)), dot(t, (-1, 0))
    return ang if abs(ang) > 1e-9 else 0.0


def _shoulder_is_corner(nose: Nose) -> bool:
    seg = nose.segments[-1]
    dx, dr = (float(v) for v in seg.derivative(seg.t1))
    return abs(dr) > 1e-9 * math.hypot(dx, dr)
