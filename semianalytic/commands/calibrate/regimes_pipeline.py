"""``calibrate --model regimes``: the whole-range regime model's posterior (4 emcee ensembles,
arviz diagnostics), its leave-one-material-out transfer (``--cross-validate`` with ``--transfer``
cases of the other materials) and the report (:mod:`.regimes_report`).  Bad input raises
InputError before anything is written."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from semianalytic.errors import InputError

__all__ = ["run_regimes"]

CURVE_VELOCITIES = np.linspace(500.0, 3100.0, 66)


def run_regimes(args, command: str) -> dict:
    from semianalytic.cache import coefficients_for_case
    from semianalytic.calibration import regimes as R
    from semianalytic.case import load_case
    from semianalytic.commands.calibrate.pipeline import check_outputs_and_load
    from semianalytic.commands.calibrate.regimes_report import build_regimes_report
    from semianalytic.report.document import to_markdown
    from semianalytic.report.output import StagedDir

    if args.model != ["regimes"]:
        raise InputError("--model", "'regimes' is calibrated alone (it holds its own rigid, deforming and eroding models)")
    for flag, val in (("--parameter", args.parameter), ("--diagnose", args.diagnose)):
        if val:
            raise InputError(flag, "not used with --model regimes (its one parameter is the dynamic factor)")
    if args.steps is not None and args.steps < 200:
        raise InputError("--steps", f"must be at least 200 with --model regimes; got {args.steps}")
    if args.transfer and not args.cross_validate:
        raise InputError("--transfer", "is used only with --cross-validate")
    from semianalytic.guards import check_sampler

    check_sampler(32, args.steps or 4500, 4, 1)  # sample_regimes: 4 chains x 8 walkers; refused before any work
    case = check_outputs_and_load(args)
    others = []
    for p in args.transfer:
        c = load_case(p)
        if R.geometry_signature(c) != R.geometry_signature(case):
            raise InputError("--transfer", f"{p}: another nose or target than {args.case}; transfer is between "
                                           "projectile materials of one geometry")
        others.append(c)
    opt = R.options_for(case, getattr(args, "option", None) or ())
    coef = coefficients_for_case(case, args.coefficients, args.cache_dir)[0]
    shots = R.regime_shots(case, coef)
    # R-hat <= 1.01 on the bundled data: 4500 steps left tau and e at 1.010-1.011 with the nose-load model set
    # (6 parameters, 14 walkers per ensemble); 9000 steps (reports/validation_regimes.md)
    steps = args.steps or 9000
    sample = R.sample_regimes(shots, opt, steps=steps, burn=steps // 3)
    posterior = R.posterior_json(case, shots, opt, sample)
    result = {"posterior": posterior, "shots": shots, "command": command, "transfer": None, "curves": {}, "options": opt}
    med = posterior["summary"]
    first = R.parameter_names(opt)[0]
    pb = med.get("breakup_factor", {}).get("q50")
    pe = med.get("erosion_factor", {}).get("q50")

    def _coef(c):
        return coefficients_for_case(c, args.coefficients, args.cache_dir)[0]

    # the nose checks (issue 36, item 4): the fitted constants on five noses, the case's rod
    if R.uses_nose_load(opt):
        result["noses"] = {kind: R.nose_ordering_study(case, _coef, R.dataclasses_replace(opt, nose_load=kind),
                                                       med[first]["q50"], pb, pe)
                           for kind in (opt.nose_load,)}
        result["seed_sphere"] = R.seed_sphere_statement(case, _coef, opt, med[first]["q50"], pb, pe)
    result["eroding_trend"] = R.eroding_trend(shots, opt, med[first]["q50"])
    if args.cross_validate:
        if not others:
            raise InputError("--cross-validate", "with --model regimes needs --transfer CASE.toml (the other material)")
        cases = [case, *others]
        coefs = [coef, *[coefficients_for_case(c, args.coefficients, args.cache_dir)[0] for c in others]]
        groups = [shots, *[R.regime_shots(c, k) for c, k in zip(others, coefs)]]
        result["transfer"] = R.transfer_study(groups, R.OPTION_SETS if not args.quick else (opt,), chosen_among=opt)
        # curves: each material predicted from the fit on the other(s) (the transfer the figures show)
        posts = {g.group: R.grid_posterior(g, opt) for g in groups}
        from semianalytic.penetration.hardness import DEFAULT_DYNAMIC_FACTOR
        from semianalytic.penetration.regime import DEFAULT_BREAKUP_FACTOR
        from semianalytic.penetration.regime_setup import NOSE_LOAD_DEFAULTS

        if R.uses_nose_load(opt):
            result["defaults"] = R.default_constants_study(
                groups, opt, posts, NOSE_LOAD_DEFAULTS["kappa"],
                NOSE_LOAD_DEFAULTS["breakup_factor"] if opt.deforming == "two_stage" else None,
                NOSE_LOAD_DEFAULTS["erosion_factor"])
        else:
            result["defaults"] = R.default_constants_study(groups, opt, posts, DEFAULT_DYNAMIC_FACTOR,
                                                           DEFAULT_BREAKUP_FACTOR if opt.deforming == "two_stage" else None)
        for c, k, g in zip(cases, coefs, groups):
            fit = next(h for h in groups if h is not g)
            f, s, t, b, e = R.draws_from_grid(posts[fit.group], 1000)
            pts = R.shots_at(c, k, CURVE_VELOCITIES)
            pred = R.predict(pts, opt, f, s, t, b=b, e=e)
            result["curves"][g.group] = {"fit": fit.group, "velocity_m_s": CURVE_VELOCITIES.tolist(),
                                         "q05_m": pred["quantiles"][0].tolist(), "q50_m": pred["quantiles"][1].tolist(),
                                         "q95_m": pred["quantiles"][2].tolist(),
                                         "regime_probability": pred["regime_probability"].tolist(), "shots": g}
    doc, files = build_regimes_report(result)
    with StagedDir(args.out, args.force) as out:
        out.write_json("posterior.json", posterior)
        if result["transfer"] is not None:
            out.write_json("transfer.json", result["transfer"])
        for name, data in files.items():
            out.write_bytes(name, data)
        out.write_text(f"{args.report_name}.md", to_markdown(doc))
    if args.report is not None:
        from semianalytic.io import atomic_write_bytes, atomic_write_text

        target = Path(args.report)
        doc2, files2 = build_regimes_report(result, prefix=target.stem + "_")
        target.parent.mkdir(parents=True, exist_ok=True)
        for name, data in files2.items():
            atomic_write_bytes(target.parent / name, data)
        atomic_write_text(target, to_markdown(doc2))
    return result
