"""``python -m semianalytic ballistic-limit CASE.toml [--json]``.

For every shot of the case's ``[ballistic_limit]`` section (a table file and/or inline
shots): the theoretical V_cr of Part IV, eq. (5) with R(1), R(2), R(3), the empirical V_cr of
eqs. (7)-(9), the measured value when given, and, for each ``critical_velocities`` entry, the
critical areal density and thickness of Table 4 (eq. (9) with P = rho_p L_p).
"""

from __future__ import annotations

import argparse
import builtins
import functools
import math

__all__ = ["add_arguments", "run"]

COLUMNS = [("V_R1_m_s", "V(R1)"), ("V_R2_m_s", "V(R2)"), ("V_R3_m_s", "V(R3)"),
           ("V_eq7_m_s", "V(7)"), ("V_eq8_m_s", "V(8)"), ("V_eq9_m_s", "V(9)")]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("case", help="TOML case file with a [ballistic_limit] section")
    from semianalytic.report.formats import add_format_arguments

    add_format_arguments(parser, json_help="print one JSON object (keys carry units)")


def _fmt(value) -> str:
    return "-" if value is None or not math.isfinite(value) else f"{value:.0f}"


def run(args) -> int:
    from semianalytic.case import load_case
    from semianalytic.commands.ballistic_limit.evaluate import evaluate_case
    from semianalytic.report.formats import Output, chosen_format, emit

    fmt = chosen_format(args)
    case = load_case(args.case)
    result = evaluate_case(case)
    emit(Output(data=result, json_options={"indent": 2, "allow_nan": False}, text=lambda s: _text(result, s)), fmt)
    return 0


def _text(result: dict, stream) -> None:
    print = functools.partial(builtins.print, file=stream)
    c = result["constants"]
    print(f"{result['case']}\n")
    print(f"theory: Part IV eq. (5), R(1) = HM delta_H ({result['hardness_rule']}), R(2) = R(3) delta_H, R(3) eq. (6)")
    print(f"empirical: eqs. (7)-(9), P = {result['areal_mass_rule']}, C1 = {c['C1_m2_per_s2']:.4g} m^2/s^2, "
          f"C2 = {c['C2_m2_per_s2_per_GPa']:.4g} (m/s)^2/GPa, C3 = {c['C3_m2_per_s2']:.4g} m^2/s^2\n")
    width = max(12, *(len(r["name"]) for r in result["rows"]))
    head = f"{'shot':<{width}}  {'measured':>8}  " + "  ".join(f"{h:>6}" for _, h in COLUMNS) + "   [m/s]"
    print(head)
    print("-" * len(head))
    for r in result["rows"]:
        meas = r.get("measured_qualifier", "") + _fmt(r.get("measured_V_m_s"))
        print(f"{r['name']:<{width}}  {meas:>8}  " + "  ".join(f"{_fmt(r.get(k)):>6}" for k, _ in COLUMNS))
    crit_rows = [(r["name"], c) for r in result["rows"] for c in r.get("critical", [])]
    if crit_rows:
        print("\ncritical areal density and thickness (Table 4; eq. (9), P = rho_p L_p)")
        for name, c in crit_rows:
            h = c.get("h_cr_m")
            print(f"  {name:<{width}}  V = {c['V_p_m_s']:.0f} m/s: (rho h)_cr = {c['rhoh_cr_kg_m2'] / 10:.2f} g/cm^2"
                  + (f", h_cr = {h * 1e3:.1f} mm" if h else ""))
