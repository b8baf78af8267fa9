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


def _loaded_after(code: str) -> list[str]:
    probe = code + f"\nimport sys, json\nprint('MODULES=' + json.dumps(sorted(m for m in {HEAVY!r} if m in sys.modules)))"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert out.returncode == 0, out.stderr
    line = [ln for ln in out.stdout.splitlines() if ln.startswith("MODULES=")][-1]
    return json.loads(line[len("MODULES="):])


def test_help_of_every_command_imports_nothing_heavy():
    code = (
        "import contextlib, io\n"
        "from semianalytic.cli import COMMANDS, main\n"
        "for name in COMMANDS:\n"
        "    with contextlib.redirect_stdout(io.StringIO()):\n"
        "        assert main([name, '--help']) == 0, name\n"
    )
    assert _loaded_after(code) == []


def test_loading_every_case_imports_nothing_heavy():
    cases = sorted(str(p.relative_to(ROOT)) for p in (ROOT / "cases").glob("*.toml"))
    assert len(cases) > 10
    code = "from semianalytic.case import load_case\n" + "".join(f"load_case({c!r})\n" for c in cases)
    assert _loaded_after(code) == []
