"""Move the commands out of the model packages (issue 39, item 1): one run, on the merged main.

The model packages (``bem``, ``coefficients``, ``penetration``, ``perforation``, ``cavity``,
``ballistic_limit``, ``nanostrength``, the pure part of ``calibration``) keep their models; every
module of a command (argument parsing, pipeline, evaluation, study, report) moves to
``semianalytic/commands/<command>/`` and every case-file section schema (``<package>/case.py``)
to ``semianalytic/sections/<package>.py``:

    semianalytic/penetration/cli.py        -> semianalytic/commands/penetrate/cli.py
    semianalytic/penetration/case.py       -> semianalytic/sections/penetration.py
    ...

What the script does, in order (each step is idempotent: a second run changes nothing):

1. ``git mv`` of every module of MOVES that exists (a module already at its new place is left);
   the new packages get an ``__init__.py``;
2. rewrites every dotted name (``semianalytic.penetration.cli``), every path
   (``semianalytic/penetration/cli.py``, in prose also ``penetration/cli.py``) and every
   ``from semianalytic.penetration import cli`` in semianalytic/, fem_check/, tests/, tools/,
   benchmarks/, docs/, reports/, cases/, README.md, ARCHITECTURE.md, Makefile, mkdocs.yml,
   pyproject.toml and .ci/;
3. edits the import contracts of pyproject.toml: the command layer ``semianalytic.commands`` above
   ``semianalytic.report``, the section layer ``semianalytic.sections`` under ``semianalytic.case``,
   the model packages as one layer (``:``, siblings that may import each other) and an
   ``acyclic_siblings`` contract that forbids a cycle between the top-level packages;
4. puts ``tools/relayout_ARCHITECTURE.md`` in place as ``ARCHITECTURE.md`` (it says where the
   replaced file had changed since the new one was written, so that nothing is lost);
5. ``--check``: runs ``lint-imports`` and lists every module left in a model package that still
   imports a command, the cache, the case layer or a report (none, when the move is complete).

Usage (from the repository root, on a clean tree)::

    python tools/relayout.py            # move, rewrite, edit the contracts, swap the doc
    python tools/relayout.py --dry-run  # list what would move and which files would change
    python tools/relayout.py --check    # after the move: lint-imports and the upward-arrow count
    python tools/relayout.py --move semianalytic.penetration.verdict=semianalytic.commands.penetrate.verdict

``--move OLD=NEW`` (repeatable) moves a module that appeared after this script was written.
The script never commits; review ``git status`` / ``git diff --stat`` and commit.
"""

from __future__ import annotations

import argparse
import ast
import hashlib
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

# model package -> the command folder its command modules go to
COMMAND_OF = {
    "penetration": "penetrate",
    "perforation": "perforate",
    "cavity": "cavity",
    "ballistic_limit": "ballistic_limit",
    "nanostrength": "nanostrength",
    "coefficients": "coefficients",
    "calibration": "calibrate",
}
# the modules of a command (whatever package they sit in)
COMMAND_MODULES = (
    "cli", "fit_cli", "bench", "pipeline", "regimes_pipeline", "report", "regimes_report",
    "corners_report", "table_out", "diagnose", "study", "figures", "evaluate", "studies",
)
MODEL_PACKAGES = ("bem", "coefficients", "penetration", "perforation", "cavity", "ballistic_limit",
                  "nanostrength", "calibration", "exact")

TEXT_DIRS = ("semianalytic", "fem_check", "tests", "tools", "benchmarks", "docs", "reports", "cases", ".ci")
TEXT_FILES = ("README.md", "ARCHITECTURE.md", "Makefile", "mkdocs.yml", "pyproject.toml")
SUFFIXES = {".py", ".md", ".toml", ".txt", ".yml", ".yaml", ".cfg", ".ini", ".sh", ".json", ".html", ""}
SKIP = {"tools/relayout.py", "tools/relayout_ARCHITECTURE.md"}

NEW_DOC = ROOT / "tools" / "relayout_ARCHITECTURE.md"
# sha256 of the ARCHITECTURE.md the new one was written against (step 4 reports a difference)
BASE_DOC_SHA256 = "da1dc6ed4619c542818bfe5598c5cf876386deedc546f2cdab80e1a37ea18797"

INIT_DOC = {
    "commands": '"""The command layer: one folder per command (argument parsing, pipeline, evaluation, studies,\n'
                'report) over the model packages, which import none of it (ARCHITECTURE.md)."""\n',
    "sections": '"""The case layer\'s section schemas (pydantic), one module per model package: a case file\'s\n'
                'section -> frozen dataclasses of SI values for the models (ARCHITECTURE.md)."""\n',
}


def planned_moves(extra: list[str]) -> dict[str, str]:
    """Old dotted module -> new dotted module, for the modules present (old or new place)."""
    moves: dict[str, str] = {}
    for pkg, cmd in COMMAND_OF.items():
        for name in COMMAND_MODULES:
            moves[f"semianalytic.{pkg}.{name}"] = f"semianalytic.commands.{cmd}.{name}"
        moves[f"semianalytic.{pkg}.case"] = f"semianalytic.sections.{pkg}"
    for item in extra:
        old, _, new = item.partition("=")
        if not (old and new):
            sys.exit(f"--move expects OLD=NEW, got {item!r}")
        moves[old] = new
    return {o: n for o, n in moves.items() if _file(o).is_file() or _file(n).is_file()}


def _file(dotted: str) -> Path:
    return ROOT / (dotted.replace(".", "/") + ".py")


def git(*args: str, check: bool = True) -> str:
    return subprocess.run(["git", *args], cwd=ROOT, check=check, capture_output=True, text=True).stdout


def move_files(moves: dict[str, str], dry: bool) -> list[str]:
    done = []
    for old, new in sorted(moves.items()):
        src, dst = _file(old), _file(new)
        if not src.is_file():
            continue  # already moved
        if dst.exists():
            sys.exit(f"both {src.relative_to(ROOT)} and {dst.relative_to(ROOT)} exist: resolve by hand")
        done.append(f"{src.relative_to(ROOT)} -> {dst.relative_to(ROOT)}")
        if dry:
            continue
        dst.parent.mkdir(parents=True, exist_ok=True)
        for pkg in (dst.parent, *dst.parent.parents):
            if pkg == ROOT / "semianalytic" or ROOT / "semianalytic" not in pkg.parents:
                break
            init = pkg / "__init__.py"
            if not init.exists():
                init.write_text(INIT_DOC.get(pkg.name, f'"""The ``{pkg.name.replace("_", "-")}`` command."""\n'))
                git("add", str(init.relative_to(ROOT)))
        git("mv", str(src.relative_to(ROOT)), str(dst.relative_to(ROOT)))
    return done


def text_files() -> list[Path]:
    out = [ROOT / f for f in TEXT_FILES if (ROOT / f).is_file()]
    for d in TEXT_DIRS:
        base = ROOT / d
        if base.is_dir():
            out += [p for p in base.rglob("*") if p.is_file() and p.suffix in SUFFIXES
                    and "__pycache__" not in p.parts and ".venv" not in p.parts]
    return [p for p in out if p.relative_to(ROOT).as_posix() not in SKIP]


def _rx_dotted(moves: dict[str, str]) -> list[tuple[re.Pattern[str], str]]:
    return [(re.compile(rf"(?<![\w.]){re.escape(o)}(?![\w])"), n) for o, n in sorted(moves.items(), key=lambda kv: -len(kv[0]))]


def _rx_paths(moves: dict[str, str]) -> list[tuple[re.Pattern[str], str]]:
    out = []
    for o, n in sorted(moves.items(), key=lambda kv: -len(kv[0])):
        op, np_ = o.replace(".", "/") + ".py", n.replace(".", "/") + ".py"
        out.append((re.compile(rf"(?<![\w/.]){re.escape(op)}(?![\w])"), np_))
        # in prose the package-relative path ("penetration/cli.py")
        short_o, short_n = op.split("/", 1)[1], np_.split("/", 1)[1]
        out.append((re.compile(rf"(?<![\w/.]){re.escape(short_o)}(?![\w])"), short_n))
    return out


def _rewrite_from_imports(text: str, moves: dict[str, str]) -> str:
    """``from semianalytic.pkg import cli, curve as c`` -> one statement per new home."""
    try:
        tree = ast.parse(text)
    except SyntaxError:
        return text
    lines = text.splitlines(keepends=True)
    edits = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.ImportFrom) or not node.module or node.level:
            continue
        moved = [a for a in node.names if f"{node.module}.{a.name}" in moves]
        if not moved:
            continue
        indent = re.match(r"\s*", lines[node.lineno - 1]).group(0)
        stmts = []
        keep = [a for a in node.names if a not in moved]
        if keep:
            stmts.append(f"{indent}from {node.module} import " + ", ".join(_alias(a) for a in keep))
        for a in moved:
            new = moves[f"{node.module}.{a.name}"]
            parent, _, leaf = new.rpartition(".")
            stmts.append(f"{indent}from {parent} import {leaf}" + (f" as {a.asname}" if a.asname else
                                                                 (f" as {a.name}" if leaf != a.name else "")))
        tail = lines[node.end_lineno - 1][node.end_col_offset:]
        edits.append((node.lineno - 1, node.end_lineno, "\n".join(stmts) + (tail if tail.strip() else "\n")))
    for start, end, new in sorted(edits, reverse=True):
        lines[start:end] = [new]
    return "".join(lines)


def _alias(a: ast.alias) -> str:
    return a.name + (f" as {a.asname}" if a.asname else "")


def rewrite(moves: dict[str, str], dry: bool) -> list[str]:
    dotted, paths = _rx_dotted(moves), _rx_paths(moves)
    changed = []
    for path in text_files():
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            continue
        new = _rewrite_from_imports(text, moves) if path.suffix == ".py" else text
        for rx, repl in dotted:
            new = rx.sub(repl, new)
        for rx, repl in paths:
            new = rx.sub(repl, new)
        if new != text:
            changed.append(path.relative_to(ROOT).as_posix())
            if not dry:
                path.write_text(new, encoding="utf-8")
    return changed


MODELS_LAYER = " : ".join(f"semianalytic.{p}" for p in MODEL_PACKAGES)


def edit_contracts(dry: bool) -> list[str]:
    """The layers contract gains the command, section and model layers; an acyclic_siblings
    contract forbids package cycles; the per-package contract covers the command folders."""
    path = ROOT / "pyproject.toml"
    text = path.read_text()
    if '"semianalytic.commands"' in text:
        return []
    notes = []

    def insert_after(anchor: str, line: str) -> None:
        nonlocal text
        m = re.search(rf"^(\s*)\"{re.escape(anchor)}\",\n", text, re.M)
        if not m:
            sys.exit(f"pyproject.toml: layer {anchor!r} not found; add {line!r} by hand")
        text = text[:m.end()] + f'{m.group(1)}"{line}",\n' + text[m.end():]
        notes.append(f"layer {line} after {anchor}")

    insert_after("semianalytic.run | semianalytic.sweep", "semianalytic.commands")
    insert_after("semianalytic.case", "semianalytic.sections")
    m = re.search(r'^(\s*)"semianalytic\.bem \| semianalytic\.exact \| semianalytic\.cli_types((?: \| [\w.]+)*)",\n',
                  text, re.M)
    if not m:
        sys.exit("pyproject.toml: the layer 'semianalytic.bem | semianalytic.exact | semianalytic.cli_types' not found")
    text = (text[:m.start()] + f'{m.group(1)}"{MODELS_LAYER}",\n{m.group(1)}"semianalytic.cli_types{m.group(2)}",\n'
            + text[m.end():])
    notes.append("models as one layer, cli_types under them")
    # the per-package layers: the command folders (and the models that keep sub-layers)
    cmds = sorted(set(COMMAND_OF.values()))
    m = re.search(r'(id = "package-layers"[\s\S]*?containers = \[\n)', text)
    if not m:
        sys.exit("pyproject.toml: contract 'package-layers' not found")
    text = text[:m.end()] + "".join(f'    "semianalytic.commands.{c}",\n' for c in cmds) + text[m.end():]
    # the pure models forbid the new layers above them
    m = re.search(r'(id = "pure-models"[\s\S]*?forbidden_modules = \[\n)', text)
    if m:
        text = text[:m.end()] + '    "semianalytic.commands",\n    "semianalytic.sections",\n' + text[m.end():]
    text += ('\n[[tool.importlinter.contracts]]\n'
             'id = "no-package-cycles"\n'
             'name = "No cycle between the packages of semianalytic (issue 39): each package is imported from above only"\n'
             'type = "acyclic_siblings"\n'
             'ancestors = ["semianalytic", "semianalytic.commands"]\n'
             'depth = 1\n')
    notes.append("acyclic_siblings contract no-package-cycles")
    if not dry:
        path.write_text(text)
    return notes


def swap_doc(old: str, dry: bool) -> str:
    """``old``: ARCHITECTURE.md as it was before step 2 rewrote its paths."""
    if not NEW_DOC.is_file():
        return "ARCHITECTURE.md already in place"
    note = "ARCHITECTURE.md replaced"
    if hashlib.sha256(old.encode()).hexdigest() != BASE_DOC_SHA256:
        base = git("log", "--format=%H", "-n1", "--", "tools/relayout_ARCHITECTURE.md").strip()
        note += (" -- the replaced file had changed since the new one was written; fold these changes in "
                 f"by hand: git diff {base} -- ARCHITECTURE.md (before this run)")
        if not dry:
            (ROOT / "ARCHITECTURE.old.md").write_text(old)
            note += "; the replaced text is kept in ARCHITECTURE.old.md (untracked)"
    if not dry:
        (ROOT / "ARCHITECTURE.md").write_text(NEW_DOC.read_text())
        git("rm", "-q", "--cached", str(NEW_DOC.relative_to(ROOT)), check=False)
        NEW_DOC.unlink()
    return note


# what a model may not import (the measure of --check)
ABOVE = ("semianalytic.commands", "semianalytic.sections", "semianalytic.case", "semianalytic.schema",
         "semianalytic.cache", "semianalytic.guards", "semianalytic.report", "semianalytic.run",
         "semianalytic.sweep", "semianalytic.optimize", "semianalytic.cli", "semianalytic.api")


def upward_arrows() -> tuple[list[tuple[str, str]], list[list[str]]]:
    """(model module -> module above) edges, and the cycles between top-level packages."""
    import grimp

    g = grimp.build_graph("semianalytic", cache_dir=None)
    arrows = []
    for m in sorted(g.modules):
        parts = m.split(".")
        if len(parts) < 2 or parts[1] not in MODEL_PACKAGES:
            continue
        for d in sorted(g.find_modules_directly_imported_by(m)):
            if any(d == a or d.startswith(a + ".") for a in ABOVE) or (
                    len(d.split(".")) > 2 and d.split(".")[2] in COMMAND_MODULES + ("case",)
                    and d.split(".")[1] in COMMAND_OF):
                arrows.append((m, d))

    def top(m: str) -> str:
        p = m.split(".")
        return ".".join(p[:3]) if len(p) > 2 and p[1] == "commands" else ".".join(p[:2])

    succ: dict[str, set[str]] = {}
    for m in g.modules:
        if not m.startswith("semianalytic.") or m.count(".") < 1:
            continue
        for d in g.find_modules_directly_imported_by(m):
            if d.startswith("semianalytic.") and top(d) != top(m):
                succ.setdefault(top(m), set()).add(top(d))
    cycles = []
    for a in sorted(succ):
        for b in sorted(succ[a]):
            if a < b and a in succ.get(b, set()):
                cycles.append([a, b])
            elif a < b:
                stack, seen = [b], {b}
                while stack:
                    x = stack.pop()
                    if x == a:
                        cycles.append([a, b, "..."])
                        break
                    for y in succ.get(x, ()):
                        if y not in seen:
                            seen.add(y)
                            stack.append(y)
    return arrows, cycles


def file_relative(moves: dict[str, str]) -> list[str]:
    """Moved modules that locate files from their own path (``__file__``): one level deeper after
    the move, a ``parents[k]`` of theirs would point elsewhere (use ``semianalytic.__file__``)."""
    out = []
    for old, new in sorted(moves.items()):
        for dotted in (old, new):
            path = _file(dotted)
            if path.is_file() and "Path(__file__)" in path.read_text():
                out.append(path.relative_to(ROOT).as_posix())
    return out


def check() -> int:
    arrows, cycles = upward_arrows()
    rel = file_relative(planned_moves([]))
    print(f"moved modules locating files from their own path (Path(__file__)): {len(rel)}")
    for r in rel:
        print(f"  {r}")
    pkgs = sorted({(a.split(".")[1], ".".join(b.split(".")[:2])) for a, b in arrows})
    print(f"upward arrows: {len(arrows)} module edges, {len(pkgs)} package edges (model package -> command/case/cache/report)")
    for a, b in pkgs:
        print(f"  package {a} -> {b.removeprefix('semianalytic.')}")
    for a, b in arrows:
        print(f"  {a} -> {b}")
    print(f"package pairs on a cycle: {len(cycles)}")
    for c in cycles:
        print("  " + " <-> ".join(c))
    exe = Path(sys.executable).with_name("lint-imports")
    rc = subprocess.run([str(exe) if exe.exists() else "lint-imports", "--no-cache"], cwd=ROOT).returncode
    return 1 if (arrows or rc or rel) else 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dry-run", action="store_true", help="say what would change, change nothing")
    ap.add_argument("--check", action="store_true", help="count upward arrows and cycles, run lint-imports")
    ap.add_argument("--move", action="append", default=[], metavar="OLD=NEW", help="one more module to move")
    args = ap.parse_args(argv)
    if args.check:
        return check()
    moves = planned_moves(args.move)
    old_doc = (ROOT / "ARCHITECTURE.md").read_text()
    moved = move_files(moves, args.dry_run)
    changed = rewrite(moves, args.dry_run)
    notes = edit_contracts(args.dry_run)
    doc = swap_doc(old_doc, args.dry_run)
    print(f"{'would move' if args.dry_run else 'moved'} {len(moved)} modules:")
    print("\n".join(f"  {m}" for m in moved))
    print(f"{'would rewrite' if args.dry_run else 'rewrote'} {len(changed)} files")
    print("\n".join(f"  {c}" for c in changed))
    print("contracts: " + ("; ".join(notes) or "already edited"))
    print(doc)
    print("next: python tools/relayout.py --check, then the tests (tools/relayout.md)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
