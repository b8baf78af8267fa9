"""Start-up (issue 14): `--help` of every command and loading every bundled case import none of
the heavy modules.  A module-set check in a fresh interpreter, not a timing (timings are in
reports/bench_startup.md)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
HEAVY = ("scipy.integrate", "dask", "distributed", "matplotlib", "pyvista", "gmsh", "skfem")


def test_help_of_every_command_imports_nothing_heavy():
    code = (
        "import contextlib, io\n"
        "from semianalytic.cli import COMMANDS, main\n"
        "for name in COMMANDS:\n"
        "    with contextlib.redirect_stdout(io.StringIO()):\n"
        "        assert main([name, '--help']) == 0, name\n"
    )
    assert _loaded(code, HEAVY) == []


def test_loading_every_case_imports_nothing_heavy():
    cases = sorted(str(p.relative_to(ROOT)) for p in (ROOT / "cases").glob("*.toml"))
    assert len(cases) > 10
    code = "from semianalytic.case import load_case\n" + "".join(f"load_case({c!r})\n" for c in cases)
    assert _loaded(code, HEAVY) == []


# What the fast paths of issues 12, 14 and 17 leave out (each made lazy or replaced in this branch):
# `penetrate --help` needs no numerics at all; a case is read without pint (common unit strings),
# pandas (shot tables: csv module) or scipy's solvers; a cached coefficient table is read without
# the BEM and without scipy (the table module imports scipy.interpolate and the BEM to build one).
SOLVERS = ("pint", "pandas", "scipy.integrate", "scipy.optimize", "scipy.interpolate", "scipy.linalg", "scipy.special",
           "semianalytic.bem", "dask", "matplotlib")


def _loaded(code: str, names, env=None) -> list[str]:
    probe = code + f"\nimport sys, json\nprint('MODULES=' + json.dumps(sorted(m for m in {tuple(names)!r} if m in sys.modules)))"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, cwd=ROOT, timeout=300, env=env)
    assert out.returncode == 0, out.stderr
    return json.loads([ln for ln in out.stdout.splitlines() if ln.startswith("MODULES=")][-1][len("MODULES="):])


def test_penetrate_help_imports_no_numerics():
    code = ("import contextlib, io\nfrom semianalytic.cli import main\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n    assert main(['penetrate', '--help']) == 0\n")
    assert _loaded(code, ("numpy", "pydantic", *SOLVERS)) == []


def test_loading_a_case_imports_no_pint_pandas_or_solvers():
    # a table nose builds its spline (scipy.interpolate) while it is validated: the other cases
    cases = sorted(str(p.relative_to(ROOT)) for p in (ROOT / "cases").glob("*.toml")
                   if 'nose = "table"' not in p.read_text())
    assert len(cases) > 10
    code = ("from semianalytic.case import load_case\n"
            "from semianalytic.penetration.validation import load_shots\n"
            + "".join(f"c = load_case({c!r})\nif c.section('data') is not None and c.projectile is not None: load_shots(c)\n"
                      for c in cases))
    assert _loaded(code, SOLVERS) == []


def test_reading_a_cached_table_imports_neither_the_bem_nor_scipy(tmp_path):
    code = ("from semianalytic.case import load_case\nfrom semianalytic.cache import cached_coefficient_table\n"
            "from semianalytic.geometry import nose_from_section\n"
            "nose = nose_from_section(load_case('cases/fig5_ogive.toml').projectile)\n"
            f"t = cached_coefficient_table(nose, {str(tmp_path)!r}, order=2, refinement=0.3, n_depths=8, "
            "max_depth_nose_lengths=4.0)\n"
            "assert t.A(0.01) > 0 and t.B(0.01) > 0\n")
    assert "semianalytic.bem" in _loaded(code, SOLVERS)  # the first call builds the table (the BEM runs)
    assert sorted(tmp_path.glob("*.npz"))
    assert _loaded(code, SOLVERS) == []  # the second reads it
