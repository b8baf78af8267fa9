"""Sweep throughput benchmark: ``python -m semianalytic.sweep.benchmark [--force]``.

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

import argparse
import os
import platform
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent.parent
CASE = ROOT / "cases" / "demo_fig5_ogive.toml"
REPORT = ROOT / "reports" / "bench_sweep.md"
VARY = ["target.resistance.yield_stress=250:745:5 MPa", "impact.striking_velocity=400:1390:10 m/s"]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m semianalytic.sweep.benchmark", description=__doc__.splitlines()[0])
    parser.add_argument("--force", action="store_true", help="overwrite reports/bench_sweep.md")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--report", default=str(REPORT))
    args = parser.parse_args(argv)

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
        s = run_sweep(CASE, spec, tmp / "local", workers=args.workers, progress=False)
        wall_local = time.perf_counter() - t
        df = pd.read_csv(tmp / "local" / "results.csv")
        s_inline = run_sweep(CASE, spec, tmp / "inline", scheduler="inline", progress=False)

        # independent check: the time-domain solver at random rows
        rng = np.random.default_rng(0)
        rows = df.iloc[rng.choice(len(df), 25, replace=False)]
        errs = []
        for _, r in rows.iterrows():
            Y = r["target.resistance.yield_stress_Pa"]
            raw = apply_overrides(case.raw, {"target.resistance.yield_stress": f"{Y!r} Pa"})
            from semianalytic.case import parse_case

            c = parse_case(raw, CASE)
            setup = PenetrationSetup.from_case(c, table, require_material=False)
            m = solve_motion(table, setup.mass, setup.target_density, setup.resistance_pa,
                             float(r["impact.striking_velocity_m_s"]), rtol=1e-11)
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

    doc = Document("Sweep throughput benchmark")
    doc.para(f"Generated by `python -m semianalytic.sweep.benchmark` on {platform.node()} "
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
    doc.para(f"25 random rows against `solve_motion` (eq. (11) in time, solve_ivp DOP853, rtol 1e-11, event at "
             f"u = 0): maximum relative difference of the final depth **{max_err:.1e}** (the sweep integrates "
             "eq. (11) in P once per worker with R_t = 1 Pa and scales the velocities by sqrt(R_t), an exact "
             "property of the linear form in u^2).")
    doc.heading("Interrupted and resumed")
    doc.para(f"The same sweep in {n_batches} batches, stopped after {n_batches // 3} of them ({before} cases written), "
             f"then `--resume`: {s_res.n_skipped} cases skipped as finished, {s_res.n_run} run; every case id present "
             f"exactly once: **{'yes' if complete else 'NO'}**.")
    doc.image(png.name, "Final depth over the swept (U_s, Y) plane.")
    atomic_write_text(report, to_markdown(doc))
    print(f"{s.cases_per_second:.0f} cases/s on {s.workers} workers; report: {report}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
