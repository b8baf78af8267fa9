"""Issue 27 (numerics found): fem_check's error bar at a corner near the free surface must bound the
FEM's distance to an independent method.  Cone of half-angle 15 deg at P = 1.001 L_h (its shoulder
corner 0.001 L_h inside the target): the shape difference in P had a step of 0.2 of that distance,
and refining h left its O(eps^2) error untouched (FEM - BEM 8.7e-5 in B, bar 4.6e-7)."""

from __future__ import annotations

import math

import pytest

from semianalytic.geometry import cone_nose


def test_error_bar_bounds_fem_minus_bem_near_a_breakpoint(tmp_path, monkeypatch):
    # the BEM (coefficients_at, refinement 1) is the independent reference: its own error here is
    # below 1e-7 of B (an independent BEM agrees with it, issue 27), far below the bars tested
    monkeypatch.setenv("FEM_CHECK_MESH_CACHE", str(tmp_path))
    from fem_check.refinement import refinement_study

    nose = cone_nose(7.11e-3, math.radians(15))
    (study,) = refinement_study(nose, [1.001], h_list=(0.16, 0.08, 0.04))
    for key in ("B_body", "dA_dP", "A"):
        d = study["diff"][key]
        assert abs(d["fem_minus_bem"]) <= d["fem_error_bar"], (key, d)
    # and the bar is not vacuous: B within 1e-4 (the target of issue 10), the bar below 3e-5
    assert study["diff"]["B_body"]["fem_error_bar"] < 3e-5
    assert study["extrapolated"]["B_body"]["step_error"] > 0.0


@pytest.mark.slow
def test_error_bar_bounds_fem_minus_bem_near_a_breakpoint_fine(tmp_path, monkeypatch):
    """The issue's own sequence (h down to d/50)."""
    monkeypatch.setenv("FEM_CHECK_MESH_CACHE", str(tmp_path))
    from fem_check.refinement import refinement_study

    nose = cone_nose(7.11e-3, math.radians(15))
    (study,) = refinement_study(nose, [1.001])
    for key in ("B_body", "dA_dP", "A"):
        d = study["diff"][key]
        assert abs(d["fem_minus_bem"]) <= d["fem_error_bar"], (key, d)
