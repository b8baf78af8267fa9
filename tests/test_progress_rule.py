"""Progress by one rule (semianalytic.progress): a bar on a terminal, one line per stage when
stderr is a file (a log), nothing with --quiet or on a pipe.  Checked through the commands a
user runs, with stderr redirected to a real file as ``cmd 2> log`` does."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def _run_to_log(tmp_path, args, name="log"):
    env = {**os.environ, "PYTHONPATH": str(ROOT), "SEMIANALYTIC_CACHE_DIR": str(tmp_path / "cache")}
    env.pop("SEMIANALYTIC_PROGRESS", None)
    log = tmp_path / name
    with open(log, "w") as err:
        proc = subprocess.run([sys.executable, "-m", *args], cwd=tmp_path, env=env, stdout=subprocess.PIPE,
                              stderr=err, text=True, timeout=900)
    assert proc.returncode == 0, log.read_text()[-2000:]
    return log.read_text()


def test_mode_follows_stderr(tmp_path, monkeypatch):
    from semianalytic import progress

    monkeypatch.delenv("SEMIANALYTIC_PROGRESS", raising=False)
    with open(tmp_path / "f", "w") as f:
        monkeypatch.setattr(sys, "stderr", f)
        assert progress.mode() == "lines"
        assert progress.mode(quiet=True) == "off"
    r, w = os.pipe()
    with os.fdopen(w, "w") as pipe:
        monkeypatch.setattr(sys, "stderr", pipe)
        assert progress.mode() == "off"
    os.close(r)
    monkeypatch.setenv("SEMIANALYTIC_PROGRESS", "bar")
    assert progress.mode() == "bar"


def test_perforate_tells_a_log_what_it_does(tmp_path):
    case = str(ROOT / "cases" / "perforation_ogive_6061T651_constant.toml")
    log = _run_to_log(tmp_path, ["semianalytic", "perforate", case, "--no-ballistic-limit"])
    assert "perforate: [1/1]" in log and "perforate: done in" in log
    assert "plate table: [1/1] BEM plate table" in log and "plate table: done in" in log  # built on first use
    quiet = _run_to_log(tmp_path, ["semianalytic", "perforate", case, "--no-ballistic-limit", "--quiet"], "quiet")
    assert "perforate: [" not in quiet


def test_coefficient_table_build_is_counted_in_a_log(tmp_path):
    log = _run_to_log(tmp_path, ["semianalytic", "coefficients", str(ROOT / "cases" / "fig5_sphere.toml")])
    lines = [ln for ln in log.splitlines() if ln.startswith("BEM depths of the coefficient table")]
    assert len(lines) == 2 and lines[0].endswith("started") and " depths in " in lines[1], log


def test_fem_verify_is_not_silent_in_a_log(tmp_path):
    pytest.importorskip("skfem")
    log = _run_to_log(tmp_path, ["fem_check", "verify", str(ROOT / "cases" / "body_sphere.toml"), "--quick", "--h", "0.1",
                                 "--no-report"])
    assert "fem_check verify: [1/1]" in log and "fem_check verify: done in" in log
