"""Part I steps of a ``run``: drag coefficients (Figs. 6-8), penetration histories and
depth curves (Figs. 9-11, 14-16), critical impact velocity (eqs. (33)/(36)) and the
validation against measured depths.  The physics is the penetration package's
(:mod:`semianalytic.penetration`); this module only calls it and draws.
"""

from __future__ import annotations

import math

import numpy as np

from semianalytic.case import Case
from semianalytic.errors import InputError
from semianalytic.report.document import fmt
from semianalytic.report.figures import Points, Series, line_figure, panels_figure, side_by_side_figure
from semianalytic.run.case import RunSection
from semianalytic.run.context import Context
from semianalytic.run.registry import Step, _coefficient_table, _has, _projectile, register

MM = 1e3  # m -> mm for display
# Integration tolerance of the report's ODE solves: 1e-9 relative is five orders below the four
# significant digits shown (the penetration package's defaults, 1e-10..1e-12, cost 2-3x the time).
RTOL = 1e-9
US = 1e6  # s -> us


# --------------------------------------------------------------------------------------
# coefficients: the BEM table, or the paper's quoted constants ([run] coefficients = "paper")


def coefficients(ctx: Context):
    """The DragCoefficients of this run (memoised): the BEM table, or with
    ``[run] coefficients = "paper"`` the paper's quoted deep-penetration constants
    (:func:`semianalytic.cache.coefficients_for_case`)."""
    if "coefficients" in ctx.memo:
        return ctx.memo["coefficients"]
    if ctx.run.coefficients == "bem":
        c = _coefficient_table(ctx)
    else:
        from semianalytic.cache import coefficients_for_case

        c, desc, fallback = coefficients_for_case(ctx.case, ctx.run.coefficients, cache_dir=ctx.cache_dir)
        why = "`[run] coefficients = \"paper\"`" if not fallback else "the BEM table is not available in this version"
        ctx.doc.note(f"Coefficients: {desc} ({why}); errata items 2, 2c.", "warning")
    ctx.memo["coefficients"] = c
    return c


def _check_paper_coefficients(case: Case, run: RunSection) -> None:
    if run.coefficients == "paper":
        from semianalytic.penetration.curve import paper_coefficients

        paper_coefficients(case.require("projectile"))


# --------------------------------------------------------------------------------------
# drag coefficients A(P), B(P), C(P) (Part I eqs. (12)-(14); Figs. 6-8)

# The paper's quoted deep-penetration values (section 2): Abar [m], Bbar (errata items 2, 2a, 2c)
PAPER_QUOTED = {"sphere": (1.5e-3, 0.58), "ogive3": (1.0e-3, 0.11)}


def _paper_key(case: Case) -> str | None:
    p = case.projectile
    if p.nose == "sphere" or (p.nose == "ogive" and p.crh == 0.5):
        return "sphere"
    if p.nose == "ogive" and p.crh == 3.0:
        return "ogive3"
    return None


def _coefficients_preflight(case: Case, run: RunSection) -> None:
    _projectile(case)


def _coefficients_run(ctx: Context) -> None:
    case = ctx.case
    table = _coefficient_table(ctx)
    pr = _projectile(case)
    d, Lh = pr.diameter, pr.nose_length
    area = math.pi * d * d / 4
    doc = ctx.doc
    doc.heading("Drag coefficients A(P), B(P), C(P) (Part I, eqs. (12)-(14); Figs. 6-8)")
    doc.para(
        "BEM solution of the half-space problem (eqs. (20)-(22), mirror method) at "
        f"{len(np.asarray(table.depth))} depths up to {fmt(float(np.max(table.depth)) * MM)} mm, interpolated "
        "smoothly in P. Normalised: Abar = 4A/(pi d^2) [mm], Bbar = 4B/(pi d^2), Cbar = 4C/(pi d^2) (errata item 2). "
        "B in three readings (errata item 2a): `body` (the paper's, default), `literal` (phi'_P at a fixed target "
        "point, as eq. (9) is printed) and `bernoulli` (= dA/dP)."
    )
    P_end = max(3.0 * Lh, pr.length)
    P = np.linspace(0.0, P_end, 240)[1:]
    readings = ("body", "literal", "bernoulli")
    Abar = np.asarray(table.A(P)) / area
    Bbar = {r: np.asarray(table.B(P, reading=r)) / area for r in readings}
    Cbar = np.asarray(table.C(P)) / area
    fig = panels_figure(
        [
            ("Abar [mm]", [Series(P * MM, Abar * MM, "Abar = 4A/(pi d^2)")]),
            ("Bbar", [Series(P * MM, Bbar[r], f"Bbar ({r})", s) for r, s in zip(readings, ("-", "--", ":"))]),
            ("Cbar", [Series(P * MM, Cbar, "Cbar = 4C/(pi d^2)")]),
        ],
        "penetration depth P [mm]",
        f"Coefficients of eq. (11), {case.projectile.nose} nose (cf. Fig. 8); nose length L_h = {fmt(Lh * MM)} mm",
    )
    ctx.figure("fig8_coefficients", fig, "A, B, C against the depth P (Part I, Fig. 8), normalised by pi d^2/4.")

    deep = {r: table.deep_limit(reading=r) for r in readings}
    A8, _, C8 = deep["body"]
    rows = [["Abar [mm]", fmt(A8 / area * MM)], ["Cbar", fmt(C8 / area)]]
    rows += [[f"Bbar ({r})", fmt(deep[r][1] / area)] for r in readings]
    key = _paper_key(case)
    header = ["deep limit (P -> infinity)", "this BEM"]
    if key is not None and abs(d - 7.11e-3) < 1e-6:
        qa, qb = PAPER_QUOTED[key]
        header.append("paper (section 2)")
        rows[0].append(fmt(qa * MM))
        rows[1].append("1.00")
        rows[2].append(fmt(qb))
        rows[3].append("-")
        rows[4].append("-")
    doc.table(header, rows, caption="Deep-penetration values; errata 2c: the paper's spherical-nose Abar is ~6% low.")

    results = {
        "depth_m": np.asarray(table.depth),
        "A_m3": np.asarray(table.A(table.depth)),
        "C_m2": np.asarray(table.C(table.depth)),
        **{f"B_{r}_m2": np.asarray(table.B(table.depth, reading=r)) for r in readings},
        "deep_limit": {"A_m3": A8, "C_m2": C8, **{f"B_{r}_m2": deep[r][1] for r in readings}},
        "A_bar_inf_m": A8 / area,
        "B_bar_inf": {r: deep[r][1] / area for r in readings},
        "C_bar_inf": C8 / area,
    }
    phi_tip = getattr(table, "phi_tip", None)
    if phi_tip is not None:
        depth = np.asarray(table.depth)
        phi = np.asarray(phi_tip(depth) if callable(phi_tip) else phi_tip)
        sel = depth <= P_end
        # phi'_P at the tip following the body (the `body` reading of errata 2a): d phi_tip / dP
        dphi = np.gradient(phi, depth)
        fig = side_by_side_figure(
            [("penetration depth P [mm]", "phi at the tip [mm] (unit speed)",
              [Series(depth[sel] * MM, phi[sel] * MM, "phi_tip (cf. Fig. 6)", "o-")]),
             ("penetration depth P [mm]", "phi'_P at the tip [-]",
              [Series(depth[sel] * MM, dphi[sel], "d(phi_tip)/dP, point A on the body (cf. Fig. 7)", "o-")])],
            f"Potential at the tip and its derivative in P, {case.projectile.nose} nose",
        )
        ctx.figure("fig6_7_phi_tip", fig, "Potential phi at the tip (Part I, Fig. 6) and phi'_P at the tip, point A "
                   "(Fig. 7), against P; phi'_P by differences of the tabulated phi_tip, following the body.")
        results["phi_tip_m"] = phi
    ctx.results["coefficients"] = results


register(Step("coefficients", "Drag coefficients", ("projectile",), ("semianalytic.coefficients.table",),
              _has("projectile"), _coefficients_preflight, _coefficients_run))


# --------------------------------------------------------------------------------------
# penetration (Part I eqs. (11), (24)-(30'); Figs. 9-11, 14-16)


def _setup(ctx: Context, mass: float | None = None):
    from semianalytic.penetration.curve import PenetrationSetup

    key = ("setup", mass)
    if key not in ctx.memo:
        ctx.memo[key] = PenetrationSetup.from_case(ctx.case, coefficients(ctx), mass=mass, require_material=False)
    return ctx.memo[key]


def _penetration_preflight(case: Case, run: RunSection) -> None:
    from semianalytic.penetration.curve import PenetrationSetup

    _check_paper_coefficients(case, run)
    PenetrationSetup.from_case(case, None, require_material=False)  # resistance, mass, material
    if case.section("data") is not None and case.section("data").file is not None:
        from semianalytic.penetration.validation import load_shots

        load_shots(case)


def _reference_velocity(U: np.ndarray) -> float:
    """The striking velocity of Fig. 9: the one closest to 1 km/s."""
    return float(U[np.argmin(np.abs(U - 1000.0))])


def _penetration_run(ctx: Context) -> None:
    from semianalytic.penetration.curve import penetration_curve
    from semianalytic.penetration.elastic import solve_elastic
    from semianalytic.penetration.motion import solve_motion

    case = ctx.case
    setup = _setup(ctx)
    coef = coefficients(ctx)
    U = np.asarray(case.impact.striking_velocities, float)
    elastic = setup.rod is not None
    # one call for the case's velocities and the P(U_s) curve (one integration in P serves all)
    lo, hi = 0.5 * float(U.min()), 1.15 * float(U.max())
    Ug = np.linspace(lo, hi, 60)
    both = penetration_curve(setup, np.concatenate([U, Ug]), elastic=elastic, rtol=RTOL)
    res = {k: np.asarray(v)[: len(U)] for k, v in both.items()}
    curve = {k: np.asarray(v)[len(U):] for k, v in both.items()}
    doc = ctx.doc
    doc.heading("Penetration (Part I, eq. (11); elastic projectile eqs. (24)-(30'))")
    doc.para(
        f"Mass m = {fmt(setup.mass * 1e3)} g, target density rho = {fmt(setup.target_density)} kg/m^3, "
        f"resistance R_t = {fmt(setup.resistance_pa / 1e6)} MPa. Rigid: eq. (11) with u(0) = U_s; quasi-rigid: "
        "u(0) = U_0 of eq. (26); elastic: eq. (30') with the paper's W2 of eq. (29), and with the vibration "
        "energy of the exact rod solution (errata item 5, bounded)."
    )
    if not elastic:
        doc.note("The projectile has no youngs_modulus: only the rigid projectile is computed.")
    rows = []
    for i, u in enumerate(U):
        rows.append([
            fmt(u), fmt(res["depth_rigid_m"][i] * MM), fmt(res["depth_quasi_rigid_m"][i] * MM),
            fmt(res["depth_elastic_m"][i] * MM), fmt(res["depth_elastic_exact_rod_m"][i] * MM),
            fmt(res["time_rigid_s"][i] * US), fmt(res["critical_velocity_m_s"][i]),
            "yes (outside the model)" if res["yields"][i] else "no",
        ])
    doc.table(
        ["U_s [m/s]", "P rigid [mm]", "P quasi-rigid [mm]", "P elastic, paper W2 [mm]", "P elastic, exact rod [mm]",
         "t rigid [us]", "U_sC [m/s]", "yields"],
        rows, caption="Final depth for each striking velocity of the case.",
    )
    if np.any(res["yields"]):
        doc.note("U_s >= U_sC for some velocities: the projectile yields and the rigid/elastic model is outside "
                 "its validity there (eq. (33)).", "warning")

    # time histories (solve_ivp with an event at u = 0), for up to six velocities across the range
    rigid = {}
    shown = U if len(U) <= 6 else U[np.unique(np.linspace(0, len(U) - 1, 6).round().astype(int))]
    for u in shown:
        rigid[float(u)] = solve_motion(coef, setup.mass, setup.target_density, setup.resistance_pa, float(u), rtol=RTOL)
    U9 = _reference_velocity(U)
    if U9 not in rigid:
        rigid[U9] = solve_motion(coef, setup.mass, setup.target_density, setup.resistance_pa, U9, rtol=RTOL)
    ctx.memo["rigid_motion"] = rigid
    r9 = rigid[U9]
    t = np.linspace(0.0, r9.penetration_time, 400)
    series = [Series(t * US, r9.at(t)[1], "1: rigid, u(0) = U_s")]
    if elastic:
        rod, nu = setup.rod, setup.poisson_ratio if setup.poisson_ratio is not None else 0.29
        e_paper = solve_elastic(coef, setup.mass, setup.target_density, setup.resistance_pa, U9, rod,
                                poisson_ratio=nu, w2="paper", rtol=RTOL)
        e_rod = solve_elastic(coef, setup.mass, setup.target_density, setup.resistance_pa, U9, rod,
                              poisson_ratio=nu, w2="exact-rod", rtol=RTOL)
        qr = e_paper.quasi_rigid
        tq = np.linspace(0.0, qr.penetration_time, 400)
        series += [
            Series(tq * US, qr.at(tq)[1], "2: quasi-rigid, u(0) = U_0 (26)", "--"),
            Series(tq * US, e_paper.velocity(tq), "3: elastic, paper's W2 (29), (30')", "-."),
            Series(tq * US, e_rod.velocity(tq), "elastic, exact-rod energy (errata 5)", ":"),
        ]
    fig = line_figure(series, "time t [us]", "penetration velocity u [m/s]",
                      f"u(t) at U_s = {fmt(U9)} m/s (cf. Fig. 9)")
    ctx.figure("fig9_velocity_time", fig, f"Velocity against time at U_s = {fmt(U9)} m/s: rigid (1), quasi-rigid (2), "
               "elastic (3) projectile (Part I, Fig. 9).")

    s_Pt, s_ut, s_uP = [], [], []
    for u, r in rigid.items():
        tt = np.linspace(0.0, r.penetration_time, 300)
        P, uu = r.at(tt)
        lab = f"U_s = {fmt(u)} m/s"
        s_Pt.append(Series(tt * US, P * MM, lab))
        s_ut.append(Series(tt * US, uu, lab))
        s_uP.append(Series(P * MM, uu, lab))
    ctx.figure("fig10_depth_time", line_figure(s_Pt, "time t [us]", "depth P [mm]", "P(t), rigid projectile (cf. Fig. 10)"),
               "Depth against time, rigid projectile (Part I, Fig. 10).")
    fig = side_by_side_figure([("time t [us]", "u [m/s]", s_ut), ("depth P [mm]", "u [m/s]", s_uP)],
                              "u(t) and u(P), rigid projectile (cf. Fig. 11)")
    ctx.figure("fig11_velocity", fig, "Velocity against time and against depth, rigid projectile (Part I, Fig. 11).")

    # P(U_s) curve with data points (Figs. 14-16)
    series = [Series(Ug, curve["depth_rigid_m"] * MM, "1: rigid projectile")]
    if elastic:
        series += [Series(Ug, curve["depth_elastic_m"] * MM, "2: elastic, paper's W2", "--"),
                   Series(Ug, curve["depth_elastic_exact_rod_m"] * MM, "elastic, exact-rod energy", ":")]
    points = []
    data = case.section("data")
    if data is not None and data.file is not None:
        from semianalytic.penetration.validation import load_shots

        shots = load_shots(case)
        if shots:
            points.append(Points(np.array([s.velocity for s in shots]), np.array([s.depth for s in shots]) * MM,
                                 f"experiment ({data.name})", "ks"))
    fig = line_figure(series, "striking velocity U_s [m/s]", "final depth P [mm]",
                      f"Depth against striking velocity (cf. Figs. 14-16); R_t = {fmt(setup.resistance_pa / 1e6)} MPa",
                      points=points)
    U_sC = float(curve["critical_velocity_m_s"][0])
    if np.isfinite(U_sC) and U_sC < hi:
        ax = fig.axes[0]
        ax.axvspan(max(U_sC, lo), hi, color="tab:red", alpha=0.08, lw=0)
        ax.text(hi, ax.get_ylim()[1] * 0.97, "U_s >= U_sC: projectile yields ", color="tab:red", fontsize=8,
                va="top", ha="right")
    ctx.figure("fig14_16_depth_velocity", fig, "Final depth against striking velocity, rigid (1) and elastic (2) "
               "projectile, with the experimental points when the case has data (Part I, Figs. 14-16).")
    out = {k: np.asarray(v) for k, v in res.items()}
    out.update(mass_kg=setup.mass, target_density_kg_m3=setup.target_density, resistance_Pa=setup.resistance_pa,
               fig9_striking_velocity_m_s=U9)
    ctx.results["penetration"] = out


def _penetration_applies(case: Case) -> bool:
    return _has("projectile", "target", "impact")(case) and case.target.resistance is not None


register(Step("penetration", "Penetration", ("projectile", "target", "impact"),
              ("semianalytic.penetration.curve",), _penetration_applies,
              _penetration_preflight, _penetration_run))


# --------------------------------------------------------------------------------------
# critical impact velocity (eqs. (31)-(36)) and the Appendix's inverse problem


def _critical_applies(case: Case) -> bool:
    p, data = case.projectile, case.section("data")
    return (p is not None and case.target is not None and case.target.resistance is not None
            and p.youngs_modulus is not None
            and (p.yield_stress is not None or (data is not None and data.critical_velocity is not None)))


def _critical_preflight(case: Case, run: RunSection) -> None:
    from semianalytic.penetration.curve import PenetrationSetup

    _check_paper_coefficients(case, run)
    p, data = case.require("projectile"), case.section("data")
    if p.youngs_modulus is None:
        raise InputError("projectile.youngs_modulus", "missing: the critical velocity needs E_p (e.g. '210 GPa')")
    if p.yield_stress is None and (data is None or data.critical_velocity is None):
        raise InputError("projectile.yield_stress",
                         "missing: give Y_p (e.g. '1.5 GPa') or a measured [data] critical_velocity")
    PenetrationSetup.from_case(case, None, require_material=False)


def _critical_run(ctx: Context) -> None:
    from semianalytic.penetration import critical as crit

    case = ctx.case
    setup = _setup(ctx)
    inputs = setup.critical_inputs()
    area = math.pi * inputs.diameter**2 / 4
    doc = ctx.doc
    doc.heading("Critical impact velocity (Part I, eqs. (31)-(36))")
    rows = [
        ["c_0 = sqrt(E_p/rho_p) [m/s]", fmt(inputs.c0)],
        ["Abar, Bbar, Cbar (deep limit)", f"{fmt(inputs.A / area * MM)} mm, {fmt(inputs.B / area)}, {fmt(inputs.C / area)}"],
        ["R_t [MPa]", fmt(inputs.resistance_pa / 1e6)],
        ["buckling factor phi (lambda = 4L/d)", fmt(setup.phi)],
    ]
    out = {"c0_m_s": inputs.c0, "resistance_Pa": inputs.resistance_pa, "phi": setup.phi}
    p = case.projectile
    if p.yield_stress is not None:
        U_sC = crit.critical_velocity(p.yield_stress, inputs, setup.phi)
        Yb, Rb = crit.reduced_strengths(setup.phi * p.yield_stress, inputs.resistance_pa, A=inputs.A, C=inputs.C,
                                        mass=inputs.mass, diameter=inputs.diameter, target_density=inputs.target_density)
        rows += [["Y_p [MPa]", fmt(p.yield_stress / 1e6)], ["reduced strengths Ybar_p, Rbar_t (35) [MPa]",
                 f"{fmt(Yb / 1e6)}, {fmt(Rb / 1e6)}"], ["U_sC (eqs. (33)/(36)) [m/s]", fmt(U_sC)]]
        out.update(yield_stress_Pa=p.yield_stress, critical_velocity_m_s=U_sC, reduced_yield_Pa=Yb, reduced_resistance_Pa=Rb)
    data = case.section("data")
    if data is not None and data.critical_velocity is not None:
        Y = crit.yield_stress_from_critical_velocity(data.critical_velocity, inputs, setup.phi)
        rows += [["measured U_sC [m/s]", fmt(data.critical_velocity)],
                 ["dynamic yield stress Y_p from U_sC (inverse of (36)) [MPa]", fmt(Y / 1e6)]]
        out.update(measured_critical_velocity_m_s=data.critical_velocity, yield_stress_from_critical_velocity_Pa=Y)
    doc.table(["quantity", "value"], rows)
    if data is not None and data.critical_velocity is not None:
        how = ("this run uses those coefficients, with R_t from eq. (16) unrounded" if ctx.run.coefficients == "paper"
               else "set `[run] coefficients = \"paper\"` to use those coefficients instead of the BEM table")
        doc.para("The Appendix's printed inputs (Abar = 1.5 mm, Bbar = 0.58, Cbar = 1.00, R_t = 1455 MPa) give "
                 f"Y_p = 2146 MPa, not the printed 2135 (errata item 3); {how}.")
    ctx.results["critical_velocity"] = out


register(Step("critical_velocity", "Critical velocity", ("projectile", "target"), ("semianalytic.penetration.critical",),
              _critical_applies, _critical_preflight, _critical_run))


# --------------------------------------------------------------------------------------
# validation against measured depths ([data] file)


def _validation_applies(case: Case) -> bool:
    data = case.section("data")
    return (case.projectile is not None and case.target is not None and case.target.resistance is not None
            and data is not None and data.file is not None)


def _validation_preflight(case: Case, run: RunSection) -> None:
    from semianalytic.penetration.curve import PenetrationSetup
    from semianalytic.penetration.validation import load_shots

    _check_paper_coefficients(case, run)
    if case.require("data").file is None:
        raise InputError("data.file", "missing: validation needs a CSV of shots")
    PenetrationSetup.from_case(case, None)
    if not load_shots(case):
        raise InputError("data.select", "no shot of the data file is left after 'select'")


def _validation_run(ctx: Context) -> None:
    from semianalytic.penetration.validation import MODEL_LABELS, error_statistics, load_shots, predict_shots

    case = ctx.case
    shots = load_shots(case)
    rows = predict_shots(case, coefficients(ctx), shots)
    stats = error_statistics(rows)
    data = case.section("data")
    doc = ctx.doc
    doc.heading(f"Validation against measured depths ({data.name})")
    if data.source:
        doc.para(f"Data: {data.source}.")
    models = [k for k in MODEL_LABELS if k in stats]
    doc.table(
        ["shot", "U_s [m/s]", "measured [mm]"] + [MODEL_LABELS[k] + " [mm]" for k in models] + ["yields"],
        [[r["shot"], fmt(r["velocity_m_s"]), fmt(r["measured_m"] * MM)] + [fmt(r[k] * MM) for k in models]
         + ["yes" if r["yields"] else "no"] for r in rows],
        caption="Predicted and measured final depth of every shot (each shot's own mass when the data give it).",
    )
    doc.table(
        ["model", "n", "mean error", "mean |error|", "max |error|", "rms"],
        [[MODEL_LABELS[k], str(stats[k]["n"]), f"{stats[k]['mean']:+.1%}", f"{stats[k]['mean_abs']:.1%}",
          f"{stats[k]['max_abs']:.1%}", f"{stats[k]['rms']:.1%}"] for k in models],
        caption="Relative error (predicted - measured)/measured per model.",
    )
    meas = np.array([r["measured_m"] for r in rows]) * MM
    lim = (0.0, 1.1 * max(meas.max(), max(max(r[k] for r in rows) for k in models) * MM))
    series = [Series(np.array(lim), np.array(lim), "predicted = measured", "k-")]
    pts = [Points(meas, np.array([r[k] for r in rows]) * MM, MODEL_LABELS[k], m)
           for k, m in zip(models, ("o", "s", "^", "v", "D", "x"))]
    fig = line_figure(series, "measured depth [mm]", "predicted depth [mm]", "Predicted against measured depth", points=pts)
    ctx.figure("validation_parity", fig, "Predicted against measured final depth, per model.")
    ctx.results["validation"] = {"shots": rows, "statistics": stats}


register(Step("validation", "Validation", ("projectile", "target", "data"), ("semianalytic.penetration.validation",),
              _validation_applies, _validation_preflight, _validation_run))
