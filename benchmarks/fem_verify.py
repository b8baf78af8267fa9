"""``python -m benchmarks.fem_verify --out reports/``: time ``fem_check verify`` against main's version.

Issue 14, item 5: ``fem_check verify cases/fig5_ogive.toml --no-report --json`` spent 58% of
its time in an O(n^2) evaluation of the hemisphere series (even for the ogive).  This benchmark
runs the command of this tree and of a git revision (default ``main``, extracted with
``git archive`` into a temporary folder) alternately in one session on the same machine, each
with a warm mesh cache of its own, and writes the ratio to ``bench_fem_verify.md``; it also
times the hemisphere series both ways in-process.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# the unloaded-machine time of main's version (with the recurrence) as the previous run of this benchmark
# estimated it: 27 s (issue 14, the version before the recurrence, unloaded) x 23.55 s / 47.89 s (CPU ratio
# measured in one run, 2026-11-24 20:xx)
MAIN_IDLE_ESTIMATE = 27.0 * 23.55 / 47.89


def _direct_series(n_terms: int = 4000) -> dict:
    """The former O(n^2) evaluation (Gauss-Legendre sums of eval_legendre), for the timing only."""
    import numpy as np
    from scipy.special import eval_legendre

    n = np.arange(0, n_terms + 1, 2)
    x, w = np.polynomial.legendre.leggauss(n_terms // 2 + 4)
    x, w = 0.5 * (x + 1), 0.5 * w
    I = np.array([np.sum(w * x * eval_legendre(k, x)) for k in n])
    c = (2 * n + 1) * I / (n + 1)
    return {"phi_tip_over_a": float(c.sum()), "Abar_over_a": float(np.sum(c * 2 * I))}


# in-process phases of the command's work for a projectile case (CPU seconds, one fresh interpreter);
# the functions are wrapped where verify calls them, so the same script times either version
PHASES = r"""
import inspect, sys, time
T = time.process_time
t0 = T()
import fem_check.coefficients as fc
import fem_check.verify as fv
import semianalytic.coefficients.table as table
from semianalytic.case import load_case
from semianalytic.geometry import nose_from_section
spent = {}
def timed(module, name, label):
    f = getattr(module, name)
    def wrapper(*a, **k):
        t = T()
        try:
            return f(*a, **k)
        finally:
            spent[label] = spent.get(label, 0.0) + T() - t
    setattr(module, name, wrapper)
timed(table, "coefficients_at", "BEM reference (direct BEM solves)")
timed(fc, "halfspace_mesh", "FEM meshes (read from the mesh cache)")
timed(fc, "moved_meshes", "moved meshes of the shape derivative (harmonic extension)")
timed(fc, "solve_potential", "FEM solves (assembly and sparse LU, 3 per depth)")
nose = nose_from_section(load_case(sys.argv[1]).projectile)
t_import = T() - t0
t1 = T()
memo = {} if "memo" in inspect.signature(fv.compare_depths).parameters else None
kw = {} if memo is None else {"memo": memo}
fv.compare_depths(nose, fv.DEFAULT_DEPTHS, h=0.04, **kw)
t_compare = T() - t1
t1 = T()
fv.convergence_study(nose, **kw)
t_study = T() - t1
print(f"{t_import:.4f}\timports and the case")
print(f"{t_compare:.4f}\tcomparison at the 8 default depths (FEM h = 0.04 d, P2, and BEM)")
print(f"{t_study:.4f}\tconvergence study (3 depths, P1 and P2, 4 element sizes)")
for label, t in spent.items():
    print(f"{t:.4f}\t  of which: {label}")
rest = t_compare + t_study - sum(spent.values())
print(f"{rest:.4f}\t  of which: the rest (surface integrals, phi_tip, ...)")
"""


def _phases(pythonpath: Path, case: str, env: dict, cwd: Path) -> list[tuple[str, float]]:
    out = subprocess.run([sys.executable, "-c", PHASES, case], check=True, cwd=cwd, capture_output=True, text=True,
                         env=dict(env, PYTHONPATH=str(pythonpath)))
    return [(name, float(t)) for t, name in (ln.split("\t", 1) for ln in out.stdout.splitlines())]


def _run(pythonpath: Path, argv: list[str], env: dict, cwd: Path) -> tuple[float, float]:
    """(wall, CPU) seconds of the command in a subprocess; CPU = user + system time of the child,
    which other users of a shared machine inflate far less than the wall time."""
    import resource

    e = dict(env, PYTHONPATH=str(pythonpath))
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    # cwd outside both trees: ``python -m`` puts the cwd first on sys.path, before PYTHONPATH
    subprocess.run([sys.executable, "-m", "fem_check", *argv], check=True, cwd=cwd, env=e,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)


def main(argv: list[str] | None = None) -> int:
    from fem_check.verify import hemisphere_reference
    from semianalytic.cli_types import OneLineParser, integer
    from semianalytic.io import extract_revision

    ap = OneLineParser(prog="python -m benchmarks.fem_verify", description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="reports", help="folder of bench_fem_verify.md (default reports)")
    ap.add_argument("--base", default="main", help="git revision to compare with (default main)")
    ap.add_argument("--case", default="cases/fig5_ogive.toml")
    ap.add_argument("--repeat", type=integer(1, 20), default=1, help="timed runs of each version after a warm-up run")
    args = ap.parse_args(argv)
    cmd = ["verify", str((ROOT / args.case).resolve()), "--no-report", "--json"]
    shown = ["verify", args.case, "--no-report", "--json"]
    with tempfile.TemporaryDirectory(prefix="bench_fem_verify_") as tmp:
        base = extract_revision(args.base, Path(tmp) / "base", "fem_check", "semianalytic")
        env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")
        envs = {"this tree": dict(env, FEM_CHECK_MESH_CACHE=str(Path(tmp) / "mesh_new")),
                args.base: dict(env, FEM_CHECK_MESH_CACHE=str(Path(tmp) / "mesh_base"))}
        paths = {"this tree": ROOT, args.base: base}
        times: dict[str, list[tuple[float, float]]] = {k: [] for k in paths}
        for k in paths:  # warm-up: meshes into each version's cache, BEM table cache
            _run(paths[k], cmd, envs[k], Path(tmp))
        load0 = os.getloadavg()
        for _ in range(args.repeat):
            for k in paths:
                times[k].append(_run(paths[k], cmd, envs[k], Path(tmp)))
        phases = {k: _phases(paths[k], cmd[1], envs[k], Path(tmp)) for k in paths}
        load1 = os.getloadavg()
    t0 = time.process_time()
    new = hemisphere_reference()
    t_new = time.process_time() - t0
    t0 = time.process_time()
    old = _direct_series()
    t_old = time.process_time() - t0
    wall = {k: min(t[0] for t in v) for k, v in times.items()}
    cpu = {k: min(t[1] for t in v) for k, v in times.items()}
    lines = [
        "# Benchmark: `fem_check verify` (issue 14, item 5)", "",
        f"Generated by `python -m benchmarks.fem_verify --out {args.out} --base {args.base}`. Command timed: "
        f"`python -m fem_check {' '.join(shown)}`, end to end (subprocess), warm mesh caches (one per version), BLAS on one "
        f"thread, the two versions run alternately in one session on a shared 2-core machine. The machine is shared with "
        f"other sessions: the CPU time (user + system of the command) is the robust measure, the wall time is given "
        f"beside it; compare ratios. Load average (1, 5, 15 min) {load0[0]:.1f}, {load0[1]:.1f}, {load0[2]:.1f} before the "
        f"timed runs and {load1[0]:.1f}, {load1[1]:.1f}, {load1[2]:.1f} after them.", "",
        "| version | CPU [s] (best) | wall [s] (best) | runs: wall / CPU [s] |", "|---|---|---|---|",
        *[f"| {k} | {cpu[k]:.2f} | {wall[k]:.2f} | {', '.join(f'{w:.1f} / {c:.1f}' for w, c in times[k])} |"
          for k in times], "",
        f"**Ratio {args.base} / this tree: {cpu[args.base] / cpu['this tree']:.2f}x in CPU time "
        f"({wall[args.base] / wall['this tree']:.2f}x wall).** Issue 14's target is at most 12 s for this command "
        f"(27 s when the issue was filed, on an unloaded machine). {args.base} already holds the hemisphere recurrence: "
        f"the previous run of this benchmark put that version at {MAIN_IDLE_ESTIMATE:.1f} s on the unloaded machine (27 s "
        f"times its measured CPU ratio, 23.55 s / 47.89 s). Scaled by this run's ratio, this tree takes "
        f"**{MAIN_IDLE_ESTIMATE * cpu['this tree'] / cpu[args.base]:.1f} s** there. The absolute CPU times above are "
        f"not that figure: under the load given above CPU time is inflated too (shared caches and cores: on this shared "
        f"machine the same command's best CPU time varies by a quarter from one run of the benchmark to the next), "
        f"which is why the ratio measured in one run is the number to carry over.", "",
        "## Where the time goes (in-process CPU seconds, one run of each version)", "",
        f"| phase | this tree | {args.base} | {args.base} / this tree |", "|---|---|---|---|",
        *[f"| {name} | {t:.2f} | {dict(phases[args.base]).get(name, math.nan):.2f} | "
          f"{dict(phases[args.base]).get(name, math.nan) / t if t > 0 else math.nan:.2f}x |" for name, t in phases["this tree"]],
        "",
        "What changed for speed in this tree: the comparison and the convergence study share the three solves they "
        "both need (P2, h = 0.04 d at 0.5, 2 and 8 L_h); the meshes moved for the shape derivative and the meshes shifted "
        "to the tip reuse the facet arrays of their original (scikit-fem would sort all facets again for every copy); "
        "the facet bases reuse the cell basis' degree-of-freedom numbering and skip the global dof locations they never "
        "read; the mesh cache keeps the scikit-fem arrays of each mesh beside its .msh file, so a cached mesh is read "
        "without meshio and without matching its tagged lines to facets again (tests/test_fem_mesh_arrays.py: the same "
        "arrays). These leave every number the command prints unchanged (its JSON, timings aside, was identical before "
        "and after them). Last, the symmetric positive definite systems (the potential with the Robin far field, and the "
        "interior block of the mesh-moving Laplacian) are factorised by SuperLU in symmetric mode (minimum-degree "
        "ordering of K + K^T, diagonal pivots) instead of its general column ordering: about a third less time in the "
        "sparse LU. The same systems are solved, to round-off: A and phi_tip agree to 3e-14 (relative), while the "
        "centred difference dA/dP, whose step is small, amplifies that round-off to 4e-8 of dA/dP (B_body 1.3e-9, "
        "B_bernoulli 7e-8), far below the FEM-BEM differences the command reports (1e-6 and more); the finest rows of the "
        "convergence study (errors near 1e-7, at that round-off floor) move in their second or third digit.", "",
        "## Hemisphere series (in-process)", "",
        "| evaluation | CPU time [s] | phi_tip / a | Abar / a |", "|---|---|---|---|",
        f"| O(n) recurrence, 400,000 terms (this tree) | {t_new:.4f} | {new['phi_tip_over_a']:.15f} | {new['Abar_over_a']:.15f} |",
        f"| O(n^2) Gauss sums of eval_legendre, 4,000 terms (main) | {t_old:.2f} | {old['phi_tip_over_a']:.15f} | "
        f"{old['Abar_over_a']:.15f} |", "",
        "Numerical notes: phi_tip / a = 0.680633550050, Abar / a = 0.553967546980. The old 4,000-term sum of phi_tip was "
        "short by 8e-10 (its alternating tail); with the recurrence, 400,000 terms cost less than a millisecond per "
        "thousand terms. What else changed in `verify`: the far-field study (a hemisphere at P = R) now runs for "
        "sphere noses only, where its exact reference applies; the meshes are graded towards corners (the ogive's tip "
        "and, while it enters, its waterline), which adds elements there.", "",
    ]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    from semianalytic.io import atomic_write_text

    atomic_write_text(out / "bench_fem_verify.md", "\n".join(lines))
    print(out / "bench_fem_verify.md")
    return 0


if __name__ == "__main__":
    from semianalytic.errors import exit_status

    raise SystemExit(exit_status(main))
