"""``python -m semianalytic run CASE.toml --out DIR [--force]``: every analysis the case asks
for, into one folder: ``results.json`` (SI values, units in the keys), ``report.md`` and
``report.html`` with PNG figures, and ``vtk/*.vtu`` fields.

The case is validated and every analysis checks its inputs before anything is computed:
bad input exits with status 2, one line naming the field, and nothing written.  The folder
is built aside and swapped in at the end (:class:`~semianalytic.report.output.StagedDir`);
an existing ``DIR`` is replaced only with ``--force``.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from semianalytic.report.case import ANALYSES


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("case", help="case file (TOML)")
    parser.add_argument("--out", required=True, help="output folder (created; replaced only with --force)")
    parser.add_argument("--force", action="store_true", help="replace an existing output folder")
    parser.add_argument("--only", action="append", choices=ANALYSES, default=None, metavar="ANALYSIS",
                        help=f"run only these analyses (repeatable; one of: {', '.join(ANALYSES)})")
    parser.add_argument("--no-render", action="store_true", help="skip the pyvista render (VTK files are still written)")
    parser.add_argument("--cache-dir", default=None, help="coefficient-table cache folder (default: the project's)")
    parser.add_argument("--json", action="store_true", help="print results.json to stdout as well")


def run_case(case_path, out, *, force: bool = False, only=None, render: bool = True, cache_dir=None) -> dict:
    """Run a case into ``out``; returns the results dict (also written to ``out/results.json``)."""
    from semianalytic.case import load_case
    from semianalytic.report.case import RunSection
    from semianalytic.report.context import Context
    from semianalytic.report.document import Document
    from semianalytic.report.html import to_html
    from semianalytic.report.document import to_markdown
    from semianalytic.report.output import StagedDir, check_output_dir
    from semianalytic.report.steps import introduction, select_steps

    t0 = time.perf_counter()
    case = load_case(case_path)
    run_section = case.section("run") or RunSection()
    steps, skipped = select_steps(case, run_section, only)
    check_output_dir(out, force)
    for step in steps:  # every input check before any output
        step.preflight(case, run_section)
    with StagedDir(out, force) as staged:
        title = case.title or Path(case_path).stem
        ctx = Context(case, staged, run_section, Document(f"Report: {title}"), render=render, cache_dir=cache_dir)
        introduction(ctx, case_path, steps, skipped)
        for step in steps:
            t = time.perf_counter()
            step.run(ctx)
            ctx.timings[step.name] = time.perf_counter() - t
        ctx.timings["total"] = time.perf_counter() - t0
        ctx.doc.heading("Run")
        ctx.doc.table(
            ["step", "time [s]"],
            [[k, f"{v:.2f}"] for k, v in ctx.timings.items()],
            caption="Wall-clock time of each analysis (this machine).",
        )
        results = {
            "case": {"path": str(case_path), "title": case.title, "reproduces": case.reproduces},
            "analyses": ctx.results,
            "skipped": skipped,
            "timings_s": ctx.timings,
            "figures": ctx.figures,
        }
        staged.write_json("results.json", results)
        staged.write_text("report.md", to_markdown(ctx.doc))
        staged.write_text("report.html", to_html(ctx.doc))
        results["files"] = sorted(staged.files)
    return results


def run(args: argparse.Namespace) -> int:
    out = Path(args.out)
    results = run_case(
        args.case, out, force=args.force, only=args.only, render=not args.no_render, cache_dir=args.cache_dir
    )
    if args.json:
        print(json.dumps(results, indent=2, default=str))
    else:
        for name, why in results["skipped"].items():
            print(f"skipped {name}: {why}")
        print(f"report: {(out / 'report.html').resolve()}")
    return 0
