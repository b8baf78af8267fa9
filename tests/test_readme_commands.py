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
READMES = (ROOT / "README.md", ROOT / "cases" / "README.md", ROOT / "docs" / "getting-started.md")
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
    asked = {args[i + 1] for i, a in enumerate(args[:-1]) if a in ("--out", "--report", "--csv")}
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


# --------------------------------------------------------------------------------------
# the README's claims


def _readme() -> str:
    return (ROOT / "README.md").read_text(encoding="utf-8")


def test_readme_starts_with_make_demo_and_make_test():
    first_block = re.search(r"```sh\n(.*?)```", _readme(), re.S).group(1).splitlines()
    assert first_block[0].startswith("make demo") and first_block[1].startswith("make test")


def test_worked_example_deep_limit_is_what_the_command_prints(tmp_path):
    """The README's sentence on the first command ("its deep limit is Abar = 1.005 mm, Bbar =
    0.1137, Cbar = 1.000"), parsed from the README, against `coefficients --json`: equal to the
    digits the README prints (half a unit of the last digit)."""
    import json

    m = re.search(r"deep limit is Abar = ([\d.]+) mm, Bbar = ([\d.]+),\s+Cbar = ([\d.]+)", _readme())
    assert m, "the worked example states the deep limit"
    env = {**os.environ, "SEMIANALYTIC_CACHE_DIR": str(tmp_path / "cache")}
    proc = subprocess.run([sys.executable, "-m", "semianalytic", "coefficients", str(ROOT / "cases" / "fig5_ogive.toml"),
                           "--json"], env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    deep = json.loads(proc.stdout)["deep_limit"]
    for text, value in zip(m.groups(), (deep["A_bar_m"] * 1e3, deep["B_bar_body"], deep["C_bar"])):
        half_ulp = 0.5 * 10 ** -len(text.split(".")[1])
        assert abs(value - float(text)) <= half_ulp, (text, value)


def test_default_tolerance_stated_is_the_schema_default():
    from semianalytic.case import CoefficientsSection

    m = re.search(r"`\[coefficients\] tolerance` \(default ([\de.-]+)", _readme())
    assert m and float(m.group(1)) == CoefficientsSection().tolerance


_STRIP = [r"`[^`]*`", r"\(\d+[\w']*\)", r"Figs?\. [\w-]+", r"[Ii]ssue \d+", r"item \d+", r"Part [IV]+",
          r"\b(?:19|20)\d\d\b", r"\bP[12]\b"]


def _claimed_numbers(text: str) -> list[str]:
    """The numbers a README passage states (code, equation, figure, issue and item numbers cut)."""
    for pat in _STRIP:
        text = re.sub(pat, " ", text)
    return re.findall(r"(?<![\w.\-/])(\d+(?:\.\d+)?(?:e-?\d+)?)(?![\w.]*\w)", text)


def _passages() -> list[tuple[str, list[Path]]]:
    """Each bullet of "What the reports show" and the contact-region paragraph, with the report
    files it names."""
    text = _readme()
    section = text.split("## What the reports show", 1)[1].split("\n## ", 1)[0]
    bullets = [b for b in re.split(r"\n- ", section) if b.strip()]
    contact = next(p for p in text.split("\n\n") if p.startswith("Contact region"))
    out = []
    for passage in [*bullets, contact]:
        names = re.findall(r"`(?:reports/)?([\w*./-]+?\.md|[\w-]+/)`", passage)
        files = []
        for n in names:
            files += sorted((ROOT / "reports").glob(n if n.endswith(".md") else n + "report.md"))
        out.append((passage, files))
    return out


@pytest.mark.parametrize("passage, files", _passages(), ids=lambda v: v[:40] if isinstance(v, str) else "")
def test_every_number_of_the_reports_section_is_in_its_report(passage, files):
    """Every number the README states about a report is printed by that report (generated by the
    command it names; tests/test_report_freshness.py keeps the reports current)."""
    numbers = _claimed_numbers(passage)
    if not numbers:
        return
    assert files, f"a passage stating {numbers} names no report: {passage[:80]}"
    text = "\n".join(f.read_text(encoding="utf-8") for f in files)
    missing = [n for n in numbers if not re.search(rf"(?<![\d.]){re.escape(n)}(?![\d])", text)]
    assert not missing, f"{missing} not found in {[f.name for f in files]}: {passage[:100]}"


# --------------------------------------------------------------------------------------
# reports/: no machine path, no dirty revision

MACHINE_PATH = re.compile(r"(?<![\w.{}])(/tmp/|/home/|/root/|/work/|/Users/|/var/folders/|[A-Z]:\\\\Users)")


def test_no_report_holds_a_machine_path_or_a_dirty_revision():
    """Every committed text file under reports/ (Markdown, HTML, JSON, CSV) is free of absolute
    folders of a machine and of a `-dirty` git revision (a revision no one can check out)."""
    bad = []
    for f in sorted((ROOT / "reports").rglob("*")):
        if f.suffix not in (".md", ".html", ".json", ".csv", ".txt") or "demo" in f.relative_to(ROOT / "reports").parts:
            continue
        text = f.read_text(encoding="utf-8", errors="replace")
        for m in MACHINE_PATH.finditer(text):
            bad.append((f.relative_to(ROOT).as_posix(), text[max(m.start() - 40, 0): m.end() + 40]))
        if re.search(r"git [0-9a-f]{7,}-dirty|-dirty\)", text):
            bad.append((f.relative_to(ROOT).as_posix(), "-dirty"))
    assert not bad, bad[:10]


def test_generated_by_lines_name_the_flags():
    """The "Generated by" command of a report written with extra options names them (the
    cornered-nose verification was made with --depths; a report that exists needs --force to be
    made again by its own command)."""
    text = (ROOT / "reports" / "fem_verify_cone30.md").read_text(encoding="utf-8")
    cmd = re.search(r"Generated by `([^`]+)`", text).group(1)
    readme = next(c for _, c in COMMANDS if "fem_check verify cases/cone30.toml" in c)
    assert cmd == readme.replace(".venv/bin/python", "python"), (cmd, readme)
