"""The ``added_mass`` step of a ``run``: the BEM added mass of a closed body in unbounded
fluid (Part I section 1.4) against Lamb's exact value for spheres and spheroids."""

from __future__ import annotations

import numpy as np

from semianalytic.case import Case
from semianalytic.run.case import RunSection
from semianalytic.run.context import Context
from semianalytic.run.registry import Step, _has, bem_options, register

# --------------------------------------------------------------------------------------
# added mass of a closed body (Part I section 1.4; exact: Lamb)


def _added_mass_preflight(case: Case, run: RunSection) -> None:
    from semianalytic.geometry import body_from_section

    body_from_section(case.require("body"))


def _added_mass_run(ctx: Context) -> None:
    from semianalytic import exact
    from semianalytic.bem import solve_body
    from semianalytic.geometry import body_from_section
    from semianalytic.report.figures import Series, line_figure

    b = ctx.case.body
    meridian = body_from_section(b)
    sol = solve_body(meridian, **bem_options(ctx.case))
    k = sol.added_mass_coefficient
    ref = None
    if b.shape == "sphere":
        ref = exact.sphere_added_mass_coefficient()
    elif b.shape == "spheroid":
        ref = exact.spheroid_added_mass_coefficient(b.length, b.diameter)
    d = ctx.doc
    d.heading("Added mass (BEM, unbounded fluid)")
    rows = [["added-mass coefficient A/V (BEM)", f"{k:.10f}"], ["unknowns", str(sol.unknowns)]]
    if ref is not None:
        rows += [["exact (Lamb)", f"{ref:.10f}"], ["relative error", f"{abs(k - ref) / ref:.2e}"]]
    d.table(["quantity", "value"], rows)
    nodes = sol.nodes
    series = [Series(nodes.x, nodes.phi, "BEM phi on the surface", "o")]
    if ref is not None:
        xs = np.linspace(nodes.x.min(), nodes.x.max(), 200)
        series.append(Series(xs, ref * xs, "exact phi = k1 x (Lamb)", "-"))
    fig = line_figure(series, "x [m]", "phi [m] (unit speed)", "Surface potential of the body")
    ctx.figure("added_mass_surface_phi", fig, "Surface potential phi(x) against the exact k1 x.")
    ctx.results["added_mass"] = {
        "added_mass_coefficient": k,
        "added_mass_coefficient_exact": ref,
        "relative_error": None if ref is None else abs(k - ref) / ref,
        "A_m3": sol.A,
        "volume_m3": meridian.volume(),
        "unknowns": sol.unknowns,
    }



register(Step("added_mass", "Added mass", ("body",), ("semianalytic.bem",), _has("body"),
              _added_mass_preflight, _added_mass_run))
