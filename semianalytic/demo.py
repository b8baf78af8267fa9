"""``python -m semianalytic demo`` (``make demo``): run the bundled Fig. 5 case
``cases/demo_fig5_ogive.toml`` (installed with the package: :mod:`semianalytic.bundled`) into ``--out`` (default: the folder ``demo`` of the per-user
cache, ``$SEMIANALYTIC_CACHE_DIR/demo`` when set; an earlier demo there is replaced) and print
the path of ``report.html``.  Nothing is written where the command runs unless asked."""  # noqa: E501

from __future__ import annotations

import argparse
import time
from pathlib import Path

from semianalytic.bundled import case_file

CASE = case_file("demo_fig5_ogive.toml")  # the package data semianalytic.cases (cases/ of a checkout)


def default_out() -> Path:
    """The demo's default folder: ``demo`` in the per-user cache (a command writes only where it
    is asked or into the per-user cache)."""
    from semianalytic.cache import cache_root

    return cache_root() / "demo"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from semianalytic.cli_types import output_dir

    parser.add_argument("--out", default=None, type=output_dir,
                        help="output folder (default: demo/ in the per-user cache, e.g. ~/.cache/semianalytic/demo)")
    parser.add_argument("--no-render", action="store_true", help="skip the pyvista render")


def run(args: argparse.Namespace) -> int:
    from semianalytic.errors import InputError
    from semianalytic.run.pipeline import run_case

    if not CASE.is_file():
        raise InputError("case", f"the bundled demo case {CASE} is missing (reinstall the package)")
    t0 = time.perf_counter()
    out = Path(args.out) if args.out is not None else default_out()
    command = "python -m semianalytic demo" + ("" if args.out is None else f" --out {out.name}") \
        + (" --no-render" if args.no_render else "")  # what the report says made it: runnable as written
    results = run_case(CASE, out, force=True, render=not args.no_render, command=command)
    for name, why in results["skipped"].items():
        print(f"skipped {name}: {why}")
    print(f"demo finished in {time.perf_counter() - t0:.1f} s")
    print(f"report: {(out / 'report.html').resolve()}")
    return 0
