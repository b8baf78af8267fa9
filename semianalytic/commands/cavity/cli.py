"""``python -m semianalytic cavity CASE.toml [--json] [--method bracket|fixed-point]``.

Solves the three-zone cavity model of Part II for the case's ``[material]`` section and
prints sigma*, the porosities, the front ratios and the cavity pressure R_r (eq. (34)).
Soft-condition warnings go to stderr; a rejected material exits with status 2.
"""

from __future__ import annotations

import argparse
import sys
import warnings

from semianalytic.errors import ModelValidityWarning

__all__ = ["add_arguments", "run", "format_result"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("case", help="TOML case file with a [material] section")
    from semianalytic.report.formats import add_format_arguments

    add_format_arguments(parser, json_help="print one JSON object (keys carry units)")
    parser.add_argument("--method", choices=("bracket", "fixed-point"), default=None,
                        help="root finder for eq. (21): bracketed root (default) or the paper's iteration (22); "
                             "overrides [material].solver")


def format_result(r) -> str:
    """Human-readable table of a :class:`~semianalytic.cavity.CavityResult`."""
    rows = [
        ("sigma* (eq. 21)", f"{r.sigma_star / 1e9:.4f} GPa"),
        ("C (eq. 21)", f"{r.C:.4f}"),
        ("theta* (eq. 17)", f"{r.theta_star:.5f}"),
        ("theta_c (eq. 18)", f"{r.theta_c:.5f}"),
        ("e_r, e_phi at b+0 (eq. 14)", f"{r.e_r:.5f}, {r.e_phi:.5f}"),
        ("e_c, gamma_c (eq. 14)", f"{r.e_c:.5f}, {r.gamma_c:.5f}"),
        ("v* (eq. 26)", f"{r.v_star:.5f}"),
        ("c/b (eq. 13)", f"{r.c_over_b:.4f}"),
        ("a/b (eqs. 28-29)", f"{r.a_over_b:.4f}"),
        ("e_k (eq. 30)", f"{r.e_k:.5f}"),
        ("e_ks (eq. 32)", f"{r.e_ks:.5f}"),
        ("theta_k (eq. 33)", f"{r.theta_k:.5f}"),
        ("R_r (eq. 34)", f"{r.cavity_pressure / 1e9:.4f} GPa"),
        ("solver", f"{r.method}, {r.iterations} iterations, g'(x*) = {r.contraction:.4f}"),
    ]
    width = max(len(k) for k, _ in rows)
    return "\n".join(f"{k:<{width}}  {v}" for k, v in rows)


def run(args) -> int:
    from semianalytic.case import load_case
    from semianalytic.cavity import BrittleMaterial, solve_cavity
    from semianalytic.report.formats import Output, chosen_format, emit

    fmt = chosen_format(args)
    from semianalytic.errors import model_field
    from semianalytic.sections.cavity import MODEL_FIELDS

    case = load_case(args.case)
    section = case.require("material")
    method = args.method or section.solver
    with warnings.catch_warnings(), model_field(MODEL_FIELDS):
        warnings.simplefilter("ignore", ModelValidityWarning)  # printed below instead
        material = BrittleMaterial.from_section(section)
        result = solve_cavity(material, method)
    for note in result.warnings:
        print(f"warning: {note}", file=sys.stderr)
    emit(Output(data={"case": case.title, **result.to_json()}, json_options={"indent": 2, "allow_nan": False},
                text=lambda s: print(f"{case.title}\n\n{format_result(result)}", file=s)), fmt)
    return 0
