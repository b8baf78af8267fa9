"""The ``cavity`` step of a ``run``: the brittle spherical-cavity expansion of Part II."""

from __future__ import annotations

import numpy as np

from semianalytic.case import Case
from semianalytic.report.document import fmt
from semianalytic.run.case import RunSection
from semianalytic.run.context import Context
from semianalytic.run.registry import Step, _has, register

# --------------------------------------------------------------------------------------
# Part II: brittle cavity expansion


def _cavity_solve(case: Case):
    import warnings

    from semianalytic.cavity import BrittleMaterial, solve_cavity
    from semianalytic.errors import ModelValidityWarning, model_field
    from semianalytic.sections.cavity import MODEL_FIELDS

    sec = case.require("material")
    with warnings.catch_warnings(), model_field(MODEL_FIELDS):
        warnings.simplefilter("ignore", ModelValidityWarning)  # reported in the document
        return BrittleMaterial.from_section(sec), solve_cavity(BrittleMaterial.from_section(sec), sec.solver)


def _cavity_preflight(case: Case, run: RunSection) -> None:
    _cavity_solve(case)  # hard conditions of errata item 20 raise ModelError here (the [material] key)


def _cavity_run(ctx: Context) -> None:
    from semianalytic.cavity import zones
    from semianalytic.report.figures import Series, line_figure

    material, r = _cavity_solve(ctx.case)
    d = ctx.doc
    d.heading("Brittle cavity expansion (Part II)")
    for w in r.warnings:
        d.note(w, "warning")
    d.table(
        ["quantity", "value"],
        [
            ["sigma* (eq. 21) [GPa]", fmt(r.sigma_star / 1e9)],
            ["C (eq. 21)", fmt(r.C)],
            ["theta* (eq. 17)", fmt(r.theta_star)],
            ["theta_c (eq. 18)", fmt(r.theta_c)],
            ["v* (eq. 26)", fmt(r.v_star)],
            ["c/b (eq. 13)", fmt(r.c_over_b)],
            ["a/b (eqs. 28-29)", fmt(r.a_over_b)],
            ["e_k (eq. 30)", fmt(r.e_k)],
            ["e_ks (eq. 32)", fmt(r.e_ks)],
            ["theta_k (eq. 33)", fmt(r.theta_k)],
            ["R_r, cavity pressure (eq. 34) [GPa]", fmt(r.cavity_pressure / 1e9)],
            ["solver", f"{r.method}, {r.iterations} iterations"],
        ],
        caption="Three-zone solution (corrected forms of errata items 7-20).",
    )
    b = 1.0
    a, c = r.a_over_b * b, r.c_over_b * b
    ra = np.linspace(a, b, 60)
    rb = np.linspace(b, c, 60)
    rc = np.linspace(c, 3 * c, 80)
    s_a, _ = zones.comminuted_zone(ra, b, r.sigma_star, r.theta_k)
    _, s_b = zones.cracked_zone(rb, b, c, r.sigma_star, material)
    _, s_c, _ = zones.elastic_zone(rc, c, material)
    fig = line_figure(
        [Series(ra, -s_a / 1e9, "comminuted a < r < b (eq. 23)"),
         Series(rb, -s_b / 1e9, "cracked b < r < c (eq. 11)"),
         Series(rc, -s_c / 1e9, "elastic r > c (eq. 5)")],
        "r / b", "-sigma_r [GPa]", "Radial stress through the three zones",
    )
    ctx.figure("cavity_radial_stress", fig, "Compressive radial stress against r/b (Part II, Fig. 1 zones).")
    ctx.results["cavity"] = r.to_json()



register(Step("cavity", "Brittle cavity expansion", ("material",), ("semianalytic.cavity",), _has("material"),
              _cavity_preflight, _cavity_run))
