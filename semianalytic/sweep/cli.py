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
    parser.add_argument("--cache-dir", default=None, type=output_dir, help="coefficient-table cache folder (default: $SEMIANALYTIC_CACHE_DIR, else the per-user cache)")  # noqa: E501
    parser.add_argument("--resume", action="store_true", help="continue an interrupted sweep in --out")
    parser.add_argument("--force", action="store_true", help="discard existing results in --out")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")


def run(args: argparse.Namespace) -> int:
    summary, stats = sweep_case(
        args.case, args.out, args.vary, args.sample, samples=args.samples, seed=args.seed, analysis=args.analysis,
        full=args.full, fmt=args.fmt, scheduler=args.scheduler, workers=args.workers, batch_size=args.batch_size,
        cache_dir=args.cache_dir, resume=args.resume, force=args.force, progress=not args.no_progress)
    info = summary.to_json()
    from semianalytic.report.formats import Output, emit

    emit(Output(data={**info, "statistics": stats}, json_options={"indent": 2},
                text=lambda s: _text(summary, info, stats, s)), "json" if args.json else "text")
    return 0 if summary.n_error == 0 else 1


def _text(summary, info: dict, stats: dict, stream) -> None:
    print(
        f"{info['n_run']} cases run ({info['n_ok']} ok, {info['n_invalid']} invalid, {info['n_error']} failed), "
        f"{info['n_skipped_finished_before']} finished before; {summary.cases_per_second:.0f} cases/s "
        f"on {info['workers']} worker(s); results: {info['results']}", file=stream,
    )
    for col, st in stats.items():
        if isinstance(st, dict):
            print(f"  {col}: mean {st['mean']:.6g}, sd {st['std']:.4g}, 5-95 % [{st['p05']:.6g}, {st['p95']:.6g}] "
                  f"(n = {st['n']})", file=stream)


def sweep_case(case_path: str, out: str, vary: list[str] = (), sample: list[str] = (), *, samples: int = 0,
               seed: int = 0, analysis: str | None = None, full: bool = False, fmt: str = "csv",
               scheduler: str | None = None, workers: int = 2, batch_size: int | None = None,
               cache_dir: str | None = None, resume: bool = False, force: bool = False, progress: bool = True):
    """The ``sweep`` command with typed arguments (the flags of the same names): checks, runs and
    writes ``out``; returns ``(summary, statistics)`` (the engine's summary and the
    ``statistics.json`` it wrote)."""
    vary, sample = list(vary), list(sample)
    from semianalytic.case import load_case
    from semianalytic.sweep.engine import run_sweep
    from semianalytic.sweep.spec import build_spec

    if resume and force:
        raise InputError("--resume", "cannot be combined with --force")
    if workers < 1:
        raise InputError("--workers", "must be at least 1")
    if batch_size is not None and batch_size < 1:
        raise InputError("--batch-size", "must be at least 1")
    if samples < 0:
        raise InputError("--samples", "must not be negative")
    if scheduler is not None and not scheduler.strip():
        raise InputError("--scheduler", "empty; give 'inline', 'local' or a dask scheduler address (host:port)")
    if scheduler is not None and scheduler.strip() not in ("inline", "local") and not scheduler.strip().endswith(".json"):
        from semianalytic.sweep.engine import probe_scheduler

        probe_scheduler(scheduler)  # a non-dask peer named up front, within seconds (issue 40)
    spec = build_spec(vary, sample, samples, seed)
    case = load_case(case_path)
    check_axes(case, spec)
    from semianalytic.guards import check_case, check_sweep_size
    from semianalytic.sweep.kernels import changes_table

    check_case(case)  # refuse before any worker starts what would not fit in memory
    geometries = 1
    for axis in spec.axes:
        if changes_table(axis.key):
            geometries *= len(axis.values)
    geometries *= samples if any(changes_table(s.key) for s in spec.samplers) else 1
    check_sweep_size(spec.n_cases, geometries, "--samples" if spec.samplers else "--vary")
    kernel = sweep_kernel(case, analysis, cache_dir, full)
    summary = run_sweep(
        str(case.path or case_path), spec, out, fmt=fmt, resume=resume, force=force,  # the bundled case, if so
        scheduler=scheduler, workers=workers, batch_size=batch_size,
        progress=progress, kernel=kernel,
    )
    stats_path = summary.out / "statistics.json"
    stats = json.loads(stats_path.read_text()) if stats_path.exists() else {}
    return summary, stats


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
    """Refuse (exit status 2) a sweep with a value the case rejects, before any worker starts:
    every axis at its smallest and largest value, every sample at the ends of its support
    (:meth:`semianalytic.sweep.spec.Sampler.support`: a lognormal whose draws leave the physical
    range of the quantity is refused, issue 40).  An axis whose every value is rejected is named
    by the case key (e.g. ``impact.striking_velocity=400:500:10 kg``, a mass where a velocity
    belongs); one bad value names the option and the value."""
    from semianalytic.case import parse_case
    from semianalytic.sweep.kernels import changes_table
    from semianalytic.sweep.spec import VELOCITY_KEY, apply_overrides, raw_value

    probes = [(f"--vary {a.key}", a.key, a.unit, a.integer, sorted({min(a.values), max(a.values)}), True)
              for a in spec.axes]
    probes += [(f"--sample {s.key}", s.key, s.unit, False, list(s.support()), False) for s in spec.samplers]
    for option, key, unit, integer, values, axis in probes:
        target = "impact.striking_velocities" if key == VELOCITY_KEY else key
        errors = []
        for value in values:
            try:
                varied = parse_case(apply_overrides(case.raw, {key: raw_value(value, unit, integer)}), case.path)
                if changes_table(key):  # the BEM table of the first and last geometry fits
                    from semianalytic.guards import check_case

                    try:
                        check_case(varied)
                    except InputError as exc:
                        raise InputError(option, f"the value {value:g}: {exc}") from None
            except InputError as exc:
                if exc.field.startswith(("--vary", "--sample")):
                    raise
                if exc.field == target or exc.field.startswith(target + "."):
                    errors.append((value, exc))
                    continue
        if not errors:
            continue
        if axis and len(errors) == len(values):
            raise InputError(errors[0][1].field, f"{errors[0][1].message} (every value from {option})")
        value, exc = errors[0]
        shown = f"{value:.4g} {unit}".strip()
        raise InputError(exc.field, f"{exc.message} (the value {shown} of {option})" if axis else
                         f"{exc.message} (the support of {option} reaches {shown}: narrow the distribution)")
