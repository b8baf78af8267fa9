"""``python -m fem_check verify CASE.toml``: FEM against BEM (and exact solutions) for a case.

* ``[body]`` case: the added mass of the closed body by FEM (P1, P2 under refinement), by the
  BEM (``semianalytic.bem.solve_body``) and, for a sphere or spheroid, exactly (Lamb).
* ``[projectile]`` case: A, B (three readings of errata item 2a), C of Part I, eq. (12) at
  several depths by FEM (:mod:`fem_check.coefficients`) and by the BEM
  (``semianalytic.coefficients.table.coefficients_at``); convergence of the BEM-FEM difference
  under refinement; for a hemispherical nose also the exact mirrored-sphere solution at P = R.

The far-field study (not with ``--quick``): the error of the truncated FEM domain against the
far radius for the Robin conditions of a dipole (k = 2), a monopole (k = 1) and for a plain
Neumann cut-off (errata item 2f), where an exact reference exists: a sphere or spheroid body,
and the hemispherical nose at P = R (so only for ``nose = "sphere"`` cases).
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

from fem_check.coefficients import body_added_mass, depth_scale, halfspace_mesh, solved_once
from fem_check.meshing import MeshOptions, body_domain, build_mesh
from fem_check.potential import solve_potential
from semianalytic.errors import InputError

DEFAULT_DEPTHS = (0.25, 0.5, 0.75, 1.5, 2.0, 4.0, 8.0, 16.0)  # in nose lengths L_h
TEST_DEPTHS = (0.5, 2.0, 8.0)
READINGS = ("body", "literal", "bernoulli")


def legendre_half_moments(n_max: int) -> np.ndarray:
    """I_n = int_0^1 mu P_n(mu) dmu for even n = 0, 2, ..., n_max (closed form, O(n)).

    With P_n(0) from the three-term (Bonnet) recurrence at mu = 0, where its middle term
    vanishes: P_{n+2}(0) = -(n+1)/(n+2) P_n(0); then for even n >= 2, from mu P_n =
    ((n+1) P_{n+1} + n P_{n-1})/(2n+1) and int_0^1 P_m = (P_{m-1}(0) - P_{m+1}(0))/(2m+1):
    I_n = -P_n(0) / ((n+2)(n-1)), and I_0 = 1/2.
    """
    n = np.arange(0, n_max + 1, 2)
    ratio = np.ones(len(n))
    ratio[1:] = -(n[1:] - 1.0) / n[1:]
    p0 = np.cumprod(ratio)  # P_n(0) = (-1)^(n/2) (n-1)!!/n!!
    moments = np.empty(len(n))
    moments[0] = 0.5
    moments[1:] = -p0[1:] / ((n[1:] + 2.0) * (n[1:] - 1.0))
    return moments


def hemisphere_reference(n_terms: int = 400_000) -> dict:
    """Hemispherical nose of radius a at depth P = a (errata item 1b conventions): mirrored in x = 0
    it is a full sphere with dphi/dR = -|cos(theta)|, solved by a Legendre series.

    phi = sum_n c_n (a/R)^(n+1) P_n(cos theta), c_n = a g_n/(n+1), |mu| = sum g_n P_n(mu) (even n),
    g_n = (2n+1) I_n with I_n of :func:`legendre_half_moments` (O(n) recurrence; the direct
    Gauss-Legendre evaluation of I_n cost O(n^2) and 58% of ``verify``).
    Returns phi_tip / a and Abar / a = 4A/(pi d^2) / a (numerical notes: 0.680633550050 and
    0.553967546980).  The phi_tip series alternates with terms ~ n^(-5/2): 400,000 terms leave
    a tail below 1e-13; Abar's terms fall like n^(-5).
    """
    n = np.arange(0, n_terms + 1, 2)
    I = legendre_half_moments(n_terms)
    g = (2 * n + 1) * I
    c = g / (n + 1)
    return {"phi_tip_over_a": float(c.sum()), "Abar_over_a": float(np.sum(c * 2 * I))}


# ------------------------------------------------------------------------------------
# body in unbounded fluid


def exact_added_mass(body_section) -> float | None:
    from semianalytic import exact

    if body_section.shape == "sphere":
        return exact.sphere_added_mass_coefficient()
    if body_section.shape == "spheroid":
        return exact.spheroid_added_mass_coefficient(body_section.length, body_section.diameter)
    return None


def body_verification(meridian, exact: float | None, h_main: float = 0.05, h_list=(0.2, 0.1, 0.05, 0.025),
                      convergence: bool = True) -> dict:
    from semianalytic.bem import solve_body

    t0 = time.perf_counter()
    bem = solve_body(meridian)
    t_bem = time.perf_counter() - t0
    bem_fine = solve_body(meridian, refinement=2.0)
    fem = body_added_mass(meridian, MeshOptions(h=h_main, order=2))
    reference = exact if exact is not None else bem_fine.added_mass_coefficient
    out = {
        "added_mass_bem": bem.added_mass_coefficient, "added_mass_fem": fem.coefficient, "added_mass_exact": exact,
        "added_mass_bem_fine": bem_fine.added_mass_coefficient, "bem_unknowns": bem.unknowns, "bem_seconds": t_bem,
        "fem_dofs": fem.n_dofs, "fem_seconds": fem.seconds, "h_over_d": h_main,
        "fem_minus_bem_rel": fem.coefficient / bem.added_mass_coefficient - 1,
        "fem_minus_exact_rel": None if exact is None else fem.coefficient / exact - 1,
        "bem_minus_exact_rel": None if exact is None else bem.added_mass_coefficient / exact - 1,
        "reference": "exact" if exact is not None else "BEM (refinement 2)",
    }
    if convergence:
        rows = []
        for order in (1, 2):
            for h in h_list:
                f = body_added_mass(meridian, MeshOptions(h=h, order=order))
                rows.append({"order": order, "h_over_d": h, "n_dofs": f.n_dofs, "coefficient": f.coefficient,
                             "error": abs(f.coefficient / reference - 1), "seconds": f.seconds})
        out["convergence"] = rows
    return out


def body_far_field_study(meridian, exact: float, fars=(1.5, 3.0, 6.0, 12.0), h: float = 0.05) -> list[dict]:
    """Relative error of the added mass against the far radius R = far * max(length, d)."""
    rows = []
    for far in fars:
        dm = build_mesh(body_domain(meridian, MeshOptions(h=h, far=far)), MeshOptions(h=h, far=far))
        V = dm.domain.info["volume"]
        row = {"far": far, "far_radius_m": dm.domain.far_radius}
        for ff in ("dipole", "monopole", "neumann"):
            row[ff] = abs(solve_potential(dm, ff).A / V / exact - 1)
        rows.append(row)
    return rows


# ------------------------------------------------------------------------------------
# projectile in the half-space


def compare_depths(nose, depths_over_Lh, h: float = 0.04, order: int = 2, bem_refinement: float = 1.0,
                   grading: float | None = None, memo: dict | None = None) -> list[dict]:
    """FEM and BEM coefficients at the given depths (in nose lengths); one dict per depth (SI).
    ``memo``: a dict shared with :func:`convergence_study` so a solve both need runs once."""
    from semianalytic.coefficients.table import coefficients_at

    scale = depth_scale(nose)  # L_h, or the radius of a flat nose
    Ps = np.asarray(depths_over_Lh, float) * scale
    t0 = time.perf_counter()
    bem = coefficients_at(nose, Ps, refinement=bem_refinement)
    t_bem = (time.perf_counter() - t0) / len(Ps)
    if memo is not None:  # the refinement study compares with the same BEM solves
        memo[("bem", id(nose), tuple(Ps), bem_refinement)] = bem
    rows = []
    for i, P in enumerate(Ps):
        opts = MeshOptions(h=h, order=order) if grading is None else MeshOptions(h=h, order=order, grading=grading)
        f = solved_once(memo, nose, float(P), opts)
        row = {"depth_m": float(P), "depth_over_Lh": float(P / scale)}
        for key, fk in (("A", "A"), ("B", "B_body"), ("C", "C")):
            row[f"{key}_bem"] = float(bem[fk if key != "B" else "B_body"][i])
            row[f"{key}_fem"] = float(getattr(f, fk))
        for rd in ("literal", "bernoulli"):
            row[f"B_{rd}_bem"] = float(bem[f"B_{rd}"][i])
            row[f"B_{rd}_fem"] = float(f.B(rd))
        row["dA_dP_bem"], row["dA_dP_fem"] = float(bem["dA_dP"][i]), f.dA_dP
        row["phi_tip_bem"], row["phi_tip_fem"] = float(bem["phi_tip"][i]), f.phi_tip
        row["rel_diff"] = {k: abs(row[f"{k}_fem"] / row[f"{k}_bem"] - 1) for k in ("A", "B", "C", "B_literal", "phi_tip")}
        S = math.pi * nose.diameter**2 / 4
        row["bar_diff"] = {k: abs(row[f"{k}_fem"] - row[f"{k}_bem"]) / S for k in ("B_bernoulli", "dA_dP")}
        row["max_rel_diff"] = max(row["rel_diff"][k] for k in ("A", "B", "C"))
        row["fem_bernoulli_identity"] = abs(f.B_bernoulli - f.dA_dP) / S
        row["fem_dofs"], row["fem_seconds"], row["bem_seconds"] = f.n_dofs, f.seconds, t_bem
        row["bem_unknowns"] = int(bem["unknowns"][i])
        row["fem_G_source"] = f.G_source
        row["fem_B_surface"] = f.G_surface + 2 * f.Q
        rows.append(row)
    return rows


def convergence_study(nose, depths_over_Lh=(0.5, 2.0, 8.0), h_list=(0.16, 0.08, 0.04, 0.02), orders=(1, 2),
                      memo: dict | None = None) -> list[dict]:
    """|FEM - BEM| / BEM for A and B_body under uniform refinement (BEM at refinement 2 as reference)."""
    from semianalytic.coefficients.table import coefficients_at

    Ps = np.asarray(depths_over_Lh, float) * nose.length
    ref = coefficients_at(nose, Ps, refinement=2.0)
    rows = []
    for i, P in enumerate(Ps):
        for order in orders:
            for h in h_list:
                f = solved_once(memo, nose, float(P), MeshOptions(h=h, order=order))
                rows.append({"depth_over_Lh": float(P / nose.length), "order": order, "h_over_d": h, "n_dofs": f.n_dofs,
                             "A": abs(f.A / ref["A"][i] - 1), "B": abs(f.B_body / ref["B_body"][i] - 1),
                             "seconds": f.seconds})
    return rows


def halfspace_far_field_study(h: float = 0.05, fars=(2.0, 4.0, 8.0, 16.0, 32.0)) -> list[dict]:
    """Hemispherical nose at P = R against the exact mirrored-sphere series: error of Abar against R_far."""
    from semianalytic.geometry import sphere_nose

    ex = hemisphere_reference()["Abar_over_a"]
    nose = sphere_nose(2.0)  # a = 1
    rows = []
    for far in fars:
        dm = halfspace_mesh(nose, 1.0, MeshOptions(h=h, far=far))
        row = {"far": far, "far_radius_over_a": dm.domain.far_radius}
        for ff in ("monopole", "dipole", "neumann"):
            row[ff] = abs(solve_potential(dm, ff).A / math.pi / ex - 1)
        rows.append(row)
    return rows


def hemisphere_check(h_list=(0.1, 0.05, 0.025)) -> list[dict]:
    """FEM Abar and phi_tip of the hemisphere at P = R against the Legendre series (exact)."""
    from semianalytic.geometry import sphere_nose

    ref = hemisphere_reference()
    nose = sphere_nose(2.0)
    rows = []
    for h in h_list:
        dm = halfspace_mesh(nose, 1.0, MeshOptions(h=h))
        s = solve_potential(dm, "monopole")
        rows.append({"h_over_d": h, "n_dofs": s.n_dofs, "Abar": abs(s.A / math.pi / ref["Abar_over_a"] - 1),
                     "phi_tip": abs(s.node_value((1.0, 0.0)) / ref["phi_tip_over_a"] - 1)})
    return rows


# ------------------------------------------------------------------------------------
# command


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from fem_check.report import add_output_arguments

    parser.add_argument("case", help="case TOML with a [body] or a [projectile]")
    from semianalytic.cli_types import number, number_list

    parser.add_argument("--depths", default=None, type=number_list(0.0, 1e4, exclude={1.0: "P = L_h is the nose-shank junction, where the BEM layout changes topology; use a nearby depth such as 0.99 or 1.01"}),  # noqa: E501
                        help="comma-separated depths in nose lengths L_h (default: " + ",".join(map(str, DEFAULT_DEPTHS)) + ")")
    parser.add_argument("--h", type=number(0.005, 0.5), default=0.04, help="FEM element size on the body over d (default 0.04)")
    parser.add_argument("--quick", action="store_true", help="skip the convergence and far-field studies")
    parser.add_argument("--study-h", default="0.16,0.08,0.04,0.02",
                        help="element sizes over d of the refinement study on cornered noses (default 0.16,0.08,0.04,0.02)")
    parser.add_argument("--grading", type=float, default=None,
                        help="corner grading mu = grading * lambda / 2 of the FEM meshes (default 0.4; 0: none)")
    add_output_arguments(parser, "")
    parser.add_argument("--quiet", action="store_true", help="no progress bar on stderr (it is off anyway when stderr is not a terminal)")


def _parse_depths(text: str | None) -> tuple[float, ...]:
    if text is None:
        return DEFAULT_DEPTHS
    if isinstance(text, tuple):  # already parsed by the option's type
        return text
    try:
        vals = tuple(float(v) for v in text.split(",") if v.strip())
    except ValueError:
        raise InputError("--depths", f"expected comma-separated numbers (depths in nose lengths); got {text!r}") from None
    if not vals or any(not (math.isfinite(v) and v > 0) for v in vals):
        raise InputError("--depths", f"depths (in nose lengths) must be positive; got {text!r}")
    return vals


def _parse_study_h(text: str) -> tuple[float, ...]:
    try:
        vals = tuple(float(v) for v in text.split(",") if v.strip())
    except ValueError:
        raise InputError("--study-h", f"expected comma-separated element sizes over d; got {text!r}") from None
    if len(vals) < 3 or any(not 0.005 <= v <= 0.5 for v in vals) or any(b >= a for a, b in zip(vals, vals[1:])):
        raise InputError("--study-h", f"need at least three decreasing sizes in [0.005, 0.5]; got {text!r}")
    return vals


def verify_command(args) -> str:
    """The command line that reproduces a report exactly: the case as given (relative) and every
    option that changes the result, with ``--force`` (the report then exists)."""
    import shlex

    case = Path(args.case)
    words = ["python", "-m", "fem_check", "verify", case.as_posix() if not case.is_absolute() else case.name]
    if args.depths is not None:
        words += ["--depths", ",".join(f"{v:g}" for v in _parse_depths(args.depths))]
    if args.h != 0.04:
        words += ["--h", f"{args.h:g}"]
    if args.quick:
        words.append("--quick")
    if args.study_h != "0.16,0.08,0.04,0.02":
        words += ["--study-h", args.study_h]
    if args.grading is not None:
        words += ["--grading", f"{args.grading:g}"]
    if args.name:
        words += ["--name", args.name]
    out = Path(args.out)
    words += ["--out", out.as_posix() if not out.is_absolute() else out.name, "--force"]
    return " ".join(shlex.quote(w) for w in words)


def verify_case(case, depths=DEFAULT_DEPTHS, *, h: float = 0.04, quick: bool = False,
                study_h=(0.16, 0.08, 0.04, 0.02), grading: float | None = None, quiet: bool = False) -> dict:
    """The FEM-BEM verification of a loaded case (``fem_check verify`` without its report): the
    added mass of a ``[body]``, or A, B, C of a ``[projectile]`` nose at ``depths`` (in nose
    lengths) with the convergence, refinement and far-field studies unless ``quick``.  Returns
    the payload the command prints with ``--json``."""
    from semianalytic.geometry import body_from_section, nose_from_section
    from semianalytic.progress import stages

    bar = stages(1 if quick else 2, "fem_check verify", quiet=quiet)
    if case.body is not None:
        meridian = body_from_section(case.body)
        exact = exact_added_mass(case.body)
        bar.step("added mass, FEM (P1, P2) against BEM" + ("" if quick else " and convergence"))
        res = body_verification(meridian, exact, h_main=min(h, 0.1), convergence=not quick)
        if not quick and exact is not None:
            bar.step("far-field study")
            res["far_field"] = body_far_field_study(meridian, exact)
        payload = {"case": case.title, "kind": "body", **res}
    else:
        from fem_check.refinement import has_singular_corners, refinement_study

        nose = nose_from_section(case.projectile)
        memo: dict = {}  # solves shared by the comparison and the convergence study
        bar.step(f"A, B, C by FEM and BEM at {len(depths)} depths")
        rows = compare_depths(nose, depths, h=h, grading=grading, memo=memo)
        scale = depth_scale(nose)
        payload = {"case": case.title, "kind": "halfspace", "nose": nose.kind, "diameter_m": nose.diameter,
                   "nose_length_m": nose.length, "depth_scale": "L_h" if scale == nose.length else "radius",
                   "depth_scale_m": scale, "h_over_d": h, "depths": rows,
                   "max_rel_diff": max(r["max_rel_diff"] for r in rows)}
        cornered = has_singular_corners(nose, np.asarray(depths) * scale)
        if not quick:
            bar.step("refinement study (cornered nose)" if cornered else "convergence and far-field studies")
        if not quick and cornered:  # no exact solution: FEM self-convergence, BEM beside it
            payload["refinement"] = refinement_study(nose, depths, study_h, grading=grading, memo=memo)
        elif not quick:
            payload["convergence"] = convergence_study(nose, memo=memo)
            if nose.kind == "sphere":  # the far-field study is of the hemisphere at P = R (exact series)
                payload["far_field"] = halfspace_far_field_study()
                payload["hemisphere_exact"] = hemisphere_check()
    bar.close()
    return payload


def run(args) -> int:
    from fem_check.report import Report, emit_json
    from semianalytic.case import load_case

    case = load_case(args.case)
    if not 0.005 <= args.h <= 0.5:
        raise InputError("--h", f"element size over d must lie in [0.005, 0.5]; got {args.h!r}")
    depths = _parse_depths(args.depths)
    study_h = _parse_study_h(args.study_h)
    if args.grading is not None and not 0 <= args.grading <= 1:
        raise InputError("--grading", f"must lie in [0, 1]; got {args.grading!r}")
    if case.body is None and case.projectile is None:
        raise InputError("case", "needs a [body] or a [projectile] section")
    from semianalytic.guards import check_case, check_fem

    check_case(case)  # the BEM side, then the FEM mesh: refused before gmsh if they would not fit
    check_fem(case, args.h, depths)
    name = args.name or f"fem_verify_{Path(args.case).stem}"
    report = None if args.no_report else Report(Path(args.out), name, args.force)
    if report:
        report.check()
    payload = verify_case(case, depths, h=args.h, quick=args.quick, study_h=study_h, grading=args.grading,
                          quiet=getattr(args, "quiet", False))
    if report:
        from fem_check.verify_report import write_verify_report

        payload["command"] = verify_command(args)

        write_verify_report(report, case, payload)
        payload["report"] = str(report.path)
    if args.json:
        emit_json(_jsonable(payload))
    else:
        if payload["kind"] == "body":
            print(f"added mass: FEM {payload['added_mass_fem']:.8f}, BEM {payload['added_mass_bem']:.8f}, "
                  f"exact {payload['added_mass_exact']}")
        else:
            print(f"max relative BEM-FEM difference of A, B, C over {len(payload['depths'])} depths: "
                  f"{payload['max_rel_diff']:.2e}")
        if report:
            print(f"report: {report.path}")
    return 0


def _jsonable(obj):
    if isinstance(obj, dict):
        return {k: _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, (np.floating, np.integer)):
        return obj.item()
    return obj
