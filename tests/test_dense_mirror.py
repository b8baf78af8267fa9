"""The half-space's mirror block once per pair (ring_dense_mirror_sym of _ring.c,
kernels.single_double_dense_mirror) and the assembly that writes it in folded order (issue 24).

References: the plain dense block of the image nodes (ring_dense, or the numpy formulas of
_single_double_numpy), and the previous assembly path (the primary nodes against all 2N nodes
by the plain dense block, the rules written into the (N, 2N) matrices, PanelSet.fold_mirror),
rebuilt here from those pieces."""

from __future__ import annotations

import numpy as np
import pytest

from semianalytic.bem import kernels
from semianalytic.bem.panels import LayoutOptions, halfspace_layout
from semianalytic.bem.solve import _flat_nodes, _layers, _layers_split, assemble, plan_assembly
from semianalytic.commands.coefficients.study import study_nose

needs_c = pytest.mark.skipif(kernels.compiled() is None, reason="no compiled kernels (built without a C compiler, or SEMIANALYTIC_KERNEL=numpy): the numpy kernels only")  # noqa: E501

SHIFT = 0.5  # images in the plane x = -0.25: x* = -x - 0.5


def _nodes(n, seed, reverse=False):
    """Nodes below the plane x = -0.25 (x in [-1, -0.25)), as a nose cut by the free surface gives
    them: some within 1e-9 .. 1e-6 of the plane (their images are as close), close pairs (1e-9
    apart), some near the axis (r down to 1e-6), arbitrary normals and weights; their images
    x* = -x - SHIFT.  ``reverse``: the same nodes in the opposite order (the other node of each
    pair comes first)."""
    rng = np.random.default_rng(seed)
    x, r = rng.uniform(-1.0, -0.25, n), rng.uniform(1e-6, 1.0, n)
    edge = rng.choice(n, n // 8, replace=False)
    x[edge] = -0.25 - 10.0 ** rng.uniform(-9, -6, edge.size)
    close = rng.choice(n, n // 10, replace=False)
    x[close[1:]] = x[close[:-1]] - 1e-9
    r[close[1:]] = r[close[:-1]]
    t = rng.uniform(0, 2 * np.pi, n)
    out = [x, r, np.cos(t), np.sin(t), rng.uniform(0.1, 2.0, n)]
    if reverse:
        out = [a[::-1].copy() for a in out]
    return (*out, -out[0] - SHIFT)


def _mirror(x, r, nx, nr, w, xs):
    S, D = np.full((x.size, x.size), 7.0), np.full((x.size, x.size), 7.0)
    kernels.single_double_dense_mirror(x, r, nx, nr, w, xs, S, D)
    return S, D


@needs_c
@pytest.mark.parametrize("n", [150, 97, 33])
@pytest.mark.parametrize("reverse", [False, True])
def test_mirror_block_against_the_dense_block_of_the_images(n, reverse):
    """The entries (i, j*), j >= i, bit for bit as the plain compiled dense block of the image
    nodes computes them (the same operations); the partner entries (j, i*), which reuse the
    pair's elliptic integrals and x_i - x*_j for x_j - x*_i, to round-off of the numpy formulas
    of the image nodes' dense block (n not a multiple of the 32-node tiles; both orders of the
    nodes, so that each pair is computed from either end)."""
    x, r, nx, nr, w, xs = _nodes(n, n, reverse)
    S, D = _mirror(x, r, nx, nr, w, xs)
    S0, D0 = kernels.single_double_dense(x, r, xs, r, -nx, nr, w)
    upper = np.triu(np.ones((n, n), bool))
    assert np.array_equal(S[upper], S0[upper]) and np.array_equal(D[upper], D0[upper])
    S1, D1 = kernels._single_double_numpy(x[:, None], r[:, None], xs[None, :], r[None, :], -nx[None, :], nr[None, :])
    S1, D1 = S1 * w, D1 * w
    lower = ~upper
    assert np.max(np.abs(S[lower] - S1[lower]) / np.abs(S1[lower])) < 1e-12
    # D: relative to each row's scale (its entries' sizes span many decades)
    scale = np.abs(D1).max(axis=1, keepdims=True)
    assert np.max((np.abs(D - D1) / scale)[lower]) < 1e-12
    assert not np.allclose(S1, S1.T)  # the block itself is not symmetric: the test sees a transposed write


def test_mirror_block_on_the_numpy_path(monkeypatch):
    """Without the compiled kernels: the numpy formulas of the image nodes' dense block with the
    same pairing of the differences, written in row blocks (a small chunk: many blocks); against
    the compiled block where there is one (to round-off: the two sum K and E differently)."""
    x, r, nx, nr, w, xs = _nodes(70, 3)
    ref = _mirror(x, r, nx, nr, w, xs) if kernels.compiled() is not None else None
    monkeypatch.setattr(kernels, "compiled", lambda: None)
    S, D = np.empty((70, 70)), np.empty((70, 70))
    kernels.single_double_dense_mirror(x, r, nx, nr, w, xs, S, D, chunk=150)
    S1, D1 = kernels._single_double_numpy(x[:, None], r[:, None], xs[None, :], r[None, :], -nx[None, :], nr[None, :])
    upper = np.triu(np.ones((70, 70), bool))
    assert np.array_equal(S[upper], (S1 * w)[upper]) and np.array_equal(D[upper], (D1 * w)[upper])
    assert np.max(np.abs(S - S1 * w) / np.abs(S1 * w)) < 1e-12
    if ref is not None:
        assert np.max(np.abs(S - ref[0]) / np.abs(ref[0])) < 1e-13
        assert np.max(np.abs(D - ref[1]) / np.abs(ref[1]).max(axis=1, keepdims=True)) < 1e-13


def test_mirror_block_refuses_inconsistent_shapes():
    x, r, nx, nr, w, xs = _nodes(10, 1)
    with pytest.raises(ValueError):
        kernels.single_double_dense_mirror(x, r, nx, nr, w, xs, np.empty((10, 11)), np.empty((10, 11)))
    with pytest.raises(ValueError):
        kernels.single_double_dense_mirror(x, r, nx, nr, w, xs[:9], np.empty((10, 10)), np.empty((10, 10)))


def _previous_assembly(ps, plan):
    """The half-space matrices as the assembly built them before: the primary nodes against all
    2N nodes by the plain dense block, the rules' entries written at (target, panel * p + j) of
    the (N, 2N) matrices, the mirror columns folded (PanelSet.fold_mirror), the diagonal rule."""
    p = ps.order
    X, R, NX, NR, W = _flat_nodes(ps)
    N = ps.n_primary * p
    S, D = kernels.single_double_dense(X[:N], R[:N], X, R, NX, NR, W)
    for rule, kern in ((plan.self_rule, _layers_split), (plan.near_rule, _layers)):
        if rule.target.size:
            Sb, Db = rule.integrate(ps, X[:N], R[:N], kern, node_targets=True)
            flat = (rule.target[:, None] * X.size + rule.panel[:, None] * p + np.arange(p)[None, :]).ravel()
            S.put(flat, Sb)
            D.put(flat, Db)
    S, D = ps.fold_mirror(S), ps.fold_mirror(D)
    D.flat[:: N + 1] -= D.sum(axis=1) + 0.5
    return S, D


def _check_against_previous(kind, depth_over_length):
    nose = study_nose(kind)
    ps = halfspace_layout(nose, depth_over_length * nose.length, LayoutOptions()).panels()
    assert ps.n_panels == 2 * ps.n_primary
    plan = plan_assembly(ps)
    S, D = assemble(ps, plan)
    S0, D0 = _previous_assembly(ps, plan)
    N = ps.n_primary * ps.order
    assert S.shape == D.shape == (N, N)
    off = ~np.eye(N, dtype=bool)
    # S: entry by entry; D: to its rows' scale (the diagonal rule sums each row, and the double
    # layer's entries span many decades, some cancelling in the bracket)
    assert np.max(np.abs(S - S0)[off] / np.abs(S0)[off]) < 1e-12
    assert np.max(np.abs(D - D0) / np.abs(D0).max(axis=1, keepdims=True)) < 1e-12
    g = -ps.nodes.tr[:ps.n_primary].ravel()
    phi = np.linalg.solve(0.5 * np.eye(N) - D, -S @ g)
    phi0 = np.linalg.solve(0.5 * np.eye(N) - D0, -S0 @ g)
    assert np.max(np.abs(phi - phi0)) < 1e-12 * np.max(np.abs(phi0))


@pytest.mark.parametrize("kind", ["ogive", "cone", "table"])
@pytest.mark.parametrize("depth_over_length", [0.5, 1.6])  # before and after the shoulder
def test_halfspace_assembly_against_the_previous_path(kind, depth_over_length):
    """The assembled half-space matrices (mirror block once per pair, in folded order, the rules'
    mirror entries remapped, the primary block added in place) against the previous path, to
    round-off, and the potentials solved from them."""
    _check_against_previous(kind, depth_over_length)


@pytest.mark.parametrize("depth_over_length", [0.5, 1.6])
def test_halfspace_assembly_against_the_previous_path_numpy(depth_over_length, monkeypatch):
    """The same on the numpy fallback (every kernel in numpy)."""
    monkeypatch.setattr(kernels, "compiled", lambda: None)
    _check_against_previous("cone", depth_over_length)


@needs_c
def test_rules_write_into_the_matrices_only_within_bounds():
    """The compiled rules write their entries straight into the assembly's matrices (numpy's put
    without its overhead); indices beyond the matrices, or matrices of the wrong type, are refused
    before the C code runs (it does not check them itself)."""
    nose = study_nose("cone")
    ps = halfspace_layout(nose, 0.5 * nose.length, LayoutOptions()).panels()
    plan = plan_assembly(ps)
    X, R = _flat_nodes(ps)[:2]
    N = ps.n_primary * ps.order
    rule = plan.near_rule
    flat, bound = rule._entries(ps.order, N)
    SS, DD = np.zeros((2, N, N)), np.zeros((2, N, N))
    Sb, Db = rule.integrate(ps, X[:N], R[:N], _layers, node_targets=True, into=(SS, DD, flat, bound))
    ref = np.zeros((2, N, N))
    ref.put(flat, Sb)
    assert np.array_equal(SS, ref)
    ref.put(flat, Db)
    assert np.array_equal(DD, ref)
    for bad in ((np.zeros((1, N, N)), np.zeros((1, N, N)), flat, bound),  # the mirror block missing
                (SS, DD, flat, 2 * N * N + 1),
                (SS.astype(np.float32), DD, flat, bound),
                (SS, DD, flat[:-1], bound)):
        with pytest.raises(ValueError):
            rule.integrate(ps, X[:N], R[:N], _layers, node_targets=True, into=bad)
