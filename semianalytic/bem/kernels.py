"""Ring kernels of the axisymmetric Laplace problem (Part I, section 1.4, eqs. (20)-(23)).

A source ring of radius r1 at axial position x1 acts on a target (x, r).  With

    d^2 = (x - x1)^2 + (r - r1)^2,   D = (x - x1)^2 + (r + r1)^2,
    a = (x - x1)^2 + r^2 + r1^2,     m = 4 r r1 / D,   1 - m = d^2 / D,

the azimuthal integrals of the free-space Green function G = 1/(4 pi R) and of its
derivatives reduce to the complete elliptic integrals K(m), E(m) (the paper's a, b = 2 r r1
and m = 2b/(a + b); errata items 1 and 1a).  The parameter 1 - m is formed directly from
the geometry (numerical notes) and K, E are evaluated as functions of it (``ellip_ke``).

Every kernel here includes the ring circumference factor r1 (it is the integral over the
ring per unit meridian arc length); multiply by the arc-length element ds1.

Near the singular point the kernels are split as ``K = regular + L Q`` with
L = -ln(1 - m)/2, using K(m) = K_reg + L (2/pi) K(1 - m) and
E(m) = E_reg + L (2/pi) (K(1 - m) - E(1 - m)) (numerical notes).  ``Q`` is returned
so that quadrature can integrate the logarithm exactly.  K(1 - m) and E(1 - m) are taken
as their power series in 1 - m truncated after ``SPLIT_TERMS`` terms: the remainder
multiplies L by (1 - m)^SPLIT_TERMS, which is smooth, while the full K(1 - m) would put a
spurious singularity on the axis (where 1 - m -> 1) into both parts of the split.

:func:`single_double`, :func:`single_double_split` and the dense blocks of the assembly
(:func:`single_double_dense`, and once per pair :func:`single_double_dense_sym` against the
surface itself and :func:`single_double_dense_mirror` against its mirror image) run compiled
from ``_ring.c`` (the same polynomials, passed from here, and the same formulas; compiled when
the package is built or installed, setup.py, and loaded from the package folder by
:mod:`semianalytic.native`: nothing is compiled at run time) when that library is there, else, or
with ``SEMIANALYTIC_KERNEL=numpy``, as the numpy code of this module (this project's own speed-up;
the two agree to a few units of 1e-16; CI runs the whole suite on each, docs/packaging.md).  The same library, under the same
dispatch, sums the near and self rules of the assembly after the panel geometry
(:func:`pair_rules_compiled`) and evaluates the geometry of panels on lines, arcs and a table
nose's cubic spline (``PanelSet.evaluate``, ``relative``).
"""

from __future__ import annotations

import ctypes
import functools
import math
import os
from pathlib import Path

import numpy as np
from scipy.special import ellipe, ellipk

from semianalytic.native import address, load_library

# Complete elliptic integrals as functions of the complementary parameter q = 1 - m,
# K = P_K(q) - ln(q) Q_K(q), E = P_E(q) - ln(q) q Q_E(q): the Cephes approximations
# (S. L. Moshier; the same as scipy.special.ellipkm1 / ellipe, accurate to ~1e-16 on
# [0, 1]).  Evaluating them here shares ln(q) between K and E and takes q directly.
_PK = np.array([1.37982864606273237150e-4, 2.28025724005875567385e-3, 7.97404013220415179367e-3,
                9.85821379021226008714e-3, 6.87489687449949877925e-3, 6.18901033637687613229e-3,
                8.79078273952743772254e-3, 1.49380448916805252718e-2, 3.08851465246711995998e-2,
                9.65735902811690126535e-2, 1.38629436111989062502e0])
_QK = np.array([2.94078955048598507511e-5, 9.14184723865917226571e-4, 5.94058303753167793257e-3,
                1.54850516649762399335e-2, 2.39089602715924892727e-2, 3.01204715227604046988e-2,
                3.73774314173823228969e-2, 4.88280347570998239232e-2, 7.03124996963957469739e-2,
                1.24999999999870820058e-1, 4.99999999999999999821e-1])
_PE = np.array([1.53552577301013293365e-4, 2.50888492163602060990e-3, 8.68786816565889628429e-3,
                1.07350949056076193403e-2, 7.77395492516787092951e-3, 7.58395289413514708519e-3,
                1.15688436810574127319e-2, 2.18317996015557253103e-2, 5.68051945617860553470e-2,
                4.43147180560990850618e-1, 1.00000000000000000299e0])
_QE = np.array([3.27954898576485872656e-5, 1.00962792679356715133e-3, 6.50609489976927491433e-3,
                1.68862163993311317300e-2, 2.61769742454493659583e-2, 3.34833904888224918614e-2,
                4.27180926518931511717e-2, 5.85936634471101055642e-2, 9.37499997197644278445e-2,
                2.49999999999888314361e-1])


def _polevl(x, coef):
    """sum coef[k] x^(n-k) (highest power first), Horner's scheme in place."""
    out = np.full_like(x, coef[0])
    for c in coef[1:]:
        out *= x
        out += c
    return out


def _powers(q, n: int = 11) -> np.ndarray:
    """Rows q^0 .. q^(n-1) (shape (n,) + q.shape): every polynomial of the kernels in q is then
    one matrix product (all coefficients positive and q in [0, 1]: the power sum is as accurate
    as Horner's scheme, and one BLAS call replaces two array passes per coefficient)."""
    q = np.asarray(q, dtype=float)
    V = np.empty((n,) + q.shape)
    V[0] = 1.0
    V[1] = q
    for k in range(2, n):
        np.multiply(V[k - 1 : k], q, out=V[k : k + 1])
    return V


def _poly_matrix(*polys) -> np.ndarray:
    """Coefficient matrix (11, len(polys)) of polynomials given highest power first."""
    M = np.zeros((11, len(polys)))
    for j, c in enumerate(polys):
        M[: len(c), j] = np.asarray(c)[::-1]
    return M


_KE_MATRIX = _poly_matrix(_PK, _QK, _PE, _QE)


def _ke_from_powers(q, V, lnq, matrix=_KE_MATRIX):
    """K(1 - q), E(1 - q) and the values of any further polynomials in ``matrix`` (columns 4 on)."""
    M = np.tensordot(matrix.T, V, axes=1)
    K = M[0] - lnq * M[1]
    E = M[2] - lnq * q * M[3]
    return K, E, M[4:]


def ellip_ke(q):
    """K(1 - q) and E(1 - q) for the complementary parameter q in [0, 1]."""
    q = np.asarray(q, dtype=float)
    K, E, _ = _ke_from_powers(q, _powers(q), np.log(q))
    return K, E

_TWO_OVER_PI = 2.0 / math.pi


def _geometry(x, r, x1, r1, delta=None):
    """(x - x1, r - r1, d^2, D); ``delta`` gives the two differences directly when they
    are known more accurately than by subtracting coordinates (points on one panel)."""
    dx, dr = (x - x1, r - r1) if delta is None else delta
    d2 = dx * dx + dr * dr
    D = dx * dx + (r + r1) ** 2
    return dx, dr, d2, D


def _single_double_numpy(x, r, x1, r1, nx1, nr1, delta=None):
    """Single-layer and double-layer ring kernels (Part I, eqs. (20)-(22); errata items 1, 1a).

    S = integral over the ring of G r1 dtheta = r1 K(m) / (pi sqrt(D)),
    Dl = integral of dG/dn1 r1 dtheta with n1 = (nx1, nr1) the normal at the source
       = [E(m) (r1 (x - y).n1 + nr1 d^2/2) / d^2 - nr1 K(m)/2] / (pi sqrt(D)).
    The second form has no 1/r factor, so targets on the axis are fine.  Near the source
    (x - y).n1 is of order d^2: with coordinates of size P it must come from accurate
    differences (``delta``), or the double layer loses digits.
    """
    dx, dr, d2, D = _geometry(x, r, x1, r1, delta)
    m1 = d2 / D
    K, E = ellip_ke(m1)
    inv = 1.0 / (math.pi * np.sqrt(D))
    bracket = r1 * (dx * nx1 + dr * nr1) + 0.5 * nr1 * d2
    S = r1 * K * inv
    Dl = (E * bracket / d2 - 0.5 * nr1 * K) * inv
    return S, Dl


SPLIT_TERMS = 10
_C2 = np.array([(math.comb(2 * n, n) / 4**n) ** 2 for n in range(SPLIT_TERMS)])
_K_SERIES = (math.pi / 2) * _C2  # K(q) = (pi/2) sum c_n^2 q^n
_KME_Q_SERIES = (math.pi / 2) * _C2 * np.array([2 * n / (2 * n - 1) for n in range(SPLIT_TERMS)])  # K - E


_SPLIT_MATRIX = _poly_matrix(_PK, _QK, _PE, _QE, _K_SERIES[::-1], _KME_Q_SERIES[::-1])


def _single_double_split_numpy(x, r, x1, r1, nx1, nr1, delta=None):
    """As :func:`single_double`, plus the coefficients QS, QD of L = -ln(1 - m)/2."""
    dx, dr, d2, D = _geometry(x, r, x1, r1, delta)
    m1 = d2 / D
    # K(1 - m) and K(1 - m) - E(1 - m), truncated, from the same powers of 1 - m as K and E
    K, E, (Kc, KcmEc) = _ke_from_powers(m1, _powers(m1), np.log(m1), _SPLIT_MATRIX)
    inv = 1.0 / (math.pi * np.sqrt(D))
    bracket_over_d2 = (r1 * (dx * nx1 + dr * nr1) + 0.5 * nr1 * d2) / d2
    S = r1 * K * inv
    Dl = (E * bracket_over_d2 - 0.5 * nr1 * K) * inv
    QS = r1 * _TWO_OVER_PI * Kc * inv
    QD = _TWO_OVER_PI * (KcmEc * bracket_over_d2 - 0.5 * nr1 * Kc) * inv
    return S, Dl, QS, QD


# ------------------------------------------------------------------------------------
# the compiled kernels (_ring.c) and the dispatch between them and the numpy code above

KERNEL_ENV = "SEMIANALYTIC_KERNEL"  # "numpy": the numpy kernels even where the C ones would load
_SOURCE = Path(__file__).with_name("_ring.c")
_P = ctypes.c_void_p
_N = ctypes.c_ssize_t


@functools.cache
def compiled():
    """The compiled ring kernels (ctypes library), or None: ``$SEMIANALYTIC_KERNEL=numpy``, or no
    library built from this ``_ring.c`` in the package folder (:func:`semianalytic.native.load_library`)."""
    if os.environ.get(KERNEL_ENV, "").strip().lower() == "numpy":
        return None
    lib = load_library(_SOURCE)
    if lib is None:
        return None
    try:
        return configured(lib)
    except AttributeError as exc:  # a library without one of the kernels: not this _ring.c
        import warnings

        warnings.warn(f"the compiled ring kernels lack a function ({exc}); the numpy kernels are used",
                      RuntimeWarning, stacklevel=2)
        return None


def configured(lib):
    """The ctypes library ``lib`` of ``_ring.c`` with its functions' argument types declared and
    its polynomials filled (a build with other flags goes through here too: the tests)."""
    lib.ring_set_coefficients.argtypes = [_P] * 6
    lib.ring_set_coefficients.restype = None
    lib.ring_single_double.argtypes = [_N] + [_P] * 10
    lib.ring_single_double.restype = None
    lib.ring_single_double_split.argtypes = [_N] + [_P] * 12
    lib.ring_single_double_split.restype = None
    lib.ring_dense.argtypes = [_N, _P, _P, _N] + [_P] * 7
    lib.ring_dense.restype = None
    lib.ring_dense_sym.argtypes = [_N] + [_P] * 5 + [_N, _P, _P, _P]
    lib.ring_dense_sym.restype = None
    lib.ring_dense_mirror_sym.argtypes = [_N] + [_P] * 6 + [_N, _P, _P]
    lib.ring_dense_mirror_sym.restype = None
    lib.ring_pair_rules.argtypes = [_N] + [_P] * 13 + [_N, _P, _P, _P, _N, _P, _P, _P, _P, _P, _P, _N, _P, _N, _P, _P, _P]
    lib.ring_pair_rules.restype = None
    lib.ring_panel_points.argtypes = [_N] + [_P] * 9 + [ctypes.c_double] + [_P] * 5 + [_N] + [_P] * 11
    lib.ring_panel_points.restype = None
    lib.ring_panel_relative.argtypes = [_N] + [_P] * 13 + [_N] + [_P] * 3 + [_P, _P]
    lib.ring_panel_relative.restype = None
    lib.ring_panel_second.argtypes = [_N] + [_P] * 9 + [ctypes.c_double] + [_P] * 5 + [_N] + [_P] * 10
    lib.ring_panel_second.restype = None
    lib.ring_newton_step.argtypes = [_N] + [_P] * 11 + [ctypes.c_double] + [_P] * 5 + [_N] + [_P] * 8
    lib.ring_newton_step.restype = None
    lib.ring_closest_points.argtypes = [_N, _P, _P, _P, _N] + [_P] * 12 + [ctypes.c_double] + [_P] * 5 + [_N] + [_P] * 9
    lib.ring_closest_points.restype = None
    if len(_K_SERIES) != 10 or len(_PK) != 11 or len(_QE) != 10:  # the sizes _ring.c is written for
        raise AssertionError("kernels.py and _ring.c disagree on the polynomials' sizes")
    coefs = [np.ascontiguousarray(a, dtype=float) for a in (_PK, _QK, _PE, _QE, _K_SERIES, _KME_Q_SERIES)]
    lib.ring_set_coefficients(*(address(a) for a in coefs))  # copied by the library
    return lib


def backend() -> str:
    """"c" when the compiled kernels are in use, else "numpy"."""
    return "numpy" if compiled() is None else "c"


def _flat_inputs(x, r, x1, r1, nx1, nr1, delta):
    """The inputs broadcast together, as contiguous float64 arrays (copies only where needed),
    and their common shape; ``delta`` a pair of such arrays or None."""
    args = (x, r, x1, r1, nx1, nr1) + (() if delta is None else tuple(delta))
    arrays = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in args))
    shape = arrays[0].shape
    flat = [np.ascontiguousarray(a).reshape(-1) for a in arrays]
    ptrs = [address(a) for a in flat] + ([None, None] if delta is None else [])
    return shape, flat, ptrs


def single_double(x, r, x1, r1, nx1, nr1, delta=None):
    """Single-layer and double-layer ring kernels (Part I, eqs. (20)-(22); errata items 1, 1a):
    :func:`_single_double_numpy` (formulas there), compiled (``_ring.c``) when available."""
    lib = compiled()
    if lib is None:
        return _single_double_numpy(x, r, x1, r1, nx1, nr1, delta)
    shape, keep, ptrs = _flat_inputs(x, r, x1, r1, nx1, nr1, delta)
    S, Dl = np.empty(shape), np.empty(shape)
    lib.ring_single_double(S.size, *ptrs, address(S), address(Dl))
    return S, Dl


def single_double_split(x, r, x1, r1, nx1, nr1, delta=None):
    """As :func:`single_double`, plus the coefficients QS, QD of L = -ln(1 - m)/2
    (:func:`_single_double_split_numpy`, compiled when available)."""
    lib = compiled()
    if lib is None:
        return _single_double_split_numpy(x, r, x1, r1, nx1, nr1, delta)
    shape, keep, ptrs = _flat_inputs(x, r, x1, r1, nx1, nr1, delta)
    out = [np.empty(shape) for _ in range(4)]
    lib.ring_single_double_split(out[0].size, *ptrs, *(address(a) for a in out))
    return tuple(out)


def single_double_dense(xr, rr, xc, rc, nxc, nrc, wc, chunk: int = 12288):
    """S[i, j] w[j] and Dl[i, j] w[j] of :func:`single_double` for the targets (xr, rr)[i] against
    the source rings (xc, rc, normal (nxc, nrc), weight wc)[j]: the plain dense block (Part I,
    eqs. (20)-(22)), the reference of :func:`single_double_dense_sym` and
    :func:`single_double_dense_mirror`.  Compiled: one fused pass writing the two (rows, cols)
    arrays; numpy: blocks of about ``chunk`` entries, so that the temporaries stay small."""
    xr, rr, xc, rc, nxc, nrc, wc = (np.ascontiguousarray(a, dtype=float).reshape(-1) for a in (xr, rr, xc, rc, nxc, nrc, wc))
    lib = compiled()
    S, Dl = np.empty((xr.size, xc.size)), np.empty((xr.size, xc.size))
    if lib is not None:
        lib.ring_dense(xr.size, address(xr), address(rr), xc.size,
                       *(address(a) for a in (xc, rc, nxc, nrc, wc)), address(S), address(Dl))
        return S, Dl
    step = max(1, chunk // max(xc.size, 1))
    for a in range(0, xr.size, step):
        with np.errstate(divide="ignore", invalid="ignore"):
            S[a:a + step], Dl[a:a + step] = _single_double_numpy(xr[a:a + step, None], rr[a:a + step, None], xc, rc, nxc, nrc)
    S *= wc
    Dl *= wc
    return S, Dl


def single_double_dense_sym(x, r, nx, nr, w, S, D, skip=None, chunk: int = 12288) -> None:
    """The dense block of the nodes (x, r) (normals (nx, nr), weights w) against themselves, written into
    the first n columns of the C-contiguous (n, ld) arrays S and D: S[i, j] w[j] and Dl[i, j] w[j] of
    :func:`single_double` (Part I, eqs. (20)-(22)), the same numbers as :func:`single_double_dense`.
    Compiled, the elliptic integrals are evaluated once per pair {i, j} (their modulus is symmetric:
    this project's own shortcut); numpy: :func:`single_double_dense` on the rows.  ``skip`` (a mask over
    the nodes, or None): pairs of two masked nodes are left unwritten (the caller copies them from a cache)."""
    x, r, nx, nr, w = (np.ascontiguousarray(a, dtype=float).reshape(-1) for a in (x, r, nx, nr, w))
    n = x.size
    if not (S.flags.c_contiguous and D.flags.c_contiguous and S.shape == D.shape and S.shape[0] == n
            and S.shape[1] >= n and S.dtype == D.dtype == np.float64) or any(a.size != n for a in (r, nx, nr, w)):
        raise ValueError("single_double_dense_sym: arrays of inconsistent shapes")
    mask = None if skip is None else np.ascontiguousarray(skip, dtype=np.uint8)
    if mask is not None and mask.size != n:
        raise ValueError("single_double_dense_sym: skip must have one entry per node")
    lib = compiled()
    if lib is not None:
        lib.ring_dense_sym(n, *(address(a) for a in (x, r, nx, nr, w)), S.shape[1], address(mask), address(S),
                           address(D))
        return
    free = np.ones(n, bool) if mask is None else mask == 0
    rows, kept = np.nonzero(free)[0], np.nonzero(~free)[0]
    if rows.size:  # the free rows against every node, then the masked rows against the free nodes
        S[rows, :n], D[rows, :n] = single_double_dense(x[rows], r[rows], x, r, nx, nr, w, chunk)
        if kept.size:
            cols = np.ix_(kept, rows)
            S[cols], D[cols] = single_double_dense(x[kept], r[kept], x[rows], r[rows], nx[rows], nr[rows], w[rows], chunk)


def single_double_dense_mirror(x, r, nx, nr, w, xs, S, D, chunk: int = 12288) -> None:
    """The dense block of the nodes (x, r) against the images of the same nodes in the free surface (the
    mirror surface S' of a half-space, Part I, eqs. (21)-(22): the image of node j at x = xs[j], the same
    r and weight, the normal (-nx, nr)), column j the image of node j, written into the C-contiguous
    (n, n) arrays S and D: S[i, j] w[j] and Dl[i, j] w[j] of :func:`single_double` (Part I, eqs. (20)-(22)).

    The modulus of the elliptic integrals is symmetric in the pair: x_i - xs[j] and x_j - xs[i] are the
    same distance to round-off, and r_i - r_j only changes sign.  So every pair {i, j} takes its axial
    difference as dx[i, j] = dx[j, i] = x[min(i, j)] - xs[max(i, j)] (the source radius, normal and weight
    stay each column's own), and compiled (``ring_dense_mirror_sym``) q, ln q, K, E and 1/(pi sqrt D) are
    evaluated once per pair (this project's own shortcut); numpy: :func:`_single_double_numpy` on row
    blocks of about ``chunk`` entries with the same differences.  The difference is formed from the image
    coordinates, not as x_i + x_j - 2 x_surface: next to the free surface both subtractions are exact
    (Sterbenz), where the sum x_i + x_j would be rounded at the size of the depth first."""
    x, r, nx, nr, w, xs = (np.ascontiguousarray(a, dtype=float).reshape(-1) for a in (x, r, nx, nr, w, xs))
    n = x.size
    if not (S.flags.c_contiguous and D.flags.c_contiguous and S.shape == D.shape == (n, n)
            and S.dtype == D.dtype == np.float64) or any(a.size != n for a in (r, nx, nr, w, xs)):
        raise ValueError("single_double_dense_mirror: arrays of inconsistent shapes")
    lib = compiled()
    if lib is not None:
        if n:
            lib.ring_dense_mirror_sym(n, *(address(a) for a in (x, r, nx, nr, w, xs)), n, address(S), address(D))
        return
    step = max(1, chunk // max(n, 1))
    cols = np.arange(n)
    for a in range(0, n, step):
        rows = slice(a, a + step)
        upper = cols >= cols[rows, None]  # j >= i: dx of the pair from (i, j*), else from (j, i*)
        dx = np.where(upper, x[rows, None] - xs, x - xs[rows, None])
        with np.errstate(divide="ignore", invalid="ignore"):
            S[rows], D[rows] = _single_double_numpy(x[rows, None], r[rows, None], xs, r, -nx, nr,
                                                    (dx, r[rows, None] - r))
    S *= w
    D *= w


def _c_array(a, dtype=float):
    return np.ascontiguousarray(a, dtype=dtype)


def pair_rules_compiled(index, x, r, xu, ru, tgt, xt, rt, delta, a, b, pair, blocks, npairs: int, tiny=None):
    """The near and self rules' sums after the panel geometry, compiled (``ring_pair_rules`` of
    ``_ring.c``; the kernels of Part I, eqs. (20)-(22)), or None without the compiled kernels.

    Point k: source x, r and derivative xu, ru d/du (entry ``index[k]`` of these arrays, or k
    when ``index`` is None), Jacobian J = |(xu, ru)|, normal (ru, -xu)/J, target
    (xt, rt)[tgt[k]] (``delta``: the differences target - source given), rule weights a (and b,
    the logarithm's, for the split kernels of :func:`single_double_split`; None: the plain
    kernels); its weighted kernels (a S + b QS) J, (a Dl + b QD) J are summed against its
    Lagrange row into row ``pair[k]`` of the two (npairs, p) blocks returned.  ``blocks`` is
    (starts, q, addresses, p, keep): block i holds the points starts[i] .. starts[i + 1] - 1,
    its rows (C-contiguous float64 (., p) arrays kept alive by ``keep``) at addresses[i],
    consecutive (q[i] = 0) or repeating every q[i] points.  ``tiny`` (or None): (mask over the
    points, the points' split (anchor x, anchor r, offset x, offset r) indexed like x, the
    targets' split indexed like xt): the masked points take their differences as
    (anchor - anchor) + (offset - offset) (the numpy path:
    :meth:`semianalytic.bem.solve.PairQuadrature.integrate`).

    :func:`pair_rules_prepare` and :func:`pair_rules_run` are its two halves: a rule that runs
    many times converts and checks its own arrays once (this project's own speed-up)."""
    rule = pair_rules_prepare(index, tgt, a, b, pair, blocks, npairs)
    return None if rule is None else pair_rules_run(rule, x, r, xu, ru, xt, rt, delta, tiny)


def pair_rules_prepare(index, tgt, a, b, pair, blocks, npairs: int):
    """The per-rule arguments of :func:`pair_rules_compiled` (everything but the geometry, the
    targets and ``tiny``) converted, checked and their addresses taken, for
    :func:`pair_rules_run`; None without the compiled kernels."""
    if compiled() is None:
        return None
    starts, q, addresses, p, keep_rows = blocks
    a = _c_array(a)
    tgt, pair = (_c_array(v, np.intp) for v in (tgt, pair))
    index = None if index is None else _c_array(index, np.intp)
    b = None if b is None else _c_array(b)
    starts, q, addresses = _c_array(starts, np.intp), _c_array(q, np.intp), _c_array(addresses, np.uintp)
    n = tgt.size
    if any(v is not None and v.size != n for v in (a, b, pair, index)) or starts[-1] != n:
        raise ValueError("pair_rules_compiled: per-point arrays of different lengths")
    keep = (a, b, tgt, pair, index, starts, q, addresses, keep_rows)
    need = (int(index.max()) + 1 if index is not None and n else n, int(tgt.max()) + 1 if n else 0)
    ptrs = (address(index), address(tgt), address(a), address(b), address(pair), q.size, address(starts),
            address(q), address(addresses), p)
    return n, npairs, p, need, ptrs, keep


def pair_rules_run(rule, x, r, xu, ru, xt, rt, delta, tiny=None, into=None):
    """:func:`pair_rules_compiled` with the per-rule arguments from :func:`pair_rules_prepare`.

    ``into`` (or None): (S_all, D_all, flat, bound), C-contiguous float64 arrays, the intp flat
    indices (n_pairs * p of them) and one past their largest (worked out once per rule): the
    blocks' entries are also written there, as ``S_all.put(flat, S)`` would (in the same call)."""
    lib = compiled()
    n, npairs, p, (nsrc, ntgt), (p_index, p_tgt, p_a, p_b, p_pair, nblk, p_starts, p_q, p_addr, _), _ = rule
    x, r, xu, ru, xt, rt = (_c_array(v) for v in (x, r, xu, ru, xt, rt))
    if x.size < nsrc or r.size < nsrc or xu.size < nsrc or ru.size < nsrc or xt.size < ntgt or rt.size < ntgt:
        raise ValueError("pair_rules_compiled: geometry arrays shorter than the rule's indices")
    ddx, ddr = (None, None) if delta is None else (_c_array(v) for v in delta)
    if ddx is not None and (ddx.size != n or ddr.size != n):
        raise ValueError("pair_rules_compiled: per-point arrays of different lengths")
    # with an index: the Jacobians and normals of the x.size distinct points once (3 x.size more)
    ngeo = min(xu.size, ru.size) if p_index is not None else 0
    SD, work = np.zeros((2, npairs, p)), np.empty(2 * n + 3 * ngeo)  # S and D: one block, one address
    S, D = SD[0], SD[1]
    ptr = address
    mask = psplit = tsplit = None
    if tiny is not None:
        mask = _c_array(tiny[0], np.uint8)
        ps_, ts_ = [_c_array(v) for v in tiny[1]], [_c_array(v) for v in tiny[2]]
        if mask.size != n or len(ps_) != 4 or len(ts_) != 4 or any(v.size != x.size for v in ps_) \
                or any(v.size < xt.size for v in ts_):
            raise ValueError("pair_rules_compiled: split arrays of the wrong lengths")
        psplit, tsplit = (np.array([address(v) for v in vs], dtype=np.uintp) for vs in (ps_, ts_))
    at = address(SD)
    flat = p_flat = p_into = None
    if into is not None:
        S_all, D_all, flat, bound = into
        if flat.dtype != np.intp or not flat.flags.c_contiguous or flat.size != S.size or bound > S_all.size \
                or S_all.size != D_all.size or any(v.dtype != np.float64 or not v.flags.c_contiguous for v in (S_all, D_all)):
            raise ValueError("pair_rules_compiled: into arrays of the wrong type or length")
        p_flat, p_into = address(flat), (address(S_all), address(D_all))
    lib.ring_pair_rules(n, p_index, ptr(x), ptr(r), ptr(xu), ptr(ru), p_tgt, ptr(xt), ptr(rt), ptr(ddx), ptr(ddr),
                        p_a, p_b, p_pair, nblk, p_starts, p_q, p_addr, p, ptr(work), at, at + S.nbytes,
                        ptr(mask), ptr(psplit), ptr(tsplit), ngeo, address(work[2 * n:]) if ngeo else None,
                        S.size, p_flat, *(p_into or (None, None)))
    return S, D


# Series of (K(m) - E(m))/m = (pi/2) sum_n c_n^2 2n/(2n - 1) m^(n-1), c_n = (2n)!/(4^n n!^2)
_KME_SERIES = np.array(
    [
        (math.pi / 2) * (math.comb(2 * n, n) / 4**n) ** 2 * (2 * n) / (2 * n - 1)
        for n in range(1, 14)
    ]
)


def k_minus_e_over_m(m):
    """(K(m) - E(m))/m without cancellation for small m (series below m = 0.05)."""
    m = np.asarray(m, dtype=float)
    small = m < 0.05
    out = np.empty_like(m)
    out[small] = _polevl(m[small], _KME_SERIES[::-1])
    mb = m[~small]
    out[~small] = (ellipk(mb) - ellipe(mb)) / mb
    return out


def gradient_kernels(x, r, x1, r1):
    """Gradients at the target (x, r) of the single layer and of a vortex ring (Part I, eq. (23)).

    Returns (Sx, Sr, Wx, Wr):

    - (Sx, Sr) = grad of S (:func:`single_double`): Part I, eq. (23) up to the factor -u and
      the density, in the cancellation-free form
      Sr = -(r1/(pi sqrt D)) [(r - r1) E/d^2 + (K - E)/(2 r)];
    - (Wx, Wr) = grad of the double layer of a density with unit arc-length derivative:
      grad W[phi] = integral grad G x (n x grad_s phi) dS, which for an axisymmetric
      density is an azimuthal vortex sheet of strength dphi/ds (Stokes' theorem on the
      closed surface), so that only 1/R^2 kernels appear.
    """
    dx, _, d2, D = _geometry(x, r, x1, r1)
    m1 = d2 / D
    m = 4.0 * r * r1 / D
    K, E = ellip_ke(m1)
    h = k_minus_e_over_m(m)  # (K - E)/m
    sD = np.sqrt(D)
    E_d2 = E / d2
    Sx = -dx * r1 * E_d2 / (math.pi * sD)
    Sr = -(r1 / (math.pi * sD)) * ((r - r1) * E_d2 + h * 2.0 * r1 / D)
    KmE = h * m
    Wx = -(1.0 / (2 * math.pi * sD)) * (2.0 * r1 * (r - r1) * E_d2 - KmE)
    Wr = (dx / (2 * math.pi * sD)) * (2.0 * r1 * E_d2 - h * 4.0 * r1 / D)
    return Sx, Sr, Wx, Wr
