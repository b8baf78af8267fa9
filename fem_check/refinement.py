"""FEM self-convergence on cornered noses: observed orders and Richardson extrapolation.

A body of revolution in a half-space has no closed-form potential once its meridian has a
corner (a flat nose's rim, a cone's shoulder), so the FEM is verified on its own by refinement:
the element size h on the body is halved (h, h/2, h/4, ...) on meshes graded towards the
corners found from the geometry (:func:`fem_check.meshing.singular_corners`), and for each
quantity X the last three values give

    observed order  p = log2(|X_{h/2} - X_h| / |X_{h/4} - X_{h/2}|),
    extrapolated    X_inf = X_{h/4} + (X_{h/4} - X_{h/2}) / (2^p - 1)   (Richardson),

with the error bar |X_inf - X_{h/4}| (the correction itself: conservative while the sequence is
in its asymptotic range; the extrapolation is given for orders between 1 and 8 only).

The quantities taken from a shape difference in P (dA/dP, B) carry a second error that refining h
does not reduce: the O(eps^2) error of the central difference, large near a breakpoint of the depth
axis (issue 27: a cone at 1.001 L_h, FEM - BEM 8.7e-5 in B against a bar of 4.6e-7).  The finest
mesh is therefore solved again with half the step, the step's error estimated by Richardson in eps,
X(eps/2) - X(eps) times 4/3, added to the extrapolated value and its size to the error bar
(``step_error``).  Predicted
orders for P2 on meshes graded with mu < lambda/2 at every corner (Babuska, Kellogg and
Pitkaranta): h^2 in the energy norm, hence h^4 for A, which is the energy (Part I, eq. (12)),
and for dA/dP (a shape derivative of the energy).  B (shape form, see
:func:`fem_check.coefficients.halfspace_coefficients`) adds H, a functional of the trace whose
end terms are the nodal values of phi at the corners: between h^2 and h^4.
"""

from __future__ import annotations

import math

import numpy as np

from fem_check.coefficients import depth_scale, halfspace_coefficients
from fem_check.meshing import MeshOptions, halfspace_domain

STUDY_KEYS = ("A", "B_body", "B_surface", "dA_dP", "B_bernoulli", "C")
STEP_KEYS = ("B_body", "B_surface", "dA_dP", "B_bernoulli")  # from the shape difference in P
PREDICTED_ORDER = {"A": 4.0, "dA_dP": 4.0, "B_body": 2.0}  # lower bounds of the asymptotic orders (P2, graded)


def richardson(values, hs) -> dict:
    """Observed order and Richardson extrapolation from the last three values of a sequence with
    h halved at each step (``hs`` decreasing)."""
    v = np.asarray(values, float)
    out = {"order": None, "extrapolated": None, "error_bar": None, "finest": float(v[-1])}
    if len(v) < 3:
        return out
    ratio = hs[-2] / hs[-1]
    d1, d2 = v[-2] - v[-3], v[-1] - v[-2]
    if d2 == 0 or d1 == 0:
        out.update(extrapolated=float(v[-1]), error_bar=0.0)
        return out
    order = math.log(abs(d1 / d2)) / math.log(ratio)
    out["order"] = order
    if 1.0 <= order <= 8.0 and d1 * d2 > 0:
        corr = d2 / (ratio**order - 1)
        out.update(extrapolated=float(v[-1] + corr), error_bar=abs(corr))
    else:  # not monotone / not asymptotic: the last change is the error bar
        out.update(extrapolated=float(v[-1]), error_bar=abs(d2))
    return out


def corners_of(nose, depth: float) -> list[dict]:
    """The singular corners of the half-space domain at depth P (from the meridian's tangent jumps)."""
    dom = halfspace_domain(nose, depth, MeshOptions())
    return [{"x_m": c.point[0], "r_m": c.point[1], "angle_deg": math.degrees(c.angle), "exponent": c.exponent,
             "on_axis": c.on_axis} for c in dom.corners]


def has_singular_corners(nose, depths_m) -> bool:
    """True if the wetted nose has a ring corner with lambda < 1 at one of the depths."""
    return any(any(not c["on_axis"] and c["exponent"] < 1 for c in corners_of(nose, float(P))) for P in depths_m)


def refinement_study(nose, depths_over_scale, h_list=(0.16, 0.08, 0.04, 0.02), grading: float | None = None,
                     bem_refinement: float = 1.0, memo: dict | None = None) -> list[dict]:
    """FEM under refinement at each depth (in units of :func:`depth_scale`), with observed orders,
    Richardson extrapolation and the BEM (``coefficients_at``) beside it.  ``memo``: the dict of
    :func:`fem_check.verify.compare_depths`, so the solves both need (its h) run once."""
    from semianalytic.coefficients.table import coefficients_at

    from fem_check.verify import _solved

    scale = depth_scale(nose)
    Ps = np.asarray(depths_over_scale, float) * scale
    bem = (memo or {}).get(("bem", id(nose), tuple(Ps), bem_refinement))
    if bem is None:
        bem = coefficients_at(nose, Ps, refinement=bem_refinement)
    S = math.pi * nose.diameter**2 / 4
    out = []
    for i, P in enumerate(Ps):
        rows = []
        for h in h_list:
            opts = MeshOptions(h=h) if grading is None else MeshOptions(h=h, grading=grading)
            f = _solved(memo, nose, float(P), opts)
            rows.append({"h_over_d": h, "n_dofs": f.n_dofs, "seconds": f.seconds, "A": f.A, "B_body": f.B_body,
                         "B_surface": f.G_surface + 2 * f.Q, "dA_dP": f.dA_dP, "B_bernoulli": f.B_bernoulli, "C": f.C,
                         "G_source": f.G_source})
        hs = [r["h_over_d"] for r in rows]
        extrap = {k: richardson([r[k] for r in rows], hs) for k in STUDY_KEYS}
        fine = MeshOptions(h=h_list[-1]) if grading is None else MeshOptions(h=h_list[-1], grading=grading)
        half = halfspace_coefficients(nose, float(P), fine, step_scale=0.5)
        half_row = {"B_body": half.B_body, "B_surface": half.G_surface + 2 * half.Q, "dA_dP": half.dA_dP,
                    "B_bernoulli": half.B_bernoulli}
        for k in STEP_KEYS:
            corr = (half_row[k] - rows[-1][k]) * 4.0 / 3.0  # Richardson in the step (error O(eps^2))
            e = extrap[k]
            e["step_error"] = abs(corr)
            if e["extrapolated"] is not None:
                e["extrapolated"] += corr
            e["error_bar"] = (e["error_bar"] or 0.0) + abs(corr)
        bem_row = {"A": float(bem["A"][i]), "B_body": float(bem["B_body"][i]), "dA_dP": float(bem["dA_dP"][i]),
                   "B_bernoulli": float(bem["B_bernoulli"][i]), "unknowns": int(bem["unknowns"][i])}
        diff = {}
        for k, norm in (("A", abs(bem_row["A"])), ("B_body", abs(bem_row["B_body"])), ("dA_dP", S)):
            e = extrap[k]
            diff[k] = {"fem_minus_bem": (e["extrapolated"] - bem_row[k]) / norm, "fem_error_bar": e["error_bar"] / norm,
                       "normalised_by": "BEM value" if k != "dA_dP" else "pi d^2/4"}
        out.append({"depth_m": float(P), "depth_over_scale": float(P / scale), "corners": corners_of(nose, float(P)),
                    "rows": rows, "extrapolated": extrap, "bem": bem_row, "diff": diff})
    return out
