"""``python -m semianalytic calibrate CASE --out DIR [--model M]... [--parameter KEY]... [--cross-validate]``

Bayesian calibration of target parameters on the case's ``[data]`` shots with a
model-discrepancy term (:mod:`semianalytic.calibration.evaluate`).  Writes DIR/posterior.json,
DIR/report.md, DIR/report.html and the figures; with ``--cross-validate`` also
DIR/cross_validation.json and the leave-one-out and transfer tables in the report.
"""

from __future__ import annotations

import shlex
import sys

from semianalytic.errors import InputError


def add_arguments(parser) -> None:
    from semianalytic.calibration.models import MODELS

    parser.add_argument("case", metavar="CASE.toml", help="case with [projectile], [target], [data] (and [calibration])")
    parser.add_argument("--out", required=True, metavar="DIR", help="output folder")
    parser.add_argument("--model", action="append", choices=MODELS, default=None,
                        help="depth model to calibrate (repeatable; default: [calibration] models, else all)")
    parser.add_argument("--parameter", action="append", default=None, metavar="KEY",
                        help="case key to calibrate, e.g. target.resistance.yield_stress (repeatable)")
    parser.add_argument("--cross-validate", action="store_true",
                        help="leave-one-out and transfer splits ([calibration] transfer and --transfer cases)")
    parser.add_argument("--transfer", action="append", default=[], metavar="CASE.toml",
                        help="a case with the same target whose shots the calibration predicts (repeatable)")
    parser.add_argument("--steps", type=int, default=None, help="emcee steps per walker (default: [calibration] steps)")
    parser.add_argument("--report-name", default="report", help="stem of the report files in DIR (default: report)")
    parser.add_argument("--coefficients", choices=("bem", "paper"), default="bem", help="A, B, C source (default: BEM table)")
    parser.add_argument("--cache-dir", default=None, help="coefficient-table cache folder")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.add_argument("--force", action="store_true", help="replace an existing DIR")


def run(args) -> int:
    from pathlib import Path

    from semianalytic.cache import coefficients_for_case
    from semianalytic.calibration.evaluate import calibrate_case, cross_validate
    from semianalytic.calibration.report import build_report
    from semianalytic.case import load_case
    from semianalytic.report.document import to_markdown
    from semianalytic.report.html import to_html
    from semianalytic.report.output import StagedDir, check_output_dir

    if args.steps is not None and args.steps < 50:
        raise InputError("--steps", f"must be at least 50; got {args.steps}")
    if not args.report_name.replace("_", "").replace("-", "").isalnum():
        raise InputError("--report-name", "letters, digits, '_' and '-' only")
    check_output_dir(args.out, args.force)
    case = load_case(args.case)
    for sec in ("projectile", "target", "data"):
        case.require(sec)
    if case.target.resistance is None:
        raise InputError("target.resistance", "missing; add [target.resistance] with a 'model'")
    transfer = []
    if args.cross_validate:
        sec = case.section("calibration")
        paths = [Path(case.path).parent / p for p in (sec.transfer if sec else [])] + [Path(p) for p in args.transfer]
        for p in paths:
            tcase = load_case(p)
            transfer.append((tcase, coefficients_for_case(tcase, args.coefficients, args.cache_dir)[0]))
    coefficients = coefficients_for_case(case, args.coefficients, args.cache_dir)[0]
    progress = not args.quiet
    result = calibrate_case(case, coefficients, models=args.model, parameters=args.parameter, progress=progress,
                            steps=args.steps)
    cv = cross_validate(case, coefficients, result, transfer, progress=progress) if args.cross_validate else None
    command = "python -m semianalytic calibrate " + " ".join(shlex.quote(a) for a in sys.argv[2:]) if sys.argv[1:2] == [
        "calibrate"] else f"python -m semianalytic calibrate {args.case} --out {args.out}"
    doc, figs = build_report(result, command, cv)
    with StagedDir(args.out, args.force) as out:
        out.write_json("posterior.json", result["posterior"])
        if cv is not None:
            out.write_json("cross_validation.json", cv)
        for name, data in figs.items():
            out.write_bytes(name, data)
        out.write_text(f"{args.report_name}.md", to_markdown(doc))
        out.write_text(f"{args.report_name}.html", to_html(doc))
    print(f"wrote {Path(args.out) / 'posterior.json'} and {Path(args.out) / (args.report_name + '.md')}")
    for m in result["settings"]["models"]:
        s = result["posterior"]["models"][m]["summary"]
        k = result["settings"]["parameters"][0]
        line = f"  {m:<18} {k} median {s[k]['q50'] / 1e6:.1f} MPa [{s[k]['q05'] / 1e6:.1f}, {s[k]['q95'] / 1e6:.1f}]" \
               f"  sigma {s['sigma']['q50']:.3f}"
        if cv is not None:
            st = cv["loo"][m]["statistics"]
            line += (f"  LOO: mean |e| {100 * st['mean_abs_error']:.1f} %, 90 % coverage {100 * st['coverage_90']:.0f} %")
        print(line)
    return 0
