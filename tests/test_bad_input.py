"""Bad-input corpus: every file in tests/bad_cases/ must be rejected by ``run`` with exit
status 2, one line ``error: <field>: ...`` naming the field given in the file's
``# expect:`` header (and, where that field is a whole section, the key named by the
``# expect-text:`` header in the message), and nothing written (neither the output folder
nor a staging folder).

The expected field is written by hand in each file (independent of the code under test).
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from semianalytic.cli import main

CORPUS = sorted((Path(__file__).parent / "bad_cases").glob("*.toml"))


def _expected(path: Path) -> str:
    for line in path.read_text().splitlines():
        if line.startswith("# expect:"):
            return line.split(":", 1)[1].strip()
    raise AssertionError(f"{path.name} has no '# expect:' header")


def _expected_text(path: Path) -> str | None:
    """Where the field is a whole section (a model-level check), the key the message must name."""
    for line in path.read_text().splitlines():
        if line.startswith("# expect-text:"):
            return line.split(":", 1)[1].strip()
    return None


def test_corpus_is_large_enough():
    assert len(CORPUS) >= 30


@pytest.mark.parametrize("path", CORPUS, ids=[p.stem for p in CORPUS])
def test_bad_case_rejected(path, tmp_path, capsys):
    out = tmp_path / "out"
    rc = main(["run", str(path), "--out", str(out), "--no-render"])
    err = capsys.readouterr().err.strip()
    assert rc == 2, err
    assert "\n" not in err, err  # one line
    assert err.startswith(f"error: {_expected(path)}"), err
    text = _expected_text(path)
    if text is not None:
        assert text in err, err
    assert not out.exists()
    assert list(tmp_path.iterdir()) == []  # no staging folder left behind


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
