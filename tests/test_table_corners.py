"""Certified tables of cornered noses at the default tolerance (issue 10: "a cornered nose's
table at the same accuracy"): the table against direct BEM solves at depths it did not
choose, seeded random ones and depths beside every breakpoint (b (1 -+ f 10^-k), k = 1..5),
where the coefficients change like non-integer powers of P - b and the table switches to its
graded variable.  The reference (a direct solve at exactly that depth, same discretisation)
is independent of the interpolation under test.  The cost against the ogive is a benchmark
(reports/bem_corners.md, `bench-bem --corners`), not a timed test.
"""

from __future__ import annotations

import io
import math

import numpy as np
import pytest

from semianalytic.coefficients.table import (
    CONTROLLED,
    DEFAULT_TOLERANCE,
    CoefficientTable,
    breakpoints,
    coefficient_table,
    depth_pieces,
    direct_coefficients,
)
from semianalytic.commands.coefficients.corners_report import ISSUE_TABLE, off_knot_depths
from semianalytic.commands.coefficients.study import table_error_study
from semianalytic.geometry import cone_nose, ogive_nose, sphere_nose, table_nose

D = 7.11e-3
NOSES = {
    "cone30_toml": lambda: cone_nose(D, math.radians(15)),  # cases/cone30.toml: 15 deg half-angle
    "blunted_cone": lambda: cone_nose(D, math.radians(15), tip_radius=D / 4),  # joint + shoulder corner
    "table_shoulder": lambda: table_nose(ISSUE_TABLE, D),  # spline knot + shoulder corner
}


@pytest.fixture(scope="module")
def tables():
    cache = {}

    def get(name):
        if name not in cache:
            nose = NOSES[name]()
            cache[name] = (nose, coefficient_table(nose))
        return cache[name]

    return get


@pytest.mark.parametrize("name", sorted(NOSES))
def test_certified_table_within_tolerance_off_knots_and_beside_breakpoints(tables, name):
    """At the default tolerance (1e-5 of each coefficient's largest magnitude), with no
    slack: the interpolation error against direct solves, and the table's own estimate at
    least the actual difference at every depth."""
    nose, table = tables(name)
    depths = off_knot_depths(nose, table, n_random=6, seed=41)
    assert len(depths) >= 6 + 10 * len(table.kinks)  # every breakpoint approached from both sides
    study = table_error_study(nose, table, depths)
    assert table.options["noise_limited_intervals"] == 0
    for q in CONTROLLED:
        assert study[q]["max_rel_error"] <= DEFAULT_TOLERANCE, (q, study[q])
        assert study[q]["bounded"] == study[q]["n"], (q, study[q])


def test_graded_pieces_only_past_corners_and_joints():
    """The graded variable is used past a corner (a cone's shoulder) and a segment joint
    (sphere cap to cone), not past a smooth nose's shoulder: the ogive and the sphere keep
    their pieces (and their cost)."""
    kinds = lambda nose: [p.kind for p in depth_pieces(nose)[0]]  # noqa: E731
    assert kinds(ogive_nose(D, 3.0)) == ["mid", "deep"]
    assert kinds(sphere_nose(D)) == ["root", "deep"]
    assert kinds(NOSES["cone30_toml"]()) == ["mid", "graded", "deep"]
    assert kinds(NOSES["blunted_cone"]()) == ["root", "graded", "graded", "deep"]
    # the table spline's middle knot, where its third derivative jumps (the not-a-knot spline
    # is C^3 at the others): a breakpoint (x = 4 mm), interpolated in P on both sides
    nose = NOSES["table_shoulder"]()
    assert breakpoints(nose) == pytest.approx([4e-3, 8e-3], rel=1e-12)
    assert kinds(nose) == ["mid", "mid", "graded", "deep"]


def test_graded_evaluation_paths_agree_and_survive_the_cache(tables):
    """Scalar and array evaluation, the .npz round trip, and dA/dP of the Hermite A against
    the BEM's B_bernoulli (= dA/dP, errata 2a) in the graded piece just past the shoulder:
    the derivative of a 1e-5 interpolant, so 1e-3 of max |B_bernoulli|."""
    nose, table = tables("cone30_toml")
    L = nose.length
    depths = L * np.array([1 + 3e-6, 1 + 2e-4, 1.01, 1.3, 1.9])
    back = CoefficientTable.from_npz(io.BytesIO(table.to_npz_bytes()))
    for q in CONTROLLED:
        arr = np.asarray(table._eval(q, depths))
        assert np.array_equal(arr, np.asarray(back._eval(q, depths)))
        assert np.allclose([table._eval(q, float(P)) for P in depths], arr, rtol=1e-13, atol=0.0)
    rows = direct_coefficients(nose, depths)
    scale = table.max_abs["B_bernoulli"]
    for P, r in zip(depths, rows):
        assert abs(float(table.dA_dP(P)) - r["B_bernoulli"]) <= 1e-3 * scale
