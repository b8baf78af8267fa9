"""``python -m semianalytic coefficients CASE.toml [--json]``.

For a ``[projectile]`` case: the table of A(P), B(P), C(P) of Part I, eqs. (12)-(14) from
first contact to deep penetration.  For a ``[body]`` case: the added-mass coefficient of
the body in unbounded fluid (with the exact value for a sphere or spheroid).
"""

from __future__ import annotations

import json
import math
import sys


from semianalytic.case import load_case
from semianalytic.coefficients import READINGS


def add_arguments(parser) -> None:
    from semianalytic.cli_types import integer, number, output_dir

    parser.add_argument("case", help="TOML case file with [projectile]+[target] or [body]")
    parser.add_argument("--json", action="store_true", help="print one JSON object instead of a table")
    parser.add_argument("--depths", type=integer(8, 2000), default=None,
                        help="a fixed grid of this many depths instead of the adaptive knots (default: adaptive)")
    parser.add_argument("--max-depth", type=number(1.0, 1e6, low_open=True), default=None, help="deepest depth in nose lengths (default 300)")
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
    case = load_case(args.case)
    if case.body is not None:
        return _run_body(case, args)
    case.require("projectile")
    return _run_projectile(case, args)


def _run_body(case, args) -> int:
    from semianalytic.bem import solve_body
    from semianalytic.exact import spheroid_added_mass_coefficient
    from semianalytic.geometry import body_from_section

    from semianalytic.guards import check_body

    check_body(case, args.order, args.refinement)  # refuse before assembly what would not fit in memory
    body = case.body
    meridian = body_from_section(body)
    order = args.order or case.bem.order
    refinement = args.refinement or case.bem.refinement or 1.0
    sol = solve_body(meridian, order=order, refinement=refinement)
    out = {
        "added_mass_coefficient": sol.added_mass_coefficient,
        "unknowns": sol.unknowns,
        "A_m3": sol.A,
        "volume_m3": meridian.volume(),
    }
    if body.shape in ("sphere", "spheroid"):
        length = body.length if body.shape == "spheroid" else body.diameter
        exact = spheroid_added_mass_coefficient(length, body.diameter)
        out["added_mass_coefficient_exact"] = exact
        out["relative_error"] = sol.added_mass_coefficient / exact - 1.0
    if args.json:
        print(json.dumps(out))
        return 0
    print(f"{case.title}")
    print(f"  added-mass coefficient (added mass / rho V): {out['added_mass_coefficient']:.12f}")
    if "added_mass_coefficient_exact" in out:
        print(f"  exact (Lamb):                              {out['added_mass_coefficient_exact']:.12f}")
        print(f"  relative error:                            {out['relative_error']:.2e}")
    print(f"  unknowns: {out['unknowns']}")
    return 0


def _run_projectile(case, args) -> int:
    from semianalytic.cache import cached_coefficient_table
    from semianalytic.coefficients.case import parse_tolerance
    from semianalytic.coefficients.evaluate import rows_at, table_output
    from semianalytic.errors import InputError
    from semianalytic.geometry import nose_from_section

    from semianalytic.guards import check_coefficients

    check_coefficients(case, args.order, args.refinement, args.max_depth)  # refuse what would not fit in memory
    nose = nose_from_section(case.projectile)
    reading = args.reading or case.coefficients.reading
    n_depths = args.depths or case.coefficients.depths
    max_depth = args.max_depth or case.coefficients.max_depth_nose_lengths
    tolerance = parse_tolerance(args.tolerance) if args.tolerance is not None else case.coefficients.tolerance
    if n_depths is not None and n_depths < 8:
        raise InputError("--depths", "needs at least 8 depths")
    order = args.order or case.bem.order
    refinement = args.refinement or case.bem.refinement or 0.3
    options = dict(order=order, refinement=refinement, max_depth_nose_lengths=max_depth,
                   progress=not args.json and sys.stderr.isatty())
    options.update(n_depths=n_depths) if n_depths is not None else options.update(tolerance=tolerance)

    def build():
        try:
            return cached_coefficient_table(nose, args.cache_dir, **options)
        except InputError as exc:  # name the flag when the flag set it
            if exc.field == "coefficients.max_depth_nose_lengths" and args.max_depth:
                raise InputError("--max-depth", exc.message) from None
            raise

    if args.at is not None:
        out = rows_at(case, args.at, reading=reading, interpolated=args.interpolated, order=order,
                      refinement=refinement, table_factory=build)
        if args.json:
            print(json.dumps(out))
        else:
            _print_rows(case, nose, out)
        return 0
    if args.interpolated:
        raise InputError("--interpolated", "needs --at DEPTHS (the depths to read from the table)")
    table = build()
    out = table_output(table, nose, reading)
    v = table.values
    area = math.pi * nose.diameter**2 / 4
    if args.json:
        print(json.dumps(out))
        return 0
    print(f"{case.title}: {nose.kind} nose, d = {nose.diameter * 1e3:.4g} mm, L_h = {nose.length * 1e3:.4g} mm")
    print(f"B reading: {reading} (errata item 2a); Abar = 4A/(pi d^2) in mm, Bbar, Cbar dimensionless")
    head = f"{'P [mm]':>10} {'P/L_h':>8} {'Abar [mm]':>10} {'Bbar':>9} {'Bbar_lit':>9} {'Bbar_bern':>10} {'Cbar':>8} {'phi_tip [mm]':>12}"
    print(head)
    for k, P in enumerate(table.depth):
        print(
            f"{P * 1e3:10.4f} {P / max(nose.length, 1e-300):8.3f} {v['A'][k] / area * 1e3:10.6f} "
            f"{v[f'B_{reading}'][k] / area:9.5f} {v['B_literal'][k] / area:9.5f} {v['B_bernoulli'][k] / area:10.2e} "
            f"{v['C'][k] / area:8.5f} {v['phi_tip'][k] * 1e3:12.6f}"
        )
    d = out["deep_limit"]
    print(
        f"deep limit: Abar = {d['A_bar_m'] * 1e3:.5f} mm, Bbar body/literal/bernoulli = "
        f"{d['B_bar_body']:.5f}/{d['B_bar_literal']:.5f}/{d['B_bar_bernoulli']:.1e}, Cbar = {d['C_bar']:.5f}"
    )
    ea, eb = max(out["A_err_m3"]) / max(map(abs, out["A_m3"])), max(out["B_err_m2"]) / max(map(abs, out["B_m2"]))
    print(f"{out['knots']} knots; estimated error (interpolation + BEM) at most {ea:.1e} of max |A|, {eb:.1e} of max |B|"
          + (f" (tolerance {out['tolerance']:g})" if out["tolerance"] else ""))
    return 0


def _print_rows(case, nose, out) -> None:
    print(f"{case.title}: {nose.kind} nose, {out['source']} values (B reading {out['reading']})")
    print(f"{'P [mm]':>10} {'Abar [mm]':>12} {'Bbar':>10} {'Cbar':>9} {'A_err [m3]':>11} {'B_err [m2]':>11}")
    for r in out["rows"]:
        print(f"{r['depth_m'] * 1e3:10.4f} {r['A_bar_m'] * 1e3:12.7f} {r['B_bar']:10.6f} {r['C_bar']:9.6f} "
              f"{r['A_err_m3']:11.1e} {r['B_err_m2']:11.1e}")
