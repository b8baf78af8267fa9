"""Part II cavity model: zone fields against the equations they must satisfy (checked by finite
differences, i.e. independently of the closed forms), the AD995 example against the numbers
printed in the paper and in errata item 19, the two solvers against each other and against
eq. (21) itself, and the rejections/warnings of errata item 20.
"""

import math
import warnings

import numpy as np
import pytest

from semianalytic.cavity import BrittleMaterial, FixedPointDivergence, fixed_point_iteration, solve_cavity
from semianalytic.cavity.model import (
    comminuted_porosity_small,
    front_equation,
    front_velocity,
    iteration_map,
    iteration_slope,
    solve_front_stress_bracket,
    strength_factor,
)
from semianalytic.cavity.zones import (
    comminuted_zone,
    crack_front_ratio,
    cracked_zone,
    elastic_zone,
    front_strains,
    lame_cavity,
)
from semianalytic.errors import ModelError, ModelValidityWarning, model_field
from semianalytic.sections.cavity import MODEL_FIELDS

GPa = 1e9
AD995 = BrittleMaterial(373.14 * GPa, 0.232, 0.262 * GPa, 2.62 * GPa, 231.8 * GPa)


def d_dr(f, r, h):
    """Central difference; with h ~ 1e-5 r its truncation error is ~1e-10 relative."""
    return (f(r + h) - f(r - h)) / (2 * h)


# ---------------------------------------------------------------------------------- zone fields


def test_lame_cavity_satisfies_navier_equations():
    E, nu, a, p = 200 * GPa, 0.3, 0.01, 1 * GPa
    r = np.linspace(a, 10 * a, 7)
    h = 1e-6 * a
    u, sr, sp = lame_cavity(r, a, p, E, nu)
    dsr = d_dr(lambda x: lame_cavity(x, a, p, E, nu)[1], r, h)
    du = d_dr(lambda x: lame_cavity(x, a, p, E, nu)[0], r, h)
    # eq. (1) equilibrium, eq. (3) Hooke's law with eq. (2) strains; FD error ~1e-9 relative
    assert np.allclose(dsr + 2 * (sr - sp) / r, 0, atol=1e-7 * p / a)
    assert np.allclose(du, (sr - 2 * nu * sp) / E, rtol=1e-7)
    assert np.allclose(u / r, ((1 - nu) * sp - nu * sr) / E, rtol=1e-12)
    assert sr[0] == pytest.approx(-p, rel=1e-14)  # boundary condition at the cavity wall
    assert lame_cavity(1e6 * a, a, p, E, nu)[0] < 1e-15  # u(inf) = 0


def test_elastic_zone_eq5():
    m = AD995
    c = 0.02
    r = np.linspace(c, 5 * c, 9)
    u, sr, sp = elastic_zone(r, c, m)
    du = d_dr(lambda x: elastic_zone(x, c, m)[0], r, 1e-6 * c)
    dsr = d_dr(lambda x: elastic_zone(x, c, m)[1], r, 1e-6 * c)
    E, nu = m.youngs_modulus, m.poisson_ratio
    assert np.allclose(dsr + 2 * (sr - sp) / r, 0, atol=1e-7 * m.tensile_strength / c)
    assert np.allclose(du, (sr - 2 * nu * sp) / E, rtol=1e-7)
    assert np.allclose(u / r, ((1 - nu) * sp - nu * sr) / E, rtol=1e-12)
    assert sp[0] == pytest.approx(m.tensile_strength, rel=1e-14)  # eq. (4)
    # errata 7: the mean stress -(sigma_r + 2 sigma_phi)/3 vanishes, and so does e_r + 2 e_phi
    assert np.allclose(sr + 2 * sp, 0, atol=1e-6)
    assert np.allclose(du + 2 * u / r, 0, atol=1e-9)
    # the elastic zone is Lame's solution with cavity radius c and pressure 2 sigma_f
    assert np.allclose(elastic_zone(r, c, m), lame_cavity(r, c, 2 * m.tensile_strength, E, nu), rtol=1e-14)


def test_cracked_zone_eqs_9_to_13():
    m = AD995
    sigma_star = -10.88 * GPa
    b = 0.01
    c = b * float(crack_front_ratio(sigma_star, m.tensile_strength))  # eq. (13)
    r = np.linspace(b, c, 11)
    u, sr = cracked_zone(r, b, c, sigma_star, m)
    h = 1e-6 * b
    du = d_dr(lambda x: cracked_zone(x, b, c, sigma_star, m)[0], r, h)
    dsr = d_dr(lambda x: cracked_zone(x, b, c, sigma_star, m)[1], r, h)
    assert np.allclose(dsr + 2 * sr / r, 0, atol=1e-7 * abs(sigma_star) / b)  # eq. (9), sigma_phi = 0
    assert np.allclose(du, sr / m.youngs_modulus, rtol=1e-7)  # eq. (10) with errata 9: sigma_r = E du/dr
    assert sr[0] == pytest.approx(sigma_star, rel=1e-14)  # eq. (7)
    assert sr[-1] == pytest.approx(-2 * m.tensile_strength, rel=1e-12)  # eq. (8): continuity at r = c
    # u continuous across r = c with the elastic zone, eq. (6)
    assert u[-1] == pytest.approx(elastic_zone(c, c, m)[0], rel=1e-12)


def test_front_strains_eq14_against_fields():
    m = AD995
    sigma_star = -10.88 * GPa
    b = 0.01
    c = b * float(crack_front_ratio(sigma_star, m.tensile_strength))
    fs = front_strains(sigma_star, m)
    u_b = cracked_zone(b, b, c, sigma_star, m)[0]
    du_b = d_dr(lambda x: cracked_zone(x, b, c, sigma_star, m)[0], b, 1e-6 * b)
    assert fs["e_phi"] == pytest.approx(u_b / b, rel=1e-12)
    assert fs["e_r"] == pytest.approx(du_b, rel=1e-7)
    assert fs["e_c"] == pytest.approx(du_b + 2 * u_b / b, rel=1e-6)
    assert fs["gamma_c"] == pytest.approx(math.sqrt(2 / 3) * abs(du_b - u_b / b), rel=1e-7)


def test_front_velocity_is_du_b_db_and_equals_hoop_strain():
    """Errata 15: v* of eq. (26) is d u(b)/db following the front (c = b sqrt(-sigma*/2 sigma_f))
    and equals e_phi* at b + 0."""
    m = AD995
    sigma_star = -10.88 * GPa
    ratio = float(crack_front_ratio(sigma_star, m.tensile_strength))

    def u_front(b):
        return cracked_zone(b, b, b * ratio, sigma_star, m)[0]

    v = front_velocity(sigma_star, m)
    assert v == pytest.approx(d_dr(u_front, 0.01, 1e-7), rel=1e-7)
    assert v == pytest.approx(front_strains(sigma_star, m)["e_phi"], rel=1e-12)


def test_comminuted_zone_equilibrium_eq24():
    sigma_star, b, theta_k = -10.88 * GPa, 0.01, 0.0178
    r = np.linspace(0.3 * b, b, 9)
    sr, sp = comminuted_zone(r, b, sigma_star, theta_k)
    dsr = d_dr(lambda x: comminuted_zone(x, b, sigma_star, theta_k)[0], r, 1e-6 * b)
    assert np.allclose(dsr + 2 * (sr - sp) / r, 0, atol=1e-6 * abs(sigma_star) / b)  # eq. (1)
    # eq. (23) must satisfy the associated flow law of eq. (19), phi p = s psi tau, with
    # s = -sqrt(3/2), psi = 2(1-theta)^3/(3 theta), phi = (1-theta)^2
    p = (sr + 2 * sp) / 3
    tau = math.sqrt(2 / 3) * np.abs(sr - sp)
    psi, phi = 2 * (1 - theta_k) ** 3 / (3 * theta_k), (1 - theta_k) ** 2
    assert np.allclose(phi * p, -math.sqrt(1.5) * psi * tau, rtol=1e-12)


def test_eq21_follows_from_flow_surface_19():
    """Errata 11: with the right-hand side (2/3)(1 - theta) Y_s^2, solving both equations of
    (19) at the front (s = -sqrt(3/2)) numerically for sigma_r, sigma_phi gives sigma_r = -C Y_s."""
    from scipy.optimize import fsolve

    theta, Ys = 0.024, 2.62e9
    psi, phi, s = 2 * (1 - theta) ** 3 / (3 * theta), (1 - theta) ** 2, -math.sqrt(1.5)

    def equations(z):
        sr, sp = z * Ys
        p, tau = (sr + 2 * sp) / 3, math.sqrt(2 / 3) * abs(sr - sp)
        return [(p**2 / psi + tau**2 / phi) / Ys**2 - 2 / 3 * (1 - theta), (phi * p - s * psi * tau) / Ys]

    sr, sp = fsolve(equations, [-4.0, -3.9], xtol=1e-14) * Ys
    assert sr == pytest.approx(-float(strength_factor(theta)) * Ys, rel=1e-10)


# ---------------------------------------------------------------------------------- AD995


def test_ad995_reproduces_errata_19_and_printed_example():
    r = solve_cavity(AD995)
    assert r.warnings == ()
    # errata item 19 (4 digits): tolerances are half a unit in the last printed digit
    assert r.sigma_star / GPa == pytest.approx(-10.88, abs=0.005)
    assert r.theta_star == pytest.approx(0.0240, abs=0.00005)
    assert r.C == pytest.approx(4.15, abs=0.005)
    assert r.a_over_b == pytest.approx(0.299, abs=0.0005)
    assert r.theta_k == pytest.approx(0.0178, abs=0.00005)
    assert r.cavity_pressure / GPa == pytest.approx(11.6, abs=0.05)
    # the paper's own printed values (2 digits): e_c = 0.024, v* = 0.027, e_ks = -0.047,
    # e_k = -0.029, R_r = 11.63 GPa
    assert r.e_c == pytest.approx(0.024, abs=0.0005)
    assert r.v_star == pytest.approx(0.027, abs=0.0005)
    assert r.e_ks == pytest.approx(-0.047, abs=0.0005)
    assert r.e_k == pytest.approx(-0.029, abs=0.0005)
    assert r.cavity_pressure / GPa == pytest.approx(11.63, abs=0.03)  # printed uses theta_k rounded to 0.018
    # c/b from eq. (13), b/c <= 1 (errata 14)
    assert r.c_over_b == pytest.approx(math.sqrt(10.8818 / 0.524), rel=1e-4)


def test_ad995_printed_Ys_does_not_reproduce():
    """Errata 19: with the printed Y_s = 2.26 GPa, sigma* is -9.9 GPa, not the printed -10.9."""
    r = solve_cavity(BrittleMaterial(373.14 * GPa, 0.232, 0.262 * GPa, 2.26 * GPa, 231.8 * GPa))
    assert abs(r.sigma_star / GPa + 10.9) > 0.5


def test_root_satisfies_eq21_and_solvers_agree():
    sigma_b, it_b = solve_front_stress_bracket(AD995)
    x = -sigma_b
    # eq. (21) written out independently of the model's helpers
    E, nu, sf, Ys = 373.14 * GPa, 0.232, 0.262 * GPa, 2.62 * GPa
    e_c = x / E * (1 - (1 - nu) * math.sqrt(2 * sf / x))
    theta = 1 - math.exp(-e_c)
    assert x == pytest.approx(2 * (1 - theta) ** 1.5 / (3 * math.sqrt(theta)) * Ys, rel=1e-13)
    run = fixed_point_iteration(AD995)
    assert run.converged
    # errata 13: about 55 steps, damped oscillation
    assert 40 <= run.iterations <= 70
    steps = np.diff(np.array(run.iterates))
    assert np.all(steps[1:10] * steps[:9] < 0)  # alternating signs: oscillation
    assert run.sigma_star == pytest.approx(sigma_b, rel=1e-10)  # iteration stops at rtol 1e-12
    r_fp = solve_cavity(AD995, "fixed-point")
    assert r_fp.iterations == run.iterations
    assert r_fp.cavity_pressure == pytest.approx(solve_cavity(AD995).cavity_pressure, rel=1e-9)
    assert it_b < 20


def test_front_equation_strictly_increasing():
    """Errata 13: F(x) = x - C(theta*(x)) Y_s increases strictly on x > 2 (1 - nu)^2 sigma_f."""
    lo = 2 * (1 - AD995.poisson_ratio) ** 2 * AD995.tensile_strength
    xs = lo * np.geomspace(1 + 1e-6, 1e3, 400)
    F = np.array([front_equation(x, AD995) for x in xs])
    assert np.all(np.diff(F) > 0)


def test_iteration_slope_against_finite_difference():
    x = 10.88 * GPa
    h = 1e-5 * x
    fd = (iteration_map(x + h, AD995) - iteration_map(x - h, AD995)) / (2 * h)
    assert iteration_slope(x, AD995) == pytest.approx(fd, rel=1e-6)


def test_fixed_point_local_convergence_follows_slope():
    """Started next to the root, the iteration (22) converges iff |g'(x*)| < 1."""
    good = BrittleMaterial(373.14 * GPa, 0.2, 3.0 * GPa, 2.62 * GPa)  # g' ~ -0.82
    bad = BrittleMaterial(373.14 * GPa, 0.05, 5.0 * GPa, 2.62 * GPa)  # g' ~ -1.26
    for m, converges in ((good, True), (bad, False)):
        root, _ = solve_front_stress_bracket(m)
        slope = iteration_slope(-root, m)
        assert (abs(slope) < 1) == converges
        run = fixed_point_iteration(m, start=root * 1.001, max_iter=400)
        assert run.converged == converges


def test_fixed_point_divergence_is_reported_and_bracket_still_solves():
    m = BrittleMaterial(373.14 * GPa, 0.05, 5.0 * GPa, 2.62 * GPa)
    with pytest.raises(FixedPointDivergence) as err:
        solve_cavity(m, "fixed-point")
    assert err.value.field == "cavity.method" and "bracket" in err.value.message
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelValidityWarning)  # theta_k > theta* here
        r = solve_cavity(m)
    assert front_equation(-r.sigma_star, m) == pytest.approx(0, abs=1e-3)  # Pa, on ~1.6e10


def test_small_value_form_after_eq33():
    """Errata 18: theta* - e_c + e_k - sigma*/K_s is the first-order form of eq. (33); the
    remainder is second order in the strains (~e^2 ~ 1e-3 here, times O(1) factors)."""
    r = solve_cavity(AD995)
    approx = comminuted_porosity_small(r.theta_star, r.e_c, r.e_k, r.sigma_star, AD995)
    assert abs(approx - r.theta_k) < 2e-3
    # with the printed 3 (1 - nu)/E instead of 1/K_s the error is first order (~0.02)
    printed = r.theta_star - r.e_c + r.e_k - 3 * (1 - AD995.poisson_ratio) * r.sigma_star / AD995.youngs_modulus
    assert abs(printed - r.theta_k) > 1e-2


def test_exact_volume_balance_gives_dilatation():
    """Errata 17: counting the outward motion of r = b, the AD995 comminuted zone dilates."""
    r = solve_cavity(AD995)
    assert r.e_k < 0 < r.e_k_exact_balance
    assert r.a_over_b ** 3 == pytest.approx(r.v_star, rel=1e-12)  # errata 16


def test_strength_factor_limits():
    assert float(strength_factor(1.0)) == 0.0
    assert float(strength_factor(1e-8)) == pytest.approx(2 / (3 * 1e-4), rel=1e-7)


# ---------------------------------------------------------------------------------- errata 20


def test_no_cracked_zone_rejected():
    m = BrittleMaterial(373.14 * GPa, 0.232, 20 * GPa, 2.62 * GPa)
    with pytest.raises(ModelError) as err:
        solve_cavity(m)
    assert err.value.field == "cavity.tensile_strength"  # the model's name; the case layer maps it
    assert "no cracked zone" in err.value.message and "2 sigma_f" in err.value.message


def test_negative_theta_k_rejected():
    m = BrittleMaterial(373.14 * GPa, 0.36, 0.262 * GPa, 2.62 * GPa)
    with pytest.raises(ModelError) as err:
        solve_cavity(m)
    assert err.value.field == "cavity.poisson_ratio" and "theta_k" in err.value.message


def test_soft_conditions_warn():
    with pytest.warns(ModelValidityWarning, match="theta_k"):
        r = solve_cavity(BrittleMaterial(373.14 * GPa, 0.1, 0.262 * GPa, 2.62 * GPa))
    assert r.theta_k > r.theta_star and len(r.warnings) == 1
    with pytest.warns(ModelValidityWarning, match="not small"):
        solve_cavity(BrittleMaterial(100 * GPa, 0.25, 0.262 * GPa, 3.0 * GPa))


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"youngs_modulus": -1.0}, "cavity.youngs_modulus"),
        ({"poisson_ratio": 0.5}, "cavity.poisson_ratio"),
        ({"tensile_strength": 0.0}, "cavity.tensile_strength"),
        ({"compressive_strength": float("nan")}, "cavity.compressive_strength"),
        ({"bulk_modulus": -2.0}, "cavity.bulk_modulus"),
        ({"initial_porosity": 1.0}, "cavity.initial_porosity"),
    ],
)
def test_bad_material_names_field(kwargs, field):
    base = dict(youngs_modulus=373e9, poisson_ratio=0.23, tensile_strength=0.26e9, compressive_strength=2.6e9)
    with pytest.raises(ModelError) as err:
        BrittleMaterial(**{**base, **kwargs})
    assert err.value.field == field
    with pytest.raises(ModelError) as err, model_field(MODEL_FIELDS):  # the case layer's mapping
        BrittleMaterial(**{**base, **kwargs})
    assert err.value.field == field.replace("cavity.", "material.") and str(err.value).startswith("material.")


def test_default_bulk_modulus():
    m = BrittleMaterial(373.14 * GPa, 0.232, 0.262 * GPa, 2.62 * GPa)
    assert m.K_s == pytest.approx(373.14 * GPa / (3 * (1 - 2 * 0.232)), rel=1e-15)


def test_initial_porosity_lowers_front_stress():
    """theta_0 > 0 raises theta* (eq. 17) and so lowers C and |sigma*| (eq. 21)."""
    r0 = solve_cavity(AD995)
    r1 = solve_cavity(BrittleMaterial(373.14 * GPa, 0.232, 0.262 * GPa, 2.62 * GPa, 231.8 * GPa, 0.01))
    assert r1.theta_star > r0.theta_star and abs(r1.sigma_star) < abs(r0.sigma_star)


def test_fixed_point_fails_at_its_start_value_limit():
    """New finding (report): with sigma*_0 = -Y_s the iteration (22) cannot start once
    Y_s <= 2 (1 - nu)^2 sigma_f (e_c <= 0 at the start), although |g'(x*)| ~ 0.74 < 1 there;
    just inside that limit it converges."""
    nu, Ys = 0.2, 2.62 * GPa
    limit = Ys / (2 * (1 - nu) ** 2)
    outside = BrittleMaterial(373.14 * GPa, nu, 1.02 * limit, Ys)
    inside = BrittleMaterial(373.14 * GPa, nu, 0.9 * limit, Ys)
    root, _ = solve_front_stress_bracket(outside)
    assert abs(iteration_slope(-root, outside)) < 0.8
    run = fixed_point_iteration(outside)
    assert not run.converged and run.iterations == 0 and "domain" in run.reason
    assert fixed_point_iteration(inside).converged
