"""``python -m semianalytic calibrate CASE --out DIR [--model M]... [--parameter KEY]... [--cross-validate]``

Bayesian calibration of target parameters on the case's ``[data]`` shots with a
model-discrepancy term (:mod:`semianalytic.calibration.evaluate`).  Writes DIR/posterior.json,
DIR/report.md, DIR/report.html and the figures; with ``--cross-validate`` also
DIR/cross_validation.json and the leave-one-out and transfer tables in the report.
"""

from __future__ import annotations

import shlex
import sys


def add_arguments(parser) -> None:
    from semianalytic.calibration.names import CALIBRATION_MODELS
    from semianalytic.cli_types import file_stem, output_dir

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
    parser.add_argument("--report-name", default="report", type=file_stem, help="stem of the report files in DIR (default: report)")
    parser.add_argument("--coefficients", choices=("bem", "paper"), default="bem", help="A, B, C source (default: BEM table)")
    parser.add_argument("--cache-dir", default=None, type=output_dir, help="coefficient-table cache folder")
    parser.add_argument("--diagnose", action="store_true",
                        help="add the study of the over-prediction of the Part I models (B reading, W1, contact region, Y)")
    parser.add_argument("--report", metavar="PATH.md", default=None,
                        help="also write the report as PATH.md and PATH.html, figures beside it (e.g. reports/validation.md)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.add_argument("--force", action="store_true", help="replace an existing DIR")


def run(args) -> int:
    from pathlib import Path

    from semianalytic.calibration.pipeline import run_calibration

    command = "python -m semianalytic calibrate " + " ".join(shlex.quote(a) for a in sys.argv[2:]) if sys.argv[1:2] == [
        "calibrate"] else f"python -m semianalytic calibrate {args.case} --out {args.out}"
    result = run_calibration(args, command)
    print(f"wrote {Path(args.out) / 'posterior.json'} and {Path(args.out) / (args.report_name + '.md')}")
    for m in result["settings"]["models"]:
        for w in result["posterior"]["models"][m]["diagnostics"].get("warnings") or []:
            print(f"warning: {m}: sampler: {w}", file=sys.stderr)
    for m in result["settings"]["models"]:
        s = result["posterior"]["models"][m]["summary"]
        line = f"  {m:<18} " + ", ".join(f"{k} median {s[k]['q50'] / 1e6:.1f} MPa [{s[k]['q05'] / 1e6:.1f}, {s[k]['q95'] / 1e6:.1f}]"
                                         for k in result["settings"]["parameters"]) + f"  sigma {s['sigma']['q50']:.3f}"
        if result["cross_validation"] is not None:
            st = result["cross_validation"]["loo"][m]["statistics"]
            line += (f"  LOO: mean |e| {100 * st['mean_abs_error']:.1f} %, 50 % coverage {100 * st['coverage_50']:.0f} %, "
                     f"90 % coverage {100 * st['coverage_90']:.0f} %")
            if m == "eroding":
                line += f" (issue 17 target: mean |e| <= 15 %, {'met' if st['mean_abs_error'] <= 0.15 else 'NOT met'})"
        print(line)
    return 0
