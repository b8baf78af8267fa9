"""The exterior Neumann problem for the velocity potential (Part I, eqs. (6)-(7), (20)-(22)).

Formulation: *direct* (Green's representation) rather than the paper's simple layer (20)-(21).
For a closed surface S with the normal n pointing out of the body into the fluid, the
potential in the fluid is

    phi(x) = integral_S [phi(y) dG/dn_y - G(x, y) g(y)] dS_y,      g = dphi/dn = -n_x,  (*)

and on the surface (at smooth points, where the collocation nodes are)

    phi(x)/2 - integral_S phi dG/dn_y dS_y = - integral_S G g dS_y.                   (**)

Equation (**) is of the second kind and uniquely solvable for the exterior Neumann problem;
it yields phi on the surface directly, which is what A, B and the pressure (9) need.

Half-space (Part I, eqs. (21)-(22), Fig. 3): the target x >= 0 with the free surface x = 0
(dphi/dn = 0 there) is replaced by the whole space around the body S and its mirror image
S', with phi even in x.  Only the nodes on S are unknowns; the columns of the mirror nodes
are folded onto their images (the kernel K(x, x1) + K(x, -x1) of the paper's reduced
equation).  The Neumann datum on the image equals that of the original point, so the net
flux is 2C != 0 and phi decays like a monopole (errata item 2f).

Discretisation: panels with p Gauss nodes each (Nystrom collocation), exact geometry, the
logarithmic singularity of the ring kernels integrated with product rules, nearly singular
pairs with dyadically graded rules; assembly vectorised over all pairs.
"""

from __future__ import annotations

import contextlib
import functools
import math
import threading
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.linalg

from semianalytic.bem import kernels as _kernels
from semianalytic.bem.kernels import (
    gradient_kernels,
    pair_rules_prepare,
    pair_rules_run,
    single_double,
    single_double_split,
)
from semianalytic.bem.panels import PanelSet, _node_grid
from semianalytic.bem.quadrature import (
    differentiation_matrix,
    gauss_legendre,
    gauss_log,
    lagrange_matrix,
)
from semianalytic.errors import ModelError
from semianalytic.native import address

N_SELF = 6  # points per half-panel in the self rules (plain and log)
N_NEAR = 8  # Gauss points per dyadic piece in the near rules
NEAR_FACTOR = 1.3  # a panel is "near" a target closer than this many panel lengths to its centre
MAX_LEVELS = 48
IMAGE_MARGIN = 4.0  # innermost self piece <= (distance to the axis image)/IMAGE_MARGIN
# kernel entries per block of rows of the dense assembly, so that the kernels' temporaries stay
# near glibc's mmap threshold (128 KiB) instead of being mapped and unmapped at every call (this
# project's own; measured in one process, alternately 8 times: the certified table nose 2.40 s
# against 2.66 s of CPU, the Fig. 5 ogive unchanged; the same numbers bitwise)
DENSE_CHUNK = 12288


@functools.cache
def _threadpools():
    from threadpoolctl import ThreadpoolController

    return ThreadpoolController()


_BLAS_LIMIT = threading.local()
_ALL = np.logical_and.reduce  # np.all without its Python wrappers (booleans in, a boolean out)
_SUM = np.add.reduce  # np.sum without its Python wrappers (the same reduction: np.sum calls it)
_MAX = np.maximum.reduce  # ndarray.max without its Python wrappers (the same reduction)


_NESTED = contextlib.nullcontext()  # reusable: no state


def _single_threaded_blas():
    """Small dense solves run far faster on one BLAS thread on a loaded 2-core machine
    (numerical notes); the limit is lifted again on exit.  Nested uses inside one thread cost
    nothing (a table sets it once for its 150 solves: each setting is ~0.1 ms of library calls;
    a nested use is a shared null context, not a new generator)."""
    return _NESTED if getattr(_BLAS_LIMIT, "on", False) else _blas_limited()


@contextlib.contextmanager
def _blas_limited():
    """The BLAS limit of :func:`_single_threaded_blas` when none is on in this thread."""
    with _threadpools().limit(limits=1, user_api="blas"):
        _BLAS_LIMIT.on = True
        try:
            yield
        finally:
            _BLAS_LIMIT.on = False


# ------------------------------------------------------------------------------------
# near pairs


@functools.cache
def _samples(order: int) -> np.ndarray:
    return np.linspace(-1.0, 1.0, 2 * order + 1)


def _sample_table(ps: PanelSet):
    """x, r, x_u, r_u of every panel at the 2p+1 samples of :func:`closest_points`, shape
    (n_panels, 2p+1): evaluated once per panel set instead of once per (target, panel) pair
    (the same numbers; kept on the panel set)."""
    table = ps.__dict__.get("_closest_samples")
    if table is None:
        table = ps.evaluate(*_sample_grid(ps.n_panels, ps.order))
        ps.__dict__["_closest_samples"] = table
    return table


@functools.lru_cache(maxsize=64)
def _sample_grid(n_panels: int, order: int):
    """The panel and the u of every sample of :func:`_sample_table`, (n_panels, 2p+1) each
    (read-only; shared by the panel sets of a topology)."""
    samples = _samples(order)
    pk = np.repeat(np.arange(n_panels), samples.size).reshape(n_panels, samples.size)
    u = np.ascontiguousarray(np.broadcast_to(samples, pk.shape))
    for a in (pk, u):
        a.setflags(write=False)
    return pk, u


def _centers(ps: PanelSet) -> tuple[np.ndarray, np.ndarray]:
    """:attr:`PanelSet.centers` (the points at u = 0) read from :func:`_sample_table`, whose middle
    sample is u = 0 (the same evaluation, one call fewer per panel set); else ``ps.centers``."""
    if _samples(ps.order)[ps.order] != 0.0:
        return ps.centers
    sx, sr = _sample_table(ps)[:2]
    return sx[:, ps.order], sr[:, ps.order]


def closest_points(ps: PanelSet, pan: np.ndarray, xq: np.ndarray, rq: np.ndarray):
    """Parameter u* of the point of panel ``pan`` nearest to (xq, rq), and the distance in
    the panel's parameter, du = distance / |dy/du| at u*.

    Sampled, then refined by Newton's method (projected onto [-1, 1]): the minimum may lie
    between an end sample and its neighbour.  A pair whose nearest sample is an end of the
    panel where the distance grows inwards ((y - x) . y' >= 0 at u = -1, <= 0 at u = +1) keeps
    that end: every Newton step from there points out of the panel and is projected back.
    Compiled (``ring_closest_points`` of ``_ring.c``, the same operations: this project's own
    speed-up) where the panel geometry is; Newton steps on corner panels always by
    :func:`_newton` (numpy's power)."""
    got = _closest_compiled(ps, pan, xq, rq)
    if got is not None:
        u, ex, er, xu, ru, todo = got
    else:
        samples = _samples(ps.order)
        sx, sr, sxu, sru = _sample_table(ps)
        x, r = sx[pan], sr[pan]
        d2 = (x - xq[:, None]) ** 2 + (r - rq[:, None]) ** 2
        j = np.argmin(d2, axis=1)
        rows = np.arange(len(pan))
        u = samples[j]
        x, r, xu, ru = x[rows, j], r[rows, j], sxu[pan, j], sru[pan, j]
        ex, er = x - xq, r - rq
        f = ex * xu + er * ru
        last = samples.size - 1
        settled = ((j == 0) & (f >= 0)) | ((j == last) & (f <= 0))
        todo = np.nonzero(~settled)[0]
    if todo.size:
        u[todo], ex[todo], er[todo], xu[todo], ru[todo] = _newton(ps, pan[todo], u[todo], xq[todo], rq[todo])
    dist = np.hypot(ex, er)
    with np.errstate(divide="ignore", invalid="ignore"):
        du = dist / np.hypot(xu, ru)
    du = ps.param_distance(pan, u, dist, np.where(np.isfinite(du), du, np.inf))
    return u, du


def _newton(ps: PanelSet, pan, u, xq, rq):
    """Two Newton steps of :func:`closest_points` from u: u, x - xq, r - rq, x_u, r_u there
    (compiled: ``ring_newton_step`` of ``_ring.c``, given numpy's powers on corner panels)."""
    got = ps._compiled_lib(pan)
    if got is not None:
        lib, pk = got
        fn = lib.ring_newton_step
        c = ps._compiled_curves[0]
        u = np.array(u, dtype=float)
        xq, rq = (np.ascontiguousarray(a, dtype=float) for a in (xq, rq))
        out = np.empty((4, u.size))  # the point at the last step: ex, er, x_u, r_u (rows at address + k * row)
        at, row = address(out), out.strides[0]
        for last in (False, True):
            pw = ps._numpy_powers(pk, u)
            fn(pk.size, address(pk), address(u), address(xq), address(rq), c["base"], c["da"], c["db"], c["half"],
               c["sign"], c["ax"], c["ar"], float(ps.offset), c["cluster"], c["power"], c["kind"], c["c0"], c["c1"],
               c["nk"], c["knots"], c["cx"], c["cr"], None if pw is None else address(pw),
               *((at, at + row, at + 2 * row, at + 3 * row) if last else (None,) * 4))
        return (u, *out)
    for _ in range(2):  # Newton on (y(u) - x) . y'(u) = 0 (from the nearest of 2p+1 samples)
        xn, rn, xun, run, xuu, ruu = ps.evaluate(pan, u, second=True)
        ex, er = xn - xq, rn - rq
        fn = ex * xun + er * run
        fp = xun * xun + run * run + ex * xuu + er * ruu
        step = np.where(fp > 0, fn / np.where(fp > 0, fp, 1.0), 0.0)
        u = np.clip(u - step, -1.0, 1.0)
    x, r, xu, ru = ps.evaluate(pan, u)
    return u, x - xq, r - rq, xu, ru


def _closest_compiled(ps: PanelSet, pan, xq, rq):
    """:func:`closest_points`' search by ``ring_closest_points``: u, x - xq, r - rq, x_u, r_u
    and the pairs left to :func:`_newton` (on corner panels); None without compiled geometry."""
    got = ps._compiled_lib(pan) if len(pan) else None
    if got is None:
        return None
    lib, pk = got
    c = ps._compiled_curves[0]
    table = [np.ascontiguousarray(a, dtype=float) for a in _sample_table(ps)]  # no copies: evaluate's own arrays
    samples = _samples(ps.order)
    xq, rq = (np.ascontiguousarray(a, dtype=float) for a in (xq, rq))
    out = np.empty((5, pk.size))  # u, ex, er, x_u, r_u: the rows of one block, at address + k * row
    todo = np.empty(pk.size, dtype=np.int8)
    at, row = address(out), out.strides[0]
    lib.ring_closest_points(
        pk.size, address(pk), address(xq), address(rq), samples.size, address(samples), *(address(a) for a in table),
        c["base"], c["da"], c["db"], c["half"], c["sign"], c["ax"], c["ar"], float(ps.offset), c["cluster"],
        c["power"], c["kind"], c["c0"], c["c1"], c["nk"], c["knots"], c["cx"], c["cr"],
        at, at + row, at + 2 * row, at + 3 * row, at + 4 * row, address(todo))
    return (*out, np.nonzero(todo)[0])


def near_pairs(ps: PanelSet, xt: np.ndarray, rt: np.ndarray, exclude_panel: np.ndarray | None = None,
               exclude_block: tuple[np.ndarray, np.ndarray] | None = None):
    """(target, panel) pairs needing graded quadrature, with the panel point u* nearest to
    the target and its distance in the panel's parameter.

    The image of the target in the axis, (x, -r), counts as well: the ring kernels,
    continued analytically through the axis, are singular there, which matters for
    panels touching the axis and targets close to it.  ``exclude_block`` = (target mask,
    panel mask): pairs of both masks are left out (their block is reused, see
    :class:`AssemblyCache`).
    """
    return _near_pairs_with(ps, xt, rt, exclude_panel, exclude_block)[:4]


def _near_pairs_with(ps: PanelSet, xt, rt, exclude_panel=None, exclude_block=None, also=None):
    """:func:`near_pairs`, and the nearest points of the further queries ``also`` = (panel,
    x, r) if given (fifth and sixth outputs, u and du): all found by one call of
    :func:`closest_points` (the same numbers as separate calls, a third of the calls)."""
    cx, cr = _centers(ps)
    reach = NEAR_FACTOR * ps.lengths[None, :]
    dx = xt[:, None] - cx[None, :]
    with np.errstate(over="ignore"):
        dx2 = dx * dx  # shared by both searches
    # the target (r - r_c) and its axis image (r + r_c, as r - (-r_c): the same numbers) against
    # every panel centre in one (2, targets, panels) array: one pass of _closer for both searches
    near = _closer(dx, rt[:, None] - _signed_radii(cr), reach, dx2)
    if exclude_panel is not None:
        near[:, np.arange(len(xt)), exclude_panel] = False
    if exclude_block is not None:
        near &= ~(exclude_block[0][:, None] & exclude_block[1][None, :])
    near, near_img = near
    tgt, pan = np.nonzero(near | near_img)
    img = np.nonzero(near_img[tgt, pan])[0]
    n, m = tgt.size, img.size
    if also is None:
        also = (np.empty(0, int), np.empty(0), np.empty(0))
    qp = np.concatenate([pan, pan[img], also[0]])
    if qp.size == 0:
        return tgt, pan, np.empty(0), np.empty(0), np.empty(0), np.empty(0)
    qx = np.concatenate([xt[tgt], xt[tgt[img]], also[1]])
    qr = np.concatenate([rt[tgt], -rt[tgt[img]], also[2]])
    uq, duq = closest_points(ps, qp, qx, qr)
    u, du = uq[:n], duq[:n]
    if m:
        u_img, du_img = uq[n:n + m], duq[n:n + m]
        use = du_img < du[img]
        u[img[use]] = u_img[use]
        du[img[use]] = du_img[use]
    return tgt, pan, u, du, uq[n + m:], duq[n + m:]


def _signed_radii(cr: np.ndarray) -> np.ndarray:
    """(2, 1, n) of +cr and -cr: r - (+-cr) is the distance in r from a panel centre and from its
    image in the axis."""
    out = np.empty((2, 1, cr.size))
    out[0, 0] = cr
    np.negative(cr, out=out[1, 0])
    return out


def _closer(a, b, reach, a2=None):
    """hypot(a, b) < reach elementwise (a and reach broadcasting to the shape of b), numpy's
    hypot deciding only where a^2 + b^2 lies within 1e-12 of reach^2 (this project's own
    shortcut, the same booleans at a quarter of the cost: a^2 + b^2 and hypot^2 differ by a
    few ulps, 1e-15; squares near under- or overflow take hypot everywhere).  ``a2``: a * a if
    the caller has it."""
    if not 1e-140 < float(np.min(reach)) <= float(np.max(reach)) < 1e140:
        return np.hypot(a, b) < reach
    r2 = reach * reach
    with np.errstate(over="ignore"):  # a^2 = inf: far, as hypot says
        s = (a * a if a2 is None else a2) + b * b
    out = s < r2 * (1.0 - 1e-12)
    edge = np.nonzero(~out & (s <= r2 * (1.0 + 1e-12)))
    if edge[0].size:
        out[edge] = np.hypot(np.broadcast_to(a, s.shape)[edge], b[edge]) < np.broadcast_to(reach, s.shape)[edge]
    return out


def _levels(side: np.ndarray, du: np.ndarray) -> np.ndarray:
    """Dyadic levels so that the innermost piece of a side is no longer than du."""
    with np.errstate(divide="ignore", invalid="ignore"):
        lev = np.ceil(np.log2(side / du))
    lev = np.where(side <= 0, 0, np.where(np.isfinite(lev), lev, MAX_LEVELS))
    # np.clip's value, without its Python wrappers (lev has no NaN here)
    return np.minimum(np.maximum(lev, 0), MAX_LEVELS, out=lev).astype(int)


@dataclass(frozen=True)
class PairQuadrature:
    """Quadrature points for a list of (target, panel) pairs, flattened.

    Point k belongs to pair ``pair[k]`` (points sorted by pair; ``starts`` indexes the
    first point of each pair), sits at the panel coordinate ``u[k]`` and contributes
    ``(a[k] K + b[k] Q) |dy/du| lag[k, j]`` to the integral of the kernel K against the
    Lagrange basis function l_j; Q is the coefficient of the logarithm (self rules only,
    b = 0 elsewhere).

    The pairs come in ``blocks`` (first pair, number of pairs, points per pair, Lagrange
    matrix): pairs of a block with a shared (Q, p) matrix (the end rules of neighbouring
    panels) or with one (Q, p) matrix each (the self rules) are summed by one matrix
    product; a block with matrix None (rules of varying length) by the flat ``lag`` rows of
    its points.
    """

    target: np.ndarray
    panel: np.ndarray
    pair: np.ndarray
    starts: np.ndarray
    u: np.ndarray
    a: np.ndarray
    b: np.ndarray
    lag: np.ndarray  # (points of the blocks without a matrix, p)
    target_u: np.ndarray | None = None  # self rules: the target's own panel coordinate
    blocks: tuple = ()
    # distinct points (panel, u) and the distinct point of each point: the pairs of one end rule
    # on one panel (the nodes of its neighbour) share their points, whose geometry is then
    # evaluated once (None: every point evaluated)
    distinct: tuple | None = None

    @cached_property
    def _point_panel(self) -> np.ndarray:
        return self.panel[self.pair]

    @cached_property
    def _point_target(self) -> np.ndarray:
        return self.target[self.pair]

    @cached_property
    def _point_target_u(self) -> np.ndarray:
        return self.target_u[self.pair]

    def entries(self, order: int, n: int) -> np.ndarray:
        """Flat indices of the (target, node) entries of each pair's block (n_pairs, order) in the
        C-ordered (2, n, n) pair of matrices of :func:`assemble` (n primary nodes): row target,
        column c = panel * order + j of matrix 0 for a primary node (c < n), and for a mirror
        node (c >= n, the image of primary node 2n - 1 - c: :meth:`PanelSet.fold_mirror`) column
        2n - 1 - c of matrix 1, the mirror block in folded order.  Kept per rule: the solves of a
        difference in P share it."""
        return self._entries(order, n)[0]

    def _entries(self, order: int, n: int) -> tuple[np.ndarray, int]:
        """:meth:`entries` and one past its largest index (0 when empty): the bound a compiled
        write through them is checked against."""
        key = (order, n)
        got = self.__dict__.setdefault("_entries_memo", {})
        if key not in got:
            c = self.panel[:, None] * order + np.arange(order)[None, :]
            c = np.where(c < n, c, n * n + (2 * n - 1 - c))
            flat = np.ascontiguousarray((self.target[:, None] * n + c).ravel(), dtype=np.intp)
            if flat.size and flat.min() < 0:
                raise ValueError("PairQuadrature.entries: a negative index (a panel or target out of range)")
            got[key] = flat, int(flat.max()) + 1 if flat.size else 0
        return got[key]


    @staticmethod
    def build(target, panel, order, parts, target_u=None) -> PairQuadrature:
        """From parts (pair indices (n,), u (n, Q), a (n, Q), b (n, Q), lag) with any Q
        each; lag is the (n, Q, p) or shared (Q, p) Lagrange matrix, or None.  The pairs
        are reordered part by part, so that each pair's points are contiguous."""
        if not parts:
            empty = np.empty(0, int)
            return PairQuadrature(empty, empty, empty, empty, *(np.empty(0),) * 3, np.empty((0, order)))
        nodes = gauss_legendre(order)[0]
        order_idx = np.concatenate([sel for sel, *_ in parts])
        # a part of flat points carries its counts per pair as a sixth entry
        counts = np.concatenate([part[5] if len(part) > 5 else np.full(len(part[0]), part[1].shape[1]) for part in parts])
        starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
        pair = np.repeat(np.arange(len(order_idx)), counts)
        u, a, b = (np.concatenate([part[k].ravel() for part in parts]) for k in (1, 2, 3))
        lags, blocks = [], []
        first = 0
        for part in parts:
            n, uu, lag = len(part[0]), part[1], part[4]
            if len(part) > 5:  # flat points of varying counts
                if lag is None:
                    lag = lagrange_matrix(nodes, uu)
                lags.append(lag)
                blocks.append((first, n, 0, None))
            else:
                if lag is None:
                    lag = lagrange_matrix(nodes, uu)
                Q = uu.shape[1]
                blocks.append((first, n, Q, lag))
            first += n
        flat = np.concatenate(lags) if lags else np.empty((0, order))
        return PairQuadrature(
            target[order_idx], panel[order_idx], pair, starts, u, a, b, flat,
            None if target_u is None else target_u[order_idx], tuple(blocks),
        )

    def subset(self, keep: np.ndarray) -> PairQuadrature:
        """The rules of the pairs where ``keep`` (a mask over pairs) is true (kept per mask, up
        to 64 masks: the self rules, shared by the depths of a table, are cut by the same masks
        of reused blocks at many depths; this project's own shortcut, the same rules)."""
        if keep.all():
            return self
        memo = self.__dict__.setdefault("_subsets", {})
        key = np.ascontiguousarray(keep, dtype=bool).tobytes()
        got = memo.get(key)
        if got is None:
            got = self._subset(keep)
            if len(memo) < 64:
                memo[key] = got
        return got

    def _subset(self, keep: np.ndarray) -> PairQuadrature:
        points = keep[self.pair]
        renumber = np.cumsum(keep) - 1
        pair = renumber[self.pair[points]]
        counts = np.bincount(pair, minlength=int(keep.sum()))
        blocks, flat_rows = [], []
        first = 0
        flat_at = 0
        for f, n, Q, lag in self.blocks:
            k = keep[f:f + n]
            m = int(k.sum())
            if lag is None:
                s0, s1 = self._points_of(f, n)
                flat_rows.append(self.lag[flat_at:flat_at + (s1 - s0)][points[s0:s1]])
                flat_at += s1 - s0
                if m:
                    blocks.append((first, m, 0, None))
            elif m:
                blocks.append((first, m, Q, lag if lag.ndim == 2 else lag[k]))
            first += m
        flat = np.concatenate(flat_rows) if flat_rows else np.empty((0, self.lag.shape[1]))
        return PairQuadrature(
            self.target[keep], self.panel[keep], pair, np.cumsum(counts) - counts, self.u[points], self.a[points],
            self.b[points], flat, None if self.target_u is None else self.target_u[keep], tuple(blocks),
        )

    def _points_of(self, f: int, n: int) -> tuple[int, int]:
        """First and past-the-last point of the pairs f .. f + n - 1."""
        return int(self.starts[f]), int(self.starts[f + n]) if f + n < len(self.starts) else self.u.size

    @cached_property
    def _block_slices(self) -> tuple:
        """Per block: (pairs, points, Q, Lagrange matrix, flat rows and reduceat offsets of a
        block without a matrix), worked out once for the rule's every reduction."""
        out = []
        flat_at = 0
        blocks = self.blocks or (((0, len(self.target), 0, None),) if len(self.target) else ())  # all rows flat
        for f, n, Q, lag in blocks:
            s0, s1 = self._points_of(f, n)
            if lag is None:
                rows = self.lag[flat_at:flat_at + (s1 - s0)]
                flat_at += s1 - s0
                out.append((slice(f, f + n), slice(s0, s1), Q, None, rows, self.starts[f:f + n] - s0))
            else:
                out.append((slice(f, f + n), slice(s0, s0 + n * Q), Q, lag, None, n))
        return tuple(out)

    def _reduce(self, wk: np.ndarray) -> np.ndarray:
        """Sum of each pair's weighted kernel values against the Lagrange basis: (n_pairs, p)."""
        out = np.empty((len(self.target), self.lag.shape[1]))
        for pairs, points, Q, lag, rows, at in self._block_slices:
            if lag is None:
                out[pairs] = np.add.reduceat(wk[points, None] * rows, at, axis=0)
            elif lag.ndim == 2:
                out[pairs] = wk[points].reshape(at, Q) @ lag
            else:
                out[pairs] = np.matmul(wk[points].reshape(at, 1, Q), lag)[:, 0, :]
        return out

    @cached_property
    def _row_blocks(self) -> tuple:
        """The Lagrange rows of the blocks as :func:`pair_rules_compiled` takes them: (first
        points and past-the-last point, rows repeating every q points (0: one row per point),
        the rows' addresses, p, the row arrays)."""
        starts, q, keep = [], [], []
        stop = 0
        for _pairs, points, Q, lag, rows, _n in self._block_slices:
            if points.start != stop:  # the blocks' points follow each other
                raise ValueError("PairQuadrature: blocks with gaps between their points")
            starts.append(points.start)
            stop = points.stop
            if lag is None:
                keep.append(np.ascontiguousarray(rows, dtype=float))
                q.append(0)
            elif lag.ndim == 2:  # one (Q, p) matrix shared by the block's pairs
                keep.append(np.ascontiguousarray(lag, dtype=float))
                q.append(Q)
            else:  # one (Q, p) matrix per pair
                keep.append(np.ascontiguousarray(lag, dtype=float))
                q.append(0)
        if (stop if starts else 0) != self.u.size:
            raise ValueError("PairQuadrature: blocks that do not cover the points")
        starts.append(self.u.size)
        addresses = np.array([address(k) for k in keep], dtype=np.uintp)
        return np.array(starts, dtype=np.intp), np.array(q, dtype=np.intp), addresses, self.lag.shape[1], keep

    def _compiled_rule(self, split: bool):
        """This rule's arguments of :func:`pair_rules_compiled`, converted and checked once
        (:func:`pair_rules_prepare`; the two assemblies of a difference in P share the rule)."""
        got = self.__dict__.setdefault("_prepared", {})
        if split not in got:
            index = None if self.distinct is None else self.distinct[2]
            got[split] = pair_rules_prepare(index, self._point_target, self.a, self.b if split else None, self.pair,
                                            self._row_blocks, len(self.target))
        return got[split]

    def integrate(self, ps: PanelSet, xt, rt, kernels, node_targets: bool = False, into=None):
        """Blocks (n_pairs, p) of each kernel integrated against the Lagrange basis.

        ``into`` (or None): (S_all, D_all, flat, bound) for the two kernels of ``_layers`` or
        ``_layers_split``: the blocks' entries are also written into those arrays at the flat
        indices (:meth:`entries`, all below ``bound``), ``S_all.put(flat, S)`` (in the compiled
        call when it runs).

        ``kernels(X, R, x, r, nx, nr)`` returns a tuple of kernel arrays, or of (K, Q)
        pairs when the rule carries logarithms (b != 0).  The single and double layer
        (``_layers``, ``_layers_split``) run compiled after the geometry when the compiled
        kernels are at hand (:func:`pair_rules_compiled`, the same sums to round-off; this
        project's own speed-up)."""
        pan = self._point_panel
        sel = None
        if self.target_u is None and node_targets and ps.tiny_panels.any():
            # targets are nodes of ps: on panels graded far below their distance from the
            # origin, differences through the shared anchors (a corner) keep their digits
            on_tiny = ps.tiny_panels[pan]
            sel = np.nonzero(on_tiny)[0]
        tiny = sel is not None and sel.size > 0
        split = _COMPILED_LAYERS.get(kernels)
        fast = split is not None and self.u.size > 0 and _kernels.compiled() is not None
        index = None
        if self.distinct is not None:
            dpan, du, index = self.distinct
            x, r, xu, ru, *parts = ps.evaluate(dpan, du, split=tiny)
            at = index[sel] if tiny else None
            if not fast:
                J = np.hypot(xu, ru)
                x, r, J, nx, nr = x[index], r[index], J[index], (ru / J)[index], (-xu / J)[index]
        else:
            x, r, xu, ru, *parts = ps.evaluate(pan, self.u, split=tiny)
            if not fast:
                J = np.hypot(xu, ru)
                nx, nr = ru / J, -xu / J
            at = sel
        t = self._point_target
        delta = None
        if self.target_u is not None:  # target and source on one panel: exact differences
            delta = ps.relative(pan, self.u, self._point_target_u)
        elif tiny and not fast:
            ax, ar, ex, er = (a[at] for a in parts)  # the points' split (anchor + offset)
            tax, tar, tex, ter = (a[t[sel]] for a in ps.node_split)
            dx, dr = xt[t] - x, rt[t] - r
            dx[sel] = (tax - ax) + (tex - ex)
            dr[sel] = (tar - ar) + (ter - er)
            delta = (dx, dr)
        if fast:
            # the differences of the points on tiny panels through the anchors, as below
            through = (on_tiny, parts, ps.node_split) if tiny else None
            return list(pair_rules_run(self._compiled_rule(split), x, r, xu, ru, xt, rt, delta, through, into))
        out = []
        for ker in kernels(xt[t], rt[t], x, r, nx, nr, delta):
            if isinstance(ker, tuple):
                K, Q = ker
                wk = (self.a * K + self.b * Q) * J
            else:
                wk = self.a * ker * J
            out.append(self._reduce(wk))
        if into is not None:
            for dest, block in zip(into[:2], out):
                dest.put(into[2], block)
        return out


def _dyadic_sides(ustar, n_l, n_r):
    """Points and weights of the rules split at u* with n_l (n_r) dyadic pieces left (right)
    of it, for arrays of pairs: (pair index per point, u, w).

    Side s (left of u*, length 1 + u*, or right, 1 - u*) with L = n - 1 levels has the
    pieces [0, 2^-L], [2^-L, 2^-L+1], ..., [1/2, 1] of :func:`dyadic_rule` scaled by the
    side's length, N_NEAR Gauss points each."""
    npieces = n_l + n_r
    first = np.cumsum(npieces) - npieces
    pair = np.repeat(np.arange(len(ustar)), npieces)
    j = np.arange(int(npieces.sum())) - first[pair]
    is_left = j < n_l[pair]
    k = np.where(is_left, j, j - n_l[pair])  # 0: the innermost piece of its side
    lev = np.where(is_left, n_l[pair], n_r[pair]) - 1
    b = np.ldexp(1.0, k - lev)
    a = np.where(k == 0, 0.0, 0.5 * b)
    side = np.where(is_left, -(1.0 + ustar[pair]), 1.0 - ustar[pair])  # signed length
    g, gw = gauss_legendre(N_NEAR)
    u = ustar[pair][:, None] + side[:, None] * (a[:, None] + (b - a)[:, None] * (0.5 * (g + 1.0)))
    w = (np.abs(side) * 0.5 * (b - a))[:, None] * gw
    return np.repeat(pair, N_NEAR), u.ravel(), w.ravel()


@functools.lru_cache(maxsize=256)
def _end_rule(order: int, end: float, n: int):
    """The rule of a pair whose nearest panel point is an end (u* = -1 or +1, a neighbouring
    panel): n dyadic pieces towards that end, and its Lagrange matrix."""
    us = np.array([end])
    n_l, n_r = (np.array([0]), np.array([n])) if end < 0 else (np.array([n]), np.array([0]))
    _, u, w = _dyadic_sides(us, n_l, n_r)
    lag = lagrange_matrix(gauss_legendre(order)[0], u)
    for a in (u, w, lag):
        a.setflags(write=False)
    return u, w, lag


_KEYS = MAX_LEVELS + 1  # the end rules' keys lie within +-_KEYS; key + _KEYS indexes tables of them


@functools.lru_cache(maxsize=256)
def _end_rules(order: int, keys: bytes):
    """The end rules of ``keys`` (int64, ascending, each the signed number of pieces of
    :func:`_end_rule`): their Lagrange matrices, numbers of points, the u and w of their points
    concatenated (rows of one (2, points) array), and per key + _KEYS its rule's number of points and
    first point in that concatenation (kept per set of keys: the neighbouring depths of a table
    share them)."""
    rules = [_end_rule(order, -1.0 if k < 0 else 1.0, int(abs(k))) for k in np.frombuffer(keys, dtype=np.int64).tolist()]
    size = np.array([r[0].size for r in rules], dtype=np.int64)
    uw = np.array([np.concatenate([r[j] for r in rules]) if rules else np.empty(0) for j in (0, 1)])
    at = np.frombuffer(keys, dtype=np.int64) + _KEYS
    size_of, first_of = np.zeros(2 * _KEYS + 1, np.int64), np.zeros(2 * _KEYS + 1, np.int64)
    size_of[at], first_of[at] = size, np.cumsum(size) - size
    return tuple(r[2] for r in rules), size, uw, size_of, first_of


def near_quadrature(target, panel, ustar, du, order) -> PairQuadrature:
    """Dyadic rules on [-1, 1] split at u* (the panel point nearest each target), with
    pieces no longer than their distance from the target (``du`` in the panel parameter).

    Pairs whose u* is an end of the panel (neighbouring panels: most pairs) take a rule
    built once per level (:func:`_end_rule`); the others are built together.  The rule's
    :attr:`PairQuadrature.distinct` points are found from the rules' structure: one set per end
    rule and panel, in the order of their keys (the pairs of one end rule on one panel, the nodes
    of its neighbour, share their points, whose geometry is then evaluated once: a fifth to a
    ninth of the points, the same numbers; this project's own shortcut), then each other pair's
    points."""
    target, panel = np.asarray(target), np.asarray(panel)
    if target.size == 0:
        return PairQuadrature.build(target, panel, order, [])
    npairs = ustar.size
    # pieces per side, left (1 + u*) and right (1 - u*) in one call; 0: the side is empty
    sides = np.concatenate([1.0 + ustar, 1.0 - ustar])
    n_lr = np.where(sides > 0, _levels(sides, np.concatenate([du, du])) + 1, 0)
    at_end = n_lr[:npairs] * n_lr[npairs:] == 0  # a side is empty
    # the rule depends on the pairs, their pieces and the u* of the pairs not at an end only: kept
    # for the next calls (neighbouring depths often repeat it; this project's own shortcut). Four
    # are kept: a rule with its prepared arguments is 0.3-1.3 MB, and 32 held 14 MB after an ogive
    # table and 43 MB after a table nose's for 12 more hits of 74 (under 1 % of the table's time)
    inner_u = b"" if _ALL(at_end) else np.ascontiguousarray(ustar[~at_end], dtype=float).tobytes()
    return _near_rule(order, target.dtype.str, target.tobytes(), panel.dtype.str, panel.tobytes(),
                      np.ascontiguousarray(n_lr, dtype=np.int64).tobytes(), inner_u)


@functools.lru_cache(maxsize=4)
def _near_rule(order: int, tdt: str, tgt: bytes, pdt: str, pan: bytes, pieces: bytes, inner_u: bytes) -> PairQuadrature:
    """:func:`near_quadrature` from its inputs as bytes: targets and panels (dtype, data), the
    numbers of pieces left and right of u* (int64, all left then all right) and u* of the pairs
    not at an end."""
    target, panel = np.frombuffer(tgt, dtype=tdt), np.frombuffer(pan, dtype=pdt)
    n_lr = np.frombuffer(pieces, dtype=np.int64)
    npairs = target.size
    n_l, n_r = n_lr[:npairs], n_lr[npairs:]
    at_end = n_l * n_r == 0
    key = n_l - n_r  # of an end pair: -n_r (u* = -1: pieces to the right) or n_l (u* = +1)
    # the end rules' pairs grouped by rule (ascending key, pairs in order within a key), each
    # point's u and w those of its distinct point; then the other pairs.
    # keys within +-_KEYS: sorted as int16 (numpy's radix sort; the same stable order)
    if _ALL(at_end):
        ends, inner = np.argsort(key.astype(np.int16), kind="stable"), np.empty(0, np.intp)
    else:
        ends, inner = np.nonzero(at_end)[0], np.nonzero(~at_end)[0]
        ends = ends[np.argsort(key[ends].astype(np.int16), kind="stable")]
    sk = key[ends] + _KEYS
    tally = np.bincount(sk, minlength=2 * _KEYS + 1)  # pairs per key
    present = tally.nonzero()[0]
    per_key = tally[present]
    lags, size, uw_cat, size_of, first_of = _end_rules(order, (present - _KEYS).tobytes())
    blocks = tuple(zip((np.cumsum(per_key) - per_key).tolist(), per_key.tolist(), size.tolist(), lags))
    counts = size_of[sk]  # points of each end pair
    pair_at = np.cumsum(counts) - counts
    # distinct points: one set per (end rule, panel), in ascending key, then panel
    span = int(panel.max()) + 1
    gkey = sk * span + panel[ends]
    present = np.zeros((2 * _KEYS + 1) * span, bool)
    present[gkey] = True
    groups = np.flatnonzero(present)
    group_of = (np.cumsum(present) - 1)[gkey]  # each end pair's set
    g_key, g_panel = np.divmod(groups, span)
    g_size = size_of[g_key]
    g_at = np.cumsum(g_size) - g_size
    n_distinct = int(g_size.sum())
    d_src = np.repeat(first_of[g_key] - g_at, g_size) + np.arange(n_distinct)
    d_panel, d_u, d_w = np.repeat(g_panel, g_size), uw_cat[0].take(d_src), uw_cat[1].take(d_src)
    # per point: its distinct point (whose u and w are its own) and its pair (ndarray.take: the
    # same gathers as indexing, at two thirds of its cost)
    d_index = np.repeat(g_at[group_of] - pair_at, counts)
    d_index += np.arange(d_index.size)
    pair = np.repeat(np.arange(ends.size), counts)
    u_end, w_end = d_u.take(d_index), d_w.take(d_index)
    flat = np.empty((0, order))
    if inner.size:
        pair, u, w = _dyadic_sides(np.frombuffer(inner_u, dtype=float), n_l[inner], n_r[inner])
        pts = np.argsort(pair, kind="stable")  # already sorted; kept explicit
        u, w = u[pts], w[pts]
        flat = lagrange_matrix(gauss_legendre(order)[0], u)
        blocks += ((ends.size, inner.size, 0, None),)
        counts = np.concatenate([counts, np.bincount(pair, minlength=inner.size)])
        # each inner pair's points are a set of their own, after the end rules' sets
        d_index = np.concatenate([d_index, n_distinct + np.arange(u.size)])
        d_panel = np.concatenate([d_panel, panel[inner][pair[pts]]])
        d_u = np.concatenate([d_u, u])
        u_end, w_end = np.concatenate([u_end, u]), np.concatenate([w_end, w])
        pair_at = np.cumsum(counts) - counts
        pair = np.repeat(np.arange(counts.size), counts)
        ends = np.concatenate([ends, inner])
    return PairQuadrature(target[ends], panel[ends], pair, pair_at, u_end, w_end, np.zeros(u_end.size), flat, None,
                          blocks, (d_panel, d_u, d_index))


def self_quadrature(levels: np.ndarray, order: int) -> PairQuadrature:
    """Self rules (log split, graded towards the node by ``levels``) for every primary node.

    The rules live in the panel coordinate only: the same levels give the same rules at
    every depth, so they are built once (cached on the levels)."""
    levels = np.ascontiguousarray(levels, dtype=np.int64)
    return _self_quadrature(levels.tobytes(), len(levels), order)


@functools.lru_cache(maxsize=128)
def _self_quadrature(key: bytes, N: int, order: int) -> PairQuadrature:
    levels = np.frombuffer(key, dtype=np.int64).reshape(N, 2)
    q = np.arange(N) % order
    uq = gauss_legendre(order)[0][q]
    key = levels[:, 0] * (MAX_LEVELS + 1) + levels[:, 1]
    parts = []
    for k in np.unique(key):
        sel = np.nonzero(key == k)[0]
        t = _self_rule_table(order, int(k // (MAX_LEVELS + 1)), int(k % (MAX_LEVELS + 1)))
        qs = q[sel]
        parts.append((sel, t["u"][qs], t["a"][qs], t["b"][qs], t["L"][qs]))
    own = np.arange(N) // order
    return PairQuadrature.build(np.arange(N), own, order, parts, target_u=uq)


# ------------------------------------------------------------------------------------
# assembly of (**)


def _flat_nodes(ps: PanelSet):
    g = ps.nodes
    return g.x.ravel(), g.r.ravel(), g.tr.ravel(), -g.tx.ravel(), g.w.ravel()


@dataclass(frozen=True)
class AssemblyPlan:
    """The quadrature of each singular and nearly singular (target, panel) pair.

    Made from one panel set and reusable on any other of the same topology (the layouts of
    neighbouring depths in a difference in P): the rules then stay the same, so the
    computed potential is a smooth function of P.
    """

    self_rule: PairQuadrature
    near_rule: PairQuadrature
    # primary panels whose block (their nodes against themselves) is taken from an
    # AssemblyCache instead of being integrated: no rules for those pairs here
    fixed: np.ndarray | None = None


@functools.lru_cache(maxsize=64)
def _corner_levels(cluster: bytes, p: int):
    """The nodes on corner panels of the primary ``cluster`` (:attr:`PanelSet.cluster` as float64
    bytes) and the least levels of both sides of their self rules: the substitution is singular
    at the corner end, at (1 + u_q) from the node, and the innermost pieces stay within half of
    that.  Depends on the topology only, so kept per cluster (this project's own shortcut)."""
    c = np.repeat(np.frombuffer(cluster, dtype=float), p)
    mapped = np.nonzero(c != 0)[0]
    um = gauss_legendre(p)[0][mapped % p]
    gap = 0.5 * np.where(c[mapped] < 0, 1.0 + um, 1.0 - um)
    lev = _levels(np.concatenate([1.0 - um, 1.0 + um]), np.concatenate([gap, gap]))
    for a in (mapped, lev):
        a.setflags(write=False)
    return mapped, lev[:mapped.size], lev[mapped.size:]


def plan_assembly(ps: PanelSet, fixed: np.ndarray | None = None) -> AssemblyPlan:
    """Choose the self and near rules for the primary nodes of ``ps``.

    Self rules are graded towards the node where the target's image in the axis, (x, -r),
    is close to its own panel (the analytically continued kernels are singular there), so
    that the innermost piece stays IMAGE_MARGIN times shorter than the distance to it.

    ``fixed`` (a mask over the primary panels, from :meth:`AssemblyCache.match`): the pairs
    among those panels are not planned (their block is reused)."""
    p = ps.order
    X, R, _, _, _ = _flat_nodes(ps)
    N = ps.n_primary * p
    xt, rt = X[:N], R[:N]
    own_panel, uq = _node_grid(ps.n_primary, p)[:2]  # each node's panel and Gauss coordinate
    levels = np.zeros((N, 2), dtype=int)
    cx, cr = _centers(ps)
    if fixed is not None and not fixed.any():
        fixed = None
    free_node = np.ones(N, bool) if fixed is None else ~fixed[own_panel]
    close = np.nonzero(free_node & (np.hypot(xt - cx[own_panel], rt + cr[own_panel])
                                    < (IMAGE_MARGIN + 1) * ps.lengths[own_panel]))[0]
    block = None
    if fixed is not None:
        block = (~free_node, np.concatenate([fixed, np.zeros(ps.n_panels - ps.n_primary, bool)]))
    # the near pairs and the self pairs' axis images: one search of the nearest points
    tgt, pan, ustar, du, _, du_img = _near_pairs_with(ps, xt, rt, own_panel, block,
                                                      (own_panel[close], xt[close], -rt[close]))
    if close.size:  # both sides of the close nodes, in one call
        uc, d = uq[close], du_img / IMAGE_MARGIN
        levels[close] = _levels(np.concatenate([1.0 - uc, 1.0 + uc]), np.concatenate([d, d])).reshape(2, -1).T
    if ps.cluster is not None:  # nodes on corner panels
        mapped, right, left = _corner_levels(np.ascontiguousarray(ps.cluster[:ps.n_primary], dtype=float).tobytes(), p)
        if mapped.size:
            levels[mapped, 0] = np.maximum(levels[mapped, 0], right)
            levels[mapped, 1] = np.maximum(levels[mapped, 1], left)
    self_rule = self_quadrature(levels, p)
    if fixed is not None:
        self_rule = self_rule.subset(free_node[self_rule.target])
    return AssemblyPlan(self_rule, near_quadrature(tgt, pan, ustar, du, p), fixed)


@dataclass
class AssemblyCache:
    """The raw single- and double-layer block of the primary nodes against the primary
    panels of the last panel set assembled, kept to be reused (this project's own).

    At depths past the shoulder only the panels next to the free surface move in the body
    frame (the nose and the shank up to its last panels stay where they are), so their
    block is the same at every depth: :meth:`match` finds the panels whose nodes coincide
    with the cached ones, :func:`plan_assembly` plans only the other pairs and
    :func:`assemble` copies the block.  Entries then agree with a fresh assembly to
    round-off of the coordinates (1e-13 relative), and the two solves of a difference in P
    read the same copy, so the error cancels in phi'_P."""

    nodes: tuple | None = None  # x, r (n_primary, p) and the largest weight of each panel of the cached nodes
    S: np.ndarray | None = None  # (N, N) raw blocks (weights applied, before folding and the diagonal rule)
    D: np.ndarray | None = None

    @staticmethod
    def _signature(ps: PanelSet) -> tuple:
        """(x, r, w of the primary nodes (n_primary, p), max |x|, |r| over them, max |w| per panel),
        kept on the panel set: matched up to three times and stored once per depth."""
        got = ps.__dict__.get("_assembly_signature")
        if got is None:
            g = ps.nodes
            n = ps.n_primary
            x, r, w = g.x[:n], g.r[:n], g.w[:n]
            # np.maximum.reduce: ndarray.max without its Python wrappers (the same reduction)
            scale = max(float(_MAX(np.abs(x), axis=None, initial=0.0)), float(_MAX(np.abs(r), axis=None, initial=0.0)),
                        1e-300)
            got = (x, r, w, scale, _MAX(np.abs(w), axis=1, initial=0.0))
            ps.__dict__["_assembly_signature"] = got
        return got

    def match(self, ps: PanelSet) -> np.ndarray:
        """Mask over the primary panels of ``ps``: True where the panel of the same index in
        the cache has the same nodes (to 1e-13 of the body's size)."""
        out = np.zeros(ps.n_primary, bool)
        if self.nodes is None or self.nodes[0].shape[1] != ps.order:
            return out
        x, r, w, scale, wmax = self._signature(ps)
        ox, or_, ow = self.nodes[:3]
        n = min(len(x), len(ox))
        close = np.maximum(_MAX(np.abs(x[:n] - ox[:n]), axis=1), _MAX(np.abs(r[:n] - or_[:n]), axis=1)) <= 1e-13 * scale
        wclose = _MAX(np.abs(w[:n] - ow[:n]), axis=1) <= 1e-13 * wmax[:n]
        np.logical_and(close, wclose, out=out[:n])
        return out

    def store(self, ps: PanelSet, S: np.ndarray, D: np.ndarray, copy: bool = True) -> None:
        """Keep the primary block of S and D (``copy=False``: views, for a caller that no longer
        writes to S and D)."""
        N = ps.n_primary * ps.order
        self.nodes = self._signature(ps)
        self.S, self.D = (S[:, :N].copy(), D[:, :N].copy()) if copy else (S[:, :N], D[:, :N])


def _layers(X, R, x, r, nx, nr, delta=None):
    return single_double(X, R, x, r, nx, nr, delta)


def _layers_split(X, R, x, r, nx, nr, delta=None):
    with np.errstate(divide="ignore", invalid="ignore"):
        S, D, QS, QD = single_double_split(X, R, x, r, nx, nr, delta)
    return (S, QS), (D, QD)


# the kernels PairQuadrature.integrate runs compiled after the geometry: split form or not
_COMPILED_LAYERS = {_layers: False, _layers_split: True}


def assemble(ps: PanelSet, plan: AssemblyPlan | None = None, cache: AssemblyCache | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Matrices (Smat, Dmat) of the single and double layer at the primary nodes.

    With ``cache`` the block of the plan's fixed panels is copied from it, and the raw
    primary block of ``ps`` is stored in it for the next assembly.

    Columns of mirror nodes are already folded onto their images, so both are
    (N, N) with N = n_primary * p, and (**) reads (I/2 - Dmat) phi = -Smat g.
    """
    plan = plan or plan_assembly(ps)
    p = ps.order
    X, R, NX, NR, W = _flat_nodes(ps)
    N = ps.n_primary * p
    xt, rt = X[:N], R[:N]

    if plan.fixed is not None and cache is None:
        raise ValueError("a plan with fixed panels needs the AssemblyCache it was matched against")
    fix = None if plan.fixed is None else np.repeat(plan.fixed, p)
    mirrored = X.size > N
    # matrix 0: the primary nodes against the primary panels (the raw block the cache keeps);
    # matrix 1 (half-space): against the mirror panels, column j the image of primary node j,
    # i.e. already in the folded order of PanelSet.fold_mirror (no (N, 2N) matrices)
    SS, DD = np.empty((1 + mirrored, N, N)), np.empty((1 + mirrored, N, N))
    S, D = SS[0], DD[0]
    # the primary nodes against themselves (compiled: once per pair, the same numbers), then the
    # fixed panels' block from the cache
    _kernels.single_double_dense_sym(xt, rt, NX[:N], NR[:N], W[:N], S, D, fix, DENSE_CHUNK)
    if mirrored:  # the image of primary node j is mirror node 2N - 1 - j (PanelSet.fold_mirror)
        _kernels.single_double_dense_mirror(xt, rt, NX[:N], NR[:N], W[:N], X[:N - 1:-1], SS[1], DD[1], DENSE_CHUNK)
    if fix is not None:
        k = int(np.count_nonzero(fix))
        block = (slice(0, k),) * 2 if fix[:k].all() else np.ix_(*(np.nonzero(fix)[0],) * 2)  # slices when they lead
        S[block], D[block] = cache.S[block], cache.D[block]
    for rule, kernels in ((plan.self_rule, _layers_split), (plan.near_rule, _layers)):
        if rule.target.size:
            rule.integrate(ps, xt, rt, kernels, node_targets=True, into=(SS, DD, *rule._entries(p, N)))
    if cache is not None:
        cache.store(ps, S, D, copy=not mirrored)  # with a mirror, the primary block is not written again
    if mirrored:  # the folding (PanelSet.fold_mirror) in place: mirror block + primary block
        S, D = SS[1], DD[1]
        S += SS[0]
        D += DD[0]
    # the double layer of a constant is -1/2 on the closed surface (S + S'): putting each
    # row's quadrature error on the diagonal makes (I/2 - D) act on phi - phi_i only, so
    # that near a corner the error follows the local variation of phi, not phi itself
    # (without it, B drifts as graded panels shrink: |grad phi| ~ s^(lambda - 1))
    D.flat[:: N + 1] -= D.sum(axis=1) + 0.5  # the diagonal (D is (N, N), C-ordered)
    return S, D


@functools.cache
def _self_rule_table(p: int, lev_right: int, lev_left: int, n: int = N_SELF):
    """Self rules for the p nodes of a panel, graded dyadically towards the node.

    For node u_q, each side [u_q, end] of length h is cut into pieces
    [0, 2^-L h], [2^-L h, 2^-(L-1) h], ..., [h/2, h] (L = 0: one piece).  The innermost
    piece carries the log split (Gauss-Legendre nodes for the smooth part with weights w
    and wl = -ln(piece length) w, and -ln(s) Gauss nodes for the logarithm); the outer
    pieces integrate the full kernel.  Returns arrays indexed by q, and the Lagrange
    matrices of each node set.  The two sides are built once per level (:func:`_self_side`)
    and joined here.
    """
    right, left = _self_side(p, 1.0, lev_right, n), _self_side(p, -1.0, lev_left, n)
    table = {k: np.concatenate([right[k], left[k]], axis=1) for k in ("su", "sw", "swl", "lu", "lw", "fu", "fw")}
    order = [(side, k) for k in ("su", "lu", "fu") for side in (right, left)]  # points: su, lu, fu; right, left
    table["L"] = np.concatenate([side["L" + k] for side, k in order], axis=1)
    # the rows of each node's rule as :func:`_self_quadrature` sums them: split nodes
    # w (K + ln|u - u_q| Q) + wl Q, log nodes w Q, outer pieces w K
    su, sw, swl, lw, fw = (table[k] for k in ("su", "sw", "swl", "lw", "fw"))
    lnu = np.concatenate([right["lnu"], left["lnu"]], axis=1)
    table["u"] = np.concatenate([su, table["lu"], table["fu"]], axis=1)
    table["a"] = np.concatenate([sw, np.zeros_like(lw), fw], axis=1)
    table["b"] = np.concatenate([sw * lnu + swl, lw, np.zeros_like(fw)], axis=1)
    return table


@functools.cache
def _self_side(p: int, sign: float, lev: int, n: int):
    """One side of :func:`_self_rule_table` (sign +1: [u_q, 1], -1: [-1, u_q]) with ``lev``
    levels, for all p nodes at once: the points, weights, ln|u - u_q| at the split nodes and
    the Lagrange matrices of each node set."""
    uq_all, _ = gauss_legendre(p)
    g, gw = gauss_legendre(n)
    g01, gw01 = 0.5 * (g + 1.0), 0.5 * gw
    t01, tw01 = gauss_log(n)
    uq = uq_all[:, None]
    h = 1.0 - uq_all if sign > 0 else 1.0 + uq_all
    inner = (h * 2.0**-lev)[:, None]
    neglog = np.array([-math.log(v) for v in inner[:, 0]])[:, None]
    a = (h[:, None] * 2.0 ** -np.arange(lev, 0, -1.0))[:, :, None]  # outer pieces, innermost first
    side = {
        "su": uq + sign * inner * g01,
        "sw": inner * gw01,
        "swl": neglog * inner * gw01,
        "lu": uq + sign * inner * t01,
        "lw": inner * tw01,
        "fu": (uq[:, :, None] + sign * (a + a * g01)).reshape(p, -1),
        "fw": (a * gw01).reshape(p, -1),
    }
    for k in ("su", "lu", "fu"):
        side["L" + k] = lagrange_matrix(uq_all, side[k])
    side["lnu"] = np.log(np.abs(side["su"] - uq))
    return side


# ------------------------------------------------------------------------------------
# solution


@functools.cache
def _tip_row(order: int) -> np.ndarray:
    """The Lagrange basis of a panel's Gauss nodes at u = -1 (its first end)."""
    row = lagrange_matrix(gauss_legendre(order)[0], np.array([-1.0]))[0]
    row.setflags(write=False)
    return row


@dataclass(frozen=True)
class SurfaceNodes:
    """Surface data at the unknowns (primary surface only), flat arrays.

    weight: the surface element 2 pi r ds of each node's quadrature weight [m^2];
    g = dphi/dn (= -n_x on the projectile, 0 on shank and hole); grad2 = |grad phi|^2.
    """

    x: np.ndarray
    r: np.ndarray
    nx: np.ndarray
    nr: np.ndarray
    weight: np.ndarray
    phi: np.ndarray
    dphi_ds: np.ndarray
    g: np.ndarray

    @property
    def grad2(self) -> np.ndarray:
        return self.dphi_ds**2 + self.g**2

    @property
    def dphi_dx(self) -> np.ndarray:
        """x-derivative of phi on the surface: tangential plus normal parts (t_x = -n_r)."""
        return -self.dphi_ds * self.nr + self.g * self.nx


@dataclass(frozen=True)
class SurfaceSolution:
    """phi on a body (or on a penetrating nose and its free-surface image) and the field.

    ``kind`` is "body" (closed body in unbounded fluid) or "halfspace" (target x >= 0,
    tip at x = depth).  Unit speed: multiply phi by u(t) for Phi of Part I, eq. (5).
    """

    panels: PanelSet
    phi_nodes: np.ndarray  # (n_primary, p)
    g_nodes: np.ndarray  # (n_primary, p)
    kind: str
    depth: float | None = None
    volume: float | None = None

    @property
    def unknowns(self) -> int:
        return self.phi_nodes.size

    @cached_property
    def flat(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """x, r, nx, weight and phi of :attr:`nodes` (flat arrays), without the surface velocity:
        what the A of a solve and a difference in P read (this project's own shortcut: the two
        solves of a depth need no dphi/ds)."""
        ps = self.panels
        n = ps.n_primary
        g = ps.nodes
        return (g.x[:n].ravel() + ps.offset, g.r[:n].ravel(), g.tr[:n].ravel(), (2 * math.pi * g.r[:n] * g.w[:n]).ravel(),
                self.phi_nodes.ravel())

    @cached_property
    def nodes(self) -> SurfaceNodes:
        ps = self.panels
        n = ps.n_primary
        g = ps.nodes
        J = g.J[:n]
        dphi_ds = (self.phi_nodes @ differentiation_matrix(ps.order).T) / J
        if not (_ALL(np.isfinite(dphi_ds), axis=None) and _ALL(np.isfinite(self.phi_nodes), axis=None)):
            raise_non_finite(ps, self.depth, "surface velocity")
        x, r, nx, weight, phi = self.flat
        return SurfaceNodes(x=x, r=r, nx=nx, nr=-g.tx[:n].ravel(), weight=weight, phi=phi, dphi_ds=dphi_ds.ravel(),
                            g=self.g_nodes.ravel())

    @property
    def A(self) -> float:
        """A = integral of phi n_x dS over the (primary) surface: Part I, eq. (12) [m^3]."""
        _, _, nx, weight, phi = self.flat
        return float(_SUM(weight * phi * nx, axis=None))

    @property
    def C(self) -> float:
        """C = integral of n_x dS: Part I, eq. (12) [m^2] (the projected contact area)."""
        _, _, nx, weight, _ = self.flat
        return float(_SUM(weight * nx, axis=None))

    @property
    def added_mass_coefficient(self) -> float:
        """Added mass over rho V (closed bodies only)."""
        if self.volume is None:
            raise ValueError("added mass coefficient is defined for closed bodies")
        return self.A / self.volume

    @property
    def phi_tip(self) -> float:
        """phi at the front pole (the nose tip): the first panel's interpolant at u = -1."""
        return float(_tip_row(self.panels.order) @ self.phi_nodes[0])

    # --- field ------------------------------------------------------------------------

    @cached_property
    def _sources(self):
        """Densities on all panels (mirror images included): phi, g and dphi/ds."""
        ps = self.panels
        phi, g = self.phi_nodes, self.g_nodes
        if ps.n_panels > ps.n_primary:
            phi = np.concatenate([phi, phi[::-1, ::-1]])
            g = np.concatenate([g, g[::-1, ::-1]])
        omega = (phi @ differentiation_matrix(ps.order).T) / ps.nodes.J
        return phi, g, omega

    def _field(self, points, gradient: bool):
        pts = np.atleast_2d(np.asarray(points, dtype=float))
        if pts.shape[-1] != 2:
            raise ValueError("points must have shape (M, 2): (x, r)")
        xt, rt = pts[:, 0] - self.panels.offset, np.abs(pts[:, 1])
        ps = self.panels
        p = ps.order
        phi, g, omega = (a.ravel() for a in self._sources)
        X, R, NX, NR, W = _flat_nodes(ps)
        with np.errstate(divide="ignore", invalid="ignore"):
            if gradient:
                Sx, Sr, Wx, Wr = gradient_kernels(xt[:, None], rt[:, None], X[None, :], R[None, :])
                gx = (Wx * omega - Sx * g) * W
                gr = (Wr * omega - Sr * g) * W
            else:
                S, D = single_double(xt[:, None], rt[:, None], X[None, :], R[None, :], NX[None, :], NR[None, :])
                val = (D * phi - S * g) * W
        tgt, pan, ustar, du = near_pairs(ps, xt, rt)
        if tgt.size:
            rule = near_quadrature(tgt, pan, ustar, du, p)
            tgt, pan = rule.target, rule.panel  # in the rule's order
            cols = pan[:, None] * p + np.arange(p)[None, :]
            if gradient:
                bSx, bSr, bWx, bWr = rule.integrate(ps, xt, rt, lambda X, R, x, r, nx, nr, delta: gradient_kernels(X, R, x, r))
                gx[tgt[:, None], cols] = bWx * omega[cols] - bSx * g[cols]
                gr[tgt[:, None], cols] = bWr * omega[cols] - bSr * g[cols]
            else:
                bS, bD = rule.integrate(ps, xt, rt, _layers)
                val[tgt[:, None], cols] = bD * phi[cols] - bS * g[cols]
        if gradient:
            out = np.column_stack([gx.sum(axis=1), gr.sum(axis=1)])
            out[:, 1] *= np.sign(np.where(pts[:, 1] < 0, -1.0, 1.0))
            return out
        return val.sum(axis=1)

    def potential(self, points) -> np.ndarray:
        """phi at field points (M, 2) of (x, r) in the fluid (Part I, eq. (20) / (*))."""
        return self._field(points, gradient=False)

    def gradient(self, points) -> np.ndarray:
        """(dphi/dx, dphi/dr) at field points; the velocity is v = -u grad(phi): Part I, eqs. (8), (23)."""
        return self._field(points, gradient=True)


def solve_panels(
    ps: PanelSet,
    kind: str,
    *,
    depth: float | None = None,
    volume: float | None = None,
    neumann=None,
    plan: AssemblyPlan | None = None,
    cache: AssemblyCache | None = None,
) -> SurfaceSolution:
    """Assemble and solve (**).

    ``neumann(x, r, nx, nr) -> g`` gives dphi/dn at the primary nodes; the default is
    unit motion in +x, g = -n_x (Part I, eq. (7)).  ``plan`` reuses the quadrature rules
    of a panel set of the same topology.
    """
    S, D = assemble(ps, plan, cache)
    phi, g = solve_assembled(ps, S, D, neumann, depth, overwrite=True)  # D: a fresh matrix of assemble's
    return SurfaceSolution(ps, phi, g, kind, depth=depth, volume=volume)


def solve_assembled(ps: PanelSet, S: np.ndarray, D: np.ndarray, neumann=None, depth: float | None = None,
                    overwrite: bool = False):
    """The boundary-integral equation (1/2 - D) phi = -S g of Part I, eq. (21) on assembled
    single- and double-layer matrices (the half-space's and the plate's, bem/slab.py): the Neumann
    data g at the primary nodes (default g = -n_x, unit motion in +x, Part I eq. (7)) and the
    solution, both shaped (n_primary, order).  A non-finite solution raises ModelError.
    ``overwrite``: D (C-ordered) may be overwritten (no (N, N) temporary)."""
    geo = ps.nodes
    n = ps.n_primary
    if neumann is None:
        g = -geo.tr[:n].ravel()
    else:
        x = geo.x[:n].ravel() + ps.offset
        g = np.asarray(neumann(x, geo.r[:n].ravel(), geo.tr[:n].ravel(), -geo.tx[:n].ravel()), dtype=float)
    A = np.negative(D, out=D) if overwrite and D.flags.c_contiguous else np.negative(D, order="C")
    A.reshape(-1)[:: A.shape[0] + 1] += 0.5  # I/2 - D, without an identity matrix (a view: A is C-ordered)
    with _single_threaded_blas():
        phi = _dense_solve(A, S @ -g)  # -S g, the same numbers (negation is exact) without -S
    if phi is None or not _ALL(np.isfinite(phi), axis=None):
        raise_non_finite(ps, depth)
    shape = (ps.n_primary, ps.order)
    return phi.reshape(shape), g.reshape(shape)


def _dense_solve(A: np.ndarray, b: np.ndarray) -> np.ndarray | None:
    """x with A x = b by LAPACK's dgesv (LU with partial pivoting), or None when A is exactly
    singular.  The same factorisation as ``scipy.linalg.solve`` without its condition estimate
    and checks, half its cost at the tables' sizes (N = 100: 57 against 116 us)."""
    _, _, x, info = scipy.linalg.lapack.dgesv(A, b, overwrite_a=True, overwrite_b=True)
    return None if info > 0 else x


def raise_non_finite(ps: PanelSet, depth: float | None, what: str = "potential"):
    """Never a silent NaN: a solve that yields a non-finite value stops with the shape and
    the depth named (exit status 2: the geometry is the input the solver could not handle)."""
    where = f" at depth P = {depth * 1e3:.6g} mm" if depth is not None else ""
    field = "projectile" if ps.label.endswith("nose") else "body"
    raise ModelError(f"the BEM solve of the {ps.label}{where} gave a non-finite {what}; "
                     "check the shape (points, radii) or the [bem] options", field)
