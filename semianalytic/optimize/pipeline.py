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
    """The ``optimize`` command: :func:`optimize_case` with the parsed flags."""
    return optimize_case(
        args.case, args.vary, args.objective, constraint=args.constraint, depth_model=args.depth_model,
        striking_velocity=getattr(args, "striking_velocity", None), method=args.method, coarse=args.coarse,
        maxfev=args.maxfev, table_depths=args.table_depths, table_nose_lengths=args.table_nose_lengths,
        depth_knots=getattr(args, "depth_knots", None), popsize=args.popsize, maxiter=args.maxiter, tol=args.tol,
        seed=args.seed, resolution=args.resolution, confirm=args.confirm, scheduler=args.scheduler,
        workers=args.workers, cache_dir=args.cache_dir, progress=not args.no_progress, out=args.out,
        report=args.report, force=args.force, command=command)


def optimize_case(case_path: str | None, vary: list[str], objective: str = "depth", *, case=None,
                  constraint: list[str] = (), depth_model: str = "rigid", striking_velocity: str | None = None,
                  method: str = "grid-pattern", coarse: int = 5, maxfev: int = 60, table_depths: int | None = None,
                  table_nose_lengths: float | None = None, depth_knots: int | None = None, popsize: int = 5,
                  maxiter: int = 12, tol: float = 1e-5, seed: int = 0, resolution: float = 1e-3, confirm: int = 5,
                  scheduler: str | None = None, workers: int = 2, cache_dir: str | None = None,
                  progress: bool = True, out: str | None = None, report: str | None = None, force: bool = False,
                  command: str = "") -> dict:
    """Optimise the case's projectile (the ``optimize`` command with typed arguments; the flags
    of the same names).  ``case`` (a loaded case) replaces reading ``case_path``.  Returns the
    optimum as the JSON ``optimize --json`` prints; writes ``out``/``report`` when given."""
    constraint = list(constraint)
    from semianalytic.cache import table_dir
    from semianalytic.case import load_case
    from semianalytic.io import check_report_target
    from semianalytic.optimize.case import build_problem
    from semianalytic.optimize.evaluate import optimise
    from semianalytic.report.output import check_output_dir
    from semianalytic.sweep.engine import connect

    for name, value, low in (("--popsize", popsize, 2), ("--maxiter", maxiter, 1), ("--workers", workers, 1),
                             ("--coarse", coarse, 2), ("--maxfev", maxfev, 1)):
        if value < low:
            raise InputError(name, f"must be at least {low}")
    if not 0 < resolution <= 0.1:
        raise InputError("--resolution", "must lie in (0, 0.1] (a fraction of each range)")
    if not 0 < tol < 1:
        raise InputError("--tol", "must lie in (0, 1)")
    if confirm < 0 or confirm == 1:
        raise InputError("--confirm", "must be 0 (no grid) or at least 2")
    case = load_case(case_path) if case is None else case
    if method not in ("grid-pattern", "grid-nm", "de"):
        raise InputError("--method", f"must be grid-pattern, grid-nm or de; got {method!r}")
    problem = build_problem(case, vary, objective, constraint, depth_model,
                            table_depths, table_nose_lengths, striking_velocity,
                            depth_knots)
    from semianalytic.guards import check_optimiser

    check_optimiser(len(problem.variables), method=method, coarse=coarse, confirm=confirm,
                    popsize=popsize, maxiter=maxiter, maxfev=maxfev)
    out = Path(out) if out else None
    report = Path(report) if report else None
    if out is not None:
        check_output_dir(out, force, protect=(case_path,) if case_path else ())
    if report is not None:
        check_report_target(report, force, inputs=[case_path] if case_path else [])
    cache_dir = str(table_dir(cache_dir))
    sched = scheduler or ("local" if workers > 1 else "inline")
    client, cluster, name = connect(sched, workers)
    bar = None
    try:
        n_var = len(problem.variables)
        if progress:
            from tqdm import tqdm

            search = (popsize * n_var * (maxiter + 1) if method == "de"
                      else coarse**n_var + min(maxfev, 15) * (2 * n_var if method == "grid-pattern" else 1))
            total = search + confirm**n_var + 4
            from semianalytic.progress import counter, mode

            bar = (tqdm(total=total, unit="design", file=sys.stderr, dynamic_ncols=True, mininterval=0.5, desc="optimize")
                   if mode() == "bar" else counter(total, "optimize", "design"))  # a log: start and end lines
        n_workers = 1 if client is None else max(1, len(client.scheduler_info().get("workers", {})))
        result = optimise(
            problem, client=client, cache_dir=cache_dir, method=method, coarse=coarse, maxfev=maxfev,
            popsize=popsize, maxiter=maxiter, tol=tol,
            seed=seed, resolution=resolution, confirm=confirm,
            on_done=None if bar is None else bar.update,
        )
    finally:
        if bar is not None:
            bar.close()
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    result.update(scheduler=name, workers=n_workers)
    from semianalytic.optimize.report import write_outputs

    write_outputs(result, out, report, force, command)
    return result
