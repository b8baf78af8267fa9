"""No import cycle in semianalytic/ (issue 16), checked on the import graph that grimp (shipped
with import-linter) builds from the source, every import statement counted, including the
ones inside functions.  Independent of the code under test: it reads the files, it runs
nothing of them.  The layer contracts themselves are pyproject.toml's [tool.importlinter],
run by ``make test``; the last test here runs them too, so that a plain pytest also holds them.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

grimp = pytest.importorskip("grimp")

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def graph():
    return grimp.build_graph("semianalytic", "fem_check", cache_dir=None)


def test_no_module_imports_itself_back(graph):
    """For every direct import a -> b inside semianalytic, no chain leads from b back to a."""
    cycles = []
    for a in sorted(m for m in graph.modules if m.startswith("semianalytic")):
        for b in graph.find_modules_directly_imported_by(a):
            if b.startswith("semianalytic") and b != a:
                back = graph.find_shortest_chain(importer=b, imported=a)
                if back is not None:
                    cycles.append((a, *back))
    assert not cycles, "import cycles: " + "; ".join(" -> ".join(c) for c in cycles[:5])


def test_registered_sections_do_not_import_the_case_module(graph):
    """semianalytic.case loads the sections of SECTIONS by name (importlib, invisible to the
    graph); none of them may import semianalytic.case back (that would be a hidden cycle)."""
    from semianalytic.case import SECTIONS

    for name, target in SECTIONS.items():
        module = target.partition(":")[0]
        assert graph.find_shortest_chain(importer=module, imported="semianalytic.case") is None, name


def test_the_check_is_imported_only_through_its_api_by_the_pipeline(graph):
    importers = {
        (a, b)
        for b in graph.modules if b.startswith("fem_check")
        for a in graph.find_modules_that_directly_import(b) if a.startswith("semianalytic")
    }
    assert importers == {("semianalytic.run.fields", "fem_check.api")}


HEAVY = ("scipy.integrate", "scipy.optimize", "scipy.special", "scipy.interpolate", "scipy.linalg", "dask")


def test_case_layer_imports_no_scipy_solvers_and_no_dask():
    """Start-up (issue 14 item 4): the case layer and the unit registry pull in no scipy solver
    (296 ms before issue 16) and no dask (82 ms, through pint).  pint.compat itself imports the
    bare ``scipy`` package (about 15 ms), which is allowed here."""
    code = "import sys, semianalytic.case, semianalytic.units as u; u.registry(); " \
           f"print(sorted(m for m in {HEAVY!r} if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT)
    assert out.stdout.strip() == "[]"


def test_import_contracts_hold():
    exe = shutil.which("lint-imports", path=str(Path(sys.executable).parent))
    if exe is None:
        pytest.skip("import-linter is not installed")
    out = subprocess.run([exe, "--no-cache"], capture_output=True, text=True, cwd=ROOT)
    assert out.returncode == 0, out.stdout[-3000:]
