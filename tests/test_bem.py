"""The BEM of Part I against exact solutions.

References, all independent of the solver: brute-force azimuthal quadrature of the 3D
Green function (kernels); the sphere's and Lamb's spheroid added mass and surface potential;
the sphere's exterior field; the pulsating sphere (phi = a); the hemispherical nose at
P = R, whose mirrored body is a sphere (Legendre-series values of the numerical notes);
the exact projected area C; and the energy identity B_bernoulli = dA/dP (errata item 2a).
"""

import math

import numpy as np
import pytest

from semianalytic.bem import solve_body, solve_halfspace
from semianalytic.bem.kernels import gradient_kernels, single_double, single_double_split
from semianalytic.bem.panels import LayoutOptions, halfspace_layout
from semianalytic.bem.solve import solve_panels
from semianalytic.coefficients.depth import coefficients_at_depth
from semianalytic.exact import (
    sphere_gradient,
    sphere_potential,
    spheroid_added_mass_coefficient,
)
from semianalytic.geometry import ogive_nose, sphere_body, sphere_nose, spheroid_body

D = 7.11e-3  # Fig. 5 diameter
OGIVE = ogive_nose(D, 3.0)
SPHERE = sphere_nose(D)


def _azimuthal(x, r, x1, r1, nx1, nr1, n=4000):
    """Ring integrals by the trapezoid rule in theta (spectrally accurate off the ring)."""
    th = np.linspace(0, 2 * np.pi, n, endpoint=False)
    X = np.array([x, r, 0.0])
    Y = np.stack([np.full_like(th, x1), r1 * np.cos(th), r1 * np.sin(th)], 1)
    N = np.stack([np.full_like(th, nx1), nr1 * np.cos(th), nr1 * np.sin(th)], 1)
    et = np.stack([0 * th, -np.sin(th), np.cos(th)], 1)
    Rv = X - Y
    R = np.linalg.norm(Rv, axis=1)
    w = 2 * np.pi / n * r1
    S = np.sum(1 / (4 * np.pi * R)) * w
    Dl = np.sum(np.sum(Rv * N, 1) / (4 * np.pi * R**3)) * w
    gS = np.sum(-Rv / (4 * np.pi * R[:, None] ** 3), 0) * w
    gW = -np.sum(np.cross(Rv, et) / (4 * np.pi * R[:, None] ** 3), 0) * w
    return S, Dl, gS[0], gS[1], gW[0], gW[1]


@pytest.mark.parametrize("seed", range(6))
def test_ring_kernels_equal_azimuthal_integrals(seed):
    rng = np.random.default_rng(seed)
    x, r = rng.normal(), abs(rng.normal()) * (seed != 5)  # seed 5: target on the axis
    x1, r1 = rng.normal(), abs(rng.normal()) + 0.1
    a = rng.uniform(0, 2 * np.pi)
    ref = _azimuthal(x, r, x1, r1, np.cos(a), np.sin(a))
    S, Dl = single_double(x, r, x1, r1, np.cos(a), np.sin(a))
    S2, D2, _, _ = single_double_split(x, r, x1, r1, np.cos(a), np.sin(a))
    got = (S, Dl, *gradient_kernels(x, r, x1, r1))
    # the trapezoid rule is exact to round-off here; 1e-12 allows for cancellation
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-12 * max(1, np.abs(ref).max()))
    assert S2 == pytest.approx(S, rel=1e-14) and D2 == pytest.approx(Dl, rel=1e-13, abs=1e-15)


@pytest.mark.parametrize("aspect", [1.0, 2.0, 5.0, 0.5])
def test_added_mass_of_spheroids(aspect):
    """Lamb's k1 for prolate (and one oblate) spheroid: <= 1e-6 with <= 400 unknowns.

    The default resolution reaches ~1e-11; the issue's tolerance is 1e-6."""
    sol = solve_body(spheroid_body(aspect, 1.0))
    exact = spheroid_added_mass_coefficient(aspect, 1.0)
    assert sol.unknowns <= 400
    assert sol.added_mass_coefficient == pytest.approx(exact, rel=1e-6, abs=0)


def test_sphere_added_mass_is_one_half_to_round_off():
    sol = solve_body(sphere_body(2.0))
    assert sol.added_mass_coefficient == pytest.approx(0.5, abs=1e-11)


@pytest.mark.parametrize("aspect", [1.0, 4.0])
def test_surface_potential_of_spheroid_is_k1_x(aspect):
    """On a spheroid the exact surface potential is k1 x (unit speed): pointwise to 1e-7 of max|phi|."""
    sol = solve_body(spheroid_body(aspect, 1.0))
    k1 = spheroid_added_mass_coefficient(aspect, 1.0)
    n = sol.nodes
    assert np.abs(n.phi - k1 * n.x).max() <= 1e-7 * np.abs(k1 * n.x).max()


def test_convergence_is_spectral_on_a_4_to_1_spheroid():
    """Doubling the panels must cut the error by far more than the 2^2 of a low-order method."""
    exact = spheroid_added_mass_coefficient(4.0, 1.0)
    e1 = abs(solve_body(spheroid_body(4.0, 1.0), refinement=0.5).added_mass_coefficient / exact - 1)
    e2 = abs(solve_body(spheroid_body(4.0, 1.0), refinement=1.0).added_mass_coefficient / exact - 1)
    assert e2 < e1 / 50


@pytest.mark.parametrize("distance", [3.0, 1.1, 1.01, 1.001, 1.0001])
def test_field_of_sphere_near_and_far(distance):
    """Potential and velocity at field points, down to 1e-4 radii from the surface (eq. (23))."""
    a = 1.0
    sol = solve_body(sphere_body(2 * a))
    th = np.linspace(0.0, np.pi, 157)
    pts = np.column_stack([distance * np.cos(th), distance * np.sin(th)])
    np.testing.assert_allclose(sol.potential(pts), sphere_potential(pts[:, 0], pts[:, 1], a), atol=1e-9)
    ge = np.column_stack(sphere_gradient(pts[:, 0], pts[:, 1], a))
    # |grad phi| ~ 1 near the surface; the graded near rules keep 1e-7 there
    np.testing.assert_allclose(sol.gradient(pts), ge, atol=1e-7)


def test_hemispherical_nose_at_depth_R_is_a_sphere():
    """At P = R the mirrored hemisphere is a full sphere with dphi/dn = -|cos theta|:
    phi_tip = 0.680633550050 a, Abar = 0.553967546980 a (Legendre series, numerical notes)."""
    a = 1.0
    sol = solve_halfspace(sphere_nose(2 * a), a)
    assert sol.phi_tip == pytest.approx(0.680633550050 * a, abs=1e-9)
    assert 4 * sol.A / (math.pi * (2 * a) ** 2) == pytest.approx(0.553967546980 * a, abs=1e-10)


def test_pulsating_sphere_through_the_mirror():
    """A source distribution dphi/dn = -1 on the mirrored sphere gives phi = a exactly."""
    a = 1.0
    layout = halfspace_layout(sphere_nose(2 * a), a)
    sol = solve_panels(layout.panels(), "halfspace", depth=a, neumann=lambda x, r, nx, nr: -np.ones_like(x))
    assert np.abs(sol.nodes.phi - a).max() < 1e-8


@pytest.mark.parametrize("nose", [OGIVE, SPHERE], ids=["ogive", "sphere"])
@pytest.mark.parametrize("frac", [0.05, 0.5, 3.0])
def test_C_is_the_projected_contact_area(nose, frac):
    """C = integral n_x dS = pi r(x=0)^2 exactly (Part I, eq. (14))."""
    P = frac * nose.length
    sol = solve_halfspace(nose, P, refinement=0.5)
    seg = nose.segments[0]
    if P < nose.length:
        from semianalytic.bem.panels import param_at_x

        r_cut = float(seg.point(param_at_x(seg, -P))[1])
    else:
        r_cut = nose.radius
    assert sol.C == pytest.approx(math.pi * r_cut**2, rel=1e-12)


@pytest.mark.parametrize("nose", [OGIVE, SPHERE], ids=["ogive", "sphere"])
@pytest.mark.parametrize("frac", [0.3, 2.0, 30.0])
def test_bernoulli_reading_equals_dA_dP(nose, frac):
    """Energy conservation: B_bernoulli = dA/dP (errata item 2a).  Both come from the same
    solves but through different formulas (surface integrals of phi'_P and |grad phi|^2,
    against the change of A); deep in the target both tend to 0, so the difference is
    measured against the size of the drag terms, B_literal.  Tolerance 1e-6 (the issue's)."""
    c = coefficients_at_depth(nose, frac * nose.length, LayoutOptions(refinement=0.5))
    assert abs(c.B_bernoulli - c.dA_dP) <= 1e-6 * abs(c.B_literal)


@pytest.mark.parametrize("frac", [0.05, 0.5, 2.0])
def test_phi_P_difference_step_is_converged(frac):
    """The default step (2nd-order central difference, STEP of the local length) against a
    4th-order difference with a 10x larger step: B agrees to 1e-7.  (A 10x smaller step
    reaches the round-off floor of the nodal potential, ~1e-7 of B, which is why the step
    is not smaller.)"""
    from semianalytic.coefficients.depth import _step

    P = frac * OGIVE.length
    opts = LayoutOptions(refinement=0.5)
    default = coefficients_at_depth(OGIVE, P, opts)
    fourth = coefficients_at_depth(OGIVE, P, opts, fd_order=4, step=10 * _step(OGIVE, P))
    for name in ("B_body", "B_literal", "B_bernoulli"):
        assert getattr(default, name) == pytest.approx(getattr(fourth, name), rel=1e-7, abs=1e-7 * abs(fourth.B_literal))


def test_deep_coefficients_against_the_paper():
    """Part I after eq. (36): Bbar = 0.58 (spherical) and 0.11 (ogival), Abar = 1.0 mm (ogival).

    The paper prints two digits, so the tolerance is half a unit of the last digit.  The
    spherical Abar = 1.5 mm is a known deviation (errata item 2c): converged it is ~1.585 mm,
    about 6% above the printed value; the test pins that deviation instead of hiding it."""
    area = math.pi * D**2 / 4
    ogive = coefficients_at_depth(OGIVE, 300 * OGIVE.length, LayoutOptions(refinement=0.5))
    sphere = coefficients_at_depth(SPHERE, 300 * SPHERE.length, LayoutOptions(refinement=0.5))
    assert ogive.B_body / area == pytest.approx(0.11, abs=0.005)
    assert sphere.B_body / area == pytest.approx(0.58, abs=0.01)
    assert ogive.A / area == pytest.approx(1.0e-3, abs=0.05e-3)
    assert 0.05 < (sphere.A / area) / 1.5e-3 - 1 < 0.07
    # errata item 2a: the literal reading is about twice the quoted values
    assert ogive.B_literal / ogive.B_body == pytest.approx(2.0, rel=0.02)
    assert sphere.B_literal / sphere.B_body == pytest.approx(2.0, rel=0.02)


def _legendre_table(x, n):
    """P_0..P_n at x by the three-term recurrence."""
    P = np.zeros((n + 1,) + np.shape(x))
    P[0] = 1.0
    P[1] = x
    for k in range(1, n):
        P[k + 1] = ((2 * k + 1) * x * P[k] - k * P[k - 1]) / (k + 1)
    return P


def test_halfspace_field_of_hemisphere_at_depth_R():
    """The field of the mirrored hemisphere (a sphere with dphi/dn = -|cos theta|) is the
    exterior Legendre series phi = sum a c_n/(n+1) (a/R)^(n+1) P_n(cos theta), |mu| = sum c_n P_n.
    Outside R = 1.05 a, 900 terms converge below 1e-12 (gradient included); the BEM field (eqs. (20), (23) through
    the representation formula) must match the series to 1e-8, including on the free surface,
    where dphi/dx must vanish (the mirror condition)."""
    a, nmax = 1.0, 900
    g, w = np.polynomial.legendre.leggauss(600)
    mu, wm = (g + 1) / 2, w / 2
    Pm = _legendre_table(mu, nmax)
    n = np.arange(nmax + 1)
    c = np.where(n % 2 == 0, (2 * n + 1) * (Pm * (wm * mu)).sum(axis=1), 0.0)
    coef = a * c / (n + 1)

    def series(x, r):
        R = np.hypot(x, r)
        ct = x / R
        P = _legendre_table(ct, nmax + 1)
        radial = (a / R)[None, :] ** (n[:, None] + 1)
        phi = np.sum(coef[:, None] * radial * P[:-1], axis=0)
        dphi_dR = np.sum(-(n[:, None] + 1) / R * coef[:, None] * radial * P[:-1], axis=0)
        # dP_n/dtheta = -sin(theta) P_n'(cos theta), (1 - x^2) P_n' = (n + 1)(x P_n - P_{n+1})
        st = r / R
        dPdth = -(n[:, None] + 1) * (ct * P[:-1] - P[1:]) / np.where(st > 0, st, 1.0)
        dphi_dth = np.sum(coef[:, None] * radial * dPdth, axis=0)
        # grad in (x, r): e_R = (cos, sin), e_theta = (-sin, cos)
        gx = dphi_dR * ct - dphi_dth * st / R
        gr = dphi_dR * st + dphi_dth * ct / R
        return phi, np.column_stack([gx, gr])

    sol = solve_halfspace(sphere_nose(2 * a), a)
    th = np.linspace(0.05, np.pi / 2, 23)
    for R in (1.05, 1.3, 3.0):
        pts = np.column_stack([R * np.cos(th), R * np.sin(th)])
        phi, grad = series(pts[:, 0], pts[:, 1])
        np.testing.assert_allclose(sol.potential(pts), phi, atol=1e-8)
        # the Neumann datum has a kink at the equator, where the hemisphere meets its image,
        # so dphi/ds is not smooth there; next to it the gradient is good to ~5e-8
        np.testing.assert_allclose(sol.gradient(pts), grad, atol=1e-7)
    surface = np.column_stack([np.zeros(9), np.linspace(1.05, 3.0, 9)])
    assert np.abs(sol.gradient(surface)[:, 0]).max() < 1e-10
