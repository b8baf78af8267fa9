"""cases/README.md indexes every case: each case file is listed, each listed file exists, and
each case says what it reproduces (a ``reproduces`` line)."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

CASES = Path(__file__).resolve().parent.parent / "cases"


def _listed() -> set[str]:
    text = (CASES / "README.md").read_text()
    return set(re.findall(r"`([A-Za-z0-9_.\-]+\.(?:toml|csv))`", text))


def test_every_case_is_in_the_index():
    missing = sorted(p.name for p in CASES.glob("*.toml") if p.name not in _listed())
    assert not missing, f"cases missing from cases/README.md: {missing}"


def test_every_indexed_file_exists():
    absent = sorted(n for n in _listed() if not (CASES / n).exists())
    assert not absent, f"cases/README.md lists files that do not exist: {absent}"


def test_every_case_says_what_it_reproduces():
    for p in CASES.glob("*.toml"):
        data = tomllib.loads(p.read_text())
        assert isinstance(data.get("reproduces"), str) and data["reproduces"].strip(), p.name
