"""``python -m semianalytic coefficients CASE.toml [--json]``.

For a ``[projectile]`` case: the table of A(P), B(P), C(P) of Part I, eqs. (12)-(14) from
first contact to deep penetration.  For a ``[body]`` case: the added-mass coefficient of
the body in unbounded fluid (with the exact value for a sphere or spheroid).
"""

from __future__ import annotations

import builtins
import functools
import math

from semianalytic.case import load_case
from semianalytic.coefficients import READINGS


def add_arguments(parser) -> None:
    from semianalytic.cli_types import integer, number, output_dir

    parser.add_argument("case", help="TOML case file with [projectile]+[target] or [body]")
    from semianalytic.report.formats import add_format_arguments

    add_format_arguments(parser, json_help="print one JSON object instead of a table")
    parser.add_argument("--depths", type=integer(8, 2000), default=None,
                        help="a fixed grid of this many depths instead of the adaptive knots (default: adaptive)")
    parser.add_argument("--max-depth", type=number(1.0, 1e6, low_open=True), default=None, help="deepest depth in nose lengths (default 300)")  # noqa: E501
    parser.add_argument("--reading", choices=READINGS, default=None, help="reading of B for B_m2 (errata item 2a)")
    parser.add_argument("--refinement", type=number(0.0, 8.0, low_open=True), default=None, help="BEM panel-count multiplier")
    parser.add_argument("--order", type=integer(2, 16), default=None, help="Gauss points per panel")
    parser.add_argument("--tolerance", default=None,
                        help="relative interpolation error of the table, in (0, 0.1) (default: [coefficients].tolerance, 1e-5)")
    parser.add_argument("--at", default=None, metavar="DEPTHS",
                        help="rows at these depths only: lengths with units ('10 mm,59.0 mm') or nose lengths ('0.5Lh,5Lh')")
    parser.add_argument("--interpolated", action="store_true",
                        help="with --at: the values of the table the dynamics uses (default: direct BEM solves)")
    parser.add_argument("--cache-dir", default=None, type=output_dir, help="coefficient-table cache folder")


def run(args) -> int:
    from semianalytic.commands.coefficients.evaluate import coefficients_output
    from semianalytic.report.formats import Output, chosen_format, emit

    fmt = chosen_format(args)
    case = load_case(args.case)
    out = coefficients_output(case, at=args.at, interpolated=args.interpolated, reading=args.reading,
                              depths=args.depths, max_depth=args.max_depth, tolerance=args.tolerance,
                              order=args.order, refinement=args.refinement, cache_dir=args.cache_dir,
                              progress=True)  # semianalytic.progress decides: bar, log lines or off
    printer = _print_body if case.body is not None else _print_rows if "rows" in out else _print_table
    emit(Output(data=out, text=lambda s: printer(case, out, s)), fmt)
    return 0


def _print_body(case, out, stream=None) -> None:
    print = functools.partial(builtins.print, file=stream)
    print(f"{case.title}")
    print(f"  added-mass coefficient (added mass / rho V): {out['added_mass_coefficient']:.12f}")
    if "added_mass_coefficient_exact" in out:
        print(f"  exact (Lamb):                              {out['added_mass_coefficient_exact']:.12f}")
        print(f"  relative error:                            {out['relative_error']:.2e}")
    print(f"  unknowns: {out['unknowns']}")


def _print_table(case, out, stream=None) -> None:
    print = functools.partial(builtins.print, file=stream)
    d, L = out["diameter_m"], out["nose_length_m"]
    area = math.pi * d**2 / 4
    print(f"{case.title}: {case.projectile.nose} nose, d = {d * 1e3:.4g} mm, L_h = {L * 1e3:.4g} mm")
    print(f"B reading: {out['reading']} (errata item 2a); Abar = 4A/(pi d^2) in mm, Bbar, Cbar dimensionless")
    head = f"{'P [mm]':>10} {'P/L_h':>8} {'Abar [mm]':>10} {'Bbar':>9} {'Bbar_lit':>9} {'Bbar_bern':>10} {'Cbar':>8} {'phi_tip [mm]':>12}"
    print(head)
    for k, P in enumerate(out["depth_m"]):
        print(
            f"{P * 1e3:10.4f} {P / max(L, 1e-300):8.3f} {out['A_bar_m'][k] * 1e3:10.6f} "
            f"{out['B_bar'][k]:9.5f} {out['B_literal_m2'][k] / area:9.5f} {out['B_bernoulli_m2'][k] / area:10.2e} "
            f"{out['C_bar'][k]:8.5f} {out['phi_tip_m'][k] * 1e3:12.6f}"
        )
    dl = out["deep_limit"]
    print(
        f"deep limit: Abar = {dl['A_bar_m'] * 1e3:.5f} mm, Bbar body/literal/bernoulli = "
        f"{dl['B_bar_body']:.5f}/{dl['B_bar_literal']:.5f}/{dl['B_bar_bernoulli']:.1e}, Cbar = {dl['C_bar']:.5f}"
    )
    ea, eb = max(out["A_err_m3"]) / max(map(abs, out["A_m3"])), max(out["B_err_m2"]) / max(map(abs, out["B_m2"]))
    print(f"{out['knots']} knots; estimated error (interpolation + BEM) at most {ea:.1e} of max |A|, {eb:.1e} of max |B|"
          + (f" (tolerance {out['tolerance']:g})" if out["tolerance"] else ""))
    where = _largest_error_note(out, L)
    if where:
        print(where)


def _largest_error_note(out, L) -> str:
    """Where the largest B error sits when it is at a corner breakpoint (a cone's shoulder entering
    the target: B jumps there, and the estimate of the knot beside the jump spans the jump), and
    the largest error away from the breakpoints."""
    P, eb = out["depth_m"], out["B_err_m2"]
    big = max(map(abs, out["B_m2"]))
    k = max(range(len(eb)), key=lambda i: eb[i])
    breaks = [b for b in out.get("breakpoints_m") or [] if b > 0]
    near = lambda x: any(abs(x - b) <= 1e-3 * b for b in breaks)  # noqa: E731
    if not near(P[k]):
        return ""
    away = [e for x, e in zip(P, eb) if not near(x)]
    rest = f"; away from the breakpoints at most {max(away) / big:.1e} of max |B|" if away else ""
    return (f"  largest B error: the knot at P = {P[k] * 1e3:.4f} mm (P/L_h = {P[k] / max(L, 1e-300):.6f}) beside the "
            "corner breakpoint where the shoulder enters the target and B jumps; the estimate there spans the jump, "
            f"it is not the interpolation error between knots{rest}")


def _print_rows(case, out, stream=None) -> None:
    print = functools.partial(builtins.print, file=stream)
    print(f"{case.title}: {case.projectile.nose} nose, {out['source']} values (B reading {out['reading']})")
    print(f"{'P [mm]':>10} {'Abar [mm]':>12} {'Bbar':>10} {'Cbar':>9} {'A_err [m3]':>11} {'B_err [m2]':>11}")
    for r in out["rows"]:
        print(f"{r['depth_m'] * 1e3:10.4f} {r['A_bar_m'] * 1e3:12.7f} {r['B_bar']:10.6f} {r['C_bar']:9.6f} "
              f"{r['A_err_m3']:11.1e} {r['B_err_m2']:11.1e}")
