"""The compiled dense block of the primary nodes against themselves, once per pair (ring_dense_sym of
_ring.c, kernels.single_double_dense_sym): the same numbers as the plain dense block, entry for entry."""

from __future__ import annotations

import numpy as np
import pytest

from semianalytic.bem import kernels

needs_c = pytest.mark.skipif(kernels.compiled() is None, reason="no compiled kernels (built without a C compiler, or SEMIANALYTIC_KERNEL=numpy): the numpy kernels only")  # noqa: E501


def _nodes(n, seed):
    """Ring nodes as a meridian gives them: most well apart, some close pairs (1e-9 apart: the nearly
    singular end of the kernels), some on the axis side (r down to 1e-6), arbitrary normals and weights."""
    rng = np.random.default_rng(seed)
    x, r = rng.uniform(-1.0, 1.0, n), rng.uniform(1e-6, 1.0, n)
    close = rng.choice(n, n // 10, replace=False)
    x[close[1:]] = x[close[:-1]] + 1e-9
    r[close[1:]] = r[close[:-1]]
    t = rng.uniform(0, 2 * np.pi, n)
    return x, r, np.cos(t), np.sin(t), rng.uniform(0.1, 2.0, n)


@needs_c
@pytest.mark.parametrize(("n", "skip"), [(150, None), (97, "random"), (150, "leading"), (33, "all")])
def test_symmetric_dense_block_equals_the_plain_one(n, skip):
    """Every entry bit for bit as single_double_dense computes it (ld > n: the block sits in the first n
    columns of wider rows, as in the assembly), the pairs of two skipped nodes left untouched; n not a
    multiple of the 32-node tiles.  Bit for bit, not a tolerance: the same operations in the same order
    (the differences only change sign, so their squares and everything built from them are the same)."""
    x, r, nx, nr, w = _nodes(n, n)
    mask = {None: None, "random": np.random.default_rng(1).random(n) < 0.5,
            "leading": np.arange(n) < 2 * n // 3, "all": np.ones(n, bool)}[skip]
    ld = n + 5
    S, D = np.full((n, ld), 7.0), np.full((n, ld), 7.0)
    kernels.single_double_dense_sym(x, r, nx, nr, w, S, D, mask)
    S0, D0 = kernels.single_double_dense(x, r, x, r, nx, nr, w)
    both = np.zeros((n, n), bool) if mask is None else mask[:, None] & mask[None, :]
    for got, ref in ((S, S0), (D, D0)):
        assert np.all(got[:, n:] == 7.0)  # beyond the block: untouched
        assert np.all(got[:, :n][both] == 7.0)
        assert np.array_equal(got[:, :n][~both], ref[~both], equal_nan=True)


@needs_c
def test_symmetric_dense_block_against_the_numpy_kernels():
    """Against the numpy formulas (an independent code path, scipy's ellipk/ellipe): within round-off of
    the entries off the diagonal (1e-12 of each entry's scale: the polynomial approximations of K and E
    agree with scipy's to a few ulps, amplified by at most the 1e-9 separations' cancellation)."""
    n = 80
    x, r, nx, nr, w = _nodes(n, 5)
    S, D = np.empty((n, n)), np.empty((n, n))
    kernels.single_double_dense_sym(x, r, nx, nr, w, S, D)
    with np.errstate(divide="ignore", invalid="ignore"):
        S0, D0 = kernels._single_double_numpy(x[:, None], r[:, None], x[None, :], r[None, :], nx[None, :], nr[None, :])
    off = ~np.eye(n, dtype=bool)
    for got, ref in ((S, S0 * w), (D, D0 * w)):
        assert np.max(np.abs(got[off] - ref[off]) / (np.abs(ref[off]) + 1e-300)) < 1e-9


@pytest.mark.parametrize("skip", [None, "random"])
def test_symmetric_dense_block_on_the_numpy_path(skip, monkeypatch):
    """Without the compiled kernels the block is the numpy dense block's, entry for entry, the pairs of
    two skipped nodes left untouched (the assembly's fallback)."""
    monkeypatch.setattr(kernels, "compiled", lambda: None)
    n = 40
    x, r, nx, nr, w = _nodes(n, 4)
    mask = None if skip is None else np.random.default_rng(2).random(n) < 0.5
    S, D = np.full((n, n + 3), 7.0), np.full((n, n + 3), 7.0)
    kernels.single_double_dense_sym(x, r, nx, nr, w, S, D, mask, chunk=100)
    S0, D0 = kernels.single_double_dense(x, r, x, r, nx, nr, w)
    both = np.zeros((n, n), bool) if mask is None else mask[:, None] & mask[None, :]
    for got, ref in ((S, S0), (D, D0)):
        assert np.all(got[:, n:] == 7.0) and np.all(got[:, :n][both] == 7.0)
        assert np.array_equal(got[:, :n][~both], ref[~both], equal_nan=True)


def test_symmetric_dense_block_refuses_inconsistent_shapes():
    x, r, nx, nr, w = _nodes(10, 0)
    with pytest.raises(ValueError):
        kernels.single_double_dense_sym(x, r, nx, nr, w, np.empty((10, 9)), np.empty((10, 9)))
    with pytest.raises(ValueError):
        kernels.single_double_dense_sym(x, r, nx, nr, w, np.empty((10, 10)), np.empty((10, 10)), np.zeros(3, bool))
