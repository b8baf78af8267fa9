"""Critical impact velocity, Part I, eqs. (31)-(36), buckling factor, Appendix inverse problem.

References: the Appendix's printed inputs and errata item 3 (Y_p = 2146 MPa), eq. (36)
written out by hand, and the defining properties of the Johnson-Euler column curve.
"""

import math

import pytest

from semianalytic.errors import InputError
from semianalytic.penetration import critical as crit

D, L = 7.11e-3, 74.675e-3
AREA = math.pi * D**2 / 4
APPENDIX = crit.CriticalInputs(
    youngs_modulus=210e9, density=8000.0, mass=8000.0 * AREA * L, diameter=D,
    A=1.5e-3 * AREA, B=0.58 * AREA, C=1.00 * AREA, target_density=2710.0, resistance_pa=1455e6,
)


def test_appendix_inverse_problem_gives_errata_value():
    # errata item 3: solving the Appendix equation with the printed inputs gives 2146 MPa
    # (the paper prints 2135, rounded); 4 significant figures -> 0.5 MPa
    assert crit.yield_stress_from_critical_velocity(1000.0, APPENDIX) / 1e6 == pytest.approx(2146, abs=0.5)


def test_eq36_by_hand():
    Yp = 2146e6
    c0 = math.sqrt(210e9 / 8000)
    assert c0 == pytest.approx(5123, abs=0.5)  # Appendix
    Ybar = (1 + 2710 * 1.5e-3 / (8000 * L)) * Yp  # eq. (35), 1.0068 Y_p in the Appendix
    assert Ybar / Yp == pytest.approx(1.0068, abs=5e-5)
    hand = Yp * c0 / 210e9 + math.sqrt(2 / (2710 * 0.58) * (Ybar - 1455e6))
    assert crit.critical_velocity(Yp, APPENDIX) == pytest.approx(hand, rel=1e-14)


def test_eq34_strong_target_branch():
    # Ybar_p < Rbar_t: U_sC = Y_p c0 / E_p (the classical rod-impact limit)
    Yp = 1.0e9
    assert crit.critical_velocity(Yp, APPENDIX) == pytest.approx(Yp * math.sqrt(210e9 / 8000) / 210e9, rel=1e-14)


def test_buckling_lowers_the_critical_velocity():
    lam = crit.slenderness(L, D)
    assert lam == pytest.approx(4 * L / D)
    phi = crit.johnson_euler_phi(lam, 210e9, 2146e6)
    assert 0 < phi < 1
    assert crit.critical_velocity(2146e6, APPENDIX, phi) < crit.critical_velocity(2146e6, APPENDIX)


def test_johnson_euler_curve_properties():
    E, Y = 210e9, 1.5e9
    lam_e = math.pi * math.sqrt(2 * E / Y)
    assert crit.johnson_euler_phi(0.0, E, Y) == 1.0
    assert crit.johnson_euler_phi(lam_e, E, Y) == pytest.approx(0.5, rel=1e-14)
    h = 1e-6 * lam_e  # both branches and their slopes meet at lambda_e
    left, right = crit.johnson_euler_phi(lam_e - h, E, Y), crit.johnson_euler_phi(lam_e + h, E, Y)
    assert (right - left) / (2 * h) == pytest.approx(-1 / lam_e, rel=1e-5)  # d/dlam of pi^2E/(lam^2 Y) at lam_e
    assert crit.johnson_euler_phi(3 * lam_e, E, Y) == pytest.approx(math.pi**2 * E / (9 * lam_e**2 * Y), rel=1e-14)


def test_table_phi_and_bad_tables():
    tab = [[0, 1.0], [50, 0.8], [100, 0.3]]
    assert crit.table_phi(25, tab) == pytest.approx(0.9)
    assert crit.table_phi(500, tab) == pytest.approx(0.3)
    assert crit.buckling_factor("table", 75, 210e9, 1e9, tab) == pytest.approx(0.55)
    for bad in ([[0, 1.0]], [[10, 1.0], [5, 0.5]], [[0, 1.0], [10, 1.5]]):
        with pytest.raises(InputError):
            crit.table_phi(1.0, bad)
    with pytest.raises(InputError):
        crit.buckling_factor("table", 10, 210e9, 1e9, None)


def test_inverse_with_yield_dependent_buckling_and_unreachable_velocity():
    lam = 20.0
    phi = lambda Y: float(crit.johnson_euler_phi(lam, 210e9, Y))  # noqa: E731
    Y = crit.yield_stress_from_critical_velocity(900.0, APPENDIX, phi)
    assert crit.critical_velocity(Y, APPENDIX, phi(Y)) == pytest.approx(900.0, rel=1e-10)
    with pytest.raises(InputError):
        crit.yield_stress_from_critical_velocity(1e6, APPENDIX, lambda Y: float(crit.johnson_euler_phi(200.0, 210e9, Y)))


def test_no_real_root_when_the_velocity_term_vanishes():
    """Issue 12 loose end: with the 'bernoulli' reading the deep B (= dA/dP) is round-off
    (-2e-14 m^2 on the Piekutowski ogive), eq. (33) has no real root and used to raise a math
    domain error.  By eq. (33) itself: with Bbar <= 0 the start stress rho B U^2/2 + C R_t never
    grows with U, so for Ybar_p >= Rbar_t no velocity yields the rod: U_sC = inf, the reason is
    stated, and the inverse problem is refused naming the option.  Eq. (34) is unaffected."""
    import dataclasses

    zero_b = dataclasses.replace(APPENDIX, B=-2.0e-14)
    assert crit.critical_velocity(2146e6, zero_b) == math.inf
    assert crit.critical_velocity(2146e6, dataclasses.replace(APPENDIX, B=0.0)) == math.inf
    assert "no real root" in crit.no_real_root_reason(zero_b) and crit.no_real_root_reason(APPENDIX) is None
    weak = 1.0e9  # Ybar_p < Rbar_t: eq. (34), the elastic limit, as with any B
    assert crit.critical_velocity(weak, zero_b) == crit.critical_velocity(weak, APPENDIX)
    with pytest.raises(InputError) as e:
        crit.yield_stress_from_critical_velocity(1000.0, zero_b)
    assert e.value.field == "coefficients.reading"


def test_cli_bernoulli_reading_no_traceback(tmp_path, capsys):
    """Through penetrate with [coefficients] reading = 'bernoulli' (the failing case): exit 0,
    U_sC = null in the (strict) JSON, the reason on stderr; the rigid depths are still the model's."""
    import json
    import shutil
    from pathlib import Path

    from semianalytic.cli import main

    cases = Path(__file__).resolve().parents[1] / "cases"
    text = (cases / "piekutowski1999_var4340.toml").read_text().replace(
        "[target]\n", '[coefficients]\nreading = "bernoulli"\n\n[target]\n', 1)
    (tmp_path / "bern.toml").write_text(text)
    shutil.copy(cases / "piekutowski1999_ogive_6061T6511.csv", tmp_path)
    code = main(["penetrate", str(tmp_path / "bern.toml"), "--json"])
    out = capsys.readouterr()
    assert code == 0, out.err
    res = json.loads(out.out, parse_constant=lambda c: pytest.fail(f"not strict JSON: {c}"))  # jq/JavaScript read it
    assert res["critical_velocity_m_s"][0] is None and not any(res["yields"])
    assert "eq. (33) has no real root" in out.err and "Traceback" not in out.err
    assert all(d > 0 for d in res["depth_rigid_m"])


@pytest.mark.parametrize("B", [0.58 * AREA, -2.0e-14, 0.0])
@pytest.mark.parametrize("Y_p", [2146e6, 1.0e9])
def test_array_form_equals_the_scalar_form(B, Y_p):
    """The Monte-Carlo kernel's array U_sC (penetration/batch.py) against critical_velocity, also
    where eq. (33) has no real root (Bbar <= 0: inf in both, no warning) and under eq. (34)."""
    import dataclasses
    import warnings

    import numpy as np

    from semianalytic.penetration.batch import critical_velocities

    c = dataclasses.replace(APPENDIX, B=B)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        got = critical_velocities(Y_p, c.youngs_modulus, np.array([c.density]), np.array([c.mass]), c.diameter, c.A,
                                  c.B, c.C, np.array([c.target_density]), np.array([c.resistance_pa]))
    assert got[0] == pytest.approx(crit.critical_velocity(Y_p, c), rel=1e-14)
