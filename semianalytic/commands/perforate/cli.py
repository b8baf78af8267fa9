"""``python -m semianalytic perforate CASE.toml [--json]``: perforation of the case's plate or
layered target (``[target] thickness`` or ``[[target.layers]]``) by the rigid projectile of
Part I, eq. (11): per striking velocity ``perforated``, ``residual_velocity_m_s`` (0 where it
stops; then ``depth_m``), ``exit_time_s``; ``failure_mode``; ``ballistic_limit_m_s`` found by the
command itself with its error estimate (``ballistic_limit_bound``: "lower" above the validity limit); the Lambert-Jonas fit ``lambert_jonas``; Part IV's V_cr formulas ``part4_v_cr_m_s``.
``--report DIR`` writes ``validation_perforation.md`` (:mod:`semianalytic.commands.perforate.report`)
for one or more cases."""  # noqa: E501

from __future__ import annotations

import math


def add_arguments(parser) -> None:
    from semianalytic.cli_types import output_dir

    parser.add_argument("cases", nargs="+", metavar="CASE.toml", help="case file(s) with [projectile], [target] thickness or layers, [impact]")  # noqa: E501
    from semianalytic.report.formats import add_format_arguments

    add_format_arguments(parser, json_help="print the results as JSON (SI units in the keys)")
    parser.add_argument("--no-ballistic-limit", action="store_true", help="skip the ballistic-limit search")
    parser.add_argument("--cache-dir", default=None, type=output_dir, help="coefficient-table cache folder")
    parser.add_argument("--quiet", action="store_true", help="no progress on stderr")
    parser.add_argument("--report", metavar="DIR", default=None, type=output_dir,
                        help="write validation_perforation.md (and its figure and CSV) into DIR")


def _text(r: dict) -> str:
    f = lambda v, s=1.0, n=1: "-" if v is None or not math.isfinite(v) else f"{v * s:.{n}f}"  # noqa: E731
    lines = [f"case: {r['title']}  ({r['case']})", f"  target: {r['thickness_m'] * 1e3:.4g} mm in {len(r['layers'])} layer(s); "
             f"back face: {r['back_face']}; failure: {r['failure']}", f"  coefficients: {r['coefficients']}",
             f"  {'V_s m/s':>9} | {'perforated':>10} | {'V_r m/s':>9} | {'depth mm':>9} | {'exit us':>9}"]
    for i, U in enumerate(r["striking_velocity_m_s"]):
        lines.append(f"  {U:9.1f} | {str(r['perforated'][i]):>10} | {f(r['residual_velocity_m_s'][i]):>9} | "
                     f"{f(r['depth_m'][i], 1e3, 2):>9} | {f(r['exit_time_s'][i], 1e6, 2):>9}")
    lines.insert(2, f"  failure mode: {r.get('failure_mode')}" + "".join(f"\n  model: {n}" for n in r.get("model_notes", [])))
    if r["ballistic_limit_m_s"] is not None:
        if r.get("ballistic_limit_bound") == "lower":
            lines.append(f"  ballistic limit: > {r['ballistic_limit_m_s']:.2f} m/s (lower bound: {r.get('ballistic_limit_reason', '')})")
        else:
            lines.append(f"  ballistic limit (the command's own search on eq. (11)): {r['ballistic_limit_m_s']:.2f} +- "
                         f"{r['ballistic_limit_error_m_s']:.2g} m/s")
    lj = r["lambert_jonas"]
    if lj:
        lines.append(f"  Lambert-Jonas fit: a = {lj['a']:.4f}, p = {lj['p']:.3f}, V_bl = {lj['V_bl_m_s']:.1f} m/s")
    if r["part4_v_cr_m_s"]:
        lines.append("  Part IV V_cr: " + ", ".join(f"{k} {v:.0f}" for k, v in r["part4_v_cr_m_s"].items()) + " m/s")
    return "\n".join(lines)


def run(args) -> int:
    from semianalytic.case import load_case
    from semianalytic.commands.perforate.evaluate import evaluate_case
    from semianalytic.report.formats import Output, chosen_format, emit

    fmt = chosen_format(args)
    cases = [load_case(p) for p in args.cases]
    for c in cases:
        for sec in ("projectile", "target", "impact"):
            c.require(sec)
    from semianalytic.progress import stages

    bar = stages(len(cases), "perforate", quiet=args.quiet)  # 20-40 s per case with new plate tables
    results = []
    for c in cases:
        bar.step(f"{c.title}: plate tables, eq. (11), ballistic limit")
        results.append(evaluate_case(c, cache_dir=args.cache_dir, ballistic=not args.no_ballistic_limit))
    bar.close()
    if args.report:
        import numpy as np

        from semianalytic.commands.perforate.evaluate import thickness_sweep
        from semianalytic.commands.perforate.report import write_report

        sweep = [1e-4, 3e-4, 1e-3, 3e-3, 3.5e-3, 3.6e-3, 1e-2, 2.63e-2, 6e-2, 0.2, 1.0, 2.0]
        results[0]["thickness_sweep"] = thickness_sweep(cases[0], sweep, np.geomspace(20.0, 3000.0, 50), args.cache_dir)

        path = write_report(results, args.report, argv=["perforate", *args.cases, "--report", str(args.report)])
        print(f"wrote {path}")
        return 0
    emit(Output(data=results[0] if len(results) == 1 else results, json_options={"indent": 1},
                text=lambda s: print("\n\n".join(_text(r) for r in results), file=s)), fmt)
    return 0
