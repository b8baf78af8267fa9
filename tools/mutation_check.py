"""Mutation check of issue 26: ten sampled tests, each must fail when the code it checks is broken.

``python tools/mutation_check.py --out reports`` copies the committed tree (``git archive HEAD``)
into a temporary folder, runs the ten tests there unbroken (each must pass), then, one at a time,
applies a small deliberate break to the code under test (a sign, a factor, a dropped term, an
off-by-one; never to the test), runs the test with an empty coefficient-table cache (a cached
table would hide a break of the solver), records whether it failed and how, and restores the file.
The working tree is never touched.  Writes ``OUT/mutation_check.md``; the section "Repeated runs"
(the flaky-test tally, measured by the shell loops it quotes) is kept from an existing report.

This project's own tool (issue 26, "0 tests that cannot fail").
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# (category, file, old text, new text, test node id, what the break is)
MUTATIONS = [
    ("BEM", "semianalytic/bem/solve.py",
     "A = 0.5 * np.eye(N) - D", "A = 0.5001 * np.eye(N) - D",
     "tests/test_bem.py::test_sphere_added_mass_is_one_half_to_round_off",
     "jump term of the double-layer equation 1/2 -> 0.5001"),
    ("penetration", "semianalytic/penetration/motion.py",
     "/ (mass + target_density * A)", "/ (mass)",
     "tests/test_penetration_motion.py::test_solve_motion_matches_the_closed_form",
     "eq. (11): added-mass term rho A dropped from the inertia"),
    ("regimes", "semianalytic/penetration/regime.py",
     "- 0.5 * rho_t * (v**2 - v_e**2)) / dr", "- 0.5 * rho_p * (v**2 - v_e**2)) / dr",
     "tests/test_penetration_regimes.py::test_eroding_depth_hydrodynamic_exact",
     "Tate integral I(v): target density replaced by the rod's in one term"),
    ("perforation", "semianalytic/perforation/model.py",
     "partly = (1.0 + L - (c / b) ** 3) / (1.0 + L)", "partly = (1.0 + L - (c / b) ** 2) / (1.0 + L)",
     "tests/test_perforation.py::test_back_face_factor_against_hill_integral",
     "Hill's finite sphere: elastic-shell exponent 3 -> 2"),
    ("CLI / bad input", "semianalytic/report/output.py",
     "if out.exists() and not force and any(out.iterdir()):", "if out.exists() and force and any(out.iterdir()):",
     "tests/test_bad_input.py::test_existing_output_folder_needs_force",
     "the --force guard inverted (an existing --out folder is overwritten)"),
    ("cavity", "semianalytic/cavity/model.py",
     "return 2.0 * (1.0 - theta) ** 1.5 / (3.0 * np.sqrt(theta))",
     "return 2.0 * (1.0 - theta) ** 1.5 / (3.1 * np.sqrt(theta))",
     "tests/test_cavity.py::test_ad995_reproduces_errata_19_and_printed_example",
     "strength factor C(theta) of the comminuted zone: 3 -> 3.1 in the denominator"),
    ("nanostrength", "semianalytic/nanostrength/interplanar.py",
     "return self.phi_b / lam * a * np.exp(-a)", "return self.phi_b / lam * a * np.exp(-1.01 * a)",
     "tests/test_nanostrength_law.py::test_uber_closed_form_and_no_compressive_peak",
     "UBER stress dPhi/de: decay exp(-a) -> exp(-1.01 a)"),
    ("ballistic limit", "semianalytic/ballistic_limit/theory.py",
     "VICKERS_HALF_ANGLE = math.radians(68.0)", "VICKERS_HALF_ANGLE = math.radians(67.0)",
     "tests/test_ballistic_limit.py::test_meyer_factor",
     "Vickers half-angle 68 -> 67 deg in the Meyer factor"),
    ("sweep", "semianalytic/sweep/spec.py",
     "n = int(math.floor((stop - start) / step * (1 + 1e-12) + 1e-9)) + 1",
     "n = int(math.floor((stop - start) / step * (1 + 1e-12) + 1e-9))",
     "tests/test_sweep_engine.py::test_range_is_inclusive_and_in_si",
     "off-by-one: the range start:stop:step loses its end point"),
    ("docs / README", "semianalytic/case.py",
     "tolerance: float = Field(default=1e-5,", "tolerance: float = Field(default=1e-6,",
     "tests/test_readme_commands.py::test_default_tolerance_stated_is_the_schema_default",
     "schema default of [coefficients] tolerance changed, README not"),
]


def _pytest(copy: Path, nodes: list[str], cache: Path) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(copy), SEMIANALYTIC_CACHE_DIR=str(cache), OPENBLAS_NUM_THREADS="1",
               OMP_NUM_THREADS="1", MPLBACKEND="Agg", PYVISTA_OFF_SCREEN="true")
    cmd = [sys.executable, "-m", "pytest", "-q", "-x", "-rf", "-p", "no:cacheprovider", *nodes]
    return subprocess.run(cmd, cwd=copy, env=env, capture_output=True, text=True, timeout=900)


def _how(out: str) -> str:
    """The first assertion line of a failure (pytest's ``E`` lines), shortened."""
    for line in out.splitlines():
        if line.startswith("E "):
            return re.sub(r"\s+", " ", line[1:].strip())[:110]
    m = re.search(r"^FAILED (.*)$", out, re.M)
    return m.group(1)[:110] if m else "(no failure line)"


def _escape(s: str) -> str:
    return s.replace("|", "\\|")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="folder of mutation_check.md")
    args = ap.parse_args(argv)
    out = Path(args.out) / "mutation_check.md"
    rev = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True,
                         check=True).stdout.strip()
    load0 = os.getloadavg()
    t0 = time.perf_counter()
    rows = []
    with tempfile.TemporaryDirectory(prefix="mutation-") as tmp:
        copy = Path(tmp) / "repo"
        copy.mkdir()
        archive = subprocess.run(["git", "archive", "HEAD"], cwd=ROOT, capture_output=True, check=True).stdout
        subprocess.run(["tar", "-x", "-C", str(copy)], input=archive, check=True)
        where = subprocess.run([sys.executable, "-c", "import semianalytic; print(semianalytic.__file__)"], cwd=copy,
                               env=dict(os.environ, PYTHONPATH=str(copy)), capture_output=True, text=True, check=True)
        assert Path(where.stdout.strip()).is_relative_to(copy), "the copy's package is not the one imported"
        base = _pytest(copy, [m[4] for m in MUTATIONS], Path(tmp) / "cache-base")
        if base.returncode != 0:
            print(base.stdout[-3000:], file=sys.stderr)
            print("error: the ten tests do not pass unbroken", file=sys.stderr)
            return 1
        for i, (cat, file, old, new, node, what) in enumerate(MUTATIONS):
            path = copy / file
            text = path.read_text()
            assert text.count(old) == 1, f"{file}: the text to break occurs {text.count(old)} times: {old!r}"
            path.write_text(text.replace(old, new))
            t = time.perf_counter()
            try:
                res = _pytest(copy, [node], Path(tmp) / f"cache-{i}")
            finally:
                path.write_text(text)
            dt = time.perf_counter() - t
            failed = res.returncode == 1 and " failed" in res.stdout
            rows.append((cat, file, old, new, node, what, failed, _how(res.stdout) if failed else res.stdout[-200:], dt))
            print(f"{'FAILED (caught)' if failed else 'NOT CAUGHT'}  {node}  ({dt:.0f} s)", file=sys.stderr)
    wall = time.perf_counter() - t0
    load1 = os.getloadavg()
    caught = sum(r[6] for r in rows)
    keep = ""
    if out.exists():
        m = re.search(r"^## Repeated runs.*", out.read_text(), re.S | re.M)
        keep = m.group(0).rstrip() + "\n" if m else ""
    lines = [
        "# Mutation check (issue 26)",
        "",
        "Generated by `python tools/mutation_check.py --out reports` at revision " + rev + ".",
        "",
        "Ten test functions sampled across the default suite, one per area; each was run unbroken "
        "(all pass), then against a small deliberate break of the code it checks, applied to a "
        "copy of the committed tree (`git archive HEAD`) with an empty coefficient-table cache, "
        "and the file restored.  Target: every test fails.",
        "",
        f"**Result: {caught} of {len(rows)} tests fail on their break.**  Wall time {wall:.0f} s; "
        f"load average (1 min) {load0[0]:.1f} at the start, {load1[0]:.1f} at the end (2 cores, "
        "shared with other work).",
        "",
        "| # | area | test | break (file: old -> new) | failed? | how |",
        "|---|---|---|---|---|---|",
    ]
    for k, (cat, file, old, new, node, what, failed, how, dt) in enumerate(rows, 1):
        lines.append(f"| {k} | {cat} | `{node}` | {what} (`{file}`: `{_escape(old)}` -> `{_escape(new)}`) | "
                     f"{'yes' if failed else '**no**'} | {_escape(how)} |")
    lines.append("")
    if keep:
        lines.append(keep)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text("\n".join(lines))
    return 0 if caught == len(rows) else 1


if __name__ == "__main__":
    sys.exit(main())
