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
    from semianalytic.calibration.names import CALIBRATION_MODELS

    parser.add_argument("case", metavar="CASE.toml", help="case with [projectile], [target], [data] (and [calibration])")
    parser.add_argument("--out", required=True, metavar="DIR", help="output folder")
    parser.add_argument("--model", action="append", choices=CALIBRATION_MODELS, default=None,
                        help="depth model to calibrate (repeatable; default: [calibration] models, else all but "
                             "'eroding'); 'eroding' (Alekseevskii-Tate, on the shots recorded eroded) runs alone")
    parser.add_argument("--parameter", action="append", default=None, metavar="KEY",
                        help="case key to calibrate, e.g. target.resistance.yield_stress (repeatable); eroding model: "
                             "target.resistance.eroding_resistance, projectile.dynamic_yield_stress (default both)")
    parser.add_argument("--cross-validate", action="store_true",
                        help="leave-one-out and transfer splits ([calibration] transfer and --transfer cases)")
    parser.add_argument("--transfer", action="append", default=[], metavar="CASE.toml",
                        help="a case with the same target whose shots the calibration predicts (repeatable)")
    parser.add_argument("--steps", type=int, default=None, help="emcee steps per walker (default: [calibration] steps)")
    parser.add_argument("--report-name", default="report", help="stem of the report files in DIR (default: report)")
    parser.add_argument("--coefficients", choices=("bem", "paper"), default="bem", help="A, B, C source (default: BEM table)")
    parser.add_argument("--cache-dir", default=None, help="coefficient-table cache folder")
    parser.add_argument("--diagnose", action="store_true",
                        help="add the study of the over-prediction of the Part I models (B reading, W1, contact region, Y)")
    parser.add_argument("--report", metavar="PATH.md", default=None,
                        help="also write the report as PATH.md and PATH.html, figures beside it (e.g. reports/validation.md)")
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
    if args.report is not None:
        from semianalytic.io import check_report_target

        if not str(args.report).endswith(".md"):
            raise InputError("--report", f"expected a path ending in .md; got {args.report!r}")
        check_report_target(args.report, args.force)
    case = load_case(args.case)
    for sec in ("projectile", "target", "data"):
        case.require(sec)
    if case.target.resistance is None:
        raise InputError("target.resistance", "missing; add [target.resistance] with a 'model'")
    transfer = []
    sec = case.section("calibration")
    if args.diagnose and "eroding" in (args.model or (sec.models if sec else None) or []):
        raise InputError("--diagnose", "studies the over-prediction of the Part I models on the rigid shots; "
                                       "not with the eroding model")
    if args.transfer and not (args.cross_validate or args.diagnose):
        raise InputError("--transfer", "is used only with --cross-validate or --diagnose")
    if args.cross_validate or args.diagnose:
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
    diag = None
    if args.diagnose:
        from semianalytic.calibration.diagnose import diagnose

        pairs = [(case, coefficients), *transfer]
        diag = diagnose(pairs, [coefficients_for_case(c, "paper")[0] for c, _ in pairs])
        if args.cross_validate and args.coefficients == "bem":
            from semianalytic.calibration.diagnose import reading_cross_validation

            diag["literal_cross_validation"] = reading_cross_validation(case, coefficients, transfer, progress=progress)
    command = "python -m semianalytic calibrate " + " ".join(shlex.quote(a) for a in sys.argv[2:]) if sys.argv[1:2] == [
        "calibrate"] else f"python -m semianalytic calibrate {args.case} --out {args.out}"
    from semianalytic.calibration.report import diagnosis_blocks

    extra = (lambda d, f: diagnosis_blocks(d, diag)) if diag is not None else None
    doc, figs = build_report(result, command, cv, extra)
    with StagedDir(args.out, args.force) as out:
        out.write_json("posterior.json", result["posterior"])
        if cv is not None:
            out.write_json("cross_validation.json", cv)
        for name, data in figs.items():
            out.write_bytes(name, data)
        out.write_text(f"{args.report_name}.md", to_markdown(doc))
        out.write_text(f"{args.report_name}.html", to_html(doc))
        if diag is not None:
            out.write_json("diagnosis.json", diag)
    if args.report is not None:
        from semianalytic.io import atomic_write_bytes, atomic_write_text

        target = Path(args.report)
        doc2, figs2 = build_report(result, command, cv, extra, prefix=target.stem + "_")
        target.parent.mkdir(parents=True, exist_ok=True)
        for name, data in figs2.items():
            atomic_write_bytes(target.parent / name, data)
        atomic_write_text(target.with_suffix(".html"), to_html(doc2))
        atomic_write_text(target, to_markdown(doc2))
    print(f"wrote {Path(args.out) / 'posterior.json'} and {Path(args.out) / (args.report_name + '.md')}")
    for m in result["settings"]["models"]:
        s = result["posterior"]["models"][m]["summary"]
        line = f"  {m:<18} " + ", ".join(f"{k} median {s[k]['q50'] / 1e6:.1f} MPa [{s[k]['q05'] / 1e6:.1f}, {s[k]['q95'] / 1e6:.1f}]"
                                         for k in result["settings"]["parameters"]) + f"  sigma {s['sigma']['q50']:.3f}"
        if cv is not None:
            st = cv["loo"][m]["statistics"]
            line += (f"  LOO: mean |e| {100 * st['mean_abs_error']:.1f} %, 50 % coverage {100 * st['coverage_50']:.0f} %, "
                     f"90 % coverage {100 * st['coverage_90']:.0f} %")
            if m == "eroding":
                line += f" (issue 17 target: mean |e| <= 15 %, {'met' if st['mean_abs_error'] <= 0.15 else 'NOT met'})"
        print(line)
    return 0
