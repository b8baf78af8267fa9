"""``python -m semianalytic demo`` (``make demo``): run the bundled Fig. 5 case
``cases/demo_fig5_ogive.toml`` into ``reports/demo/`` (replacing an earlier demo) and print
the path of ``report.html``."""

from __future__ import annotations

import argparse
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CASE = ROOT / "cases" / "demo_fig5_ogive.toml"
OUT = ROOT / "reports" / "demo"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from semianalytic.cli_types import output_dir

    parser.add_argument("--out", default=str(OUT), type=output_dir, help=f"output folder (default {OUT})")
    parser.add_argument("--no-render", action="store_true", help="skip the pyvista render")


def run(args: argparse.Namespace) -> int:
    from semianalytic.errors import InputError
    from semianalytic.run.pipeline import run_case

    if not CASE.is_file():
        raise InputError("case", f"the bundled demo case {CASE} is missing (run from a checkout of the project)")
    t0 = time.perf_counter()
    command = "python -m semianalytic demo" + ("" if Path(args.out) == OUT else f" --out {Path(args.out).name}") \
        + (" --no-render" if args.no_render else "")  # what the report says made it: runnable as written
    results = run_case(CASE, Path(args.out), force=True, render=not args.no_render, command=command)
    for name, why in results["skipped"].items():
        print(f"skipped {name}: {why}")
    print(f"demo finished in {time.perf_counter() - t0:.1f} s")
    print(f"report: {(Path(args.out) / 'report.html').resolve()}")
    return 0
