"""``python -m semianalytic calibrate CASE --out DIR [--model M]... [--parameter KEY]... [--cross-validate]``

Bayesian calibration of target parameters on the case's ``[data]`` shots with a
model-discrepancy term (:mod:`semianalytic.commands.calibrate.evaluate`).  Writes DIR/posterior.json,
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
    parser.add_argument("--model", action="append", choices=(*CALIBRATION_MODELS, "regimes"), default=None,
                        help="depth model to calibrate (repeatable; default: [calibration] models, else all but "
                             "'eroding'); 'eroding' (Alekseevskii-Tate, on the shots recorded eroded) runs alone; 'regimes' (the whole "
                             "velocity range from the projectile's hardness, every shot) runs alone")
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
    parser.add_argument("--quick", action="store_true",
                        help="--model regimes --cross-validate: the transfer of the default model set only (no comparison)")
    parser.add_argument("--option", action="append", default=[], metavar="KEY=VALUE",
                        help="--model regimes: a choice of the model set over the case's [regimes] keys (repeatable), e.g. "
                             "nose_load=forrestal; keys: onset, erosion, nose_load, resistance, rod_strength, deforming, "
                             "deformed_depth, rigid_depth, discrepancy")
    parser.add_argument("--force", action="store_true", help="replace an existing DIR")


def run(args) -> int:
    from pathlib import Path

    from semianalytic.commands.calibrate.pipeline import run_calibration

    command = "python -m semianalytic calibrate " + " ".join(shlex.quote(a) for a in sys.argv[2:]) if sys.argv[1:2] == [
        "calibrate"] else f"python -m semianalytic calibrate {args.case} --out {args.out}"
    if args.model and "regimes" in args.model:
        return _run_regimes(args, command)
    result = run_calibration(args, command)
    print(f"wrote {Path(args.out) / 'posterior.json'} and {Path(args.out) / (args.report_name + '.md')}")
    for m in result["settings"]["models"]:
        for w in result["posterior"]["models"][m]["diagnostics"].get("warnings") or []:
            print(f"warning: {m}: sampler: {w}", file=sys.stderr)
    for m in result["settings"]["models"]:
        s = result["posterior"]["models"][m]["summary"]
        line = f"  {m:<18} " + ", ".join(f"{k} median {s[k]['q50'] / 1e6:.1f} MPa, 90 % interval [{s[k]['q05'] / 1e6:.1f}, {s[k]['q95'] / 1e6:.1f}] MPa"  # noqa: E501
                                         for k in result["settings"]["parameters"]) + f"  sigma {s['sigma']['q50']:.3f} (model discrepancy, dimensionless)"  # noqa: E501
        if result["cross_validation"] is not None:
            st = result["cross_validation"]["loo"][m]["statistics"]
            line += (f"  LOO: mean |e| {100 * st['mean_abs_error']:.1f} %, 50 % coverage {100 * st['coverage_50']:.0f} %, "
                     f"90 % coverage {100 * st['coverage_90']:.0f} %")
            if m == "eroding":
                line += f" (issue 17 target: mean |e| <= 15 %, {'met' if st['mean_abs_error'] <= 0.15 else 'NOT met'})"
        print(line)
    return 0


def _run_regimes(args, command: str) -> int:
    from pathlib import Path

    from semianalytic.commands.calibrate.regimes_pipeline import run_regimes

    result = run_regimes(args, command)
    post = result["posterior"]
    for w in post["diagnostics"]["warnings"]:
        print(f"warning: regimes: sampler: {w}", file=sys.stderr)
    print(f"wrote {Path(args.out) / 'posterior.json'} and {Path(args.out) / (args.report_name + '.md')}")
    s = post["summary"]
    diag = post["diagnostics"]["parameters"]
    first = next(iter(s))  # dynamic_factor (legacy model sets) or nose_load_factor
    print(f"  regimes ({', '.join(f'{k}={v}' for k, v in post['options'].items())}): {first.replace('_', ' ')} median "
          f"{s[first]['q50']:.3f} [{s[first]['q05']:.3f}, {s[first]['q95']:.3f}], sigma "
          f"{s['sigma']['q50']:.3f}, tau {s['tau']['q50']:.3f}; R-hat "
          + ", ".join(f"{k} {d['r_hat']:.3f}" for k, d in diag.items()) + "; ESS "
          + ", ".join(f"{k} {min(d['ess_bulk'], d['ess_tail']):.0f}" for k, d in diag.items()))
    tr = result["transfer"]
    if tr is not None:
        best = next(o for o in tr["options"] if o["options"] == tr["chosen"])
        sm = best["summary"]
        print(f"  transfer (leave one material out), chosen model set {best['label']}: regime label right "
              f"{sm['label_right']}/{sm['labelled']}")
        for k in ("rigid", "deforming", "eroding"):
            if sm[k]["n"]:
                print(f"    {k:<10} n {sm[k]['n']:2d}  mean |e| of the median {100 * sm[k]['mean_abs_error']:5.1f} %  "
                      f"90 % coverage {100 * sm[k]['coverage_90']:5.1f} %  labels right {sm[k]['label_right']}/{sm[k]['labelled']}")
    return 0
