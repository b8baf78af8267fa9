"""The built wheel, installed into a fresh virtual environment, run from an empty folder (issue 38):
``semianalytic demo`` exits 0 and writes its report; the README's commands (README.md, the quick
ones: tests/test_readme_commands.py runs every one from a checkout) run on the bundled cases
through the console scripts ``semianalytic`` and ``fem-check``; the docs' gallery scripts run;
the compiled ring kernels are the ones built into the wheel; ``bench-bem`` (the benchmarks are not
installed) exits 2 with one line.  Nothing is written into the empty folder but what was asked.

The wheel is built from a copy of the tracked files (nothing written into the checkout) with this
environment's pip; its dependencies come from the package index through pip's cache (the machine
and CI reach PyPI).  Minutes of work: marked ``long`` (``make test``, CI), not ``make check``.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
pytestmark = pytest.mark.long

# the README commands that take minutes (renders, FEM convergence studies): run from a checkout by
# tests/test_readme_commands.py (marked slow there too); one quick FEM command is run below instead
SLOW = ("semianalytic run ", "fem_check verify", "semianalytic sweep")


def _copy_tracked(dest: Path) -> Path:
    if (ROOT / ".git").exists():
        files = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout.split(b"\0")
        names = [n.decode() for n in files if n]
    else:  # an unpacked source tree
        names = [p.relative_to(ROOT).as_posix() for p in ROOT.rglob("*") if p.is_file() and ".venv" not in p.parts[:1]
                 and "__pycache__" not in p.parts and not p.name.endswith(".so")]
    for name in names:
        src = ROOT / name
        if src.is_file():
            (dest / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(src, dest / name)
    return dest


def _run(args, cwd, env, timeout=900):
    proc = subprocess.run(args, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    return proc


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """(venv bin folder, wheel path, environment) of the wheel installed into a fresh venv."""
    base = tmp_path_factory.mktemp("wheel")
    src = _copy_tracked(base / "src")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "SEMIANALYTIC_KERNEL", "VIRTUAL_ENV")}
    proc = _run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--disable-pip-version-check", "-w", str(base / "dist"),
                 str(src)], base, env, timeout=1200)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-3000:]
    (wheel,) = (base / "dist").glob("penetration_mechanics-*.whl")
    subprocess.run([sys.executable, "-m", "venv", str(base / "venv")], check=True, timeout=300)
    bin_ = base / "venv" / "bin"
    proc = _run([str(bin_ / "python"), "-m", "pip", "install", "--quiet", "--disable-pip-version-check", str(wheel)],
                base, env, timeout=1800)
    assert proc.returncode == 0, proc.stderr[-3000:]
    env.update(SEMIANALYTIC_CACHE_DIR=str(base / "cache"), FEM_CHECK_MESH_CACHE=str(base / "meshes"), MPLBACKEND="Agg",
               PYVISTA_OFF_SCREEN="true", PATH=f"{bin_}{os.pathsep}{env.get('PATH', '')}")
    return bin_, wheel, env


@pytest.fixture
def empty(tmp_path):
    work = tmp_path / "empty"
    work.mkdir()
    return work


def test_wheel_contents(installed):
    """The wheel holds the packages, the bundled cases, the compiled kernels and the licence, and
    no benchmarks, tests or reports."""
    _, wheel, _ = installed
    names = zipfile.ZipFile(wheel).namelist()
    cases = {n.rsplit("/", 1)[1] for n in names if n.startswith("semianalytic/cases/")}
    assert {p.name for p in (ROOT / "cases").iterdir() if p.suffix in (".toml", ".csv", ".md")} <= cases
    assert any(re.fullmatch(r"semianalytic/bem/_ring\..*\.so", n) for n in names)
    assert any(n.endswith(".dist-info/licenses/LICENSE") for n in names)
    assert not [n for n in names if n.split("/")[0] in ("benchmarks", "tests", "reports", "cases", "docs", "tools")]
    meta = zipfile.ZipFile(wheel).read(next(n for n in names if n.endswith(".dist-info/METADATA"))).decode()
    assert "License-Expression: MIT" in meta and "Programming Language :: Python :: 3.13" in meta
    entry = zipfile.ZipFile(wheel).read(next(n for n in names if n.endswith(".dist-info/entry_points.txt"))).decode()
    assert "semianalytic = semianalytic.cli:main" in entry and "fem-check = fem_check.cli:main" in entry


def test_demo_from_an_empty_folder(installed, empty):
    bin_, _, env = installed
    proc = _run([str(bin_ / "semianalytic"), "demo"], empty, env)
    assert proc.returncode == 0, proc.stderr[-3000:]
    report = Path(proc.stdout.strip().splitlines()[-1].removeprefix("report: "))
    assert report.is_file() and report.is_relative_to(Path(env["SEMIANALYTIC_CACHE_DIR"]))
    assert list(empty.iterdir()) == []  # nothing where it ran
    assert "Traceback" not in proc.stderr


def test_compiled_kernels_of_the_wheel(installed, empty):
    """The installed kernels are the compiled ones (loaded from site-packages), with no compiler
    on the PATH and a cache folder that holds nothing."""
    bin_, _, env = installed
    code = ("from semianalytic.bem import kernels; from semianalytic import native; "
            "print(kernels.backend(), native.library_path(kernels._SOURCE))")
    proc = _run([str(bin_ / "python"), "-c", code], empty, {**env, "CC": "/nonexistent/cc", "PATH": str(bin_)})
    assert proc.returncode == 0, proc.stderr
    backend, path = proc.stdout.split()
    assert backend == "c" and "site-packages" in path


def _readme_commands():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    out = []
    for block in re.findall(r"```sh\n(.*?)```", text, re.S):
        for line in block.splitlines():
            line = re.sub(r"\s+#.*$", "", line.strip())
            if re.match(r"(\.venv/bin/)?python -m (semianalytic|fem_check) ", line) and not any(s in line for s in SLOW):
                out.append(line)
    return out


COMMANDS = _readme_commands()


def test_the_readme_has_quick_commands():
    assert len(COMMANDS) >= 4


@pytest.mark.parametrize("command", COMMANDS, ids=[c[:60] for c in COMMANDS])
def test_readme_command_from_an_empty_folder(installed, empty, command):
    """Each command through its console script; ``cases/X.toml`` is the bundled case (one note)."""
    bin_, _, env = installed
    args = shlex.split(command)
    tool = {"semianalytic": "semianalytic", "fem_check": "fem-check"}[args[2]]
    args = [str(bin_ / tool), *args[3:]]
    proc = _run(args, empty, env)
    assert proc.returncode == 0, f"{command}\n{proc.stderr[-3000:]}"
    assert "Traceback" not in proc.stderr
    asked = {args[i + 1].split("/")[0] for i, a in enumerate(args[:-1]) if a in ("--out", "--report", "--csv")}
    assert {p.name for p in empty.iterdir()} <= asked
    if "cases/" in command:
        assert "reading the bundled" in proc.stderr


def test_fem_check_from_an_empty_folder(installed, empty):
    """``fem-check verify cases/fig5_ogive.toml --json`` (quick and coarse, to stay fast)."""
    bin_, _, env = installed
    proc = _run([str(bin_ / "fem-check"), "verify", "cases/fig5_ogive.toml", "--json", "--quick", "--h", "0.1",
                 "--depths", "2"], empty, env)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert proc.stdout.lstrip().startswith("{") and list(empty.iterdir()) == []


@pytest.mark.parametrize("script", sorted((ROOT / "docs" / "examples").glob("*.py")), ids=lambda p: p.stem)
def test_gallery_example_from_an_empty_folder(installed, empty, script):
    """Each script of docs/examples/ with the installed package; a file of reports/ that a script
    reads (a calibration's posterior.json: the output of `calibrate`, not of the package) is put
    where it looks, as a user who ran that calibration has it."""
    bin_, _, env = installed
    for name in set(re.findall(r"\"(reports/[\w./-]+)\"", script.read_text())):
        (empty / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(ROOT / name, empty / name)
    proc = _run([str(bin_ / "python"), str(script)], empty, env, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert proc.stdout.strip() and "Traceback" not in proc.stderr


def test_benchmarks_are_not_installed(installed, empty):
    bin_, _, env = installed
    for args in (["semianalytic", "bench-bem", "--out", "x"], ["fem-check", "bench"]):
        proc = _run([str(bin_ / args[0]), *args[1:]], empty, env, timeout=120)
        assert proc.returncode == 2, proc.stderr
        (line,) = proc.stderr.strip().splitlines()
        assert "checkout of the project" in line
    assert list(empty.iterdir()) == []
