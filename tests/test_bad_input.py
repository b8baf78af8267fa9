"""Bad-input corpus of ``run``: the files of tests/bad_cases/ are run by tests/test_corpus.py
(exit status 2, one line naming the hand-written ``# expect:`` field and, for a whole section,
the ``# expect-text:`` key; nothing written).  Here: the same in a subprocess, and an existing
output folder without --force.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from semianalytic.cli import main

CORPUS = sorted((Path(__file__).parent / "bad_cases").glob("*.toml"))


def test_corpus_is_large_enough():
    # each file is run (expected field, one line, nothing written) by tests/test_corpus.py, once
    assert len(CORPUS) >= 30


def test_bad_case_exit_status_in_a_subprocess(tmp_path):
    path = Path(__file__).parent / "bad_cases" / "poisson_half.toml"
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "semianalytic", "run", str(path), "--out", str(out)],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines() == [proc.stderr.strip()]
    assert proc.stderr.startswith("error: projectile.poisson_ratio")
    assert not out.exists()


def test_existing_output_folder_needs_force(tmp_path, capsys):
    good = Path(__file__).parent.parent / "cases" / "body_sphere.toml"
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.txt").write_text("mine")
    rc = main(["run", str(good), "--out", str(out), "--no-render"])
    assert rc == 2
    assert capsys.readouterr().err.startswith("error: --out")
    assert [p.name for p in out.iterdir()] == ["keep.txt"]
