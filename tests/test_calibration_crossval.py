"""``calibrate --cross-validate`` on the bundled Piekutowski et al. (1999) shots, held against the
experiment: the measured depths of the paper's tables (read here from the CSV, independently of
the code under test) and the bounds issue 12 states, not our own earlier output.

Leave-one-out on the 7 VAR 4340 rigid shots and the transfer split to the 7 AerMet 100 rigid
shots (same 6061-T6511 target), for the physically consistent model (quasi-rigid start plus
exact-rod energy) and Forrestal's cavity-expansion model.

Tolerances and why:
* issue 12's targets for the best physically consistent model (elastic_exact_rod, leave-one-out):
  90 % intervals cover 80-98 % of the shots (with 7 shots: exactly 6 of 7) and the median's mean
  |error| is at most 7 %;
* every other split and model: the 90 % intervals cover at least 5 of 7 shots (if they were
  calibrated, P(at most 4 of 7 inside) = 2.6 % under Binomial(7, 0.9): a failure means the
  intervals are too narrow, not bad luck) and the 50 % intervals at least 1 of 7 (P(0 of 7) =
  0.8 % under Binomial(7, 0.5)); the median's mean |error| at most 10 %, above what these two
  models reach on the 14 rigid shots without any calibration (mean |e| 8.3 % and 4.2 % with the
  paper's strength, reports/validation_piekutowski1999.md): a calibrated prediction worse than
  that is a regression;
* leave-one-out bias: |mean error| at most 5 %, two standard errors of the mean of 7 draws of
  a log-normal error with the calibrated sigma (about 0.07: 2 x 0.07 / sqrt(7) = 5.3 %); the
  transfer to the other steel may carry a real bias and is not bounded beyond the 10 %.
"""

import csv
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from semianalytic.cli import main

ROOT = Path(__file__).resolve().parents[1]
MODELS = ("elastic_exact_rod", "forrestal")


def _measured(material: str) -> dict[str, float]:
    """Measured depth [m] of the shots the data record as rigid, by shot id (the paper's tables)."""
    with open(ROOT / "cases" / "piekutowski1999_ogive_6061T6511.csv", newline="") as f:
        rows = csv.DictReader(line for line in f if not line.startswith("#"))
        return {r["shot"]: float(r["P_mm"]) / 1e3 for r in rows
                if r["material"] == material and r["regime"] == "rigid" and r["P_mm"].strip()}


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


def _split(cv, split, model):
    if split == "loo":
        return cv["loo"][model], _measured("VAR4340")
    (entry,) = cv["transfer"].values()
    assert entry["case"].endswith("piekutowski1999_aermet100.toml")
    return entry["models"][model], _measured("AerMet100")


def _against_experiment(block, measured):
    """(errors of the median, inside 50 %, inside 90 %) recomputed against the measured depths."""
    sh = block["shots"]
    assert sorted(sh["id"]) == sorted(measured) and len(measured) == 7
    P = np.array([measured[i] for i in sh["id"]])
    q = {k: np.asarray(sh[k]) for k in ("0.05", "0.25", "0.5", "0.75", "0.95")}
    assert np.all(q["0.05"] < q["0.25"]) and np.all(q["0.25"] < q["0.5"]) and np.all(q["0.75"] < q["0.95"])
    err = (q["0.5"] - P) / P
    return err, (q["0.25"] <= P) & (P <= q["0.75"]), (q["0.05"] <= P) & (P <= q["0.95"])


def test_issue_targets_leave_one_out(cross_validation):
    """Issue 12: the best physically consistent model's 90 % intervals cover 80-98 % of the
    held-out VAR 4340 shots and its median's mean |error| is at most 7 %, recomputed from the
    measured depths."""
    cv, _ = cross_validation
    err, _, in90 = _against_experiment(cv["loo"]["elastic_exact_rod"], _measured("VAR4340"))
    assert 0.80 <= in90.mean() <= 0.98
    assert np.mean(np.abs(err)) <= 0.07
    st = cv["loo"]["elastic_exact_rod"]["statistics"]  # the reported figures are these
    assert st["n"] == 7 and st["coverage_90"] == pytest.approx(in90.mean()) and st["mean_abs_error"] == pytest.approx(
        np.mean(np.abs(err)))


@pytest.mark.parametrize("split", ["loo", "transfer"])
@pytest.mark.parametrize("model", MODELS)
def test_predictions_against_the_measured_depths(cross_validation, split, model):
    """Every model and split against the experiment, with the bounds of the module docstring."""
    cv, _ = cross_validation
    block, measured = _split(cv, split, model)
    err, in50, in90 = _against_experiment(block, measured)
    assert in90.sum() >= 5 and in50.sum() >= 1
    assert np.mean(np.abs(err)) <= 0.10
    if split == "loo":
        assert abs(np.mean(err)) <= 0.05
    st = block["statistics"]
    assert st["mean_abs_error"] == pytest.approx(np.mean(np.abs(err))) and st["mean_error"] == pytest.approx(np.mean(err))
    assert st["coverage_50"] == pytest.approx(in50.mean()) and st["coverage_90"] == pytest.approx(in90.mean())
    # the density of ln P at the measured depth: a log-normal of sd ~0.07 has ~5.7 at its centre and
    # 0.5 beyond 2.6 sd; the mean over 7 shots below 0.5 would mean the intervals miss the data
    assert st["mean_log_predictive_density"] > 0.5


def test_report_has_the_tables(cross_validation):
    _, out = cross_validation
    text = (out / "report.md").read_text()
    assert "Leave-one-out, per model" in text and "Transfer: calibrated on this case's shots" in text
    assert (out / "report.html").is_file()
