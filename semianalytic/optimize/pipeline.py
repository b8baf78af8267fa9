"""The ``optimize`` command's pipeline: check everything, connect, optimise, write.

Bad input (case, flags, bounds, constraints, output targets, scheduler) raises InputError
before anything is written.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from semianalytic.errors import InputError


def run_optimize(args: argparse.Namespace, command: str) -> dict:
    from semianalytic.case import load_case
    from semianalytic.cache import table_dir
    from semianalytic.optimize.case import build_problem
    from semianalytic.optimize.evaluate import optimise
    from semianalytic.report.output import check_output_dir
    from semianalytic.io import check_report_target
    from semianalytic.sweep.engine import connect

    for name, low in (("--popsize", 2), ("--maxiter", 1), ("--workers", 1), ("--coarse", 2), ("--maxfev", 1)):
        if getattr(args, name[2:].replace("-", "_")) < low:
            raise InputError(name, f"must be at least {low}")
    if not 0 < args.resolution <= 0.1:
        raise InputError("--resolution", "must lie in (0, 0.1] (a fraction of each range)")
    if not 0 < args.tol < 1:
        raise InputError("--tol", "must lie in (0, 1)")
    if args.confirm < 0 or args.confirm == 1:
        raise InputError("--confirm", "must be 0 (no grid) or at least 2")
    case = load_case(args.case)
    if args.method not in ("grid-pattern", "grid-nm", "de"):
        raise InputError("--method", f"must be grid-pattern, grid-nm or de; got {args.method!r}")
    problem = build_problem(case, args.vary, args.objective, args.constraint, args.depth_model,
                            args.table_depths, args.table_nose_lengths, getattr(args, "striking_velocity", None),
                            getattr(args, "depth_knots", None))
    from semianalytic.guards import check_optimiser

    check_optimiser(len(problem.variables), method=args.method, coarse=args.coarse, confirm=args.confirm,
                    popsize=args.popsize, maxiter=args.maxiter, maxfev=args.maxfev)
    out = Path(args.out) if args.out else None
    report = Path(args.report) if args.report else None
    if out is not None:
        check_output_dir(out, args.force, protect=(args.case,))
    if report is not None:
        check_report_target(report, args.force, inputs=[args.case])
    cache_dir = str(table_dir(args.cache_dir))
    sched = args.scheduler or ("local" if args.workers > 1 else "inline")
    client, cluster, name = connect(sched, args.workers)
    bar = None
    try:
        n_var = len(problem.variables)
        if not args.no_progress:
            from tqdm import tqdm

            search = (args.popsize * n_var * (args.maxiter + 1) if args.method == "de"
                      else args.coarse**n_var + min(args.maxfev, 15) * (2 * n_var if args.method == "grid-pattern" else 1))
            total = search + args.confirm**n_var + 4
            bar = tqdm(total=total, unit="design", file=sys.stderr, dynamic_ncols=True, mininterval=0.5,
                       desc="optimize")
        workers = 1 if client is None else max(1, len(client.scheduler_info().get("workers", {})))
        result = optimise(
            problem, client=client, cache_dir=cache_dir, method=args.method, coarse=args.coarse, maxfev=args.maxfev,
            popsize=args.popsize, maxiter=args.maxiter, tol=args.tol,
            seed=args.seed, resolution=args.resolution, confirm=args.confirm,
            on_done=None if bar is None else bar.update,
        )
    finally:
        if bar is not None:
            bar.close()
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    result.update(scheduler=name, workers=workers)
    from semianalytic.optimize.report import write_outputs

    write_outputs(result, out, report, args.force, command)
    return result
