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
    from semianalytic.cli_types import integer, number

    parser.add_argument("case", help="TOML case file with [projectile]+[target] or [body]")
    parser.add_argument("--json", action="store_true", help="print one JSON object instead of a table")
    parser.add_argument("--depths", type=integer(8, 2000), default=None, help="number of depths (default: [coefficients].depths, 60)")
    parser.add_argument("--max-depth", type=number(1.0, 1e6, low_open=True), default=None, help="deepest depth in nose lengths (default 300)")
    parser.add_argument("--reading", choices=READINGS, default=None, help="reading of B for B_m2 (errata item 2a)")
    parser.add_argument("--refinement", type=number(0.0, 8.0, low_open=True), default=None, help="BEM panel-count multiplier")
    parser.add_argument("--order", type=integer(2, 16), default=None, help="Gauss points per panel")


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
    from semianalytic.coefficients.table import coefficient_table
    from semianalytic.geometry import nose_from_section

    from semianalytic.guards import check_coefficients

    check_coefficients(case, args.order, args.refinement, args.max_depth)  # refuse what would not fit in memory
    nose = nose_from_section(case.projectile)
    reading = args.reading or case.coefficients.reading
    n_depths = args.depths or case.coefficients.depths
    max_depth = args.max_depth or case.coefficients.max_depth_nose_lengths
    if n_depths < 8:
        from semianalytic.errors import InputError

        raise InputError("--depths", "needs at least 8 depths")
    table = coefficient_table(
        nose,
        order=args.order or case.bem.order,
        refinement=args.refinement or case.bem.refinement or 0.3,
        n_depths=n_depths,
        max_depth_nose_lengths=max_depth,
        progress=not args.json and sys.stderr.isatty(),
    )
    area = math.pi * nose.diameter**2 / 4
    v = table.values
    out = {
        "depth_m": table.depth.tolist(),
        "A_m3": v["A"].tolist(),
        "B_m2": v[f"B_{reading}"].tolist(),
        "B_body_m2": v["B_body"].tolist(),
        "B_literal_m2": v["B_literal"].tolist(),
        "B_bernoulli_m2": v["B_bernoulli"].tolist(),
        "C_m2": v["C"].tolist(),
        "A_bar_m": (v["A"] / area).tolist(),
        "B_bar": (v[f"B_{reading}"] / area).tolist(),
        "C_bar": (v["C"] / area).tolist(),
        "phi_tip_m": v["phi_tip"].tolist(),
        "dA_dP_m2": v["dA_dP"].tolist(),
        "unknowns": table.unknowns.tolist(),
        "reading": reading,
        "nose_length_m": nose.length,
        "diameter_m": nose.diameter,
        "deep_limit": {
            "A_bar_m": table.limits["A"] / area,
            "B_bar_body": table.limits["B_body"] / area,
            "B_bar_literal": table.limits["B_literal"] / area,
            "B_bar_bernoulli": table.limits["B_bernoulli"] / area,
            "C_bar": table.limits["C"] / area,
        },
    }
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
    return 0
