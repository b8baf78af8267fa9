"""What ``coefficients`` prints for a projectile case: the certified table with its error
estimates, or rows at chosen depths (direct BEM solves, or the table the dynamics uses)."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["ROW_KEYS", "coefficients_output", "body_output", "projectile_output", "table_output", "rows_at",
           "direct_rows", "interpolated_rows"]

ROW_KEYS = ("depth_m", "A_m3", "B_m2", "B_literal_m2", "B_bernoulli_m2", "C_m2", "A_bar_m", "B_bar", "C_bar",
            "phi_tip_m", "dA_dP_m2", "A_err_m3", "B_err_m2", "C_err_m2")


def _row(P, A, B, B_lit, B_bern, C, phi, dA, errs, area) -> dict:
    return {
        "depth_m": P, "A_m3": A, "B_m2": B, "B_literal_m2": B_lit, "B_bernoulli_m2": B_bern, "C_m2": C,
        "A_bar_m": A / area, "B_bar": B / area, "C_bar": C / area, "phi_tip_m": phi, "dA_dP_m2": dA,
        "A_err_m3": errs[0], "B_err_m2": errs[1], "C_err_m2": errs[2],
    }


def direct_rows(nose, depths, reading: str, order: int, refinement: float) -> list[dict]:
    """Rows of direct BEM solves at exactly the given depths (Part I, eqs. (12)-(14)).  The
    error estimate of each is the change against a solve at order - 2 (an upper bound of the
    discretisation error of the spectrally converging order)."""
    from semianalytic.coefficients.table import direct_coefficients

    area = math.pi * nose.diameter**2 / 4
    hi = direct_coefficients(nose, depths, order=order, refinement=refinement)
    lo = direct_coefficients(nose, depths, order=max(order - 2, 2), refinement=refinement)
    out = []
    for h, l in zip(hi, lo):
        B = h[f"B_{reading}"]
        errs = (abs(h["A"] - l["A"]), abs(B - l[f"B_{reading}"]), abs(h["C"] - l["C"]))
        out.append(_row(h["depth"], h["A"], B, h["B_literal"], h["B_bernoulli"], h["C"], h["phi_tip"], h["dA_dP"],
                        errs, area) | {"unknowns": int(h["unknowns"])})
    return out


def interpolated_rows(table, depths, reading: str) -> list[dict]:
    """Rows of the table the dynamics uses, at the given depths, with its error estimates."""
    P = np.asarray(depths, float)
    out = []
    for p in P:
        p = float(p)
        errs = (float(table.error("A", p)), float(table.error(f"B_{reading}", p)), float(table.error("C", p)))
        out.append(_row(p, float(table.A(p)), float(table.B(p, reading)), float(table.B(p, "literal")),
                        float(table.B(p, "bernoulli")), float(table.C(p)), float(table.phi_tip(p)),
                        float(table.dA_dP(p)), errs, table.area))
    return out


def table_output(table, nose, reading: str) -> dict:
    """The table as one JSON-able dict: columns over the knots with their error estimates,
    the deep limit with its error, the tolerance and the knots' count."""
    area = math.pi * nose.diameter**2 / 4
    P = table.depth
    v = table.values
    if isinstance(table.options.get("depths"), list):  # a fixed grid: exactly the depths asked for
        P = np.asarray(table.options["depths"], float)
        v = {k: np.asarray(table._eval(k, P)) for k in ("A", "B_body", "B_literal", "B_bernoulli", "C", "phi_tip")}
        v["dA_dP"] = np.asarray(table.dA_dP(P))
        keep = np.isin(table.depth, P)
        unknowns = table.unknowns[keep] if keep.sum() == len(P) else np.full(len(P), int(table.unknowns.max()))
    else:
        unknowns = table.unknowns
    lim = table.limits
    le = table.limit_errors
    be = table.bem_errors
    return {
        "depth_m": P.tolist(),
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
        "A_err_m3": np.asarray(table.error("A", P)).tolist(),
        "B_err_m2": np.asarray(table.error(f"B_{reading}", P)).tolist(),
        "C_err_m2": np.asarray(table.error("C", P)).tolist(),
        "unknowns": np.asarray(unknowns).tolist(),
        "reading": reading,
        "tolerance": table.tolerance,
        "knots": len(table.depth),
        "breakpoints_m": list(table.kinks),
        "nose_length_m": nose.length,
        "diameter_m": nose.diameter,
        "deep_limit": {
            "A_bar_m": lim["A"] / area,
            "B_bar_body": lim["B_body"] / area,
            "B_bar_literal": lim["B_literal"] / area,
            "B_bar_bernoulli": lim["B_bernoulli"] / area,
            "C_bar": lim["C"] / area,
            "A_err_m3": le["A"] + be["A"],
            "B_err_m2": le[f"B_{reading}"] + be[f"B_{reading}"],
            "C_err_m2": le["C"] + be["C"],
        },
        "bem_error_estimate": be,
    }


def rows_at(case, depths_text: str, *, reading: str, interpolated: bool, order: int, refinement: float,
            table_factory=None) -> dict:
    """``--at``: {"rows": [...]} at the depths of ``depths_text`` (see :func:`semianalytic.sections.coefficients.parse_depths`)."""
    from semianalytic.geometry import nose_from_section
    from semianalytic.sections.coefficients import parse_depths

    nose = nose_from_section(case.projectile)
    depths = parse_depths(depths_text, nose.length)
    if interpolated:
        rows = interpolated_rows(table_factory(), depths, reading)
    else:
        rows = direct_rows(nose, depths, reading, order, refinement)
    return {"rows": rows, "reading": reading, "source": "interpolated" if interpolated else "direct",
            "nose_length_m": nose.length, "diameter_m": nose.diameter}


def coefficients_output(case, **options) -> dict:
    """What ``coefficients`` gives for a case: :func:`body_output` for a ``[body]`` case, else
    :func:`projectile_output` (``options`` are the command's flags, None = the case's value)."""
    if case.body is not None:
        return body_output(case, order=options.get("order"), refinement=options.get("refinement"))
    case.require("projectile")
    return projectile_output(case, **options)


def body_output(case, *, order=None, refinement=None) -> dict:
    """Added-mass coefficient of a body in unbounded fluid (BEM), with Lamb's exact value and
    the relative error for a sphere or spheroid."""
    from semianalytic.bem import solve_body
    from semianalytic.exact import spheroid_added_mass_coefficient
    from semianalytic.geometry import body_from_section
    from semianalytic.guards import check_body

    check_body(case, order, refinement)  # refuse before assembly what would not fit in memory
    body = case.body
    meridian = body_from_section(body)
    sol = solve_body(meridian, order=order or case.bem.order, refinement=refinement or case.bem.refinement or 1.0)
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
    return out


def projectile_output(case, *, at=None, interpolated=False, reading=None, depths=None, max_depth=None, tolerance=None,
                      order=None, refinement=None, cache_dir=None, progress=False) -> dict:
    """The certified table of the case's nose (:func:`table_output`), or with ``at`` the rows at
    those depths (:func:`rows_at`).  Each option None takes the case's value."""
    from semianalytic.cache import cached_coefficient_table
    from semianalytic.errors import InputError
    from semianalytic.geometry import nose_from_section
    from semianalytic.guards import check_coefficients
    from semianalytic.sections.coefficients import parse_tolerance

    check_coefficients(case, order, refinement, max_depth, depths=depths)  # refuse what would not fit in memory or time
    nose = nose_from_section(case.projectile)
    reading = reading or case.coefficients.reading
    n_depths = depths or case.coefficients.depths
    tol = parse_tolerance(tolerance) if tolerance is not None else case.coefficients.tolerance
    if n_depths is not None and n_depths < 8:
        raise InputError("--depths", "needs at least 8 depths")
    if interpolated and at is None:
        raise InputError("--interpolated", "needs --at DEPTHS (the depths to read from the table)")
    order = order or case.bem.order
    refinement = refinement or case.bem.refinement or 0.3
    options = dict(order=order, refinement=refinement,
                   max_depth_nose_lengths=max_depth or case.coefficients.max_depth_nose_lengths, progress=progress)
    options.update(n_depths=n_depths) if n_depths is not None else options.update(tolerance=tol)

    def build():
        try:
            return cached_coefficient_table(nose, cache_dir, **options)
        except InputError as exc:  # name the flag when the flag set it
            if exc.field == "coefficients.max_depth_nose_lengths" and max_depth:
                raise InputError("--max-depth", exc.message) from None
            raise

    if at is not None:
        return rows_at(case, at, reading=reading, interpolated=interpolated, order=order, refinement=refinement,
                       table_factory=build)
    return table_output(build(), nose, reading)
