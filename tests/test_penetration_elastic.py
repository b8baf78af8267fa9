"""Elastic projectile, Part I, eqs. (26), (28)-(30'), and the all-models curve.

Reference for the paper's W2 with constant coefficients (independent of the code): the
quasi-rigid velocity is the closed form ubar(t) = a tan(atan(U0/a) - a k t); W2 = K t with
K = pi d^2 sigma0^2 c0 / (8 E_p) (eq. (29)); the stop t* solves m ubar^2 = 2 K t and
P = int_0^t* sqrt(ubar^2 - 2 K t / m) dt (eq. (30')), both by scipy (brentq, quad).
"""

import math

import numpy as np
import pytest
from scipy import integrate, optimize

from semianalytic.coefficients import ConstantCoefficients
from semianalytic.penetration import elastic as el
from semianalytic.penetration import rod as rodmod
from semianalytic.penetration.curve import PenetrationSetup, penetration_curve

D = 7.11e-3
COEF = ConstantCoefficients.from_normalised(1.0e-3, 0.11, 1.0, D)
M, RHO, RT = 0.0204, 2710.0, 1.4535e9
ROD = rodmod.Rod(0.0711, D, 210e9, 7830.0)


def _start(U_s):
    A, B, C = COEF.A_m3, COEF.B_m2, COEF.C_m2
    area = math.pi * D**2 / 4
    sigma = lambda u: M * (0.5 * RHO * B * u * u + C * RT) / (M + RHO * A) / area  # noqa: E731
    U0 = optimize.brentq(lambda u: u - (U_s - sigma(u) * ROD.c0 / ROD.youngs_modulus), 0, U_s, xtol=1e-14)
    return U0, sigma(U0)


def _reference_paper_W2(U_s):
    U0, s0 = _start(U_s)
    A, B, C = COEF.A_m3, COEF.B_m2, COEF.C_m2
    k = RHO * B / (2 * (M + RHO * A))
    a = math.sqrt(2 * C * RT / (RHO * B))
    ub = lambda t: a * math.tan(math.atan(U0 / a) - a * k * t)  # noqa: E731
    K = math.pi * D**2 * s0**2 * ROD.c0 / (8 * ROD.youngs_modulus)
    T = math.atan(U0 / a) / (a * k)
    t_star = optimize.brentq(lambda t: M * ub(t) ** 2 - 2 * K * t, 0, T, xtol=1e-16, rtol=1e-15)
    P = integrate.quad(lambda t: math.sqrt(max(ub(t) ** 2 - 2 * K * t / M, 0.0)), 0, t_star, epsabs=0, epsrel=1e-12, limit=200)[0]
    return U0, s0, t_star, P


@pytest.mark.parametrize("U_s", [600.0, 1147.0, 1700.0])
def test_paper_W2_against_the_closed_form_reference(U_s):
    U0, s0, t_star, P = _reference_paper_W2(U_s)
    r = el.solve_elastic(COEF, M, RHO, RT, U_s, ROD, w2="paper")
    assert r.U0 == pytest.approx(U0, rel=1e-12) and r.sigma0 == pytest.approx(s0, rel=1e-12)
    # time-domain ODE at rtol 1e-10, brentq and Gauss panels: 1e-8
    assert r.t_star == pytest.approx(t_star, rel=1e-8)
    assert r.final_depth == pytest.approx(P, rel=1e-8)
    curve = penetration_curve(PenetrationSetup(COEF, M, RHO, RT, ROD, 0.29, 2e9), [U_s])
    assert curve["depth_elastic_m"][0] == pytest.approx(P, rel=1e-8)
    assert curve["stop_time_elastic_s"][0] == pytest.approx(t_star, rel=1e-8)
    assert curve["start_velocity_m_s"][0] == pytest.approx(U0, rel=1e-12)


def test_fast_curve_matches_the_time_domain_for_every_option():
    setup = PenetrationSetup(COEF, M, RHO, RT, ROD, 0.29, 2e9)
    U = np.array([450.0, 900.0, 1500.0, 2100.0])
    for w1 in el.W1_MODELS:
        c = penetration_curve(setup, U, w1=w1)
        for i, u in enumerate(U):
            for w2, key in (("paper", "elastic"), ("exact-rod", "elastic_exact_rod")):
                r = el.solve_elastic(COEF, M, RHO, RT, u, ROD, poisson_ratio=0.29, w2=w2, w1=w1)
                # the exact-rod energy has kinks every L/c0 that the curve's Gauss panels do not
                # straddle (the time-domain quadrature does): 2e-6; W1 has one kink at P = L: 1e-7;
                # smooth integrands: 1e-8
                tol = 2e-6 if w2 == "exact-rod" else (1e-8 if w1 == "neglect" else 1e-7)
                assert c[f"depth_{key}_m"][i] == pytest.approx(r.final_depth, rel=tol)
                assert c[f"stop_time_{key}_s"][i] == pytest.approx(r.t_star, rel=1e-9)
            assert c["depth_quasi_rigid_m"][i] == pytest.approx(r.quasi_rigid.final_depth, rel=1e-8)
            assert c["time_quasi_rigid_s"][i] == pytest.approx(r.quasi_rigid.penetration_time, rel=1e-8)


def test_model_ordering_and_energy_bounds():
    setup = PenetrationSetup(COEF, M, RHO, RT, ROD, 0.29, 2e9)
    c = penetration_curve(setup, np.linspace(300, 2000, 12))
    assert np.all(c["depth_quasi_rigid_m"] < c["depth_rigid_m"])
    assert np.all(c["depth_elastic_exact_rod_m"] < c["depth_quasi_rigid_m"])
    # the paper's W2 grows with t and exceeds the bounded exact-rod energy: shallower
    assert np.all(c["depth_elastic_m"] < c["depth_elastic_exact_rod_m"])
    # errata item 5(b): W1's bound over W2's exact maximum is 2 (1 - nu_p)
    s0 = 1.6e9
    W1 = el.lateral_energy("bound", 1.0, sigma0=s0, resistance_pa=RT, rod=ROD, poisson_ratio=0.29)
    assert W1 / rodmod.max_vibrational_energy(ROD, s0) == pytest.approx(2 * (1 - 0.29), rel=1e-12)


def test_corrected_velocity_eq30():
    assert el.corrected_velocity(1000.0, 0.5 * 0.02 * 1000.0**2 * 0.19, 0.02) == pytest.approx(1000 * math.sqrt(0.81), rel=1e-14)
    assert el.corrected_velocity(10.0, 1e3, 0.02) == 0.0


def test_no_penetration_below_the_elastic_jump():
    # U_s <= sigma0 c0 / E_p: the quasi-rigid start velocity (26) is zero
    setup = PenetrationSetup(COEF, M, RHO, RT, ROD, 0.29, 2e9)
    c = penetration_curve(setup, [5.0, 20.0])
    assert np.all(c["start_velocity_m_s"] == 0.0) and np.all(c["depth_quasi_rigid_m"] == 0.0)
    assert np.all(c["depth_elastic_m"] == 0.0) and np.all(c["depth_rigid_m"] > 0)


class _UniformPressure:
    """Constant coefficients with a flat contact-pressure profile p_c = R_t over the submerged length."""

    def __init__(self):
        self.diameter = COEF.diameter

    def A(self, P):
        return COEF.A(P)

    def B(self, P):
        return COEF.B(P)

    def C(self, P):
        return COEF.C(P)

    def pressure_profile(self, P, rho, u, du_dt, R_t, reading=None):
        x = np.linspace(0.0, P, 41)
        return x, np.full_like(x, R_t)


def test_W1_from_a_pressure_profile_reduces_to_the_static_form():
    # with p_c = R_t everywhere, eq. (28) is e(R_t) min(P, L): the "static" closed form
    P = np.array([0.01, 0.05, 0.0711, 0.2])
    for p in P:
        x, pc = _UniformPressure().pressure_profile(p, RHO, 0, 0, RT)
        ref = el.lateral_energy("static", p, sigma0=0.0, resistance_pa=RT, rod=ROD, poisson_ratio=0.29)
        assert el.lateral_energy_from_profile(x, pc, p, ROD, 0.29) == pytest.approx(ref, rel=1e-12)
    a = el.solve_elastic(_UniformPressure(), M, RHO, RT, 1000.0, ROD, w2="paper", w1="pressure")
    b = el.solve_elastic(COEF, M, RHO, RT, 1000.0, ROD, w2="paper", w1="static")
    # W1 sampled at 201 times and interpolated linearly (kink at P = L): 1e-6
    assert a.final_depth == pytest.approx(b.final_depth, rel=1e-6)
