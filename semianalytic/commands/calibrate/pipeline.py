"""The ``calibrate`` command's pipeline: check the flags and the case, calibrate, cross-validate
and diagnose as asked, build the report and write everything (staged: nothing half-written).

Bad input raises InputError before anything is written.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from semianalytic.errors import InputError


def check_outputs_and_load(args):
    """Refuse an existing --out / --report (without --force) or a --report not ending in .md, then
    load the case and require [projectile], [target] and [data]."""
    from semianalytic.case import load_case
    from semianalytic.report.output import check_output_dir

    if args.steps is not None and args.steps < 50:
        raise InputError("--steps", f"must be at least 50; got {args.steps}")
    check_output_dir(args.out, args.force, protect=(args.case,))
    if args.report is not None:
        from semianalytic.io import check_report_target

        if not str(args.report).endswith(".md"):
            raise InputError("--report", f"expected a path ending in .md; got {args.report!r}")
        check_report_target(args.report, args.force, inputs=[args.case, *args.transfer])
    case = load_case(args.case)
    for sec in ("projectile", "target", "data"):
        case.require(sec)
    return case


def run_calibration(args: argparse.Namespace, command: str) -> dict:
    """Calibrate ``args.case`` as the flags say and write DIR (and ``--report``); returns the
    calibration result (:func:`semianalytic.commands.calibrate.evaluate.calibrate_case`) with the
    cross-validation under "cross_validation" (None without ``--cross-validate``)."""
    from semianalytic.cache import coefficients_for_case
    from semianalytic.case import load_case
    from semianalytic.commands.calibrate.evaluate import calibrate_case, cross_validate
    from semianalytic.commands.calibrate.report import build_report
    from semianalytic.report.document import to_markdown
    from semianalytic.report.html import to_html
    from semianalytic.report.output import StagedDir

    case = check_outputs_and_load(args)
    from semianalytic.guards import check_sampler
    from semianalytic.sections.calibration import CalibrationSection

    csec = case.section("calibration") or CalibrationSection()
    n_models = len(args.model or csec.models or ["m"] * 2)
    n_params = len(args.parameter or csec.parameters or ["p"] * 3)
    check_sampler(csec.walkers, args.steps or csec.steps, n_params, n_models,
                  "--steps" if args.steps else "calibration.steps")
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
        from semianalytic.io import case_input_path

        paths = [case_input_path(case.path, p, "calibration.transfer") for p in (sec.transfer if sec else [])] + [
            Path(p) for p in args.transfer]
        for p in paths:
            tcase = load_case(p)
            transfer.append((tcase, coefficients_for_case(tcase, args.coefficients, args.cache_dir)[0]))
    coefficients = coefficients_for_case(case, args.coefficients, args.cache_dir)[0]
    from semianalytic.progress import mode, stages

    progress = mode(args.quiet) == "bar"  # tqdm bars on a terminal only; one line per stage in a log
    stage = stages(2 if args.cross_validate else 1, "calibrate", quiet=args.quiet or progress)
    stage.step("sampling the posterior (emcee)")
    result = calibrate_case(case, coefficients, models=args.model, parameters=args.parameter, progress=progress,
                            steps=args.steps)
    if args.cross_validate:
        stage.step("leave-one-out refits")
    cv = cross_validate(case, coefficients, result, transfer, progress=progress) if args.cross_validate else None
    stage.close()
    diag = None
    if args.diagnose:
        from semianalytic.commands.calibrate.diagnose import diagnose

        pairs = [(case, coefficients), *transfer]
        diag = diagnose(pairs, [coefficients_for_case(c, "paper")[0] for c, _ in pairs])
        if args.cross_validate and args.coefficients == "bem":
            from semianalytic.commands.calibrate.diagnose import reading_cross_validation

            diag["literal_cross_validation"] = reading_cross_validation(case, coefficients, transfer, progress=progress)
    from semianalytic.commands.calibrate.report import diagnosis_blocks

    extra = (lambda d, f: diagnosis_blocks(d, diag)) if diag is not None else None
    doc, figs = build_report(result, command, cv, extra)
    with StagedDir(args.out, args.force, protect=(args.case,)) as out:
        out.write_json("posterior.json", result["posterior"])
        if cv is not None:
            out.write_json("cross_validation.json", cv)
        for name, data in figs.items():
            out.write_bytes(name, data)
        out.write_text(f"{args.report_name}.md", to_markdown(doc))
        out.write_text(f"{args.report_name}.html", to_html(doc, images=figs.get))  # figures inline: self-contained
        if diag is not None:
            out.write_json("diagnosis.json", diag)
    if args.report is not None:
        from semianalytic.io import atomic_write_bytes, atomic_write_text

        target = Path(args.report)
        doc2, figs2 = build_report(result, command, cv, extra, prefix=target.stem + "_")
        target.parent.mkdir(parents=True, exist_ok=True)
        for name, data in figs2.items():
            atomic_write_bytes(target.parent / name, data)
        atomic_write_text(target.with_suffix(".html"), to_html(doc2, images=figs2.get))
        atomic_write_text(target, to_markdown(doc2))
    result["cross_validation"] = cv
    return result
