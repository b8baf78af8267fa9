"""``python -m semianalytic penetrate CASE.toml [CASE.toml ...]``

For each striking velocity of each case: final depth and time of the rigid, quasi-rigid and
elastic projectiles of Part I (eq. (11); eqs. (26), (29)/(30'); the exact-rod energy of errata
item 5), the critical impact velocity U_sC (eqs. (33)/(36)) and the flag U_s >= U_sC (the
projectile yields: the model is outside its validity).  With a ``[data]`` section: the
dynamic yield stress from a measured U_sC (Appendix) and/or the comparison with measured
depths.  ``--json`` prints the same as JSON (lists over velocity); ``--report DIR`` writes the
markdown report with plots (:mod:`semianalytic.commands.penetrate.report`).

Regimes (:mod:`semianalytic.penetration.regime`): ``regime`` per velocity (rigid, deforming,
eroding), ``depth_m`` (the Part I model ``--part1-model`` below the erosion onset, the
Alekseevskii-Tate eroding rod above), ``depth_eroding_m``, ``transition_velocity_m_s`` (U_sC),
``erosion_velocity_m_s``, ``valid`` (per model, a list of booleans); every depth outside its
model's validity is warned on stderr, naming the model and the reason.

``--posterior`` of ``calibrate --model regimes`` (issue 22) adds ``regime_probability``
({"rigid", "deforming", "eroding"} per velocity, summing to 1), ``regime_model_holds`` and
``depth_quantiles_m["regime_aware"]`` from the mixture of the regimes' predictions
(:func:`semianalytic.calibration.regimes.predict_case`).
"""

from __future__ import annotations

import math
import sys

from semianalytic.errors import InputError

JSON_KEYS = (
    "striking_velocity_m_s",
    "depth_rigid_m",
    "depth_quasi_rigid_m",
    "depth_elastic_m",
    "depth_elastic_exact_rod_m",
    "critical_velocity_m_s",
    "yields",
    "regime",
    "depth_m",
    "depth_eroding_m",
    "transition_velocity_m_s",
    "valid",
)


def add_arguments(parser) -> None:
    from semianalytic.cli_types import file_stem, output_dir
    from semianalytic.penetration.options import W1_MODELS

    parser.add_argument("cases", nargs="+", metavar="CASE.toml", help="case file(s) with [projectile], [target], [impact]")
    from semianalytic.report.formats import add_format_arguments

    add_format_arguments(parser, provides=("data", "text", "rows"), json_help="print the results as JSON (SI units in the keys)")
    parser.add_argument(
        "--coefficients", choices=("bem", "paper"), default="bem",
        help="A, B, C from the BEM table of the nose (default) or the paper's quoted constants",
    )
    parser.add_argument("--w1", choices=W1_MODELS, default="neglect",
                        help="lateral-compression energy W1 of eq. (28) (default: neglect, as the paper)")
    parser.add_argument("--cache-dir", default=None, type=output_dir, help="coefficient-table cache folder (default: $SEMIANALYTIC_CACHE_DIR, else the per-user cache)")  # noqa: E501
    parser.add_argument("--report", metavar="DIR", default=None, type=output_dir, help="write a markdown report with plots into DIR")
    parser.add_argument("--report-name", default=None, type=file_stem, help="report file stem (default: validation_<data name>)")
    parser.add_argument("--contact", choices=("full", "separated"), default=None,
                        help="contact region of eq. (15) in eq. (11) (default: [coefficients].contact)")
    parser.add_argument("--tolerance", default=None, help="relative error of the coefficient table (default 1e-5)")
    parser.add_argument("--force", action="store_true", help="overwrite an existing report (and --csv file)")
    parser.add_argument("--part1-model", choices=("rigid", "quasi_rigid", "elastic", "elastic_exact_rod"),
                        default="elastic_exact_rod", help="Part I model of the regime-aware depth_m below the erosion "
                        "onset (default: elastic_exact_rod, the elastic projectile with the exact-rod W2)")
    parser.add_argument("--posterior", metavar="POSTERIOR.json", default=None, action="append",
                        help="add predictive depth quantiles (depth_quantiles_m, with 'regime_aware') from a posterior "
                             "written by calibrate; repeat it to add the eroding rod's posterior (calibrate --model eroding); a "
                             "posterior of calibrate --model regimes adds regime_probability and the regime mixture")
    parser.add_argument("--regime-rule", choices=("nose_load", "meyer", "tate_tabor", "nose_length"), default="nose_load",
                        help="regime labels without a posterior: nose_load (default, chosen by transfer: the dynamic load "
                             "of the case's own nose against kappa x the rod's Meyer hardness surplus, penetration/nose_load.py), "
                             "meyer (the previous default: Tate's tip "
                             "pressure against the rod's static Meyer hardness for the onset, a breakup factor times it "
                             "(printed, and breakup_factor in the JSON) for the breakup where the depth drops to the eroding rod's, 3 x the dynamic ultimate strength for erosion), "  # noqa: E501
                             "tate_tabor (the previous default: 3 x the dynamic yield stress for the onset) or nose_length "
                             "(the earlier rule: U_sC of eqs. (33)/(36), then the shank eroded to the nose length)")
    parser.add_argument("--csv", metavar="FILE", default=None,
                        help="also write FILE (CSV): one row per case, striking velocity and model (units in the header)")


def _load(paths):
    from semianalytic.case import load_case

    cases = []
    for p in paths:
        case = load_case(p)
        for sec in ("projectile", "target", "impact"):
            case.require(sec)
        if case.target.resistance is None:
            raise InputError("target.resistance", f"{p}: missing; add [target.resistance] with a 'model'")
        cases.append(case)
    return cases


def _fmt(x, scale=1.0, digits=1):
    return "nan" if not math.isfinite(x) else f"{x * scale:.{digits}f}"


def _print_text(result: dict, desc: str, file=None) -> None:
    p = lambda *a: print(*a, file=file or sys.stdout)  # noqa: E731
    p(f"case: {result['title']}  ({result['case']})")
    p(f"  coefficients: {desc}")
    p(
        f"  deep limit: Abar = {result['deep_A_bar_m'] * 1e3:.4f} mm, Bbar = {result['deep_B_bar']:.4f}, "
        f"Cbar = {result['deep_C_bar']:.4f};  R_t = {result['resistance_Pa'] / 1e6:.1f} MPa ({result['resistance_equation']}); "
        f"m = {result['mass_kg'] * 1e3:.3f} g"
    )
    if "yield_stress_from_critical_velocity_Pa" in result:
        p(
            f"  Appendix inverse problem: U_sC = {result['measured_critical_velocity_m_s']:.0f} m/s gives the dynamic "
            f"yield stress Y_p = {result['yield_stress_from_critical_velocity_Pa'] / 1e6:.1f} MPa (eq. (36))"
        )
    Uc = result["critical_velocity_m_s"][0]
    p(
        f"  U_sC = {_fmt(Uc, 1, 0)} m/s (eqs. (33)/(36); Y_p = {result['yield_stress_Pa'] / 1e6:.0f} MPa, "
        f"buckling factor {result['buckling_factor']:.3f}); W1: {result['w1']}"
    )
    if result.get("regime_rule") == "nose_length":
        p(f"  regimes (--regime-rule nose_length): rigid below U_sC = {_fmt(result['transition_velocity_m_s'], 1, 0)} m/s, "
          f"eroding from U_e = {_fmt(result['erosion_velocity_m_s'], 1, 0)} m/s (Alekseevskii-Tate, Y_p = "
          f"{result['eroding_inputs']['rod_strength_Pa'] / 1e6:.0f} MPa, R_t = {result['eroding_inputs']['target_resistance_Pa'] / 1e6:.0f} MPa), "  # noqa: E501
          f"deforming between; depth = {result['part1_model']} below U_e, eroding above")
    elif result.get("regime_rule") == "nose_load":
        p(f"  regimes (the nose's own load against the rod's Meyer hardness): rigid below U_y = "
          f"{_fmt(result['transition_velocity_m_s'], 1, 0)} m/s (Forrestal depth), bent (Forrestal depth) to U_b = "
          f"{_fmt(result['breakup_velocity_m_s'], 1, 0)} m/s, eroding from U_e = {_fmt(result['erosion_velocity_m_s'], 1, 0)} m/s; "
          f"Alekseevskii-Tate rod from U_b (Y_p = {result['eroding_inputs']['rod_strength_Pa'] / 1e6:.0f} MPa, R_t = "
          f"{result['eroding_inputs']['target_resistance_Pa'] / 1e6:.0f} MPa)")
    elif result.get("regime_rule") == "meyer":
        p(f"  regimes (Tate 1967 tip pressure against the rod's Meyer hardness H_M and 3 x its dynamic ultimate strength, "
          f"Tabor 1951): rigid below U_y = {_fmt(result['transition_velocity_m_s'], 1, 0)} m/s, the rod breaks up "
          f"(tip pressure {result['breakup_factor']:g} H_M, this project's own) from U_b = {_fmt(result['breakup_velocity_m_s'], 1, 0)} m/s, eroding "  # noqa: E501
          f"from U_e = {_fmt(result['erosion_velocity_m_s'], 1, 0)} m/s; depth = {result['part1_model']} below U_b, "
          f"Alekseevskii-Tate rod above (Y_p = {result['eroding_inputs']['rod_strength_Pa'] / 1e6:.0f} MPa, R_t = "
          f"{result['eroding_inputs']['target_resistance_Pa'] / 1e6:.0f} MPa)")
    else:
        p(f"  regimes (Tate 1967 tip pressure against 3 x the rod's strength, Tabor 1951): rigid below U_y = "
          f"{_fmt(result['transition_velocity_m_s'], 1, 0)} m/s, eroding from U_e = {_fmt(result['erosion_velocity_m_s'], 1, 0)} m/s, "
          f"deforming between; depth = {result['part1_model']} below U_y, Alekseevskii-Tate rod above (Y_p = "
          f"{result['eroding_inputs']['rod_strength_Pa'] / 1e6:.0f} MPa, R_t = {result['eroding_inputs']['target_resistance_Pa'] / 1e6:.0f} MPa)")  # noqa: E501
    head = (
        f"  {'U_s':>7} | {'regime':>9} | {'depth':>7} || {'rigid':>15} | {'quasi-rigid':>15} | {'elastic (29)':>15} |"
        f" {'elastic exact rod':>17} | {'Forrestal':>9} | {'Chen-Li':>8} | {'eroding':>8}"
    )
    p("  verdict (regime and its depth) first; then each model's own depth (valid only in its regime)")
    p(head)
    p(f"  {'m/s':>7} | {'':>9} | {'P mm':>7} || {'P mm    t us':>15} | {'P mm    t us':>15} | {'P mm   t* us':>15} | {'P mm   t* us':>17} | {'P mm':>9} | {'P mm':>8} | {'P mm':>8}")  # noqa: E501
    p("  (P: final depth; t: time to rest, eq. (11); t*: the elastic projectile's stop, eq. (30'), where "
      "m ubar^2 = 2 (W1 + W2))")
    n = len(result["striking_velocity_m_s"])
    for i in range(n):
        r = {k: result[k][i] for k in (
            "striking_velocity_m_s", "depth_rigid_m", "time_rigid_s", "depth_quasi_rigid_m", "time_quasi_rigid_s",
            "depth_elastic_m", "stop_time_elastic_s", "depth_elastic_exact_rod_m", "stop_time_elastic_exact_rod_s",
            "depth_forrestal_m", "depth_chen_li_m")}
        p(
            f"  {r['striking_velocity_m_s']:7.0f} | {result['regime'][i]:>9} | {_fmt(result['depth_m'][i], 1e3):>7} ||"
            f" {_fmt(r['depth_rigid_m'], 1e3):>7} {_fmt(r['time_rigid_s'], 1e6):>7} |"
            f" {_fmt(r['depth_quasi_rigid_m'], 1e3):>7} {_fmt(r['time_quasi_rigid_s'], 1e6):>7} |"
            f" {_fmt(r['depth_elastic_m'], 1e3):>7} {_fmt(r['stop_time_elastic_s'], 1e6):>7} |"
            f" {_fmt(r['depth_elastic_exact_rod_m'], 1e3):>8} {_fmt(r['stop_time_elastic_exact_rod_s'], 1e6):>8} |"
            f" {_fmt(r['depth_forrestal_m'], 1e3):>9} | {_fmt(r['depth_chen_li_m'], 1e3):>8} |"
            f" {_fmt(result['depth_eroding_m'][i], 1e3):>8}"
        )
    U = result["striking_velocity_m_s"]
    src = result.get("regime_source") or []
    if "posterior" in src:
        p(f"  verdict source: the regimes posterior's most probable regime at U_s = "
          f"{', '.join(f'{u:.0f}' for u, s in zip(U, src) if s == 'posterior')} m/s, else the {result.get('regime_rule')} rule")
    def at(flags):
        hit = [f"{u:.0f}" for u, x in zip(U, flags or []) if x]
        return f"at U_s = {', '.join(hit)} m/s" if hit else "at no striking velocity"

    p(f"  diagnostics (they follow the verdict or are marked as not used by it): yields (the regime is not rigid) "
      f"{at(result['yields'])}; Part I's U_s >= U_sC (eqs. (33)/(36); not used by the {result.get('regime_rule')} "
      f"rule) {at(result.get('part1_critical_exceeded'))}")
    est = result.get("depth_error_estimate_m")
    if est:
        worst = {k: max((e / d for e, d in zip(est[k], result[f"depth_{k}_m"]) if d and math.isfinite(d)), default=math.nan)
                 for k in est}
        p("  estimated numerical error of the depths (coefficient tables + integrator), at most: "
          + ", ".join(f"{k.replace('_', ' ')} {v:.1e}" for k, v in worst.items()) + " relative")
    if "depth_quantiles_m" in result:
        p(f"  predictive depth from {result['posterior_file']}: median [5 %, 95 %] mm")
        for model, q in result["depth_quantiles_m"].items():
            cells = "  ".join(f"{a * 1e3:.0f} [{b * 1e3:.0f}, {c * 1e3:.0f}]" for a, b, c in zip(q["0.5"], q["0.05"], q["0.95"]))
            p(f"    {model:<18} {cells}")
        prob = result.get("regime_probability")
        if prob:
            cells = "  ".join("-" if r is None or not math.isfinite(r) else f"{r:.2f}/{d:.2f}/{e:.2f}"
                              for r, d, e in zip(prob["rigid"], prob["deforming"], prob["eroding"]))
            p(f"    {'P(rigid/def./ero.)':<18} {cells}")
        for u, note in zip(result["striking_velocity_m_s"], result.get("regime_notes") or []):
            if note:
                p(f"    at {u:.0f} m/s: {note}")
        tr = result.get("posterior_transfer") or {}
        if tr.get("transfer"):
            p(f"    transfer ({'; '.join(tr['reasons'])}): tau + {tr['tau_added']:.3f}, sigma + {tr['sigma_added']:.3f} "
              "in quadrature (posterior_transfer gives the rule)")
    val = result.get("validation")
    if val:
        p(f"  measured depths ({len(val['shots'])} shots): relative error (predicted - measured)/measured")
        for key, st in val["statistics"].items():
            p(f"    {key:<18} mean {st['mean'] * 100:+6.1f} %   mean |e| {st['mean_abs'] * 100:5.1f} %   max |e| {st['max_abs'] * 100:5.1f} %")  # noqa: E501


def _warn_separation(result: dict) -> None:
    """Under full contact, say on stderr where the pressure of eq. (9) would separate (eq. (15))."""
    onset = result.get("separation_onset_m") or []
    hits = [(U, P) for U, P in zip(result["striking_velocity_m_s"], onset) if P is not None]
    if hits and result.get("contact") == "full":
        first = ", ".join(f"{U:.0f} m/s at P = {P * 1e3:.2f} mm" for U, P in hits[:3])
        print(f"warning: {result['case']}: the contact pressure (eq. (9)) turns negative on the nose for {len(hits)} "
              f"striking velocities ({first}{', ...' if len(hits) > 3 else ''}): the target would separate (eq. (15)); "
              "full contact is assumed (try --contact separated)", file=sys.stderr)


def _shot_intervals(case, shots, args):
    """The 90 % predictive interval of ``--posterior`` at the shots' velocities (None without it)."""
    if not args.posterior:
        return None
    from semianalytic.cache import coefficients_for_case
    from semianalytic.commands.calibrate.evaluate import predict_with_posterior

    coefficients = coefficients_for_case(case, args.coefficients, args.cache_dir)[0]
    q = predict_with_posterior(case, coefficients, args.posterior, [s["velocity_m_s"] for s in shots],
                               part1_model=args.part1_model)["depth_quantiles_m"]
    return q.get(args.part1_model)


def run(args) -> int:
    from semianalytic.cache import coefficients_for_case, override_coefficients
    from semianalytic.commands.penetrate.evaluate import evaluate_case
    from semianalytic.io import check_report_target
    from semianalytic.report.formats import Output, chosen_format, emit

    fmt = chosen_format(args)
    cases = [override_coefficients(c, contact=args.contact, tolerance=args.tolerance) for c in _load(args.cases)]
    if args.posterior:  # a bad posterior file stops before any table is built
        from semianalytic.commands.calibrate.evaluate import check_posterior_files

        check_posterior_files(args.posterior)
    if args.coefficients == "bem":  # refuse before solving what would not fit in memory
        from semianalytic.guards import check_coefficients

        for case in cases:
            check_coefficients(case)
    if args.csv is not None:
        from semianalytic.commands.penetrate.table_out import check_csv_target

        check_csv_target(args.csv, args.force, inputs=args.cases)
    if args.report is not None:
        from semianalytic.commands.penetrate.report import report_path

        check_report_target(report_path(args.report, cases, args.report_name), args.force, inputs=args.cases)
    results, descs = [], []
    for case in cases:
        coefficients, desc, fallback = coefficients_for_case(case, args.coefficients, args.cache_dir)
        if fallback:
            print("warning: the BEM coefficient table is not available in this version; using the paper's quoted "
                  "constant Abar, Bbar, Cbar instead", file=sys.stderr)
        quantiles = {}
        if args.posterior is not None:  # first: a bad posterior stops before anything is computed
            from semianalytic.commands.calibrate.evaluate import predict_with_posterior

            quantiles = predict_with_posterior(case, coefficients, args.posterior, part1_model=args.part1_model)
        notes = quantiles.pop("warnings", [])
        results.append(dict(evaluate_case(case, coefficients, w1=args.w1, part1_model=args.part1_model,
                                                 regime_rule=args.regime_rule), **quantiles))
        results[-1]["warnings"] = [*results[-1]["warnings"], *notes]
        from semianalytic.commands.penetrate.evaluate import one_verdict

        one_verdict(results[-1])  # with a regimes posterior, its most probable regime is the verdict
        descs.append(desc)
        _warn_separation(results[-1])
        for line in results[-1]["warnings"]:
            from semianalytic.errors import one_line

            print(one_line(f"{line} [{case.path or case.title}]"), file=sys.stderr)  # a file name may hold a newline
    if fmt != "text":  # the registered formats (semianalytic.report.formats)
        from semianalytic.commands.penetrate.table_out import depth_csv
        from semianalytic.report.output import json_safe  # strict JSON: a non-finite number is null

        objs = [dict(r, coefficients=d) for r, d in zip(results, descs)]
        emit(Output(data=json_safe(objs[0] if len(objs) == 1 else {"cases": objs}), json_options={"indent": 1, "allow_nan": False},
                    rows=lambda: depth_csv([(str(c.path.name) if c.path else c.title, r) for c, r in zip(cases, results)])), fmt)
    else:
        from semianalytic.commands.penetrate.table_out import shot_table

        for r, d, case in zip(results, descs, cases):
            _print_text(r, d)
            shots = (r.get("validation") or {}).get("shots")
            if shots:  # predicted against measured, shot by shot
                print("\n".join(shot_table(shots, args.part1_model, _shot_intervals(case, shots, args))))
    if args.csv is not None:
        from semianalytic.commands.penetrate.table_out import depth_csv
        from semianalytic.io import atomic_write_text

        atomic_write_text(args.csv, depth_csv([(str(c.path.name) if c.path else c.title, r) for c, r in zip(cases, results)]))
        if fmt == "text":
            print(f"csv: {args.csv}")
    if args.report is not None:
        from semianalytic.commands.penetrate.report import write_report

        path = write_report(args.report, cases, args, name=args.report_name, force=args.force)
        if fmt == "text":
            print(f"report: {path}")
    return 0
