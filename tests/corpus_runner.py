"""Runs bad inputs through the command-line entry points in-process and classifies each run.

Shared by ``tests/test_corpus.py`` (assertions in ``make test``) and ``tests/hardening_tally.py``
(the tally of ``reports/hardening.md``).  Each corpus file in ``tests/corpus/`` and
``tests/bad_cases/`` starts with hand-written headers:

- ``# expect: FIELD``: every command exits 2 with one line; the primary commands' line is
  ``error: FIELD...`` (the field written by hand, independent of the code);
- ``# expect: warn FIELD``: exit 0 with a ``warning: FIELD`` line on stderr;
- ``# expect: ok``: exit 0;
- ``# expect-text: TEXT``: where the field is a whole section, the key the message must name;
- ``# commands: NAME ...``: the primary commands (default: coefficients, penetrate, run);
- ``# args: ...``: further arguments of the primary commands, ``{corpus}`` standing for this
  folder (e.g. ``--posterior {corpus}/posteriors/regimes_nan.json``).

Binary and non-UTF-8 files carry the same ASCII header before their bytes.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
from dataclasses import dataclass
from pathlib import Path

HERE = Path(__file__).resolve().parent
CORPUS_DIRS = (HERE / "corpus", HERE / "bad_cases")
PRIMARY = ("coefficients", "penetrate", "run")
LOADERS = ("cavity", "ballistic-limit", "nanostrength")  # cheap: fail at load or solve a small model
HEAVY = ("sweep", "fem_check verify")
ALL_COMMANDS = PRIMARY + LOADERS + HEAVY


def corpus_files() -> list[Path]:
    return sorted(p for d in CORPUS_DIRS for p in d.glob("*.toml"))


def headers(path: Path) -> dict[str, str]:
    out = {}
    for line in path.read_bytes().split(b"\n")[:6]:
        m = re.match(rb"# (expect-text|expect|commands|args|why): (.*)", line)
        if m:
            out[m.group(1).decode()] = m.group(2).decode("utf-8", "replace").strip()
    return out


def argv(command: str, case: str, out: Path, args: str = "") -> tuple[str, list[str]]:
    """(package, argv) of one command on ``case`` writing only under ``out`` (``args``: the
    file's ``# args:`` header)."""
    if command == "fem_check verify":
        return "fem_check", ["verify", case, "--quick", "--h", "0.1", "--json"]
    extra = {
        "run": ["--out", str(out / "run"), "--no-render"],
        "sweep": ["--out", str(out / "sweep"), "--vary", "impact.striking_velocity=400:500:100 m/s",
                  "--scheduler", "inline", "--no-progress"],
        "coefficients": ["--json", "--depths", "8"],
        "penetrate": ["--json"],
        "cavity": ["--json"],
        "ballistic-limit": ["--json"],
        "nanostrength": ["--json"],
        "calibrate": ["--out", str(out / "calibrate"), "--quiet"],
    }[command]
    more = [a.replace("{corpus}", str(HERE / "corpus")) for a in args.split()]
    return "semianalytic", [command, case, *extra, *more]


@dataclass
class Outcome:
    rc: int
    err: str
    out: str

    @property
    def traceback(self) -> bool:
        return "Traceback (most recent call last)" in self.err or "internal error" in self.err

    @property
    def errors(self) -> list[str]:
        return [line for line in self.err.splitlines() if line.startswith("error:")]

    @property
    def warned(self) -> bool:
        return any(line.startswith("warning:") for line in self.err.splitlines())

    @property
    def kind(self) -> str:
        if self.traceback:
            return "traceback"
        if self.rc == 2:
            return "rejected"
        if self.rc == 0:
            return "warned" if self.warned else "accepted"
        return f"exit {self.rc}"


def run_command(command: str, case: str, out: Path, extra: str = "") -> Outcome:
    """One in-process run (stdout and stderr captured)."""
    package, args = argv(command, case, out, extra)
    if package == "fem_check":
        from fem_check.cli import main
    else:
        from semianalytic.cli import main
    err, std = io.StringIO(), io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(std):
        rc = main(args)
    return Outcome(rc, err.getvalue(), std.getvalue())


def files_under(root: Path) -> set[str]:
    return {str(p.relative_to(root)) for p in root.rglob("*")}


@contextlib.contextmanager
def working_directory(path: Path):
    old = os.getcwd()
    os.chdir(path)
    try:
        yield
    finally:
        os.chdir(old)
