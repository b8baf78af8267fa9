"""``python -m semianalytic sweep CASE.toml --vary KEY=START:STOP:STEP ... --out DIR``.

Grid sweeps (``--vary``, repeatable: the Cartesian product) and seeded Monte-Carlo studies
(``--sample KEY=normal(MEAN,SD) --samples N --seed S``), run with dask (a local cluster by
default, ``--scheduler tcp://HOST:PORT`` for an existing one, ``--scheduler inline`` for no
dask).  Each finished batch is appended to ``DIR/results.csv`` (or ``DIR/results.parquet/``)
at once; ``--resume`` skips the finished cases after an interruption.  Examples::

    python -m semianalytic sweep cases/fig15a_ogive_6061T651.toml --out sweeps/vel \\
        --vary "impact.striking_velocity=400:1800:10 m/s" \\
        --vary "target.resistance.yield_stress=250:550:5 MPa"
    python -m semianalytic sweep cases/fig15a_ogive_6061T651.toml --out sweeps/mc --samples 2000 --seed 7 \\
        --sample "target.resistance.yield_stress=normal(400 MPa, 20 MPa)" \\
        --sample "target.density=uniform(2690 kg/m^3, 2730 kg/m^3)"

(quote each KEY=... that contains a space).
"""

from __future__ import annotations

import argparse
import json

from semianalytic.errors import InputError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from semianalytic.cli_types import integer, output_dir

    parser.add_argument("case", help="case file (TOML)")
    parser.add_argument("--out", required=True, type=output_dir, help="output folder (results file + sweep.json)")
    parser.add_argument("--vary", action="append", default=[], metavar="KEY=START:STOP:STEP",
                        help="grid axis (STOP included) or KEY=V1,V2,...; repeat for a Cartesian product")
    parser.add_argument("--sample", action="append", default=[], metavar="KEY=DIST(...)",
                        help="random input: normal(MEAN,SD), uniform(LOW,HIGH), lognormal(MEDIAN,SIGMA), "
                             "triangular(LOW,MODE,HIGH)")
    parser.add_argument("--samples", type=integer(0, 10_000_000), default=0, help="number of Monte-Carlo samples (with --sample)")
    parser.add_argument("--seed", type=integer(0, 2**63 - 1), default=0, help="seed of the Monte-Carlo draws (default 0)")
    parser.add_argument("--analysis", choices=["penetration", "cavity", "perforation"], default=None,
                        help="what to compute per case (default: from the case's sections; perforation: residual "
                             "velocity and ballistic limit of a plate case, e.g. --vary target.thickness=10:30:5 mm)")
    parser.add_argument("--full", action="store_true",
                        help="penetration: also quasi-rigid and elastic depths (slower, case by case)")
    parser.add_argument("--format", dest="fmt", choices=["csv", "parquet"], default="csv")
    parser.add_argument("--scheduler", default=None,
                        help="dask scheduler address (tcp://HOST:PORT) or its scheduler file (FILE.json, written by "
                             "'dask scheduler --scheduler-file'; docs/cluster.md); 'inline' runs in this process, 'local' "
                             "starts a local cluster; default: chosen from the work (inline for cheap cases, "
                             "a local cluster for geometry sweeps)")
    parser.add_argument("--workers", type=integer(1, 256), default=2, help="workers of the local cluster (default 2)")
    parser.add_argument("--batch-size", type=integer(1, 10_000_000), default=None, help="cases per task (default: automatic)")
    parser.add_argument("--cache-dir", default=None, type=output_dir, help="coefficient-table cache folder (default: $SEMIANALYTIC_CACHE_DIR, else the per-user cache)")
    parser.add_argument("--resume", action="store_true", help="continue an interrupted sweep in --out")
    parser.add_argument("--force", action="store_true", help="discard existing results in --out")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")


def run(args: argparse.Namespace) -> int:
    from semianalytic.case import load_case
    from semianalytic.sweep.engine import run_sweep
    from semianalytic.sweep.spec import build_spec

    if args.resume and args.force:
        raise InputError("--resume", "cannot be combined with --force")
    if args.workers < 1:
        raise InputError("--workers", "must be at least 1")
    if args.batch_size is not None and args.batch_size < 1:
        raise InputError("--batch-size", "must be at least 1")
    if args.samples < 0:
        raise InputError("--samples", "must not be negative")
    if args.scheduler is not None and not args.scheduler.strip():
        raise InputError("--scheduler", "empty; give 'inline', 'local' or a dask scheduler address (host:port)")
    spec = build_spec(args.vary, args.sample, args.samples, args.seed)
    case = load_case(args.case)
    check_axes(case, spec)
    from semianalytic.guards import check_case, check_sweep_size
    from semianalytic.sweep.kernels import changes_table

    check_case(case)  # refuse before any worker starts what would not fit in memory
    geometries = 1
    for axis in spec.axes:
        if changes_table(axis.key):
            geometries *= len(axis.values)
    geometries *= args.samples if any(changes_table(s.key) for s in spec.samplers) else 1
    check_sweep_size(spec.n_cases, geometries, "--samples" if spec.samplers else "--vary")
    kernel = sweep_kernel(case, args.analysis, args.cache_dir, args.full)
    summary = run_sweep(
        args.case, spec, args.out, fmt=args.fmt, resume=args.resume, force=args.force,
        scheduler=args.scheduler, workers=args.workers, batch_size=args.batch_size,
        progress=not args.no_progress, kernel=kernel,
    )
    info = summary.to_json()
    stats_path = summary.out / "statistics.json"
    stats = json.loads(stats_path.read_text()) if stats_path.exists() else {}
    if args.json:
        print(json.dumps({**info, "statistics": stats}, indent=2))
    else:
        print(
            f"{info['n_run']} cases run ({info['n_ok']} ok, {info['n_invalid']} invalid, {info['n_error']} failed), "
            f"{info['n_skipped_finished_before']} finished before; {summary.cases_per_second:.0f} cases/s "
            f"on {info['workers']} worker(s); results: {info['results']}"
        )
        for col, st in stats.items():
            if isinstance(st, dict):
                print(f"  {col}: mean {st['mean']:.6g}, sd {st['std']:.4g}, 5-95 % [{st['p05']:.6g}, {st['p95']:.6g}] "
                      f"(n = {st['n']})")
    return 0 if summary.n_error == 0 else 1


def sweep_kernel(case, analysis, cache_dir, full):
    """The kernel: ``perforation`` when asked for, or by default for a plate case (``[target]
    thickness`` or layers, issue 23 item 6), else :func:`semianalytic.sweep.kernels.select_kernel`."""
    from semianalytic.sweep.kernels import select_kernel
    from semianalytic.sweep.perforation import PerforationKernel, has_plate

    if analysis == "perforation" or (analysis is None and case.projectile is not None and has_plate(case)):
        if not has_plate(case):
            raise InputError("target.thickness", "--analysis perforation needs a plate case: [target] thickness = "
                                                 "'20 mm' (or [[target.layers]])")
        return PerforationKernel(cache_dir=None if cache_dir is None else str(cache_dir))
    return select_kernel(case, analysis, cache_dir=cache_dir, full=full)


def check_axes(case, spec) -> None:
    """Refuse (exit status 2) an axis whose every value the case rejects for that key, e.g.
    ``impact.striking_velocity=400:500:10 kg`` (a mass where a velocity belongs): checked at
    the first and the last value of each axis, before any worker starts."""
    from semianalytic.case import parse_case
    from semianalytic.sweep.kernels import changes_table
    from semianalytic.sweep.spec import VELOCITY_KEY, apply_overrides, raw_value

    for axis in spec.axes:
        target = "impact.striking_velocities" if axis.key == VELOCITY_KEY else axis.key
        errors = []
        for value in {axis.values[0], axis.values[-1]}:
            try:
                varied = parse_case(apply_overrides(case.raw, {axis.key: raw_value(value, axis.unit, axis.integer)}),
                                    case.path)
                if changes_table(axis.key):  # the BEM table of the first and last geometry fits
                    from semianalytic.guards import check_case

                    try:
                        check_case(varied)
                    except InputError as exc:
                        raise InputError(f"--vary {axis.key}", f"the value {value:g}: {exc}") from None
            except InputError as exc:
                if exc.field.startswith("--vary"):
                    raise
                if exc.field == target or exc.field.startswith(target + "."):
                    errors.append(exc)
                    continue
            break
        else:
            raise InputError(errors[0].field, f"{errors[0].message} (every value from --vary {axis.key})")
