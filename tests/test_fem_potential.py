"""FEM potential problem (fem_check) against exact solutions and the BEM.

References, all independent of the FEM code: the exact added mass of a sphere (1/2) and Lamb's
spheroid coefficient; the hemisphere at P = R, whose mirrored body is a full sphere solved by a
Legendre series (numbers printed in the project's numerical notes); the BEM of semianalytic.
"""

import math

import numpy as np
import pytest

from fem_check.coefficients import body_added_mass, halfspace_coefficients, halfspace_mesh
from fem_check.meshing import MeshOptions
from fem_check.potential import solve_potential
from semianalytic.geometry import ogive_nose, sphere_body, sphere_nose, spheroid_body

D = 7.11e-3  # Fig. 5 diameter


def lamb_k1(length, diameter):
    """Lamb's added-mass coefficient of a prolate spheroid, written out here independently."""
    a, b = length / 2, diameter / 2
    e = math.sqrt(1 - (b / a) ** 2)
    alpha0 = 2 * (1 - e * e) / e**3 * (0.5 * math.log((1 + e) / (1 - e)) - e)
    return alpha0 / (2 - alpha0)


def test_sphere_added_mass_within_1e3_of_one_half():
    # P2 with curved edges at h = d/10: measured 2.4e-4; the brief's tolerance is 1e-3.
    am = body_added_mass(sphere_body(1.0), MeshOptions(h=0.1, order=2))
    assert abs(am.coefficient - 0.5) < 1e-3


def test_sphere_added_mass_p2_converges_at_about_fourth_order():
    # A is the energy: P2 error ~ h^4 (measured ratio 9.6 from h = 0.2 to 0.1, order 3.3, rising to
    # 3.7 on the next halving). Require order > 3 so that a fall-back to h^2 (straight edges) fails.
    errs = [abs(body_added_mass(sphere_body(1.0), MeshOptions(h=h, order=2)).coefficient - 0.5) for h in (0.2, 0.1)]
    assert math.log2(errs[0] / errs[1]) > 3.0


def test_spheroid_aspect_4_added_mass_against_lamb():
    # measured 1.7e-4 at h = 0.1 (P2); tolerance 1e-3 as for the sphere.
    am = body_added_mass(spheroid_body(4.0, 1.0), MeshOptions(h=0.1, order=2))
    assert abs(am.coefficient / lamb_k1(4.0, 1.0) - 1) < 1e-3


def test_hemisphere_at_depth_R_against_mirrored_sphere_series():
    # numerical notes: phi_tip = 0.680633550050 a, Abar = 0.553967546980 a (Legendre series).
    # measured at h = 0.05 d: Abar 1.2e-5, phi_tip 7.8e-6 relative; tolerance 1e-4 (order 4 behind it).
    nose = sphere_nose(2.0)  # a = 1
    s = solve_potential(halfspace_mesh(nose, 1.0, MeshOptions(h=0.05)), "monopole")
    assert abs(s.A / math.pi / 0.553967546980 - 1) < 1e-4
    assert abs(s.node_value((1.0, 0.0)) / 0.680633550050 - 1) < 1e-4


def test_far_field_monopole_robin_beats_dipole_and_neumann_in_the_halfspace():
    # errata 2f: the mirrored nose is a source. At far = 4 the monopole condition leaves
    # ~1e-5 (the discretisation error), the dipole ~3e-2, Neumann is O(1) wrong.
    nose = sphere_nose(2.0)
    dm = halfspace_mesh(nose, 1.0, MeshOptions(h=0.08, far=4.0))
    err = {ff: abs(solve_potential(dm, ff).A / math.pi / 0.553967546980 - 1) for ff in ("monopole", "dipole", "neumann")}
    assert err["monopole"] < 1e-4
    assert err["dipole"] > 100 * err["monopole"]
    assert err["neumann"] > 0.1


@pytest.mark.parametrize("kind", ["sphere", "ogive"])
def test_bem_and_fem_agree_at_three_depths(kind):
    # brief: A and C within 1e-3, B within 5e-3 at the test resolution (here P2, h = 0.08 d,
    # where the measured differences are below 1e-4 for A, B_body and C, for both noses).
    from semianalytic.coefficients.table import coefficients_at

    nose = sphere_nose(D) if kind == "sphere" else ogive_nose(D, 3.0)
    depths = np.array([0.5, 2.0, 8.0]) * nose.length
    bem = coefficients_at(nose, depths)
    for i, P in enumerate(depths):
        f = halfspace_coefficients(nose, float(P), MeshOptions(h=0.08))
        assert abs(f.A / bem["A"][i] - 1) < 1e-3
        assert abs(f.C / bem["C"][i] - 1) < 1e-3
        assert abs(f.B_body / bem["B_body"][i] - 1) < 5e-3
        # the literal reading is B_body minus 2 int dphi/dx n_x dS: same tolerance
        assert abs(f.B_literal / bem["B_literal"][i] - 1) < 5e-3
        # B_bernoulli -> 0 at depth: compare in Bbar units (measured < 2e-4 at h = 0.08 d)
        S = math.pi * D * D / 4
        assert abs(f.B_bernoulli - bem["B_bernoulli"][i]) / S < 1e-3


def test_fem_bernoulli_identity_and_deep_values():
    # errata 2a: B_bernoulli = dA/dP (energy conservation). The FEM gets B_bernoulli from surface
    # integrals and dA/dP from a shape difference of A: independent routes (measured 1.5e-4 in Bbar
    # units at h = 0.08 d). The body reading tends to the paper's 0.58 (errata 2a: ~0.586 at infinite
    # depth; 0.582 at P = 8 L_h).
    nose = sphere_nose(D)
    S = math.pi * D * D / 4
    f = halfspace_coefficients(nose, 2.0 * nose.length, MeshOptions(h=0.08))
    assert abs(f.B_bernoulli - f.dA_dP) / S < 5e-4
    deep = halfspace_coefficients(nose, 8.0 * nose.length, MeshOptions(h=0.08))
    assert 0.57 < deep.B_body / S < 0.60
