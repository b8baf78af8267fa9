"""Every command of README.md and cases/README.md, run as written, in a fresh copy of the
repository (the tracked files only: what a fresh clone has), with this environment's python.

The ``make`` lines are skipped (they reinstall); ``make demo`` is run as its python command.
cases/README.md writes ``<case>`` and ``<folder>`` as placeholders: they are filled with the
case its tables name for that command (``fig15a_ogive_6061T651``) and ``out/<n>``.  After each
command the copy holds nothing new except the folder the command was asked to write (and the
caches, which live outside the copy).  The slow ones (a full ``run`` with renders, the full
FEM verification with its convergence studies, the demo) are marked ``slow``.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
READMES = (ROOT / "README.md", ROOT / "cases" / "README.md")
SLOW = ("semianalytic run ", "fem_check verify", "semianalytic demo", "semianalytic sweep")


def readme_commands() -> list[tuple[str, str]]:
    """(readme, command) for every ``python -m`` line of a fenced shell block, comments cut."""
    out = []
    for readme in READMES:
        text = readme.read_text(encoding="utf-8")
        for block in re.findall(r"```sh\n(.*?)```", text, re.S):
            for line in block.splitlines():
                line = line.strip()
                if re.match(r"(\.venv/bin/)?python -m ", line):
                    out.append((readme.relative_to(ROOT).as_posix(), re.sub(r"\s+#.*$", "", line)))
    out.append(("README.md", "python -m semianalytic demo"))  # `make demo` without the reinstall
    return out


COMMANDS = readme_commands()


def _tracked_copy(dest: Path) -> Path:
    files = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout.split(b"\0")
    for name in filter(None, files):
        src = ROOT / name.decode()
        if src.is_file():
            target = dest / name.decode()
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(src.read_bytes())
    return dest


@pytest.fixture(scope="module")
def fresh_copy(tmp_path_factory):
    if not (ROOT / ".git").exists():
        pytest.skip("not a git checkout")
    return _tracked_copy(tmp_path_factory.mktemp("clone") / "repo")


def _snapshot(root: Path) -> set[str]:
    return {p.relative_to(root).as_posix() for p in root.rglob("*") if "__pycache__" not in p.parts}


def test_the_readmes_show_commands():
    assert len(COMMANDS) >= 7


@pytest.mark.parametrize(
    "readme, command",
    [pytest.param(r, c, marks=pytest.mark.slow) if any(s in c for s in SLOW) else (r, c) for r, c in COMMANDS],
    ids=[c[:70] for _, c in COMMANDS],
)
def test_readme_command_runs_verbatim(fresh_copy, tmp_path, readme, command):
    n = len(list(fresh_copy.glob("out/*")))
    text = command.replace("<case>", "fig15a_ogive_6061T651").replace("<folder>", f"out/{n}")
    args = shlex.split(text)
    args[0] = sys.executable  # `python` or `.venv/bin/python` of the README: this environment's
    env = {**os.environ, "SEMIANALYTIC_CACHE_DIR": str(tmp_path / "cache"), "FEM_CHECK_MESH_CACHE": str(tmp_path / "meshes"),
           "MPLBACKEND": "Agg", "PYVISTA_OFF_SCREEN": "true"}
    env.pop("PYTHONPATH", None)
    before = _snapshot(fresh_copy)
    proc = subprocess.run(args, cwd=fresh_copy, env=env, capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, f"{readme}: {command}\n{proc.stderr[-2000:]}"
    assert "Traceback" not in proc.stderr
    asked = {args[i + 1] for i, a in enumerate(args[:-1]) if a in ("--out", "--report")}
    if "semianalytic demo" in command:
        asked.add("reports/demo")
    new = {p for p in _snapshot(fresh_copy) - before if not any(p == a or p.startswith(a.rstrip("/") + "/")
                                                                   or a.startswith(p + "/") for a in asked)}
    assert not new, f"{command} wrote outside what it was asked: {sorted(new)[:10]}"


def test_fem_verify_json_from_an_empty_folder_writes_nothing(tmp_path):
    """The README's `fem_check verify ... --json` from another folder (here with --quick and a
    coarse mesh to stay fast): prints JSON, creates nothing where it runs."""
    work = tmp_path / "elsewhere"
    work.mkdir()
    env = {**os.environ, "SEMIANALYTIC_CACHE_DIR": str(tmp_path / "cache"), "FEM_CHECK_MESH_CACHE": str(tmp_path / "meshes")}
    proc = subprocess.run([sys.executable, "-m", "fem_check", "verify", str(ROOT / "cases" / "fig5_ogive.toml"), "--json",
                           "--quick", "--h", "0.1", "--depths", "2"], cwd=work, env=env, capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.lstrip().startswith("{")
    assert list(work.iterdir()) == []
