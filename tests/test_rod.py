"""The rod of Part I, eq. (24): closed form against the paper's series and against an
independent d'Alembert construction; energies (eq. (29), errata item 5).

d'Alembert (independent of the code): a compressive step sigma0 applied at x = L at t = 0
sends fronts back and forth; at a point x the k-th front (k = 0, 1, ...) passes at
t_k = (2 L floor(k/2) + L - x)/c0 (k even) or (2 L floor(k/2) + L + x)/c0 (k odd).  Every front
adds sigma0/(rho c0) to the particle speed (towards -x), and the stress is -sigma0 after an
odd number of fronts, 0 after an even number.
"""

import math

import numpy as np
import pytest

from semianalytic.penetration import rod as R

ROD = R.Rod(length=0.0711, diameter=7.11e-3, youngs_modulus=210e9, density=7830.0)
S0 = 1.6e9


def _fronts_passed(x, t, rod=ROD):
    L, c = rod.length, rod.c0
    k = np.arange(0, 200)
    tk = np.where(k % 2 == 0, 2 * L * (k // 2) + L - x, 2 * L * (k // 2) + L + x) / c
    return int(np.sum(tk < t))


# points away from fronts (the series converges pointwise there)
XS = np.array([0.013, 0.029, 0.041, 0.057]) * (ROD.length / 0.0711)
TS = np.array([0.37, 1.21, 1.83, 2.66, 5.12]) * ROD.length / ROD.c0


def test_closed_form_equals_the_papers_series():
    x, t = np.meshgrid(XS, TS)
    w_closed = R.displacement(ROD, S0, x, t)
    w_series = R.displacement(ROD, S0, x, t, terms=4000)
    # the displacement series converges like 1/i^2: the tail after n terms is below 2 sigma0 L/(pi^2 E n)
    tail = 2 * S0 * ROD.length / (math.pi**2 * ROD.youngs_modulus * 4000)
    np.testing.assert_allclose(w_closed, w_series, rtol=0, atol=2 * tail)
    e_closed = R.strain(ROD, S0, x, t)
    e_series = R.strain(ROD, S0, x, t, terms=200000)
    # the strain series (27) converges like 1/i (conditionally): 2e-4 of sigma0/E after 2e5 terms at these points
    np.testing.assert_allclose(e_closed, e_series, rtol=0, atol=2e-4 * S0 / ROD.youngs_modulus)


def test_velocity_and_strain_match_dalembert():
    unit_v = S0 / (ROD.density * ROD.c0)
    for x in XS:
        for t in TS:
            n = _fronts_passed(x, t)
            # exact piecewise-constant fields: round-off only
            assert R.velocity(ROD, S0, x, t) == pytest.approx(-n * unit_v, rel=1e-12, abs=1e-12 * unit_v)
            assert R.strain(ROD, S0, x, t) == pytest.approx(-(n % 2) * S0 / ROD.youngs_modulus, abs=1e-15)


def test_end_motion_of_eq25_during_the_first_round_trip():
    t = np.linspace(0.0, 2 * ROD.length / ROD.c0, 50)[1:-1]
    v0 = S0 * ROD.c0 / ROD.youngs_modulus
    np.testing.assert_allclose(R.end_velocity(ROD, S0, t), -v0, rtol=1e-12)
    np.testing.assert_allclose(R.end_displacement(ROD, S0, t), -v0 * t, rtol=1e-12)
    # later the loaded end moves faster (3 v0 after the first reflection returns): eq. (25) holds only for t < 2L/c0
    assert R.end_velocity(ROD, S0, 2.5 * ROD.length / ROD.c0) == pytest.approx(-3 * v0, rel=1e-12)


def test_rod_fully_compressed_at_odd_multiples_of_L_over_c0():
    # text after eq. (27): at t = (2i - 1) L/c0 the strain is -sigma0/E_p at every x (the front is
    # then exactly at the free end x = 0, where the value is a matter of convention: left out)
    x = np.linspace(0.0, ROD.length, 41)[1:]
    for i in (1, 2, 3):
        np.testing.assert_allclose(R.strain(ROD, S0, x, (2 * i - 1) * ROD.length / ROD.c0), -S0 / ROD.youngs_modulus, rtol=1e-12)


def test_energy_balance_of_the_exact_solution():
    # kinetic + strain energy integrated over x from the fields = work of the end force N |w(L, t)|;
    # minus the rigid-body kinetic energy (N t)^2/(2m) it is the vibrational energy (errata item 5)
    N = S0 * ROD.area
    x = np.linspace(0.0, ROD.length, 200001)
    for t in (0.4, 1.0, 1.7, 3.3, 6.05):
        t = t * ROD.length / ROD.c0
        v = R.velocity(ROD, S0, x, t)
        e = R.strain(ROD, S0, x, t)
        dens = 0.5 * ROD.density * ROD.area * v**2 + 0.5 * ROD.youngs_modulus * ROD.area * e**2
        total = float(np.sum(0.5 * (dens[1:] + dens[:-1]) * np.diff(x)))
        work = N * abs(float(R.end_displacement(ROD, S0, t)))
        vib = total - (N * t) ** 2 / (2 * ROD.mass)
        # trapezoid over piecewise-constant fields with a jump: error ~ one cell's share (1/200000)
        assert total == pytest.approx(work, rel=2e-5)
        assert float(R.vibrational_energy(ROD, S0, t)) == pytest.approx(vib, rel=1e-4, abs=1e-6 * work)


def test_vibrational_energy_is_bounded_and_periodic():
    Wmax = math.pi * ROD.diameter**2 * S0**2 * ROD.length / (8 * ROD.youngs_modulus)
    assert R.max_vibrational_energy(ROD, S0) == pytest.approx(Wmax, rel=1e-15)
    T = ROD.length / ROD.c0
    assert float(R.vibrational_energy(ROD, S0, T)) == pytest.approx(Wmax, rel=1e-12)
    assert float(R.vibrational_energy(ROD, S0, 2 * T)) == pytest.approx(0.0, abs=1e-12 * Wmax)
    t = np.linspace(0, 40 * T, 4001)
    W = R.vibrational_energy(ROD, S0, t)
    assert W.max() <= Wmax * (1 + 1e-12) and W.min() >= -1e-12 * Wmax
    np.testing.assert_allclose(R.vibrational_energy(ROD, S0, t + 2 * T), W, rtol=1e-9, atol=1e-9 * Wmax)


def test_paper_W2_is_half_the_end_work_during_the_first_trip_then_grows_without_bound():
    # eq. (29): W2 = N w(L, t)/2 with w(L, t) = sigma0 c0 t / E_p of eq. (25)
    N = S0 * ROD.area
    t = np.linspace(0, 2 * ROD.length / ROD.c0, 11)
    np.testing.assert_allclose(R.paper_W2(ROD, S0, t), 0.5 * N * np.abs(R.end_displacement(ROD, S0, t)), rtol=1e-12, atol=1e-30)
    long = 100 * ROD.length / ROD.c0
    # errata item 5: the paper's energy exceeds the exact one's bound by about c0 t / L at late times
    assert float(R.paper_W2(ROD, S0, long)) / R.max_vibrational_energy(ROD, S0) == pytest.approx(100.0, rel=1e-12)
