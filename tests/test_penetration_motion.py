"""Equation of motion, Part I, eq. (11): adaptive integration against the closed form of
Part IV, eqs. (2)-(3) with errata items 22-24 (constant A, B, C), against the second
method (P as the independent variable) for depth-dependent coefficients, and convergence
under tolerance refinement.

The closed-form references are written out here from the ODE du/dt = -k (u^2 + a^2),
k = rho B / (2 (m + rho A)), a^2 = 2 C R_t / (rho B), independently of the code.
"""

import math
from dataclasses import dataclass

import numpy as np
import pytest
from scipy import integrate

from semianalytic.coefficients import ConstantCoefficients
from semianalytic.penetration.motion import ConstantCoefficientSolution, depth_profile, final_depth, solve_motion

D = 7.11e-3
COEF = ConstantCoefficients.from_normalised(1.0e-3, 0.11, 1.0, D)  # the paper's ogive values
M, RHO, RT = 0.0204, 2710.0, 1.4535e9


def _k_a(coef=COEF):
    A, B, C = coef.A_m3, coef.B_m2, coef.C_m2
    k = RHO * B / (2 * (M + RHO * A))
    return k, math.sqrt(2 * C * RT / (RHO * B))


def _u_exact(U0, t):
    k, a = _k_a()
    return a * math.tan(math.atan(U0 / a) - a * k * t)


@dataclass(frozen=True)
class RampCoefficients:
    """Smooth depth-dependent A, B, C of the kind the BEM gives (nose entry over ell)."""

    diameter: float = D
    ell: float = 11.8e-3

    def _f(self, P):
        P = np.asarray(P, float)
        return (1 - np.exp(-P / self.ell))

    def A(self, P):
        return (COEF.A_m3 * (1 + 0.5 * np.exp(-np.asarray(P, float) / (3 * self.ell))))[()]

    def B(self, P):
        return (COEF.B_m2 * self._f(P) ** 2)[()]

    def C(self, P):
        return (COEF.C_m2 * self._f(P))[()]


@pytest.mark.parametrize("U0", [300.0, 1147.0, 2500.0])
def test_solve_motion_matches_the_closed_form(U0):
    r = solve_motion(COEF, M, RHO, RT, U0)
    k, a = _k_a()
    T = math.atan(U0 / a) / (a * k)
    Pf = math.log1p(U0**2 / a**2) / (2 * k)
    # rtol 1e-10 per step; accumulated over ~10-40 steps: 1e-8 relative
    assert r.penetration_time == pytest.approx(T, rel=1e-9)
    assert r.final_depth == pytest.approx(Pf, rel=1e-8)
    t = np.linspace(0, T, 17)
    P, u = r.at(t)
    u_ex = np.array([_u_exact(U0, x) for x in t])
    P_ex = np.log(np.cos(a * k * t) + U0 / a * np.sin(a * k * t)) / k  # errata item 24
    np.testing.assert_allclose(u, u_ex, rtol=0, atol=1e-8 * U0)
    np.testing.assert_allclose(P, P_ex, rtol=0, atol=1e-8 * Pf)
    # N = -m du/dt > 0 and equals m k (u^2 + a^2) on the steps
    np.testing.assert_allclose(r.force, M * k * (r.u**2 + a**2), rtol=1e-12)
    assert np.all(r.force > 0) and np.allclose(r.deceleration, -r.du_dt)


def test_closed_form_class_follows_errata_22_to_24():
    cf = ConstantCoefficientSolution(COEF.A_m3, COEF.B_m2, COEF.C_m2, M, RHO, RT, 1147.0)
    k, a = _k_a()
    t = np.linspace(0, cf.penetration_time, 9)
    np.testing.assert_allclose(cf.velocity(t), [_u_exact(1147.0, x) for x in t], rtol=0, atol=1e-9 * 1147)
    # P(t) of errata 24 is the integral of u(t) (quadrature of the exact u), P(u) of errata 23 too
    for x in t[1:]:
        Pq = integrate.quad(lambda s: _u_exact(1147.0, s), 0, x, epsabs=0, epsrel=1e-13)[0]
        assert float(cf.depth(x)) == pytest.approx(Pq, rel=1e-11)
        assert float(cf.depth_at_velocity(cf.velocity(x))) == pytest.approx(Pq, rel=1e-9)
    # the printed IV-(2) with the denominator a - u_s tan(g) does not satisfy the ODE (errata 22):
    # its initial slope is k (U^2 - a^2) instead of -k (U^2 + a^2)
    dt = 1e-9
    g = a * k * dt
    printed = a * (1147 - a * math.tan(g)) / (a - 1147 * math.tan(g))
    assert (printed - 1147) / dt == pytest.approx(k * (1147**2 - a**2), rel=1e-5)
    assert abs((printed - 1147) / dt / (-k * (1147**2 + a**2)) - 1) > 0.1


def test_uniform_deceleration_when_B_vanishes():
    coef = ConstantCoefficients(COEF.A_m3, 0.0, COEF.C_m2, D)
    r = solve_motion(coef, M, RHO, RT, 800.0)
    dec = COEF.C_m2 * RT / (M + RHO * COEF.A_m3)
    assert r.final_depth == pytest.approx(800.0**2 / (2 * dec), rel=1e-9)
    assert r.penetration_time == pytest.approx(800.0 / dec, rel=1e-9)


def test_vectorised_final_depth_matches_the_closed_form():
    U = np.linspace(50.0, 2000.0, 40)
    k, a = _k_a()
    ref = np.log1p(U**2 / a**2) / (2 * k)
    # integration in P to rtol 1e-12 and a Newton root: 1e-10
    np.testing.assert_allclose(final_depth(COEF, M, RHO, RT, U), ref, rtol=1e-10)
    assert final_depth(COEF, M, RHO, RT, 0.0) == 0.0


def test_two_methods_agree_for_depth_dependent_coefficients():
    coef = RampCoefficients()
    U = np.array([200.0, 700.0, 1300.0, 1900.0])
    Pf = final_depth(coef, M, RHO, RT, U)
    for u0, p in zip(U, Pf):
        r = solve_motion(coef, M, RHO, RT, u0, rtol=1e-12)
        assert r.final_depth == pytest.approx(p, rel=1e-9)  # two independent integrations, each ~1e-11
    prof = depth_profile(coef, M, RHO, RT, U.max())
    # u^2(P) from the P form against the time history
    r = solve_motion(coef, M, RHO, RT, 1300.0, rtol=1e-12)
    np.testing.assert_allclose(prof.speed2(1300.0, r.P[:-1]), r.u[:-1] ** 2, rtol=1e-8, atol=1e-8 * 1300.0**2)


def test_ode_results_converge_under_tolerance_refinement():
    # Target of the issue: results converge to <= 1e-6 relative under tolerance refinement.
    coef = RampCoefficients()
    ref = solve_motion(coef, M, RHO, RT, 1147.0, rtol=1e-13)
    prev = None
    for rtol in (1e-5, 1e-7, 1e-9, 1e-11):
        r = solve_motion(coef, M, RHO, RT, 1147.0, rtol=rtol)
        err = max(abs(r.final_depth / ref.final_depth - 1), abs(r.penetration_time / ref.penetration_time - 1))
        if prev is not None:
            assert err < prev  # refinement reduces the error
        prev = err
        if rtol <= 1e-7:
            assert err <= 1e-6
    assert prev <= 1e-9
