"""``penetrate`` command: JSON keys and values against closed forms, the Appendix through the
CLI, the bundled data set, bad input (exit status 2, field named, nothing written) and report
overwrite protection.  Uses the paper's constant coefficients (--coefficients paper), with which
eq. (11) has the closed form P = (m + rho A)/(rho B) ln(1 + rho B U^2/(2 C R_t)) (Part IV,
eq. (3) with errata item 23) and eq. (36) is explicit.
"""

import json
import math
from pathlib import Path

import pytest
from case_blocks import TARGET_6061_T651

from semianalytic.cli import main

D = 7.11e-3
AREA = math.pi * D**2 / 4
CASE = """
title = "cli test"
[projectile]
nose = "ogive"
crh = 3.0
diameter = "7.11 mm"
shank_length = "59.3 mm"
mass = "20.4 g"
density = "7830 kg/m^3"
youngs_modulus = "210 GPa"
poisson_ratio = 0.29
yield_stress = "1.64 GPa"
""" + TARGET_6061_T651 + """[impact]
striking_velocities = ["600 m/s", "1.0 km/s", "1.3 km/s"]
"""


def _write(tmp_path, text, name="case.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def _run(capsys, *argv):
    code = main(["penetrate", *map(str, argv)])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_json_keys_and_closed_form(tmp_path, capsys):
    code, out, err = _run(capsys, _write(tmp_path, CASE), "--json", "--coefficients", "paper")
    assert code == 0, err
    res = json.loads(out)
    for key in ("striking_velocity_m_s", "depth_rigid_m", "depth_quasi_rigid_m", "depth_elastic_m",
                "depth_elastic_exact_rod_m", "critical_velocity_m_s", "yields"):
        assert len(res[key]) == 3, key
    m, rho = 20.4e-3, 2710.0
    A, B, C = 1.0e-3 * AREA, 0.11 * AREA, 1.0 * AREA
    R = 2 / 3 * 400e6 * (1 + math.log(68.9e9 / (3 * 400e6 * 0.67)))
    for U, P in zip(res["striking_velocity_m_s"], res["depth_rigid_m"]):
        # spectral panel quadrature + Newton root: 1e-10
        assert P == pytest.approx((m + rho * A) / (rho * B) * math.log1p(rho * B * U**2 / (2 * C * R)), rel=1e-10)
    c0 = math.sqrt(210e9 / 7830)
    Ybar = (1 + rho * A / m) * 1.64e9
    UsC = 1.64e9 * c0 / 210e9 + math.sqrt(2 / (rho * 0.11) * (Ybar - R))  # eq. (36) by hand
    assert res["critical_velocity_m_s"][0] == pytest.approx(UsC, rel=1e-12)
    # Part I's own criterion is the diagnostic part1_critical_exceeded; yields follows the verdict (issue 36 item 7)
    assert res["part1_critical_exceeded"] == [U >= UsC for U in res["striking_velocity_m_s"]] == [False, False, True]
    assert res["yields"] == [r != "rigid" for r in res["regime"]]
    assert all(e <= q <= r for e, q, r in zip(res["depth_elastic_m"], res["depth_quasi_rigid_m"], res["depth_rigid_m"]))


def test_text_output_flags_yielding(tmp_path, capsys):
    code, out, err = _run(capsys, _write(tmp_path, CASE), "--coefficients", "paper")
    assert code == 0, err
    assert "U_sC" in out and "YES (outside the model)" not in out  # issue 36 item 7: no verdict beside a contrary flag
    from semianalytic.penetration.regime_setup import DEFAULT_REGIME_RULE

    assert f"Part I's U_s >= U_sC (eqs. (33)/(36); not used by the {DEFAULT_REGIME_RULE} rule) at U_s = " in out


def test_appendix_inverse_problem_through_the_cli(tmp_path, capsys):
    # the Appendix inputs with its printed R_t and the cylinder mass: Y_p = 2146 MPa (errata item 3)
    L = 74.675e-3
    text = f"""
[projectile]
nose = "sphere"
diameter = "7.11 mm"
shank_length = "{(L - D / 2) * 1e3:.6f} mm"
mass = "{8000 * AREA * L * 1e3:.9f} g"
density = "8000 kg/m^3"
youngs_modulus = "210 GPa"
[target]
density = "2710 kg/m^3"
[target.resistance]
model = "constant"
value = "1455 MPa"
[impact]
striking_velocities = ["1000 m/s"]
[data]
critical_velocity = "1000 m/s"
"""
    code, out, err = _run(capsys, _write(tmp_path, text), "--json", "--coefficients", "paper")
    assert code == 0, err
    res = json.loads(out)
    assert res["yield_stress_from_critical_velocity_Pa"] / 1e6 == pytest.approx(2146, abs=0.5)
    assert res["critical_velocity_m_s"][0] == pytest.approx(1000.0, rel=1e-9)


def test_bundled_piekutowski_data():
    from semianalytic.case import load_case
    from semianalytic.penetration.validation import error_statistics, load_shots

    root = Path(__file__).resolve().parents[1] / "cases"
    var = load_shots(load_case(root / "piekutowski1999_var4340.toml"))
    aer = load_shots(load_case(root / "piekutowski1999_aermet100.toml"))
    # the data README: 14 rigid-regime shots (7 per steel); 1-0415: 569 m/s, 58 mm, 20.38 g
    assert len(var) == 7 and len(aer) == 7
    first = min(var, key=lambda s: s.velocity)
    assert (first.id, first.velocity, first.depth, first.mass) == ("1-0415", 569.0, pytest.approx(0.058), pytest.approx(0.02038))
    st = error_statistics([{"measured_m": 1.0, "rigid": 1.1}, {"measured_m": 2.0, "rigid": 1.8}], models=("rigid",))
    assert st["rigid"]["mean"] == pytest.approx(0.0) and st["rigid"]["max_abs"] == pytest.approx(0.1)
    assert st["rigid"]["rms"] == pytest.approx(0.1)


@pytest.mark.parametrize(
    "old, new, field",
    [
        ('model = "elastic-plastic"', 'model = "plasticine"', "target.resistance"),
        ('youngs_modulus = "210 GPa"\n', "", "projectile.youngs_modulus"),
        ('yield_stress = "1.64 GPa"\n', "", "projectile.yield_stress"),
        ('"600 m/s"', '"-600 m/s"', "impact.striking_velocities"),
        ('"600 m/s"', '"0 m/s"', "impact.striking_velocities"),
        ('yield_stress = "400 MPa"\n', "", "target.resistance"),
        ('[target.resistance]\nmodel = "elastic-plastic"\nyield_stress = "400 MPa"\nyoungs_modulus = "68.9 GPa"\npoisson_ratio = 0.33\n',
         "", "target.resistance"),
    ],
)
def test_bad_input_exits_2_names_the_field_and_writes_nothing(tmp_path, capsys, old, new, field):
    assert old in CASE
    out_dir = tmp_path / "out"
    code, out, err = _run(capsys, _write(tmp_path, CASE.replace(old, new)), "--coefficients", "paper", "--report", out_dir)
    assert code == 2
    assert len(err.strip().splitlines()) == 1 and field in err
    assert not out_dir.exists()


def test_report_is_not_overwritten_without_force(tmp_path, capsys):
    case = _write(tmp_path, CASE.replace('["600 m/s", "1.0 km/s", "1.3 km/s"]', '["1.0 km/s"]'))
    out_dir = tmp_path / "rep"
    code, _, err = _run(capsys, case, "--coefficients", "paper", "--report", out_dir, "--report-name", "r")
    assert code == 0, err
    md = out_dir / "r.md"
    text = md.read_text()
    assert "Histories at one striking velocity" in text and (out_dir / "r_fig9_velocity_time.png").exists()
    code, _, err = _run(capsys, case, "--coefficients", "paper", "--report", out_dir, "--report-name", "r")
    assert code == 2 and "--force" in err
    assert md.read_text() == text
    code, _, err = _run(capsys, case, "--coefficients", "paper", "--report", out_dir, "--report-name", "r", "--force")
    assert code == 0, err
