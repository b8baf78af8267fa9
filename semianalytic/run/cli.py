"""``python -m semianalytic run CASE.toml --out DIR [--force]``: every analysis the case asks
for, into one folder (:func:`semianalytic.run.pipeline.run_case`): ``results.json``,
``report.md``, ``report.html`` with PNG figures and ``vtk/*.vtu`` fields.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from semianalytic.run.case import ANALYSES


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from semianalytic.cli_types import output_dir

    parser.add_argument("case", help="case file (TOML)")
    parser.add_argument("--out", required=True, type=output_dir, help="output folder (created; replaced only with --force)")
    parser.add_argument("--force", action="store_true", help="replace an existing output folder")
    parser.add_argument("--only", action="append", choices=ANALYSES, default=None, metavar="ANALYSIS",
                        help=f"run only these analyses (repeatable; one of: {', '.join(ANALYSES)})")
    parser.add_argument("--no-render", action="store_true", help="skip the pyvista render (VTK files are still written)")
    parser.add_argument("--cache-dir", default=None, type=output_dir, help="coefficient-table cache folder (default: $SEMIANALYTIC_CACHE_DIR, else the per-user cache)")  # noqa: E501
    from semianalytic.report.formats import add_format_arguments

    add_format_arguments(parser, provides=("data", "text", "rows"), json_help="print results.json to stdout as well")
    parser.add_argument("--contact", choices=("full", "separated"), default=None,
                        help="contact region of eq. (15) in eq. (11) (default: [coefficients].contact)")
    parser.add_argument("--tolerance", default=None, help="relative error of the coefficient table (default 1e-5)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar on stderr (it is off anyway when stderr is not a terminal)")
    parser.add_argument("--csv", metavar="FILE", default=None,
                        help="also write FILE: one row per striking velocity and model of the penetration (units in the header)")


def run(args: argparse.Namespace) -> int:
    from semianalytic.case import load_case
    from semianalytic.guards import check_case
    from semianalytic.report.formats import Output, chosen_format, emit
    from semianalytic.run.pipeline import run_case

    fmt = chosen_format(args)
    check_case(load_case(args.case), field=True)  # refuse before solving what would not fit in memory
    if args.csv is not None:
        from semianalytic.commands.penetrate.table_out import check_csv_target

        check_csv_target(args.csv, args.force, inputs=[args.case])
    out = Path(args.out)
    results = run_case(
        args.case, out, force=args.force, only=args.only, render=not args.no_render, cache_dir=args.cache_dir,
        contact=args.contact, tolerance=args.tolerance, quiet=args.quiet,
    )
    from semianalytic.commands.penetrate.table_out import depth_csv

    pen = results["analyses"].get("penetration") or {}
    rows = lambda: depth_csv([(Path(args.case).name, pen)] if pen else [])  # noqa: E731
    if args.csv is not None:
        from semianalytic.io import atomic_write_text

        atomic_write_text(args.csv, rows())

    def text(stream) -> None:
        for name, why in results["skipped"].items():
            print(f"skipped {name}: {why}", file=stream)
        print(f"report: {(out / 'report.html').resolve()}", file=stream)
        if args.csv is not None:
            print(f"csv: {args.csv}" + ("" if pen else " (header only: the case has no penetration)"), file=stream)

    emit(Output(data=results, json_options={"indent": 2, "default": str}, text=text, rows=rows), fmt)
    return 0
