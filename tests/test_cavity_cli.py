"""`python -m semianalytic cavity`: JSON keys, bundled cases, bad input (exit 2, one line naming
the field, nothing written).  Numbers are checked against errata item 19 (independent)."""

import json
from pathlib import Path

import pytest

from semianalytic.cli import main

ROOT = Path(__file__).resolve().parents[1]
CASE = """
[material]
youngs_modulus = "373.14 GPa"
poisson_ratio = 0.232
tensile_strength = "0.262 GPa"
compressive_strength = "2.62 GPa"
{extra}
"""


def run_cli(capsys, *argv):
    code = main(["cavity", *map(str, argv)])
    out, err = capsys.readouterr()
    return code, out, err


def test_json_keys_and_values(capsys):
    code, out, err = run_cli(capsys, ROOT / "cases" / "cavity_ad995.toml", "--json")
    assert code == 0, err
    data = json.loads(out)
    for key in ("sigma_star_Pa", "theta_star", "theta_k", "a_over_b", "c_over_b", "cavity_pressure_Pa", "iterations"):
        assert key in data
    # errata item 19, half a unit in the last printed digit
    assert data["sigma_star_Pa"] == pytest.approx(-10.88e9, abs=0.005e9)
    assert data["cavity_pressure_Pa"] == pytest.approx(11.6e9, abs=0.05e9)


def test_fixed_point_option_and_default_bulk_modulus(tmp_path, capsys):
    case = tmp_path / "c.toml"
    case.write_text(CASE.format(extra=""))  # K_s defaults to E/(3(1-2 nu)) = 232.05 GPa
    code, out, _ = run_cli(capsys, case, "--json", "--method", "fixed-point")
    assert code == 0
    data = json.loads(out)
    assert data["method"] == "fixed-point" and 40 <= data["iterations"] <= 70
    assert data["e_ks"] == pytest.approx(-10.88e9 / 232.05e9, rel=1e-3)


@pytest.mark.parametrize("name", ["cavity_sic.toml", "cavity_b4c.toml"])
def test_other_ceramics_run_and_warn(name, capsys):
    code, out, err = run_cli(capsys, ROOT / "cases" / name)
    assert code == 0
    assert "R_r (eq. 34)" in out
    assert "warning: theta_k" in err  # nu ~ 0.16-0.17: errata item 20 soft condition


@pytest.mark.parametrize(
    "extra, field",
    [
        ('initial_porosity = 1.5', "material.initial_porosity"),
        ('bulk_modulus = "231 m"', "material.bulk_modulus"),
        ('colour = "white"', "material.colour"),
        ('solver = "newton"', "material.solver"),
    ],
)
def test_bad_case_exit_2(tmp_path, capsys, extra, field):
    case = tmp_path / "bad.toml"
    case.write_text(CASE.format(extra=extra))
    before = sorted(p.name for p in tmp_path.iterdir())
    code, out, err = run_cli(capsys, case)
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and field in err
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_model_rejection_exit_2(tmp_path, capsys):
    case = tmp_path / "soft.toml"
    case.write_text(CASE.format(extra="").replace('"0.262 GPa"', '"20 GPa"'))
    code, _, err = run_cli(capsys, case)
    assert code == 2 and "material.tensile_strength" in err and "no cracked zone" in err


def test_missing_section_exit_2(tmp_path, capsys):
    case = tmp_path / "empty.toml"
    case.write_text('title = "nothing"\n')
    code, _, err = run_cli(capsys, case)
    assert code == 2 and "material" in err


def test_report_not_overwritten_without_force(tmp_path, capsys):
    from semianalytic.commands.cavity.report import main as report_main

    target = tmp_path / "part2_cavity.md"
    target.write_text("old\n")
    assert report_main(["--out", str(tmp_path)]) == 2
    assert target.read_text() == "old\n" and sorted(p.name for p in tmp_path.iterdir()) == [target.name]


@pytest.mark.slow
def test_report_builds(tmp_path):
    from semianalytic.commands.cavity.report import main as report_main

    assert report_main(["--out", str(tmp_path)]) == 0
    assert "Deviations and findings" in (tmp_path / "part2_cavity.md").read_text()
