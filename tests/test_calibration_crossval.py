"""``calibrate --cross-validate`` on the bundled Piekutowski et al. (1999) shots: the figures
documented in reports/validation.md, held against the experiment (issue 12 targets).

Leave-one-out on the 7 VAR 4340 rigid shots and the transfer split to the 7 AerMet 100 rigid
shots (same 6061-T6511 target), for the physically consistent model (quasi-rigid start plus
exact-rod energy) and Forrestal's cavity-expansion model.  Tolerances: the documented values
come from the same seeds; they allow for the Monte-Carlo error of the 500-step refits (about
0.3 % on a median) and the exact-rod surrogate (0.4 %), i.e. 1 % absolute on mean errors; a
coverage of 7 shots moves in steps of 1/7, so it is held to the documented count.
"""

import json
import shutil
from pathlib import Path

import pytest

from semianalytic.cli import main

ROOT = Path(__file__).resolve().parents[1]

# reports/validation.md (python -m semianalytic calibrate cases/piekutowski1999_var4340.toml
# --cross-validate --diagnose --out reports/calibration_piekutowski1999 --report reports/validation.md)
DOCUMENTED = {
    "loo": {
        "elastic_exact_rod": {"mean_abs_error": 0.056, "mean_error": 0.006, "coverage_90": 6 / 7},
        "forrestal": {"mean_abs_error": 0.039, "mean_error": 0.001, "coverage_90": 6 / 7},
    },
    "transfer": {
        "elastic_exact_rod": {"mean_abs_error": 0.065, "mean_error": 0.060, "coverage_90": 7 / 7},
        "forrestal": {"mean_abs_error": 0.049, "mean_error": -0.014, "coverage_90": 5 / 7},
    },
}


@pytest.fixture(scope="module")
def cross_validation(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("cv")
    for name in ("piekutowski1999_var4340.toml", "piekutowski1999_aermet100.toml", "piekutowski1999_ogive_6061T6511.csv"):
        shutil.copy(ROOT / "cases" / name, tmp / name)
    out = tmp / "out"
    code = main(["calibrate", str(tmp / "piekutowski1999_var4340.toml"), "--out", str(out), "--cross-validate",
                 "--model", "elastic_exact_rod", "--model", "forrestal", "--quiet"])
    assert code == 0
    return json.loads((out / "cross_validation.json").read_text()), out


def test_issue_targets_leave_one_out(cross_validation):
    """Issue 12: the best physically consistent model's 90 % intervals cover 80-98 % of the
    held-out VAR 4340 shots and its median's mean |error| is at most 7 %."""
    cv, _ = cross_validation
    st = cv["loo"]["elastic_exact_rod"]["statistics"]
    assert st["n"] == 7
    assert 0.80 <= st["coverage_90"] <= 0.98
    assert st["mean_abs_error"] <= 0.07


@pytest.mark.parametrize("split", ["loo", "transfer"])
@pytest.mark.parametrize("model", ["elastic_exact_rod", "forrestal"])
def test_documented_figures(cross_validation, split, model):
    cv, _ = cross_validation
    if split == "loo":
        st = cv["loo"][model]["statistics"]
    else:
        (entry,) = cv["transfer"].values()
        assert entry["case"].endswith("piekutowski1999_aermet100.toml")
        st = entry["models"][model]["statistics"]
    doc = DOCUMENTED[split][model]
    assert st["mean_abs_error"] == pytest.approx(doc["mean_abs_error"], abs=0.01)
    assert st["mean_error"] == pytest.approx(doc["mean_error"], abs=0.01)
    assert st["coverage_90"] == pytest.approx(doc["coverage_90"], abs=1e-9)
    assert 0.0 <= st["coverage_50"] <= st["coverage_90"]
    assert st["mean_log_predictive_density"] > 0.5  # sigma ~ 0.05-0.07: density of ln P ~ 5-8 at the centre


def test_report_has_the_tables(cross_validation):
    _, out = cross_validation
    text = (out / "report.md").read_text()
    assert "Leave-one-out, per model" in text and "Transfer: calibrated on this case's shots" in text
    assert (out / "report.html").is_file()
