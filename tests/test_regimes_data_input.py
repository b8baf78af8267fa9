"""Issue 40: the regimes calibration's data validated at the door.  Each defect is written into a
copy of the bundled Piekutowski et al. (1999) table and run through ``python -m semianalytic
calibrate CASE --model regimes`` (subprocess): exit 2, one line naming the field and the row
(counted here by hand), nothing written.  The clean table reads, with the recorded regimes
counted here from the CSV."""

from __future__ import annotations

import csv
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
CASE = ROOT / "cases" / "piekutowski1999_var4340_hardness_regimes.toml"
CSV = ROOT / "cases" / "piekutowski1999_ogive_6061T6511.csv"


def _table():
    lines = CSV.read_text().splitlines()
    comments = [line for line in lines if line.startswith("#")]
    rows = list(csv.DictReader(line for line in lines if not line.startswith("#")))
    return comments, rows


def _write(tmp_path, edit_row=None, edit_case=None, name="d"):
    comments, rows = _table()
    if edit_row:
        edit_row(rows)
    out = tmp_path / f"{name}.csv"
    with out.open("w", newline="") as fh:
        fh.write("\n".join(comments) + "\n")
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    text = CASE.read_text().replace('file = "piekutowski1999_ogive_6061T6511.csv"', f'file = "{out.name}"')
    if edit_case:
        text = edit_case(text)
    case = tmp_path / f"{name}.toml"
    case.write_text(text)
    return case


def _nth_var(rows, k):
    """Index in the file and the row number (1-based among the data rows) of the k-th VAR 4340 shot."""
    idx = [i for i, r in enumerate(rows) if r["material"] == "VAR4340"][k]
    return idx, idx + 1


def _calibrate(tmp_path, case):
    out = tmp_path / "out"
    res = subprocess.run([sys.executable, "-m", "semianalytic", "calibrate", str(case), "--model", "regimes",
                          "--out", str(out), "--quiet"], capture_output=True, text=True, cwd=tmp_path, timeout=600)
    assert not out.exists(), "refused input must write nothing"
    return res


def _set(k, col, value):
    def f(rows):
        i, _ = _nth_var(rows, k)
        rows[i][col] = value
    return f


_, ROWS = _table()


@pytest.mark.parametrize("k,col,value,field,text", [
    (2, "regime", "rigdi", "data.response_column", "'rigdi' is not a known label"),
    (4, "Vs_m_s", "1e9", "data.velocity_column", "1e+09 m/s is outside"),
    (5, "hardness_Rc", "", "data.hardness_column", "hardness '' is not a number"),
    (6, "hardness_Rc", "99", "data.hardness_column", "99 HRC is outside 20-68 HRC"),
    (1, "P_mm", "NaN", "data.file", "not a finite number"),
])
def test_row_defect_refused_naming_the_row(tmp_path, k, col, value, field, text):
    case = _write(tmp_path, _set(k, col, value))
    res = _calibrate(tmp_path, case)
    _, row = _nth_var(ROWS, k)
    assert res.returncode == 2, res.stderr[-500:]
    assert len(res.stderr.strip().splitlines()) == 1 and "Traceback" not in res.stderr
    assert res.stderr.startswith(f"error: {field}: row {row} of d.csv") and text in res.stderr


def test_all_labels_blank_refused(tmp_path):
    def blank(rows):
        for r in rows:
            r["regime"] = ""
    res = _calibrate(tmp_path, _write(tmp_path, blank))
    assert res.returncode == 2 and res.stderr.startswith("error: data.response_column:") and "blank" in res.stderr


def test_missing_response_column_refused(tmp_path):
    case = _write(tmp_path, edit_case=lambda t: t.replace('response_column = "regime"', 'response_column = "regim"'))
    res = _calibrate(tmp_path, case)
    assert res.returncode == 2 and res.stderr.startswith("error: data.response_column:") and "'regim'" in res.stderr


def test_penetrate_refuses_the_typo_too(tmp_path):
    """penetrate reads the same [data] (regime validation): the same row named."""
    case = _write(tmp_path, _set(2, "regime", "rigdi"))
    res = subprocess.run([sys.executable, "-m", "semianalytic", "penetrate", str(case), "--json"],
                         capture_output=True, text=True, cwd=tmp_path, timeout=600)
    _, row = _nth_var(ROWS, 2)
    assert res.returncode == 2 and res.stderr.startswith(f"error: data.response_column: row {row} of d.csv")


def test_clean_table_reads_with_its_labels(tmp_path):
    """The bundled VAR 4340 rows read, each recorded response mapped as in the data's legend
    (rigid; curved, exited, turned_around, broken -> deforming; eroded, broken_eroding -> eroding),
    counted here from the CSV."""
    from semianalytic.cache import coefficients_for_case
    from semianalytic.calibration.regimes import regime_shots
    from semianalytic.case import load_case

    case = load_case(_write(tmp_path))
    shots = regime_shots(case, coefficients_for_case(case, "paper", None)[0])
    legend = {"rigid": 0, "curved": 1, "exited": 1, "turned_around": 1, "broken": 1, "eroded": 2, "broken_eroding": 2}
    var = [r for r in ROWS if r["material"] == "VAR4340"]
    assert [int(x) for x in shots.recorded] == [legend[r["regime"]] for r in var]
