"""Eq. (11) with a (small) BEM coefficient table: the two integrations agree, and the
Bernoulli reading of B (errata item 2a: B = dA/dP, here dA/dP of the table's own A
interpolant) conserves energy exactly.

Energy check (independent of both integrators): with B = dA/dP, eq. (11) is
d/dt [ (m + rho A(P)) u^2 / 2 ] = -C(P) R_t u, and A(0) = 0, so the projectile stops where
int_0^P_f C(P) dP = m U_0^2 / (2 R_t); the integral is taken by scipy quad of the table's C.
"""

import numpy as np
import pytest
from scipy import integrate, optimize

from semianalytic.coefficients.table import coefficient_table
from semianalytic.geometry import ogive_nose
from semianalytic.penetration.curve import PenetrationSetup, penetration_curve
from semianalytic.penetration.elastic import solve_elastic
from semianalytic.penetration.motion import final_depth, solve_motion
from semianalytic.penetration.rod import Rod

M, RHO, RT = 0.0204, 2710.0, 1.4535e9


@pytest.fixture(scope="module")
def table():
    # a coarse table (16 depths, order 6): these tests check the dynamics, not the BEM accuracy
    return coefficient_table(ogive_nose(7.11e-3, 3.0), n_depths=16, max_depth_nose_lengths=30, order=6, refinement=0.5)


def test_time_and_depth_integrations_agree_on_the_table(table):
    U = np.array([300.0, 1100.0])
    Pf = final_depth(table, M, RHO, RT, U)
    for u0, p in zip(U, Pf):
        r = solve_motion(table, M, RHO, RT, u0, rtol=1e-11)
        # adaptive RK across the table's C^1 knots (its error estimate cannot see the jumps of
        # the second derivative there) vs panel quadrature aligned with them: measured up to
        # ~6e-8 depending on the table, hence 1e-7 (the issue asks for 1e-6)
        assert r.final_depth == pytest.approx(p, rel=1e-7)


class _DerivativeReading:
    """The table with B = dA/dP of its own A interpolant (the Bernoulli reading, exactly)."""

    def __init__(self, table):
        self.t = table
        self.diameter = table.diameter
        self.depth = table.depth

    def A(self, P):
        return self.t.A(P)

    def B(self, P):
        return self.t.dA_dP(P)

    def C(self, P):
        return self.t.C(P)


def test_bernoulli_reading_conserves_energy(table):
    tb = _DerivativeReading(table)
    U0 = 900.0
    Pf = float(final_depth(tb, M, RHO, RT, U0))
    knots = list(tb.depth[tb.depth < 1.2 * Pf])
    CI = lambda P: integrate.quad(lambda s: float(tb.C(s)), 0, P, points=[k for k in knots if k < P], limit=400, epsabs=0, epsrel=1e-12)[0]  # noqa: E731
    target = M * U0**2 / (2 * RT)
    P_energy = optimize.brentq(lambda P: CI(P) - target, 1e-6, 2 * Pf, xtol=1e-14)
    # panel quadrature vs quad + brentq: 1e-10
    assert Pf == pytest.approx(P_energy, rel=1e-10)
    r = solve_motion(tb, M, RHO, RT, U0, rtol=1e-11)
    # time integration across the interpolant's C^1 knots, where the embedded error estimate
    # cannot see the jumps of the second derivative: measured 1e-8..3e-8, hence 1e-7
    assert r.final_depth == pytest.approx(P_energy, rel=1e-7)


def test_elastic_curve_matches_time_domain_on_the_table(table):
    rod = Rod(0.0711, 7.11e-3, 210e9, 7830.0)
    c = penetration_curve(PenetrationSetup(table, M, RHO, RT, rod, 0.29, 1.64e9), [1000.0])
    r = solve_elastic(table, M, RHO, RT, 1000.0, rod, w2="paper", rtol=1e-11)
    assert c["depth_elastic_m"][0] == pytest.approx(r.final_depth, rel=1e-7)  # two methods, 1e-8 each
    assert c["depth_quasi_rigid_m"][0] == pytest.approx(r.quasi_rigid.final_depth, rel=1e-7)  # as above
