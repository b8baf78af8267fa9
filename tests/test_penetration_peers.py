"""Peer models: Forrestal (cavity expansion), Chen & Li, Alekseevskii-Tate.

References: closed-form nose factors (ogive N* = (8 psi - 1)/(24 psi^2), hemisphere, cone),
direct numerical quadrature of Forrestal's depth integral, the algebraic identity of the
Chen-Li formula with the two-term Forrestal result for k = 0, and the hydrodynamic and
rigid-rod limits of the Tate equations (P = L sqrt(rho_p/rho_t); Part IV, eq. (3)).
"""

import math

import numpy as np
import pytest
from scipy import integrate

from semianalytic.geometry import cone_nose, ogive_nose, sphere_nose
from semianalytic.penetration import peers

D = 7.11e-3


@pytest.mark.parametrize("psi", [0.5, 1.0, 3.0, 6.0])
def test_ogive_nose_factor(psi):
    N1, N2 = peers.nose_factors(ogive_nose(D, psi))
    assert N2 == pytest.approx(peers.ogive_nose_factor(psi), rel=1e-12)  # 64-point Gauss on an arc


def test_sphere_and_cone_factors():
    assert peers.nose_factors(sphere_nose(D)) == pytest.approx((2 / 3, 1 / 2), rel=1e-12)
    th = 0.4
    N1, N2 = peers.nose_factors(cone_nose(D, th))
    assert (N1, N2) == pytest.approx((math.sin(th), math.sin(th) ** 2), rel=1e-12)


@pytest.mark.parametrize("B, C", [(0.983, 0.940), (0.0, 0.983), (2.5, 0.0), (40.0, 0.1)])
def test_forrestal_closed_form_against_quadrature(B, C):
    law = peers.CavityLaw(276e6, 5.04, B, C)
    N1, N2 = peers.nose_factors(ogive_nose(D, 3.0))
    a = D / 2
    for V in (300.0, 1147.0, 2500.0):
        f = lambda v: 0.0204 * v / (math.pi * a * a * 276e6 * (5.04 + B * N1 * math.sqrt(2710 / 276e6) * v + C * N2 * 2710 / 276e6 * v * v))  # noqa: E731
        ref = integrate.quad(f, 0, V, epsabs=0, epsrel=1e-13)[0]
        assert peers.forrestal_depth(0.0204, D, 2710, law, V, N1, N2) == pytest.approx(ref, rel=1e-10)


def test_chen_li_equals_two_term_forrestal_without_crater():
    N1, N2 = peers.nose_factors(ogive_nose(D, 3.0))
    U = np.array([400.0, 900.0, 1700.0])
    cl = peers.chen_li_depth(0.0204, D, 2710, 5.04 * 276e6, 0.983, N2, U)
    fo = peers.forrestal_depth(0.0204, D, 2710, peers.CavityLaw.two_term(276e6, 5.04, 0.983), U, N1, N2)
    np.testing.assert_allclose(cl, fo, rtol=1e-12)


def test_chen_li_is_continuous_at_the_crater_depth():
    # the two branches meet where X/d = k: find the impact velocity there by bisection
    k, N2 = 2.0, 0.5
    f = lambda V: peers.chen_li_depth(0.0204, D, 2400, 40e6, 1.0, N2, V) / D - k  # noqa: E731
    lo, hi = 1.0, 2000.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if f(mid) < 0 else (lo, mid)
    eps = 1e-6 * lo
    assert peers.chen_li_depth(0.0204, D, 2400, 40e6, 1.0, N2, lo + eps) == pytest.approx(
        peers.chen_li_depth(0.0204, D, 2400, 40e6, 1.0, N2, lo - eps), rel=1e-5)


def test_tate_hydrodynamic_limit():
    # equal strengths: u = v / (1 + sqrt(rho_t/rho_p)) at every v, so dP/dL = -u/(v - u) = -sqrt(rho_p/rho_t) and
    # P = (L - L_r) sqrt(rho_p / rho_t) exactly, whatever the deceleration; L_r = L exp(-k I(U)) is left when v = 0.
    # Y = 0.3 GPa: k U^2 = rho_p U^2 / Y = 81-510, inside the quadrature's range (regime.eroding_depth_per_length)
    for rho_p in (2700.0, 7850.0, 17000.0):
        r = peers.tate_penetration(0.1, rho_p, 3e8, 2700.0, 3e8, 3000.0)
        assert r.eroded and r.residual_length < 1e-6
        assert r.depth == pytest.approx((0.1 - r.residual_length) * math.sqrt(rho_p / 2700.0), rel=1e-8)


def test_tate_rigid_limit_is_part4_eq3():
    # a rod too strong to erode decelerates rigidly: P = (rho_p L / rho_t) ln(1 + rho_t V^2 / (2 R))
    r = peers.tate_penetration(0.0711, 7830.0, 50e9, 2710.0, 1.45e9, 1200.0)
    assert not r.eroded and r.residual_length == 0.0711
    assert r.depth == pytest.approx(7830 * 0.0711 / 2710 * math.log1p(2710 * 1200.0**2 / (2 * 1.45e9)), rel=1e-14)


def test_tate_eroding_rod_conserves_the_interface_balance():
    rho_p, Y_p, rho_t, R_t = 7830.0, 1.64e9, 2710.0, 1.45e9
    v = np.linspace(400, 3000, 7)
    u = peers.tate_interface_velocity(v, rho_p, Y_p, rho_t, R_t)
    np.testing.assert_allclose(0.5 * rho_p * (v - u) ** 2 + Y_p, 0.5 * rho_t * u**2 + R_t, rtol=1e-12)
    r = peers.tate_penetration(0.0711, rho_p, Y_p, rho_t, R_t, 2500.0)
    assert r.eroded and 0 < r.residual_length < 0.0711
    assert r.transition_velocity == pytest.approx(math.sqrt(2 * (Y_p - R_t) / rho_t), rel=1e-9)
