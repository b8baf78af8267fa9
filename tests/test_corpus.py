"""Hardening corpus (issue 13): every hand-written bad input in tests/corpus/ and
tests/bad_cases/ through the commands, in-process.

Invariants: exit status 0 or 2, never a traceback, one line on stderr for exit 2, the line of
the primary commands naming the field written by hand in the file's ``# expect:`` header,
and no file written outside ``--out`` (each run's working directory is an empty folder that
must stay empty apart from the asked outputs).  The memory guard's cases (crh = 1e12, a cone
of 0.001 deg, a 801 x 801 x 180 field grid) are refused before any allocation.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from corpus_runner import HEAVY, LOADERS, PRIMARY, corpus_files, headers, run_command, working_directory

FILES = corpus_files()


def test_corpus_is_large_enough():
    assert len(list((Path(__file__).parent / "corpus").glob("*.toml"))) >= 100


@pytest.mark.parametrize("path", FILES, ids=[f"{p.parent.name}/{p.stem}" for p in FILES])
def test_corpus_file(path, tmp_path, monkeypatch):
    monkeypatch.setenv("SEMIANALYTIC_CACHE_DIR", os.environ.get("SEMIANALYTIC_CACHE_DIR") or str(tmp_path / "cache"))
    head = headers(path)
    expect = head["expect"]
    default = ["run"] if path.parent.name == "bad_cases" else list(PRIMARY)  # bad_cases/ were written for run
    primary = head["commands"].split() if "commands" in head else default
    # other commands: the invariants only; the heavier ones only where the file fails at the door
    # (a rejected file of tests/corpus/ without a command list)
    heavy = path.parent.name == "corpus" and "commands" not in head and expect != "ok" and not expect.startswith("warn")
    others = [c for c in (*LOADERS, *(HEAVY if heavy else ())) if c not in primary]
    work = tmp_path / "work"
    work.mkdir()
    with working_directory(work):
        for command in [*primary, *others]:
            res = run_command(command, str(path), work / "out", head.get("args", "") if command in primary else "")
            assert not res.traceback, (command, res.err)
            assert res.rc in (0, 2), (command, res.rc, res.err)
            if res.rc == 2:
                assert len(res.err.strip().splitlines()) == 1, (command, res.err)
            if command not in primary:
                continue
            if expect == "ok" or expect.startswith("warn"):
                assert res.rc == 0, (command, res.err)
                if expect.startswith("warn"):
                    field = expect.split(None, 1)[1]
                    assert any(line.startswith(f"warning: {field}") for line in res.err.splitlines()), res.err
                continue
            assert res.rc == 2, (command, res.out[:200], res.err)
            assert res.err.startswith(f"error: {expect}"), (command, res.err)
            if "expect-text" in head:  # the field is a whole section: the key the message names
                assert head["expect-text"] in res.err, (command, res.err)
            # nothing written anywhere: not in the cwd, not under --out
            assert not any(work.iterdir()), (command, sorted(map(str, work.rglob("*"))))
    # whatever ran, nothing appeared outside the asked --out folders (no ./.cache, no ./reports)
    assert {p.name for p in work.iterdir()} <= {"out"}, sorted(map(str, work.iterdir()))


def test_generated_inputs(tmp_path):
    """Inputs too big or too odd to commit: a 5 MB file, a folder, a missing file, a FIFO-free
    special path (/dev/null), 100 000 nested arrays."""
    huge = tmp_path / "huge.toml"
    huge.write_text("# " + "x" * (5 * 2**20) + "\n")
    deep = tmp_path / "deep.toml"
    deep.write_text("a = " + "[" * 100_000 + "]" * 100_000 + "\n")
    folder = tmp_path / "folder.toml"
    folder.mkdir()
    for case in (huge, deep, folder, tmp_path / "missing.toml", Path("/dev/null")):
        for command in ("coefficients", "penetrate", "cavity"):
            res = run_command(command, str(case), tmp_path / "out")
            assert res.rc == 2 and res.err.startswith("error: case"), (case, command, res.err)
            assert len(res.err.strip().splitlines()) == 1
