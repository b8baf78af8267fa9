"""Sweep throughput benchmark: ``python -m benchmarks.sweep [--force]``.

Issue 14 adds two parts (``--skip-engines`` leaves out the long first one):

- engines: a geometry sweep of 64 ogive designs (``--vary projectile.crh``, one BEM table each,
  each engine with its own empty table cache) inline, on a LocalCluster of two workers and on
  an external scheduler with two worker processes started here (``dask scheduler``,
  ``dask worker``) and stopped after: wall times, speed-up and parallel efficiency;
- Monte Carlo on arrays: 20,020 cases per resistance model inline, beside the case-by-case path
  (each sample validated as its own case) and the grid sweep, measured in the same run.

A 10,000-case velocity-by-material sweep (100 target yield stresses x 100 striking
velocities, Part I eq. (11) with R_t of eq. (16)) of the bundled Fig. 5 ogive on one cached
coefficient table, on a dask LocalCluster with two single-threaded workers.  Writes
``reports/bench_sweep.md`` and ``reports/bench_sweep_depth_map.png``:

- throughput of the cases (cluster started and warmed up, table loaded: the steady rate),
  and the wall time of the whole command including the cluster start;
- a check of 25 random rows against an independent evaluation: the penetration package's
  time-domain solver (``solve_motion``, solve_ivp with an event at u = 0) at that row's R_t;
- an interrupted sweep (stopped after a third of its batches) resumed with ``--resume``:
  the cases run before and after, and that every case id is present exactly once.
"""

from __future__ import annotations

import os
import platform
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from semianalytic.sweep.kernels import PenetrationKernel

ROOT = Path(__file__).resolve().parents[1]  # the checkout (benchmarks/ is not installed)
CASE = ROOT / "cases" / "demo_fig5_ogive.toml"
REPORT = ROOT / "reports" / "bench_sweep.md"
ENGINES_REPORT = ROOT / "reports" / "bench_sweep_engines.md"
ENGINE_COLUMNS = ["engine", "workers", "wall time [s]", "speed-up vs inline", "parallel efficiency (wall)", "cases ok",
                  "CPU-time efficiency per worker", "CPU time / inline's", "tables per process",
                  "CPU per table [s]", "BLAS threads", "load average (1 min) before each block",
                  "machine busy during its blocks"]
VARY = ["target.resistance.yield_stress=250:745:5 MPa", "impact.striking_velocity=400:1390:10 m/s"]


def main(argv=None) -> int:
    from semianalytic.cli_types import OneLineParser, integer

    parser = OneLineParser(prog="python -m benchmarks.sweep", description=__doc__.splitlines()[0])
    parser.add_argument("--force", action="store_true", help="overwrite reports/bench_sweep.md")
    parser.add_argument("--workers", type=integer(1, 64), default=2)
    parser.add_argument("--report", default=str(REPORT))
    parser.add_argument("--skip-engines", action="store_true", help="leave out the 64-design geometry sweep")
    parser.add_argument("--designs", type=integer(1, 1000), default=64, help="designs of the geometry sweep (default 64)")
    parser.add_argument("--engines-only", action="store_true",
                        help="only the geometry sweep on the three engines, into reports/bench_sweep_engines.md "
                             "(or --report)")
    args = parser.parse_args(argv)
    if args.engines_only:
        return engines_report(Path(args.report if args.report != str(REPORT) else ENGINES_REPORT), args.force,
                              args.designs)

    import pandas as pd

    from semianalytic.case import load_case
    from semianalytic.io import atomic_write_bytes, atomic_write_text, check_report_target
    from semianalytic.penetration.curve import PenetrationSetup
    from semianalytic.penetration.motion import solve_motion
    from semianalytic.report.document import Document, fmt, to_markdown
    from semianalytic.report.figures import png_bytes
    from semianalytic.sweep.engine import run_sweep
    from semianalytic.sweep.kernels import coefficient_table_for
    from semianalytic.sweep.spec import apply_overrides, build_spec

    report = check_report_target(Path(args.report), args.force)
    case = load_case(CASE)
    t = time.perf_counter()
    table = coefficient_table_for(case)
    t_table = time.perf_counter() - t
    spec = build_spec(VARY)

    with tempfile.TemporaryDirectory(prefix="bench_sweep_") as tmp:
        tmp = Path(tmp)
        t = time.perf_counter()
        s = run_sweep(CASE, spec, tmp / "local", scheduler="local", workers=args.workers, progress=False)
        wall_local = time.perf_counter() - t
        df = pd.read_csv(tmp / "local" / "results.csv")
        s_inline = run_sweep(CASE, spec, tmp / "inline", scheduler="inline", progress=False)

        # independent check: the time-domain solver at random rows, chosen by case id (results.csv
        # is written in dask's completion order, so a choice by position differed from run to run)
        rng = np.random.default_rng(0)
        ids = np.sort(df.case_id.to_numpy())
        rows = df.set_index("case_id").loc[rng.choice(ids, 25, replace=False)]
        errs = []
        for _, r in rows.iterrows():
            Y = r["target.resistance.yield_stress_Pa"]
            raw = apply_overrides(case.raw, {"target.resistance.yield_stress": f"{Y!r} Pa"})
            from semianalytic.case import parse_case

            c = parse_case(raw, CASE)
            setup = PenetrationSetup.from_case(c, table, require_material=False)
            m = solve_motion(table, setup.mass, setup.target_density, setup.resistance_pa,
                             float(r["impact.striking_velocity_m_s"]), rtol=1e-13)
            errs.append(abs(r.depth_rigid_m - m.final_depth) / m.final_depth)
        max_err = max(errs)

        # interrupted and resumed
        count = {"n": 0}
        n_batches = 24

        def stop(_):
            count["n"] += 1
            if count["n"] == n_batches // 3:
                raise KeyboardInterrupt

        size = -(-spec.n_cases // n_batches)
        try:
            run_sweep(CASE, spec, tmp / "resume", scheduler="inline", progress=False, batch_size=size, on_batch=stop)
        except KeyboardInterrupt:
            pass
        before = len(pd.read_csv(tmp / "resume" / "results.csv"))
        s_res = run_sweep(CASE, spec, tmp / "resume", scheduler="inline", progress=False, resume=True, batch_size=size)
        ids = pd.read_csv(tmp / "resume" / "results.csv").case_id
        complete = sorted(ids) == list(range(spec.n_cases))

    # depth map
    from matplotlib.figure import Figure

    Y = np.array(spec.axes[0].values) / 1e6
    U = np.array(spec.axes[1].values)
    Z = df.sort_values("case_id").depth_rigid_m.to_numpy().reshape(len(Y), len(U)) * 1e3
    fig = Figure(figsize=(6.4, 4.4), layout="constrained")
    ax = fig.add_subplot()
    cs = ax.contourf(U, Y, Z, levels=20, cmap="viridis")
    fig.colorbar(cs, ax=ax, label="final depth, rigid projectile [mm]")
    ax.set_xlabel("striking velocity U_s [m/s]")
    ax.set_ylabel("target yield stress Y [MPa] (R_t by eq. (16))")
    ax.set_title("10,000-case sweep: Fig. 5 ogive into aluminium", fontsize=10)
    png = report.with_name(report.stem + "_depth_map.png")
    atomic_write_bytes(png, png_bytes(fig))
    mc_rows = monte_carlo_rows()
    engine_rows = None if args.skip_engines else engine_benchmark(args.designs)

    doc = Document("Sweep throughput benchmark")
    doc.para(f"Generated by `python -m benchmarks.sweep` on {platform.node()} "
             f"({os.cpu_count()} logical cores, Python {platform.python_version()}, {time.strftime('%Y-%m-%d %H:%M')}). "
             "The machine is shared with other jobs: the load average is given with the timings.")
    doc.para(f"Case `{CASE.relative_to(ROOT)}` (Fig. 5 ogive, 6061-T651 target, eq. (16)); sweep "
             + " x ".join(f"`--vary {v}`" for v in VARY) + f" = {spec.n_cases} cases; rigid final depth, "
             "U_sC (eqs. (33)/(36)) and the yield flag per case.")
    load = os.getloadavg()
    doc.table(
        ["quantity", "value"],
        [
            ["coefficient table (BEM, cached on disk after the first build) [s]", fmt(t_table, 3)],
            ["LocalCluster: workers x threads", f"{s.workers} x 1"],
            ["cluster start + worker warm-up + table hand-out [s]", fmt(s.seconds_prepare, 3)],
            ["cases: wall time [s]", fmt(s.seconds_cases, 3)],
            ["**throughput, LocalCluster [cases/s]**", f"**{s.cases_per_second:.0f}**"],
            ["whole command incl. cluster start [s]", fmt(wall_local, 3)],
            ["throughput incl. cluster start [cases/s]", f"{spec.n_cases / wall_local:.0f}"],
            ["inline (one process, no dask) [cases/s]", f"{s_inline.cases_per_second:.0f}"],
            ["ok / invalid / failed", f"{s.n_ok} / {s.n_invalid} / {s.n_error}"],
            ["load average (1, 5, 15 min) after the run", ", ".join(f"{v:.1f}" for v in load)],
        ],
        caption="Target: >= 1000 cases/s on this machine's two cores.",
    )
    doc.heading("Check against an independent solver")
    doc.para(f"25 random rows against `solve_motion` (eq. (11) in time, solve_ivp DOP853, rtol 1e-13, event at "
             f"u = 0): maximum relative difference of the final depth **{max_err:.1e}** (the sweep integrates "
             "eq. (11) in P once per worker with R_t = 1 Pa and scales the velocities by sqrt(R_t), an exact "
             "property of the linear form in u^2).")
    doc.heading("Interrupted and resumed")
    doc.para(f"The same sweep in {n_batches} batches, stopped after {n_batches // 3} of them ({before} cases written), "
             f"then `--resume`: {s_res.n_skipped} cases skipped as finished, {s_res.n_run} run; every case id present "
             f"exactly once: **{'yes' if complete else 'NO'}**.")
    doc.image(png.name, "Final depth over the swept (U_s, Y) plane.")
    doc.heading("Monte Carlo on arrays (issue 14)")
    doc.para("A Monte-Carlo run validates the case once at every corner of the box spanned by all its samples "
             "(the fields' validity is a range; a run whose box has an invalid corner checks each batch's box, and a "
             "batch with an invalid corner goes case by case, reporting each invalid sample), draws the samples as "
             "arrays and evaluates them together: R_t from the resistance model's closed form on the arrays "
             "(eqs. (16), (17), (19), Part IV eq. (6), constant; eq. (18)'s integral and the Part II cavity solve on "
             "a Chebyshev grid of 17 points per sampled field over the samples' box, checked against direct "
             "evaluation at three samples to 1e-11, else sample by sample), the final depth of eq. (11) "
             "for all (m, rho, R_t, U_s) on one coefficient table (`semianalytic/penetration/batch.py`), U_sC of "
             "eqs. (33)/(34) on arrays, and the results written as columns. The case-by-case path "
             "(`PenetrationKernel(vectorised=False)`) validates every sample as its own case through pydantic and pint, "
             "as before; `tests/test_sweep_vectorised.py` compares the two on the same samples for every "
             "model. Inline (one process), BEM table cached; 1540 samples x 13 striking velocities of "
             "`cases/fig15a_ogive_6061T651.toml`-like cases, samplers: the model's strength, "
             "`target.density=uniform(2690, 2730 kg/m^3)`, `projectile.density=normal(8020, 50 kg/m^3)`. The grid "
             "sweep (a velocity-by-strength grid, also evaluated on arrays) is run before and after the Monte-Carlo "
             "runs; the ratio is to the mean of its two rates.")
    doc.table(["run", "cases", "ok", "cases/s (cases)", "ratio to the grid sweep", "cases/s (whole call)",
               "load average (1 min)"], mc_rows,
              caption="Target: >= 20,000 cases/s inline for every model. All rates measured in this one run on the "
                      "shared machine; compare them as ratios. 'cases' excludes reading the case and checking the "
                      "spec and the sampled box (once per run), 'whole call' includes them.")
    if engine_rows is not None:
        doc.heading("Engines: a geometry sweep (issue 14)")
        doc.para(engine_rows["text"])
        doc.table(ENGINE_COLUMNS, engine_rows["rows"], caption=ENGINE_CAPTION)
    atomic_write_text(report, to_markdown(doc))
    print(f"{s.cases_per_second:.0f} cases/s on {s.workers} workers; report: {report}")
    return 0


MC_CASE = ROOT / "cases" / "fig15a_ogive_6061T651.toml"
MC_MODELS = {
    "elastic-plastic (eq. 16)": (None, "target.resistance.yield_stress=normal(400 MPa, 20 MPa)"),
    "brittle (eq. 17)": ('model = "brittle"\ncompressive_strength = "150 MPa"\ntensile_strength = "15 MPa"\n'
                         'youngs_modulus = "60 GPa"\npoisson_ratio = 0.2\nalpha = 0.8',
                         "target.resistance.compressive_strength=normal(150 MPa, 10 MPa)"),
    "hardening (eq. 18)": ('model = "hardening"\nyield_stress = "400 MPa"\nyoungs_modulus = "68.9 GPa"\nhardening_exponent = 0.1',
                           "target.resistance.yield_stress=normal(400 MPa, 20 MPa)"),
    "limestone (eq. 19)": ('model = "limestone"', "target.resistance.psi=normal(607 MPa, 30 MPa)"),
    "part4 (Part IV eq. 6)": ('model = "part4"\nyield_stress = "400 MPa"\nyoungs_modulus = "68.9 GPa"',
                              "target.resistance.yield_stress=normal(400 MPa, 20 MPa)"),
    "constant": ('model = "constant"\nvalue = "1.2 GPa"', "target.resistance.value=lognormal(1.2 GPa, 0.05)"),
    # Part II's AD995 constants (cases/cavity_ad995.toml) as the target's R_t, for the rate only
    "cavity (Part II, AD995 constants)": ('model = "cavity"\nyoungs_modulus = "373.14 GPa"\npoisson_ratio = 0.232\n'
                                          'tensile_strength = "0.262 GPa"\ncompressive_strength = "2.62 GPa"',
                                          "target.resistance.compressive_strength=normal(2.62 GPa, 0.05 GPa)"),
}


def _case_with_resistance(tmp: Path, resistance: str | None, name: str = "case") -> Path:
    text = MC_CASE.read_text()
    if resistance is not None:
        head, _, tail = text.partition("[target.resistance]")
        rest = tail.split("\n[", 1)
        text = head + "[target.resistance]\n" + resistance + "\n" + ("\n[" + rest[1] if len(rest) > 1 else "")
    p = tmp / f"{name}.toml"
    p.write_text(text)
    return p


def monte_carlo_rows() -> list[list[str]]:
    """Rates of the Monte-Carlo path per resistance model, the case-by-case path and the grid sweep,
    in one run (the grid sweep first and last: the load drifts), with the ratio to the grid sweep."""
    from semianalytic.sweep.engine import run_sweep
    from semianalytic.sweep.kernels import PenetrationKernel
    from semianalytic.sweep.spec import build_spec

    runs = []
    common = ["target.density=uniform(2690 kg/m^3, 2730 kg/m^3)", "projectile.density=normal(8020 kg/m^3, 50 kg/m^3)"]
    with tempfile.TemporaryDirectory(prefix="bench_mc_") as tmp:
        tmp = Path(tmp)
        grid_case = _case_with_resistance(tmp, None, "grid")

        def grid(label):
            s = run_sweep(grid_case, build_spec(VARY), tmp / "grid", scheduler="inline", progress=False, force=True)
            runs.append((label, s, os.getloadavg()[0]))
            return s.cases_per_second

        g0 = grid("grid sweep (Y x U_s, the 10,000 cases above), before")
        for name, (res, sample) in MC_MODELS.items():
            case = _case_with_resistance(tmp, res, f"mc{len(runs)}")
            spec = build_spec([], [sample, *common], 1540, 1)
            s = run_sweep(case, spec, tmp / "mc", scheduler="inline", progress=False, force=True)
            runs.append((f"Monte Carlo on arrays: {name}", s, os.getloadavg()[0]))
        spec = build_spec([], [MC_MODELS["elastic-plastic (eq. 16)"][1], *common], 40, 1)
        s = run_sweep(grid_case, spec, tmp / "mc", scheduler="inline", progress=False, force=True,
                      kernel=PenetrationKernel(vectorised=False))
        runs.append(("case by case (before issue 14): elastic-plastic", s, os.getloadavg()[0]))
        g1 = grid("grid sweep, after")
    ref = 0.5 * (g0 + g1)
    return [[label, str(s.n_run), str(s.n_ok), f"{s.cases_per_second:.0f}", f"{s.cases_per_second / ref:.2f}",
             f"{s.n_run / s.seconds_total:.0f}", f"{load:.1f}"] for label, s, load in runs]


@dataclass(frozen=True)
class _RecordingKernel(PenetrationKernel):
    """The penetration kernel, recording per coefficient table the worker (pid, session), its wall
    and CPU time and its BLAS thread limit (one line per table, appended to ``log``)."""

    log: str = ""

    def prepare(self, case):
        import json

        t, c = time.perf_counter(), time.process_time()
        table = super().prepare(case)
        try:
            from threadpoolctl import threadpool_info

            blas = max((i.get("num_threads", 1) for i in threadpool_info()), default=1)
        except ImportError:
            blas = None
        line = json.dumps({"pid": os.getpid(), "sid": os.getsid(0), "wall": time.perf_counter() - t,
                           "cpu": time.process_time() - c, "blas_threads": blas,
                           "openblas_env": os.environ.get("OPENBLAS_NUM_THREADS"),
                           "malloc_trim": os.environ.get("MALLOC_TRIM_THRESHOLD_")})
        with open(self.log, "a") as fh:
            fh.write(line + "\n")
        return table


def _worker_stats(log: Path) -> dict:
    import json

    recs = [json.loads(x) for x in log.read_text().splitlines()] if log.exists() else []
    per = {}
    for r in recs:
        per.setdefault(r["pid"], []).append(r)
    wall = sum(r["wall"] for r in recs)
    cpu = sum(r["cpu"] for r in recs)
    return {"tables_per_process": sorted((len(v) for v in per.values()), reverse=True),
            "sessions": len({r["sid"] for r in recs}), "cpu_share": cpu / wall if wall > 0 else float("nan"),
            "cpu_per_table": cpu / max(len(recs), 1), "blas_threads": sorted({r["blas_threads"] for r in recs}, key=str),
            "openblas_env": sorted({str(r["openblas_env"]) for r in recs}),
            "malloc_trim": sorted({str(r.get("malloc_trim")) for r in recs}),
            "cpu_per_process": sorted((sum(r["cpu"] for r in v) for v in per.values()), reverse=True),
            "cpu_total": cpu}


_DIAGNOSTIC = """
import os, sys, time
from pathlib import Path
from semianalytic.case import load_case, parse_case
from semianalytic.sweep.kernels import coefficient_table_for
from semianalytic.sweep.spec import apply_overrides
case_file, cache, n = Path(sys.argv[1]), sys.argv[2], int(sys.argv[3])
case = load_case(case_file)
coefficient_table_for(parse_case(apply_overrides(case.raw, {"projectile.crh": 9.9}), case_file), cache + "w")
t0 = os.times()
for k in range(n):
    coefficient_table_for(parse_case(apply_overrides(case.raw, {"projectile.crh": 1.05 + 0.1 * k}), case_file), cache)
t1 = os.times()
print((t1.user - t0.user) / n, (t1.system - t0.system) / n)
"""


def malloc_diagnostic(case: Path, tmp: Path, n: int = 8) -> dict:
    """CPU per table (user, system) in a plain process, with and without dask's MALLOC_TRIM_THRESHOLD_."""
    import subprocess
    import sys

    out = {}
    for label, trim in (("plain", None), ("MALLOC_TRIM_THRESHOLD_=65536", "65536")):
        env = {k: v for k, v in os.environ.items() if k != "MALLOC_TRIM_THRESHOLD_"}
        env["OPENBLAS_NUM_THREADS"] = "1"
        if trim:
            env["MALLOC_TRIM_THRESHOLD_"] = trim
        res = subprocess.run([sys.executable, "-c", _DIAGNOSTIC, str(case), str(tmp / f"diag_{len(out)}"), str(n)],
                             env=env, capture_output=True, text=True, check=True)
        user, system = map(float, res.stdout.split()[-2:])
        out[label] = (user, system)
    return out


ENGINE_CAPTION = ("Target: CPU-time efficiency >= 80 % per worker on 2 workers on a quiet machine (and a speed-up >= 1.6x "
                  "there); on a shared machine the workers get a share of the cores, given by the load columns.")


def engines_report(report: Path, force: bool, n_designs: int) -> int:
    """``--engines-only``: the geometry sweep on the three engines, alone, into ``report``."""
    from semianalytic.io import atomic_write_text, check_report_target
    from semianalytic.report.document import Document, to_markdown

    report = check_report_target(report, force)
    rows = engine_benchmark(n_designs)
    doc = Document("Sweep engines: a geometry sweep inline, on a LocalCluster and on an external scheduler")
    doc.para(f"Generated by `python -m benchmarks.sweep --engines-only --designs {n_designs} --force` "
             f"({os.cpu_count()} logical cores, Python {platform.python_version()}, {time.strftime('%Y-%m-%d %H:%M')}). "
             "The machine is shared with other jobs: the load average and the machine's busy fraction are given "
             "beside every timing.")
    doc.para(rows["text"])
    doc.table(ENGINE_COLUMNS, rows["rows"], caption=ENGINE_CAPTION)
    atomic_write_text(report, to_markdown(doc))
    print(rows["summary"] + f"; report: {report}")
    return 0


def _cpu_counters() -> tuple[float, float] | None:
    """(busy, total) jiffies of all cores since boot (/proc/stat), None where unavailable."""
    try:
        fields = [float(v) for v in Path("/proc/stat").read_text().splitlines()[0].split()[1:]]
    except (OSError, ValueError, IndexError):
        return None
    idle = fields[3] + (fields[4] if len(fields) > 4 else 0.0)  # idle + iowait
    return sum(fields) - idle, sum(fields)


def engine_benchmark(n_designs: int = 64) -> dict:
    """The geometry sweep on the three engines (see the module docstring)."""
    import json
    import shutil
    import subprocess
    import sys

    from semianalytic.report.document import fmt
    from semianalytic.sweep.engine import connect, run_sweep
    from semianalytic.sweep.spec import build_spec

    step = 0.1
    crh = [1.0 + step * k for k in range(n_designs)]
    n_blocks = 4 if n_designs >= 16 else 1
    blocks = [crh[i::n_blocks] for i in range(n_blocks)]  # interleaved: each block spans the whole range
    engines = ("inline", "local", "external")
    walls = dict.fromkeys(engines, 0.0)
    loads: dict[str, list] = {e: [] for e in engines}
    busy = dict.fromkeys(engines, 0.0)  # machine busy and total jiffies during each engine's blocks
    total = dict.fromkeys(engines, 0.0)
    summaries: dict = {}
    with tempfile.TemporaryDirectory(prefix="bench_engines_") as tmp:
        tmp = Path(tmp)
        # the optimize case with lighter tables (20 depths to 40 nose lengths): a design costs about a second
        case = tmp / "geometry_sweep.toml"
        text = (ROOT / "cases" / "optimize_fig5_into_fig15a.toml").read_text()
        case.write_text(text.replace("depths = 40", "depths = 20").replace("max_depth_nose_lengths = 60.0",
                                                                          "max_depth_nose_lengths = 40.0"))
        diag = malloc_diagnostic(case, tmp, n=min(8, n_designs))  # a small run (the tests) builds fewer
        t = time.perf_counter()
        client, cluster, _ = connect("local", 2)  # what run_sweep starts for scheduler="local"
        local_start = time.perf_counter() - t
        client.close()
        sched_file = tmp / "scheduler.json"
        env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
        dask = shutil.which("dask", path=str(Path(sys.executable).parent)) or "dask"
        procs = [subprocess.Popen([dask, "scheduler", "--scheduler-file", str(sched_file), "--port", "0",
                                   "--dashboard-address", ":0", "--no-show"], env=env,
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
        try:
            for _ in range(300):
                if sched_file.exists() and sched_file.stat().st_size > 0:
                    break
                time.sleep(0.1)
            # two worker processes, each in its own session, as workers started by another service are (and as
            # the LocalCluster's workers move themselves: sweep.engine.own_session)
            for _ in range(2):
                # --no-nanny: a nanny would set MALLOC_TRIM_THRESHOLD_ (see sweep.engine.connect)
                procs.append(subprocess.Popen([dask, "worker", "--scheduler-file", str(sched_file), "--nthreads", "1",
                                               "--no-nanny", "--no-dashboard"], env=env, start_new_session=True,
                                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
            address = json.loads(sched_file.read_text())["address"]
            from dask.distributed import Client

            with Client(address, timeout="30s") as c:
                c.wait_for_workers(2, timeout=120)
            sched = {"inline": "inline", "local": cluster.scheduler_address, "external": address}
            # the engines take turns block by block (order rotated), so each sees the same load of the other
            # sessions on this shared machine
            for b, values in enumerate(blocks):
                spec = build_spec(["projectile.crh=" + ",".join(f"{v:.4f}" for v in values)])
                for engine in engines[b % 3:] + engines[: b % 3]:
                    loads[engine].append(os.getloadavg()[0])
                    c0 = _cpu_counters()
                    t = time.perf_counter()
                    s = run_sweep(case, spec, tmp / f"{engine}{b}", scheduler=sched[engine], workers=2,
                                  progress=False, force=True,
                                  kernel=_RecordingKernel(cache_dir=str(tmp / f"cache_{engine}"),
                                                          log=str(tmp / f"log_{engine}.jsonl")))
                    walls[engine] += time.perf_counter() - t
                    c1 = _cpu_counters()
                    if c0 and c1:
                        busy[engine] += c1[0] - c0[0]
                        total[engine] += c1[1] - c0[1]
                    summaries.setdefault(engine, []).append(s)
            stats = {e: _worker_stats(tmp / f"log_{e}.jsonl") for e in engines}
        finally:
            cluster.close()
            for p in reversed(procs):
                p.terminate()
            for p in procs:
                try:
                    p.wait(timeout=30)
                except subprocess.TimeoutExpired:
                    p.kill()
    base = walls["inline"]
    rows = []
    summary = []
    for engine in engines:
        wall, st = walls[engine], stats[engine]
        n_ok = sum(x.n_ok for x in summaries[engine])
        workers = summaries[engine][0].workers
        speed = base / wall
        name = {"inline": "inline (this process)", "local": "LocalCluster (2 x 1 thread, processes, own sessions)",
                "external": "dask scheduler + 2 x dask worker --no-nanny (own sessions)"}[engine]
        started = f"{speed:.2f}x" if engine != "local" else f"{speed:.2f}x ({base / (wall + local_start):.2f}x with the start)"
        per_worker = [c / wall for c in st["cpu_per_process"]]
        inflation = st["cpu_total"] / stats["inline"]["cpu_total"] if stats["inline"]["cpu_total"] else float("nan")
        machine = f"{100 * busy[engine] / total[engine]:.0f} % of {os.cpu_count()} cores" if total[engine] else "n/a"
        rows.append([name, str(workers), fmt(wall, 4) + (f" + {local_start:.1f} start" if engine == "local" else ""),
                     started, f"{100 * speed / max(workers, 1):.0f} %", str(n_ok),
                     " / ".join(f"{100 * e:.0f} %" for e in per_worker), f"{inflation:.2f}",
                     " / ".join(str(n) for n in st["tables_per_process"]), f"{st['cpu_per_table']:.2f}",
                     ", ".join(map(str, st["blas_threads"])), ", ".join(f"{v:.1f}" for v in loads[engine]), machine])
        summary.append(f"{engine}: {wall:.1f} s, CPU-time efficiency per worker "
                       + "/".join(f"{100 * e:.0f}%" for e in per_worker) + f", load {np.mean(loads[engine]):.1f}")
    autogroup = Path("/proc/sys/kernel/sched_autogroup_enabled")
    ag = autogroup.read_text().strip() if autogroup.exists() else "n/a"
    text = (f"`--vary projectile.crh=1.0:{1.0 + step * (n_designs - 1):.1f}:{step}` on "
            f"`cases/optimize_fig5_into_fig15a.toml` with lighter tables (20 depths to 40 nose lengths): "
            f"{n_designs} ogive designs x 7 striking velocities; every design builds its own BEM coefficient table, "
            "each engine with an empty table cache. The designs run in 4 interleaved blocks of 16 and the engines "
            "take turns block by block (order rotated), so that all three see the same load of the other sessions "
            "on this shared machine; wall time = the sum of the blocks' `run_sweep` calls; the LocalCluster "
            "(started by `sweep.engine.connect`, as `run_sweep` starts it) is started once and its start time given "
            "apart, the external cluster is started beforehand, as a user's would be. Without `--scheduler` "
            "the sweep picks the engine itself (`sweep/engine.py: choose_engine`): this sweep goes to a local "
            "cluster, a velocity or material sweep on one table runs inline. Recorded inside every table build: "
            "which process built it (tables per process: both workers get work), its CPU time, the CPU share (CPU "
            "time / wall time of the builds: 1.0 = a whole core while building) and the BLAS thread limit "
            "(threadpoolctl).\n\n"
            "What made the local cluster slower than inline (0.84x in the previous version of this report), found by "
            "timing the same table builds in one plain process and inside dask workers: (1) dask starts its "
            "workers with MALLOC_TRIM_THRESHOLD_ = 65536 (`distributed.nanny.pre-spawn-environ`); an explicit trim "
            "threshold turns off glibc's dynamic mmap threshold, so every large array of the BEM is mmap-ed and "
            "page-faulted afresh. Measured in this run, 8 tables in a plain process: CPU per table (user + system) "
            + " against ".join(f"{u + sy:.2f} s ({sy:.2f} s system) {lab}" for lab, (u, sy) in
                               [("with MALLOC_TRIM_THRESHOLD_ = 65536", diag["MALLOC_TRIM_THRESHOLD_=65536"]),
                                ("without", diag["plain"])])
            + "; the LocalCluster now starts its workers without it, and the "
            "external workers here run without a nanny (`dask worker --no-nanny`), which does not set it; (2) the "
            "workers' statistical profiler (a thread sampling the task's stack every 10 ms, for the dashboard) is "
            "off (the table below gives the CPU per table in the workers against inline); (3) the "
            "kernel's autogroup scheduling (`/proc/sys/kernel/sched_autogroup_enabled` = "
            f"{ag}) shares the CPU between sessions, so workers left in the sweep's session share one session's "
            "share while other sessions keep the cores busy (measured: the two local workers at about 50 % of a core "
            "each beside another session's one process at 95 %); the LocalCluster's workers now move into sessions "
            "of their own (`own_session`), as workers started by a scheduler service are; (4) every table went to "
            "the client and was broadcast to every worker before the cases started; now one task per design "
            "builds its table and evaluates its cases. The BLAS thread limit is 1 in the workers (the inline "
            "process keeps its 2 threads). The speed-up still depends on the other sessions' load: with k busy "
            "sessions on 2 cores, one inline process gets about 2/(k+1) of a core and two workers about "
            "2 x 2/(k+2), so at best 2 on an idle machine and (2k+2)/(k+2) on a shared one (1.33 for k = 1); "
            "the load averages are given.")
    text += ("\n\nColumns (this project's own definitions): *CPU-time efficiency per worker* = the CPU time the "
             "worker process spent building its tables / the engine's wall time (100 %: it computed all the time; "
             "on a shared machine it is bounded by the worker's share of a core); *CPU time / inline's* = the CPU "
             "time of all the engine's table builds over the inline builds' (the work's inflation in the workers: "
             "1.00 = none); *machine busy* = the busy fraction of all cores (/proc/stat) while the engine's blocks "
             "ran, every session's work included. On a quiet machine the speed-up on n workers is about n x the "
             "CPU-time efficiency / the inflation. To measure it there: "
             "`python -m benchmarks.sweep --engines-only --force` (a few minutes; "
             "`--designs 16` for a shorter run).")
    return {"rows": rows, "text": text, "summary": "; ".join(summary)}


if __name__ == "__main__":
    from semianalytic.errors import exit_status

    raise SystemExit(exit_status(main))
