"""FEM on cornered noses (issue 10, item 3) and the hemisphere series by recurrence (issue 14, item 5).

References independent of the code under test: the direct Gauss-Legendre evaluation of the
hemisphere series with scipy.special.eval_legendre and the values of the project's numerical
notes; the corner exponents pi/omega and the Legendre-function condition of a cone point checked
with scipy.special.lpmv; the predicted convergence order of P2 on graded meshes (h^4 for A);
the BEM of semianalytic (a second method).
"""

import math

import numpy as np
import pytest
from scipy.special import eval_legendre, lpmv

from fem_check.coefficients import halfspace_coefficients
from fem_check.meshing import MeshOptions, halfspace_domain
from fem_check.refinement import richardson
from fem_check.verify import hemisphere_reference, legendre_half_moments
from semianalytic.geometry import cone_nose, flat_nose, table_nose

D = 7.11e-3


def test_hemisphere_recurrence_equals_direct_legendre_series():
    n_terms = 200
    n = np.arange(0, n_terms + 1, 2)
    x, w = np.polynomial.legendre.leggauss(n_terms // 2 + 4)
    x, w = 0.5 * (x + 1), 0.5 * w  # Gauss rule on [0, 1], exact for mu P_n(mu), n <= n_terms
    direct = np.array([np.sum(w * x * eval_legendre(k, x)) for k in n])
    # the direct Gauss sums (104 nodes, terms up to 0.01) carry round-off of about 1e-15 absolute
    assert np.max(np.abs(legendre_half_moments(n_terms) - direct)) < 1e-14
    c = (2 * n + 1) * direct / (n + 1)
    ref = hemisphere_reference(n_terms)
    # the brief's 1e-13: the same truncated series evaluated two ways
    assert abs(ref["phi_tip_over_a"] - c.sum()) < 1e-13
    assert abs(ref["Abar_over_a"] - np.sum(c * 2 * direct)) < 1e-13


def test_hemisphere_series_matches_numerical_notes():
    ref = hemisphere_reference()
    # numerical notes print 12 digits: 0.680633550050 and 0.553967546980
    assert abs(ref["phi_tip_over_a"] - 0.680633550050) < 1e-12
    assert abs(ref["Abar_over_a"] - 0.553967546980) < 1e-12


def _corners(nose, depth):
    return halfspace_domain(nose, depth, MeshOptions()).corners


def test_corners_found_from_geometry_flat_rim_and_cone():
    (rim,) = _corners(flat_nose(D), D)
    assert rim.point == pytest.approx((D, D / 2), abs=1e-15)
    assert rim.angle == pytest.approx(1.5 * math.pi) and rim.exponent == pytest.approx(2 / 3)
    beta = math.radians(30)
    cone = cone_nose(D, beta)
    by_axis = {c.on_axis: c for c in _corners(cone, 2 * cone.length)}
    # shoulder: the fluid turns around pi + beta; tip: 3D cone point
    assert by_axis[False].exponent == pytest.approx(math.pi / (math.pi + beta))
    nu = by_axis[True].exponent - 0.5
    x0, dx = -math.cos(beta), 1e-6
    dP = (lpmv(0, nu, x0 + dx) - lpmv(0, nu, x0 - dx)) / (2 * dx)  # Neumann on the cone: P_nu'(-cos beta) = 0
    assert abs(dP) < 1e-6 and 1 < nu < 1.2  # a Neumann needle barely disturbs a linear field: nu -> 1
    # shallow: waterline corner of opening pi/2 + beta, exponent above 1 (graded for P2, not singular)
    wl = [c for c in _corners(cone, 0.5 * cone.length) if not c.on_axis]
    assert len(wl) == 1 and wl[0].exponent == pytest.approx(math.pi / (0.5 * math.pi + beta))


def test_table_nose_shoulder_corner_found_without_the_nose_name():
    # a table nose whose last tangent is not axial meets the shank at a corner; a smooth ogive does not
    pts = [[0, 0], [2e-3, 1.8e-3], [4e-3, 2.7e-3], [6e-3, 3.2e-3], [8e-3, D / 2]]
    nose = table_nose(pts, D)
    ring = [c for c in _corners(nose, 2 * nose.length) if not c.on_axis]
    assert len(ring) == 1 and ring[0].point == pytest.approx((nose.length, D / 2), rel=1e-9)
    assert ring[0].exponent < 1


def test_fem_flat_nose_converges_at_the_graded_rate():
    # P2 graded with mu < lambda/2 at the rim (lambda = 2/3): predicted h^4 for A (the energy) and dA/dP;
    # measured 3.3 on this pre-asymptotic sequence (4.0 with grading 0.8), 1.2 for B without grading.
    nose = flat_nose(D)
    fs = [halfspace_coefficients(nose, D, MeshOptions(h=h)) for h in (0.16, 0.08, 0.04)]
    hs = [0.16, 0.08, 0.04]
    oa = richardson([f.A for f in fs], hs)["order"]
    ob = richardson([f.B_body for f in fs], hs)["order"]
    assert 3.0 < oa < 5.0
    assert ob > 2.0  # predicted at least 2 (the corner nodal value in H), measured 3.3
    # the surface-gradient G tends to the shape-form G (errata 2a identity) but slowly: rho_min^(1/3)
    gaps = [abs(f.G_surface - f.G_shape) / f.G_shape for f in fs]
    assert gaps[0] > gaps[1] > gaps[2] and gaps[2] < 3e-3


@pytest.mark.parametrize("kind", ["cone", "flat"])
def test_fem_and_bem_agree_at_one_depth_on_cornered_noses(kind):
    from semianalytic.coefficients.table import coefficients_at

    nose = cone_nose(D, math.radians(15)) if kind == "cone" else flat_nose(D)  # cases/cone30.toml, flat_nose.toml
    P = 2 * (nose.length if kind == "cone" else D / 2)
    f = halfspace_coefficients(nose, P, MeshOptions(h=0.08))
    bem = coefficients_at(nose, [P])
    # the FEM's own error at h = 0.08 d, from its refinement (reports/fem_verify_cone30.md, fem_verify_flat.md;
    # observed orders 3-4): A 4e-5 to 5e-5 (both noses), B 1e-4 (cone), 5e-6 (flat).  Tolerances about 3x that:
    # the BEM (converged to 1e-6 and better) adds nothing visible, so a failure means the FEM or the BEM broke.
    assert abs(f.A / bem["A"][0] - 1) < 2e-4
    assert abs(f.B_body / bem["B_body"][0] - 1) < 3e-4


@pytest.mark.slow
@pytest.mark.parametrize("case", ["cone30", "flat_nose"])
def test_refinement_study_meets_issue_10_targets(case, tmp_path, capsys):
    """The full study of reports/fem_verify_{cone30,flat}.md: FEM (extrapolated) against the BEM at four depths."""
    import json
    from pathlib import Path

    from fem_check.cli import main

    root = Path(__file__).resolve().parents[1]
    assert main(["verify", str(root / "cases" / f"{case}.toml"), "--depths", "0.5,2,5,20", "--study-h", "0.16,0.08,0.04",
                 "--json", "--out", str(tmp_path)]) == 0
    study = json.loads(capsys.readouterr().out)["refinement"]
    assert len(study) >= 3
    for st in study:
        # issue 10's targets: 1e-4 in A, 1e-3 in B; the FEM's own error bars are 1e-5 (A) and 1e-4 (B) or less
        assert abs(st["diff"]["A"]["fem_minus_bem"]) < 1e-4 and st["diff"]["A"]["fem_error_bar"] < 1e-4
        assert abs(st["diff"]["B_body"]["fem_minus_bem"]) < 1e-3 and st["diff"]["B_body"]["fem_error_bar"] < 1e-3
        assert st["extrapolated"]["A"]["order"] > 3.0  # predicted 4


def test_verify_cli_on_a_flat_nose_depths_in_radii(capsys):
    import json
    from pathlib import Path

    from fem_check.cli import main

    case = Path(__file__).resolve().parents[1] / "cases" / "flat_nose.toml"
    assert main(["verify", str(case), "--quick", "--depths", "3", "--h", "0.16", "--json", "--no-report"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["depth_scale"] == "radius" and d["depths"][0]["depth_m"] == pytest.approx(3 * D / 2)
    # h = 0.16 d, graded: FEM error 3e-4 (A), 1e-4 (B) by refinement at 2 radii; C = pi R^2 on the flat face
    assert d["max_rel_diff"] < 1e-3


@pytest.mark.parametrize("argv, field", [
    (["--study-h", "0.1,0.2,0.05"], "--study-h"),
    (["--study-h", "0.1,0.05"], "--study-h"),
    (["--grading", "2"], "--grading"),
])
def test_verify_bad_study_options_exit_2(capsys, tmp_path, argv, field):
    from pathlib import Path

    from fem_check.cli import main

    case = Path(__file__).resolve().parents[1] / "cases" / "flat_nose.toml"
    assert main(["verify", str(case), *argv, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and field in err[0]
    assert not any(tmp_path.iterdir())
