"""Mutation check: sampled tests, one per core model, each must fail when the code it checks is broken.

``python tools/mutation_check.py --out reports`` first checks that every target text exists exactly
once (a missing target is an error, exit 1, before anything runs; ``--targets`` does only that),
copies the committed tree (``git archive HEAD``) into a temporary folder, runs the sampled tests
there unbroken (each must pass), then, one at a time,
applies a small deliberate break to the code under test (a sign, a factor, a dropped term, an
off-by-one; never to the test), runs the test with an empty coefficient-table cache (a cached
table would hide a break of the solver), records whether it failed and how, and restores the file.
The working tree is never touched.  Writes ``OUT/mutation_check.md``; the section "Repeated runs"
(the flaky-test tally, measured by the shell loops it quotes) is kept from an existing report.

The report states the kill rate (mutants caught / mutants).  This project's own tool.
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

# (category, file, old text, new text, test node id, what the break is).  Each old text must occur
# exactly once in its file: a target that is missing (the code moved or changed) is reported and
# makes the check fail, before any test runs (``--targets`` checks only that, in a second).
MUTATIONS = [
    ("BEM", "semianalytic/bem/solve.py",
     "A.reshape(-1)[:: A.shape[0] + 1] += 0.5", "A.reshape(-1)[:: A.shape[0] + 1] += 0.5001",
     "tests/test_bem.py::test_sphere_added_mass_is_one_half_to_round_off",
     "jump term of the double-layer equation I/2 - D: 1/2 -> 0.5001"),
    ("penetration", "semianalytic/penetration/motion.py",
     "/ (mass + target_density * A)", "/ (mass)",
     "tests/test_penetration_motion.py::test_solve_motion_matches_the_closed_form",
     "Part I, eq. (11): added-mass term rho A dropped from the inertia"),
    ("resistance", "semianalytic/penetration/resistance.py",
     "return 2.0 / 3.0 * Y * (1.0 + _log(E / (3.0 * Y * (1.0 - nu))))",
     "return 2.0 / 3.0 * Y * (1.0 + _log(E / (3.0 * Y * (1.0 + nu))))",
     "tests/test_resistance.py::test_eq16_hand_value_and_the_appendix_number",
     "Part I, eq. (16): 1 - nu -> 1 + nu"),
    ("critical velocity", "semianalytic/penetration/critical.py",
     "return elastic + math.sqrt(2.0 / (c.target_density * Bbar) * (Ybar - Rbar))",
     "return elastic + math.sqrt(2.1 / (c.target_density * Bbar) * (Ybar - Rbar))",
     "tests/test_critical.py::test_eq36_by_hand",
     "Part I, eq. (36): factor 2 -> 2.1 under the root"),
    ("elastic rod", "semianalytic/penetration/rod.py",
     "return _S(a + np.pi) - 0.5 * (_S(a + b + np.pi) + _S(a - b + np.pi))",
     "return _S(a + np.pi) - 0.49 * (_S(a + b + np.pi) + _S(a - b + np.pi))",
     "tests/test_rod.py::test_closed_form_equals_the_papers_series",
     "closed form of the rod series (Part I, eq. (26)): 1/2 -> 0.49"),
    ("perforation", "semianalytic/perforation/model.py",
     "partly = (1.0 + L - (c / b) ** 3) / (1.0 + L)", "partly = (1.0 + L - (c / b) ** 2) / (1.0 + L)",
     "tests/test_perforation.py::test_back_face_factor_against_hill_integral",
     "Hill's finite sphere: elastic-shell exponent 3 -> 2"),
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
     "return np.sqrt(2.0 * np.asarray(R, dtype=float) / rho_t * np.expm1(al))[()]",
     "return np.sqrt(2.1 * np.asarray(R, dtype=float) / rho_t * np.expm1(al))[()]",
     "tests/test_ballistic_limit.py::test_ballistic_limit_inverts_eq4",
     "Part IV, eq. (5): a^2 = 2R/rho_t -> 2.1 R/rho_t"),
    ("CLI / bad input", "semianalytic/report/output.py",
     "        if out.exists() and any(out.iterdir()):", "        if out.exists() and not any(out.iterdir()):",
     "tests/test_bad_input.py::test_existing_output_folder_needs_force",
     "the guard of an existing non-empty --out folder inverted (it would be replaced)"),
    ("docs / README", "semianalytic/case.py",
     "tolerance: float = Field(default=1e-5,", "tolerance: float = Field(default=1e-6,",
     "tests/test_readme_commands.py::test_default_tolerance_stated_is_the_schema_default",
     "schema default of [coefficients] tolerance changed, README not"),
]


def missing_targets(root: Path = ROOT) -> list[str]:
    """One line per mutation whose file, old text (exactly once) or test function is not there."""
    bad = []
    for cat, file, old, _new, node, _what in MUTATIONS:
        path = root / file
        n = path.read_text().count(old) if path.is_file() else -1
        if n != 1:
            bad.append(f"{cat}: {file}: the text to break occurs {n} times (expected once): {old!r}"
                       if n >= 0 else f"{cat}: {file} does not exist")
        test_file, _, func = node.partition("::")
        tpath = root / test_file
        if not tpath.is_file() or not re.search(rf"^def {re.escape(func)}\(", tpath.read_text(), re.M):
            bad.append(f"{cat}: the test {node} does not exist")
    return bad


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
    ap.add_argument("--out", help="folder of mutation_check.md")
    ap.add_argument("--targets", action="store_true", help="only check that every target exists (no test runs)")
    args = ap.parse_args(argv)
    bad = missing_targets()
    for line in bad:
        print(f"error: missing target: {line}", file=sys.stderr)
    if bad or args.targets:
        if not bad:
            print(f"{len(MUTATIONS)} targets present")
        return 1 if bad else 0
    if not args.out:
        ap.error("--out is required (or --targets)")
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
            print(f"error: the {len(MUTATIONS)} tests do not pass unbroken", file=sys.stderr)
            return 1
        for i, (cat, file, old, new, node, what) in enumerate(MUTATIONS):
            path = copy / file
            text = path.read_text()
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
        "# Mutation check (issues 26, 39)",
        "",
        "Generated by `python tools/mutation_check.py --out reports` at revision " + rev + ".",
        "",
        f"{len(rows)} test functions sampled across the default suite, one per area of the core models; each was run unbroken "
        "(all pass), then against a small deliberate break of the code it checks, applied to a "
        "copy of the committed tree (`git archive HEAD`) with an empty coefficient-table cache, "
        "and the file restored.  Target: every test fails.",
        "",
        f"**Kill rate: {caught}/{len(rows)} = {100 * caught / len(rows):.0f} % of the mutants caught.**  "
        "A target that no longer exists fails the check before any test runs "
        "(`python tools/mutation_check.py --targets`, also run by `tests/test_mutation_targets.py`).  "
        f"Wall time {wall:.0f} s; "
        f"load average (1 min) {load0[0]:.1f} at the start, {load1[0]:.1f} at the end (2 cores, "
        "shared with other work).",
        "",
        "| # | area | test | break (file: old -> new) | failed? | how |",
        "|---|---|---|---|---|---|",
    ]
    for k, (cat, file, old, new, node, what, failed, how, _dt) in enumerate(rows, 1):
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
