"""What the assembly keeps between calls stays correct when the panel sets differ (issue 24).

A table's depth builds three panel sets (P, P - h, P + h) and one plan, assembles the two
stencil sets with that plan and matches all three against the AssemblyCache. Kept between
these calls: each rule's compiled arguments (on the rule) and each panel set's node signature
(on the panel set). The references here do not use those caches: a rule built afresh for
every assembly, and which nodes moved read directly from the node arrays.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from semianalytic.bem import kernels
from semianalytic.bem.panels import LayoutOptions, halfspace_layout
from semianalytic.bem.solve import AssemblyCache, assemble, plan_assembly
from semianalytic.geometry import ogive_nose

D = 7.11e-3
OPTS = LayoutOptions(6, 0.3, 6)


def _fresh(plan):
    """The plan with new rule objects (nothing kept from an earlier assembly)."""
    return dataclasses.replace(plan, self_rule=dataclasses.replace(plan.self_rule),
                               near_rule=dataclasses.replace(plan.near_rule))


def test_a_shared_plan_assembles_each_panel_set_as_a_fresh_one():
    """The two stencil sets share the plan of the centre: assembling the second after the first
    gives bit for bit the matrices of fresh rules (no number of the first set carried over),
    and the two sets' matrices differ (the test would see a stale reuse)."""
    nose = ogive_nose(D, 3.0)
    P = 0.5 * nose.length
    layout = halfspace_layout(nose, P, OPTS)
    h = 1e-3 * P  # far above round-off: every moved node moves by ~1e-3 of the nose length
    sets = [layout.at_depth(P + k * h).panels() for k in (-1, 1)]
    plan = plan_assembly(layout.panels())
    shared = [assemble(ps, plan) for ps in sets]
    fresh = [assemble(ps, _fresh(plan)) for ps in sets]
    for (S, Dm), (S0, D0) in zip(shared, fresh):
        assert np.array_equal(S, S0) and np.array_equal(Dm, D0)
    assert not np.array_equal(shared[0][0], shared[1][0])
    if kernels.compiled() is not None:  # the compiled rules were prepared once, on the plan's rules
        assert plan.self_rule.__dict__.get("_prepared") and plan.near_rule.__dict__.get("_prepared")


def test_cache_match_follows_each_panel_set():
    """After the cache stores one set, the mask of another marks exactly the panels whose nodes
    are the same (read from the node arrays): on the shank past the shoulder only the panels
    next to the free surface move; a set matched earlier (its signature kept) is matched again
    against the new content of the cache, not the old."""
    nose = ogive_nose(D, 3.0)
    a = halfspace_layout(nose, 3.0 * nose.length, OPTS).panels()
    b = halfspace_layout(nose, 3.2 * nose.length, OPTS).panels()
    c = halfspace_layout(nose, 0.5 * nose.length, OPTS).panels()  # on the nose: every panel differs
    cache = AssemblyCache()
    assert not cache.match(a).any()
    S, Dm = assemble(a, plan_assembly(a, cache.match(a)), cache)
    assert cache.match(a).all()
    n = min(a.n_primary, b.n_primary)
    # a panel either stays (its nodes agree to round-off, ~1e-16 of the size, as the layout
    # re-evaluates the same parameters) or moves with the depth (by ~1e-2 of the size): any
    # threshold between tells them apart
    size = np.abs(a.nodes.x[: a.n_primary]).max()
    same = np.array([max(np.abs(a.nodes.x[k] - b.nodes.x[k]).max(), np.abs(a.nodes.r[k] - b.nodes.r[k]).max(),
                         np.abs(a.nodes.w[k] - b.nodes.w[k]).max()) < 1e-9 * size for k in range(n)])
    assert same.any() and not same.all()
    got = cache.match(b)
    assert np.array_equal(got[:n], same) and not got[n:].any()
    assert not cache.match(c).any()
    # the cache now holds b: a's panels next to the free surface no longer match
    assemble(b, plan_assembly(b, cache.match(b)), cache)
    again = cache.match(a)
    assert np.array_equal(again[:n], same) and not again[n:].any()


def _arrays(ps):
    return [ps.base, ps.anchor_x, ps.anchor_r, ps.da, ps.db, ps.sign, ps.segment_index] + \
        [a for a in (ps.power, ps.cluster) if a is not None]


def test_restretched_stencil_sets_are_the_fresh_panel_sets():
    """A stencil set built from the centre's arrays (``panels(like=...)``) has bit for bit the
    arrays, nodes and compiled geometry of the panel set built from its pieces: on an ogive cut
    by the free surface (one stretched piece), past its shoulder (a new shank line) and on a
    table nose cut between knots (many pieces, a spline)."""
    from semianalytic.commands.coefficients.study import study_nose

    for nose, P in ((ogive_nose(D, 3.0), 0.5), (ogive_nose(D, 3.0), 2.0), (study_nose("table"), 0.6)):
        P *= nose.length
        layout = halfspace_layout(nose, P, OPTS)
        centre = layout.panels()
        for k in (-1, 1):
            moved = layout.at_depth(P + k * 1e-3 * P)
            fresh, derived = moved.panels(), moved.panels(like=centre)
            assert derived.segments == fresh.segments and derived.offset == fresh.offset
            assert derived.n_primary == fresh.n_primary and (derived.power is None) == (fresh.power is None)
            for a, b in zip(_arrays(derived), _arrays(fresh)):
                assert a.dtype == b.dtype and np.array_equal(a, b)
            for a, b in zip(dataclasses.astuple(derived.nodes), dataclasses.astuple(fresh.nodes)):
                assert np.array_equal(a, b)
            assert not np.array_equal(fresh.nodes.x, centre.nodes.x)  # the test sees a stale copy
            if kernels.compiled() is not None:
                (ad, kd), (af, kf) = derived._compiled_curves, fresh._compiled_curves  # noqa: F841
                assert set(kd) == set(kf) and all(np.array_equal(kd[n], kf[n]) for n in kf)
