"""Start-up and end-to-end benchmark: ``python -m benchmarks.startup --force`` -> reports/bench_startup.md.

Issue 14 (``coefficients --json`` <= 0.9 s, ``penetrate --help`` <= 0.3 s), issue 12
(``penetrate --posterior`` <= 2 s) and issue 17 (one ``penetrate`` call for 50 velocities in all
regimes <= 0.5 s), end to end in fresh interpreters on a cached coefficient table.  Each command
runs for this tree and for a git revision (default ``main``, extracted with ``git archive``)
alternately in one session, each version with its own warm coefficient cache; the report gives
the CPU time (user + system of the command: what other users of a shared machine inflate least),
the wall time, and the ratio of the two versions' CPU times.  Then the in-process times of the
parts of ``penetrate --posterior`` and of the 50-velocity call (imports, case, table, models,
posterior), and the ``python -X importtime`` budget of ``penetrate --help`` and of loading a case.
"""

from __future__ import annotations

import os
import platform
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]  # the checkout (benchmarks/ is not installed)
REPORT = ROOT / "reports" / "bench_startup.md"
CASE = "cases/fig5_ogive.toml"
CALIBRATED = "cases/piekutowski1999_var4340.toml"
N_VELOCITIES = 50  # issue 17: 0.5 to 3 km/s, rigid, deforming and eroding

# in-process phases of ``penetrate CASE [--posterior FILE] --json`` (CPU seconds, one fresh interpreter)
PHASES = r"""
import sys, time
T = time.process_time
marks, t0 = [], T()
def mark(name):
    global t0
    t = T(); marks.append((name, t - t0)); t0 = t
case_path, posterior = sys.argv[1], (sys.argv[2] if len(sys.argv) > 2 else None)
import numpy; mark("import numpy")
from semianalytic.case import load_case; mark("import semianalytic.case (pydantic, schemas)")
case = load_case(case_path); mark("load_case")
from semianalytic.cache import coefficients_for_case
coefficients, _, _ = coefficients_for_case(case); mark("cached coefficient table (read)")
import semianalytic.penetration.curve, semianalytic.penetration.critical
from semianalytic.commands.penetrate.evaluate import evaluate_case; mark("import the models (scipy.integrate, interpolate, optimize)")
if posterior:
    from semianalytic.commands.calibrate.evaluate import predict_with_posterior; mark("import the calibration")
    predict_with_posterior(case, coefficients, posterior); mark("predictive quantiles (predict_with_posterior)")
import warnings
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    evaluate_case(case, coefficients); mark("the depths (evaluate_case)")
    evaluate_case(case, coefficients); mark("the depths again, same process (evaluate_case)")
for name, t in marks:
    print(f"{t:.4f}\t{name}")
"""


def _run(pythonpath: Path, argv: list[str], env: dict, cwd: Path) -> tuple[float, float]:
    """(wall, CPU) seconds of ``python argv`` in a subprocess; CPU = user + system time of the child."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    # cwd outside both trees: ``python -m`` puts the cwd first on sys.path, before PYTHONPATH
    subprocess.run([sys.executable, *argv], check=True, cwd=cwd, env=dict(env, PYTHONPATH=str(pythonpath)),
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)


def _phases(pythonpath: Path, args: list[str], env: dict, cwd: Path) -> list[tuple[str, float]]:
    out = subprocess.run([sys.executable, "-c", PHASES, *args], check=True, cwd=cwd, capture_output=True, text=True,
                         env=dict(env, PYTHONPATH=str(pythonpath)))
    rows = []
    for line in out.stdout.splitlines():
        t, name = line.split("\t", 1)
        rows.append((name, float(t)))
    return rows


def _importtime(pythonpath: Path, args: list[str], env, cwd: Path, top: int = 12) -> list[tuple[str, float, float]]:
    out = subprocess.run([sys.executable, "-X", "importtime", *args], cwd=cwd, capture_output=True, text=True,
                         env=dict(env, PYTHONPATH=str(pythonpath)))
    rows = []
    for line in out.stderr.splitlines():
        if not line.startswith("import time:") or "cumulative" in line:
            continue
        self_us, cum_us, name = line[len("import time:"):].split("|", 2)
        depth = len(name) - len(name.lstrip(" "))
        if depth <= 1:  # top-level imports (what the program asked for)
            rows.append((name.strip(), float(self_us) / 1e6, float(cum_us) / 1e6))
    rows.sort(key=lambda r: -r[2])
    return rows[:top]


def _fifty_velocities_case(folder: Path) -> Path:
    """The calibrated VAR 4340 case with 50 striking velocities from 0.5 to 3 km/s (its data file beside it)."""
    text = (ROOT / CALIBRATED).read_text()
    velocities = ", ".join(f'"{500 + 2500 * k / (N_VELOCITIES - 1):.1f} m/s"' for k in range(N_VELOCITIES))
    text, n = re.subn(r"striking_velocities = \[[^\]]*\]", f"striking_velocities = [{velocities}]", text)
    if n != 1:
        raise RuntimeError(f"{CALIBRATED}: no striking_velocities list to replace")
    data = re.search(r'^file = "([^"]+)"', text, re.M)
    if data:
        shutil.copy(ROOT / "cases" / data.group(1), folder / data.group(1))
    path = folder / f"var4340_{N_VELOCITIES}_velocities.toml"
    path.write_text(text)
    return path


def main(argv=None) -> int:
    from semianalytic.cli_types import OneLineParser, integer

    parser = OneLineParser(prog="python -m benchmarks.startup", description=__doc__.splitlines()[0])
    parser.add_argument("--force", action="store_true", help="overwrite the report")
    parser.add_argument("--repeat", type=integer(1, 20), default=3, help="timed runs of each command and version (after a warm-up)")
    parser.add_argument("--base", default="main", help="git revision to compare with (default main; '' for none)")
    parser.add_argument("--report", default=str(REPORT))
    args = parser.parse_args(argv)

    from semianalytic.io import atomic_write_text, check_report_target
    from semianalytic.report.document import Document, to_markdown

    report = check_report_target(Path(args.report), args.force)
    with tempfile.TemporaryDirectory(prefix="bench_startup_") as tmp_name:
        tmp = Path(tmp_name)
        env0 = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
        versions = {"this tree": ROOT}
        if args.base:
            from semianalytic.io import extract_revision

            versions[args.base] = extract_revision(args.base, tmp / "base", "semianalytic", "fem_check")
        envs = {k: dict(env0, SEMIANALYTIC_CACHE_DIR=str(tmp / f"cache_{i}")) for i, k in enumerate(versions)}
        work = tmp / "work"
        work.mkdir()
        fifty = _fifty_velocities_case(work)
        case, calibrated = str(ROOT / CASE), str(ROOT / CALIBRATED)
        # the posterior of the bundled calibration (this tree's calibrate; both versions read it)
        subprocess.run([sys.executable, "-m", "semianalytic", "calibrate", calibrated, "--out", str(tmp / "posterior"),
                        "--quiet"], check=True, cwd=work, env=dict(envs["this tree"], PYTHONPATH=str(ROOT)),
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        posterior = str(tmp / "posterior" / "posterior.json")
        commands = [
            ("`python -c pass` (the bare interpreter)", ["-c", "pass"], ""),
            ("`python -c 'import numpy'`", ["-c", "import numpy"], ""),
            ("`python -m semianalytic penetrate --help`", ["-m", "semianalytic", "penetrate", "--help"], "<= 0.3 s"),
            (f"`python -m semianalytic coefficients {CASE} --json`", ["-m", "semianalytic", "coefficients", case, "--json"],
             "<= 0.9 s"),
            (f"`python -m semianalytic penetrate {CALIBRATED} --posterior DIR/posterior.json --json`",
             ["-m", "semianalytic", "penetrate", calibrated, "--posterior", posterior, "--json"], "<= 2 s"),
            (f"`python -m semianalytic penetrate` of the same case at {N_VELOCITIES} velocities, 0.5-3 km/s, `--json`",
             ["-m", "semianalytic", "penetrate", str(fifty), "--json"], "<= 0.5 s (issue 17)"),
        ]
        load0 = os.getloadavg()
        for k, path in versions.items():  # warm-up: each version's coefficient cache, the file-system cache
            for _, argv_, _ in commands:
                _run(path, argv_, envs[k], work)
        times = {(label, k): [] for label, _, _ in commands for k in versions}
        for _ in range(args.repeat):
            for label, argv_, _ in commands:
                for k, path in versions.items():
                    times[label, k].append(_run(path, argv_, envs[k], work))
        phases = {k: {"posterior": _phases(path, [calibrated, posterior], envs[k], work),
                      "fifty": _phases(path, [str(fifty)], envs[k], work)} for k, path in versions.items()}
        help_budget = _importtime(ROOT, ["-m", "semianalytic", "penetrate", "--help"], envs["this tree"], work)
        case_budget = _importtime(ROOT, ["-c", f"from semianalytic.case import load_case; load_case({case!r})"],
                                  envs["this tree"], work)
        load1 = os.getloadavg()

    names = list(versions)
    doc = Document("Start-up and end-to-end benchmark")
    doc.para(f"Generated by `python -m benchmarks.startup --force` on {platform.node()} ({os.cpu_count()} logical "
             f"cores, Python {platform.python_version()}, {time.strftime('%Y-%m-%d %H:%M')}). Every command runs in a fresh "
             f"interpreter, end to end, with a warm coefficient cache (one per version), BLAS on one thread; "
             f"{args.repeat} timed runs per command and version after a warm-up, the versions alternating. Load average "
             f"(1, 5, 15 min) {load0[0]:.1f}, {load0[1]:.1f}, {load0[2]:.1f} before and {load1[0]:.1f}, {load1[1]:.1f}, "
             f"{load1[2]:.1f} after: the machine is shared with other sessions, so the CPU time (user + system of the "
             "command) is the measure to read; the wall time is given beside it and is longer by the waiting for a "
             "core. On an idle machine the wall time of these single-threaded commands is their CPU time plus about "
             "0.01 s.")
    header = ["command", *(f"CPU [s] {k} (best)" for k in names), *(f"wall [s] {k} (best)" for k in names)]
    if args.base:
        header.append(f"CPU {args.base} / this tree")
    header.append("target")
    rows = []
    for label, _, target in commands:
        cpu = {k: min(c for _, c in times[label, k]) for k in names}
        wall = {k: min(w for w, _ in times[label, k]) for k in names}
        row = [label, *(f"{cpu[k]:.3f}" for k in names), *(f"{wall[k]:.3f}" for k in names)]
        if args.base:
            row.append(f"{cpu[args.base] / cpu['this tree']:.2f}x")
        rows.append([*row, target])
    doc.table(header, rows)
    doc.para("Issue 17's target (one `penetrate` call for 50 velocities in at most 0.5 s) cannot be met end to end: the "
             "interpreter, numpy, scipy's solvers and the case schemas alone cost more. The in-process times below give "
             "what the call itself costs once the process runs (the row 'the depths again, same process'; the first call "
             "also imports what the models load on use).")
    for key, title in (("posterior", f"`penetrate {CALIBRATED} --posterior ... --json`, in-process parts (CPU s)"),
                       ("fifty", f"`penetrate` at {N_VELOCITIES} velocities, in-process parts (CPU s)")):
        labels = [n for n, _ in phases["this tree"][key]]
        by = {k: dict(phases[k][key]) for k in names}
        doc.table(["part", *names], [[n, *(f"{by[k].get(n, float('nan')):.3f}" for k in names)] for n in labels],
                  caption=title)
    doc.heading("Import budget (`python -X importtime`, this tree)")
    doc.para("The largest top-level imports (cumulative, one run; wall time, so inflated by the load). What is not here "
             "is not imported: `tests/test_startup_imports.py` checks that `--help` of every command imports none of "
             "scipy.integrate, dask, distributed, matplotlib, pyvista, gmsh, scikit-fem, and `penetrate --help` not even "
             "numpy or pydantic; that loading every bundled case (and its shot table) imports none of pint, pandas, "
             "scipy.integrate/optimize/interpolate/linalg/special, the BEM, dask, matplotlib (a table nose excepted: it "
             "builds its spline with scipy.interpolate); and that reading a cached coefficient table imports neither the "
             "BEM nor those.")
    for title, budget in (("`python -m semianalytic penetrate --help`", help_budget), (f"`load_case({CASE!r})`", case_budget)):
        doc.table(["module", "self [ms]", "cumulative [ms]"],
                  [[f"`{n}`", f"{s * 1e3:.1f}", f"{c * 1e3:.1f}"] for n, s, c in budget], caption=title)
    doc.para("Budget: the interpreter and `site` about 0.03 s of CPU; `penetrate --help` imports only the dispatcher and "
             "the command's argument parser; a projectile case adds numpy and pydantic with the case schemas, not pint: "
             "the common unit strings ('7.11 mm', '1.0 km/s', '7830 kg/m^3', ...) are read with pint's own conversion "
             "factors (`semianalytic/units.py`, checked bit for bit against pint by `tests/test_units_fast_path.py`), "
             "every other string goes to pint. A cached coefficient table is read without scipy or the BEM "
             "(`coefficients/table.py` imports scipy.interpolate and the BEM when it builds a table). The shot tables "
             "are read with the csv module, not pandas. The models import scipy.integrate, scipy.interpolate and "
             "scipy.optimize because every depth uses them (cumulative_simpson, CubicSpline, brentq, solve_ivp); "
             "scipy.special alone costs about 0.25 s of CPU here, mostly scipy's array-API layer importing numpy's "
             "optional submodules.")
    atomic_write_text(report, to_markdown(doc))
    cpu = {label: min(c for _, c in times[label, "this tree"]) for label, _, _ in commands}
    print("; ".join(f"{label}: {t:.3f} s CPU" for label, t in cpu.items()) + f"; report: {report}")
    return 0


if __name__ == "__main__":
    from semianalytic.errors import exit_status

    raise SystemExit(exit_status(main))
