"""The quadrature plan's shortcuts (semianalytic/bem/solve.py) against the general code they
replace: near_quadrature's distinct points, found from the end rules' structure, against
_distinct_by_unique below (a second method, np.unique over the pairs' keys: the code the
shortcut replaced), on the
layouts of the study noses, with pairs whose nearest point is inside the panel too."""

from __future__ import annotations

import numpy as np
import pytest

from semianalytic.bem.panels import LayoutOptions, halfspace_layout
from semianalytic.bem.solve import near_pairs, near_quadrature
from semianalytic.commands.coefficients.study import study_nose


def _distinct_by_unique(rule):
    """The distinct points of a near rule by the general method: the points of the pairs of a shared
    end rule (a block with one (Q, p) matrix) on one panel are one set, found by np.unique over the
    pairs' (block, panel) keys; every other pair's points a set of their own."""
    npairs, npoints = len(rule.target), rule.u.size
    shared = np.zeros(npairs, bool)
    block = np.empty(npairs, dtype=np.int64)
    for k, (f, n, _, lag) in enumerate(rule.blocks):
        block[f:f + n] = k
        shared[f:f + n] = lag is not None and lag.ndim == 2
    span = int(rule.panel.max()) + 1
    key = np.where(shared, block * span + rule.panel, len(rule.blocks) * span + np.arange(npairs))
    _, first, inv = np.unique(key, return_index=True, return_inverse=True)
    counts = np.diff(np.append(rule.starts, npoints))
    size = counts[first]
    at = np.cumsum(size) - size  # first distinct point of each distinct pair
    src = np.repeat(rule.starts[first] - at, size) + np.arange(int(size.sum()))
    within = np.arange(npoints) - rule.starts[rule.pair]
    return rule.panel[rule.pair[src]], rule.u[src], at[inv.ravel()][rule.pair] + within


@pytest.mark.parametrize("kind, f", [("ogive", 0.4), ("ogive", 2.5), ("cone", 0.3), ("table", 1.5), ("flat", 0.7)])
def test_near_quadrature_distinct_points(kind, f):
    nose = study_nose(kind)
    ps = halfspace_layout(nose, f * nose.depth_unit, LayoutOptions(8, 0.3, 6)).panels()
    g = ps.nodes
    N = ps.n_primary * ps.order
    tgt, pan, ustar, du = near_pairs(ps, g.x.ravel()[:N], g.r.ravel()[:N], np.arange(N) // ps.order)
    rng = np.random.default_rng(2)
    inner = ustar.copy()
    moved = rng.random(ustar.size) < 0.3
    inner[moved] = rng.uniform(-1, 1, int(moved.sum()))
    for us in (ustar, inner, np.clip(inner, -0.5, 0.5)):  # at the ends, some inside, all inside
        rule = near_quadrature(tgt, pan, us, du, ps.order)
        ref = _distinct_by_unique(rule)
        assert rule.distinct is not None and len(rule.distinct) == 3
        for a, b in zip(rule.distinct, ref, strict=True):
            assert a.dtype.kind == b.dtype.kind and np.array_equal(a, b)
        # every point's distinct point is the point itself
        panel_of, u_of, index = rule.distinct
        assert np.array_equal(panel_of[index], rule.panel[rule.pair]) and np.array_equal(u_of[index], rule.u)


def test_closer_is_hypot_below_reach():
    """solve._closer (squared distances, hypot only at the margin) against numpy's hypot(a, b)
    < reach, the test it replaces, element for element: random points, points on the circle of
    radius reach (the 3-4-5 triangle, exact) and an ulp either side, scales from 1e-200 to 1e200
    (the fallback where squares would under- or overflow)."""
    from semianalytic.bem.solve import _closer

    rng = np.random.default_rng(4)
    for scale in (1e-200, 1e-9, 1.0, 1e200):
        a = rng.standard_normal((60, 30)) * scale
        b = rng.standard_normal((60, 30)) * scale
        reach = np.abs(rng.standard_normal(30)) * scale * 1.5
        a[:5], b[:5] = 0.6 * reach, 0.8 * reach  # on the circle
        a[5:10] = np.nextafter(0.6 * reach, np.inf)
        a[10:15] = np.nextafter(0.6 * reach, -np.inf)
        assert np.array_equal(_closer(a, b, reach[None, :]), np.hypot(a, b) < reach[None, :])


def test_closer_both_searches_in_one_pass():
    """solve._closer as _near_pairs_with calls it: a of (targets, panels) broadcast against b of
    (2, targets, panels) (the target and its axis image), points on the circle of radius reach
    among them: the same booleans as hypot for each search alone."""
    from semianalytic.bem.solve import _closer, _signed_radii

    rng = np.random.default_rng(5)
    dx = rng.standard_normal((40, 20))
    rt, cr = np.abs(rng.standard_normal(40)), np.abs(rng.standard_normal(20))
    reach = np.abs(rng.standard_normal(20))[None, :] * 1.5
    dx[:5] = 0.6 * reach[0]  # on the circle for targets at r = cr +- 0.8 reach
    rt[:5] = cr[3] + 0.8 * reach[0, 3]
    both = _closer(dx, rt[:, None] - _signed_radii(cr), reach, dx * dx)
    assert both.shape == (2, 40, 20)
    assert np.array_equal(both[0], np.hypot(dx, rt[:, None] - cr[None, :]) < reach)
    assert np.array_equal(both[1], np.hypot(dx, rt[:, None] + cr[None, :]) < reach)
