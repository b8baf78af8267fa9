"""What a user reads: the messages of a misspelt key and of a wrong choice, ``--version``, the
start-here lines of ``--help``, ``penetrate --csv`` and its per-shot table, the progress bar (on
stderr, only on a terminal, off with ``--quiet``).  Through the command line, as a user runs it.
"""

from __future__ import annotations

import csv
import io
import json
import os
import pty
import re
import subprocess
import sys
from importlib.metadata import version as dist_version
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
VAR4340 = ROOT / "cases" / "piekutowski1999_var4340.toml"


def _run(args, tmp_path, **kw):
    env = {**os.environ, "SEMIANALYTIC_CACHE_DIR": str(tmp_path / "cache"), "FEM_CHECK_MESH_CACHE": str(tmp_path / "meshes"),
           "MPLBACKEND": "Agg"}
    return subprocess.run([sys.executable, "-m", *args], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=600, **kw)


def _case_with(tmp_path, old: str, new: str) -> Path:
    text = (ROOT / "cases" / "fig15a_ogive_6061T651.toml").read_text()
    assert old in text
    case = tmp_path / "case.toml"
    case.write_text(text.replace(old, new, 1))
    return case


def test_misspelt_key_is_named_with_the_closest_valid_key(tmp_path):
    case = _case_with(tmp_path, 'diameter = "7.11 mm"', 'diamter = "7.11 mm"')
    proc = _run(["semianalytic", "penetrate", str(case)], tmp_path)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: projectile.diamter: unknown key"), proc.stderr
    assert "did you mean 'diameter'?" in lines[0]


def test_wrong_choice_lists_the_valid_ones_in_the_projects_words(tmp_path):
    case = _case_with(tmp_path, 'model = "elastic-plastic"', 'model = "elastic_plastic"')
    proc = _run(["semianalytic", "penetrate", str(case)], tmp_path)
    assert proc.returncode == 2
    line = proc.stderr.strip()
    assert line.startswith("error: target.resistance.model: 'elastic_plastic' is not one of"), line
    # the valid values, written here by hand (the models of Part I and the peers' tables)
    for valid in ("elastic-plastic", "brittle", "hardening", "limestone", "part4", "cavity", "constant", "tate"):
        assert valid in line
    assert "did you mean 'elastic-plastic'?" in line
    for leak in ("Input tag", "Input should", "expected tags", "pydantic"):
        assert leak not in line


def test_wrong_nose_and_unknown_section(tmp_path):
    case = _case_with(tmp_path, 'nose = "ogive"', 'nose = "ogiv"')
    line = _run(["semianalytic", "penetrate", str(case)], tmp_path).stderr.strip()
    assert line.startswith("error: projectile.nose: 'ogiv' is not one of ogive, sphere, cone, flat, table, power, spline; "
                           "did you mean 'ogive'?"), line
    case = _case_with(tmp_path, "[impact]", "[impakt]")
    line = _run(["semianalytic", "penetrate", str(case)], tmp_path).stderr.strip()
    assert line.startswith("error: impakt: unknown section or key; did you mean 'impact'?"), line


@pytest.mark.parametrize("tool", ["semianalytic", "fem_check"])
def test_version(tool, tmp_path):
    proc = _run([tool, "--version"], tmp_path)
    assert proc.returncode == 0
    assert f"penetration-mechanics {dist_version('penetration-mechanics')}" in proc.stdout


def test_help_opens_with_three_start_here_lines(tmp_path):
    lines = _run(["semianalytic", "--help"], tmp_path).stdout.splitlines()
    assert lines[0].startswith("start here: python -m semianalytic demo")
    assert "penetrate" in lines[1] and "--help" in lines[2]
    assert lines[3] == "" and lines[4].startswith("usage:")


def _data_depths_mm() -> dict[str, float]:
    """The rigid VAR 4340 shots of the bundled data file, read here with the csv module."""
    text = (ROOT / "cases" / "piekutowski1999_ogive_6061T6511.csv").read_text()
    rows = csv.DictReader(line for line in io.StringIO(text) if not line.startswith("#"))
    return {r["shot"]: float(r["P_mm"]) for r in rows if r["regime"] == "rigid" and r["material"] == "VAR4340"}


def test_penetrate_csv_and_per_shot_table(tmp_path):
    out_csv = tmp_path / "out" / "depths.csv"
    proc = _run(["semianalytic", "penetrate", str(VAR4340), "--csv", str(out_csv)], tmp_path)
    assert proc.returncode == 0, proc.stderr[-2000:]
    rows = list(csv.reader(out_csv.read_text().splitlines()))
    header = rows[0]
    assert header[:4] == ["case", "striking_velocity [m/s]", "model", "depth [m]"] and "time [s]" in header
    body = rows[1:]
    velocities = sorted({float(r[1]) for r in body})
    assert velocities == [500.0 + 100.0 * k for k in range(9)]  # the case's striking velocities, 500-1300 m/s
    models = {r[2] for r in body}
    assert {"rigid", "quasi_rigid", "elastic", "elastic_exact_rod", "forrestal", "chen_li", "regime_aware"} <= models
    assert len(body) == len(velocities) * len(models)  # one row per velocity and model
    # the per-shot table: every rigid shot of the data file, its measured depth as the file prints it
    shots = _data_depths_mm()
    table = proc.stdout.split("model elastic_exact_rod: error")[1]
    for shot, depth in shots.items():
        m = re.search(rf"^\s+{re.escape(shot)}\s+(\d+)\s+([\d.]+)\s+([\d.]+)\s+([+-][\d.]+)", table, re.M)
        assert m, shot
        predicted, measured, error = float(m.group(2)), float(m.group(3)), float(m.group(4))
        assert measured == pytest.approx(depth, abs=0.05)  # printed to 0.1 mm
        assert error == pytest.approx((predicted - measured) / measured * 100, abs=0.2)  # rounding of the mm columns
    # --csv refuses to overwrite without --force (exit 2, one line), and writes with it
    again = _run(["semianalytic", "penetrate", str(VAR4340), "--csv", str(out_csv)], tmp_path)
    assert again.returncode == 2 and again.stderr.startswith("error: --csv:")


def _with_a_terminal(args, tmp_path) -> str:
    """stderr of the command when it is a terminal (a pseudo-terminal), as text."""
    import fcntl
    import struct
    import termios

    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))  # a terminal 100 columns wide
    env = {**os.environ, "SEMIANALYTIC_CACHE_DIR": str(tmp_path / "cache"), "FEM_CHECK_MESH_CACHE": str(tmp_path / "meshes")}
    proc = subprocess.Popen([sys.executable, "-m", *args], cwd=tmp_path, env=env, stdout=subprocess.DEVNULL,
                            stderr=slave, stdin=subprocess.DEVNULL)
    os.close(slave)
    chunks = []
    while True:
        try:
            data = os.read(master, 4096)
        except OSError:
            break
        if not data:
            break
        chunks.append(data)
    proc.wait(timeout=600)
    os.close(master)
    assert proc.returncode == 0, b"".join(chunks)[-2000:]
    return b"".join(chunks).decode("utf-8", "replace")


VERIFY = ["fem_check", "verify", str(ROOT / "cases" / "fig5_ogive.toml"), "--quick", "--h", "0.1", "--depths", "2"]


def test_progress_on_a_terminal_only_and_not_with_quiet(tmp_path):
    shown = _with_a_terminal(VERIFY, tmp_path)
    assert "fem_check verify:" in shown and "steps" in shown
    assert "fem_check verify:" not in _with_a_terminal([*VERIFY, "--quiet"], tmp_path)
    piped = _run(VERIFY, tmp_path)  # stderr a pipe: no bar
    assert piped.returncode == 0 and "fem_check verify:" not in piped.stderr


def test_run_csv_one_row_per_velocity_and_model(tmp_path):
    """`run --csv`: the penetration of the case, one row per striking velocity (the 13 of the
    Fig. 15a case, 0.4-1.6 km/s, written here by hand) and model."""
    case = ROOT / "cases" / "fig15a_ogive_6061T651.toml"
    out_csv = tmp_path / "depths.csv"
    proc = _run(["semianalytic", "run", str(case), "--out", str(tmp_path / "out"), "--only", "penetration",
                 "--no-render", "--csv", str(out_csv)], tmp_path)
    assert proc.returncode == 0, proc.stderr[-2000:]
    rows = list(csv.reader(out_csv.read_text().splitlines()))
    assert rows[0][:4] == ["case", "striking_velocity [m/s]", "model", "depth [m]"]
    velocities = sorted({round(float(r[1])) for r in rows[1:]})
    assert velocities == list(range(400, 1700, 100))
    models = {r[2] for r in rows[1:]}
    assert {"rigid", "quasi_rigid", "elastic", "elastic_exact_rod"} <= models
    assert len(rows) - 1 == len(velocities) * len(models)
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    assert "--csv" not in results["generated_by"]["command"]  # the report's command reproduces the folder
