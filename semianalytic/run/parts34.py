"""Part III and Part IV steps of a ``run``: the ballistic limit velocity (Part IV, through
:func:`semianalytic.commands.ballistic_limit.evaluate.evaluate_case`) and the theoretical strength of
nanoparticles (Part III, through :mod:`semianalytic.nanostrength`)."""

from __future__ import annotations

import math

import numpy as np

from semianalytic.case import Case
from semianalytic.report.document import fmt
from semianalytic.report.figures import Points, Series, line_figure
from semianalytic.run.case import RunSection
from semianalytic.run.context import Context
from semianalytic.run.registry import Step, _has, register

# --------------------------------------------------------------------------------------
# Part IV: ballistic limit velocity

_BL_COLUMNS = [
    ("V_R1_m_s", "V(R1), eq. (5)"),
    ("V_R2_m_s", "V(R2), eq. (5)"),
    ("V_R3_m_s", "V(R3), eq. (5)"),
    ("V_eq7_m_s", "V, eq. (7)"),
    ("V_eq8_m_s", "V, eq. (8)"),
    ("V_eq9_m_s", "V, eq. (9)"),
]


def _bl_evaluate(case: Case) -> dict:
    from semianalytic.commands.ballistic_limit.evaluate import evaluate_case

    return evaluate_case(case)


def _bl_preflight(case: Case, run: RunSection) -> None:
    _bl_evaluate(case)  # reads the shot table, checks every shot


def _bl_run(ctx: Context) -> None:
    res = _bl_evaluate(ctx.case)
    rows = res["rows"]
    doc = ctx.doc
    doc.heading("Ballistic limit velocity (Part IV)")
    c = res["constants"]
    doc.para(
        f"Theory: eq. (5) with R(1) = HM delta_H ({res['hardness_rule']} hardness), R(2) = R(3) delta_H, R(3) of "
        f"eq. (6). Empirical: eqs. (7)-(9) with P = {res['areal_mass_rule']} (errata 26), C1 = "
        f"{c['C1_m2_per_s2']:.4g} m^2/s^2, C2 = {c['C2_m2_per_s2_per_GPa']:.4g} (m/s)^2/GPa, "
        f"C3 = {c['C3_m2_per_s2']:.4g} m^2/s^2."
    )
    cols = [k for k, _ in _BL_COLUMNS if any(r.get(k) is not None for r in rows)]
    labels = dict(_BL_COLUMNS)

    def cell(v):
        return "-" if v is None or not math.isfinite(v) else f"{v:.0f}"

    doc.table(
        ["shot", "measured V_cr [m/s]"] + [labels[k] + " [m/s]" for k in cols],
        [[r["name"], r.get("measured_qualifier", "") + cell(r.get("measured_V_m_s"))] + [cell(r.get(k)) for k in cols]
         for r in rows],
        caption="Ballistic limit per shot.",
    )
    # measured values given as bounds ("<280") are shown but not used in the error statistics
    meas = [r for r in rows if r.get("measured_V_m_s") is not None and not r.get("measured_qualifier")]
    if meas:
        m = np.array([r["measured_V_m_s"] for r in meas])
        pts, stats = [], []
        for k, mk in zip(cols, ("o", "s", "^", "v", "D", "x")):
            pred = np.array([r.get(k) if r.get(k) is not None else np.nan for r in meas], float)
            ok = np.isfinite(pred)
            if ok.any():
                pts.append(Points(m[ok], pred[ok], labels[k], mk))
                e = (pred[ok] - m[ok]) / m[ok]
                stats.append([labels[k], str(int(ok.sum())), f"{e.mean():+.1%}", f"{np.abs(e).mean():.1%}",
                              f"{np.abs(e).max():.1%}"])
        doc.table(["formula", "n", "mean error", "mean |error|", "max |error|"], stats,
                  caption="Relative error (computed - measured)/measured.")
        hi = 1.1 * max(m.max(), max(float(np.nanmax(p.y)) for p in pts))
        fig = line_figure([Series(np.array([0, hi]), np.array([0, hi]), "computed = measured", "k-")],
                          "measured V_cr [m/s]", "computed V_cr [m/s]", "Ballistic limit: computed against measured",
                          points=pts)
        ctx.figure("ballistic_limit_parity", fig, "Computed against measured ballistic limit velocity (Part IV).")
    crit = [(r["name"], cc) for r in rows for cc in r.get("critical", [])]
    if crit:
        doc.table(
            ["shot", "V_p [m/s]", "(rho h)_cr [g/cm^2]", "h_cr [mm]"],
            [[n, fmt(cc["V_p_m_s"]), fmt(cc["rhoh_cr_kg_m2"] / 10), fmt(cc.get("h_cr_m") and cc["h_cr_m"] * 1e3)]
             for n, cc in crit],
            caption="Critical areal density and thickness (Table 4; eq. (9), P = rho_p L_p).",
        )
    ctx.results["ballistic_limit"] = res


register(Step("ballistic_limit", "Ballistic limit", ("ballistic_limit",), ("semianalytic.commands.ballistic_limit.evaluate",),
              _has("ballistic_limit"), _bl_preflight, _bl_run))


# --------------------------------------------------------------------------------------
# Part III: theoretical strength of diamond-like crystals and nanoparticles


def _nano_preflight(case: Case, run: RunSection) -> None:
    section = case.require("nanostrength")
    section.crystals()
    section.studies()


def _nano_run(ctx: Context) -> None:
    from semianalytic.commands.nanostrength.report import build_report
    from semianalytic.sections.nanostrength import analyse_section

    section = ctx.case.require("nanostrength")
    a = analyse_section(section)
    o = a.options
    doc = ctx.doc
    doc.heading("Theoretical strength of diamond-like crystals and nanoparticles (Part III)")
    doc.para(f"Interplanar law `{o['law']}` calibrated to Tables 1-2, stress measure `{o['stress_measure']}`, "
             f"odd-plate surface ratio {o['odd_surface_ratio']:g} (errata item 21: the paper's pseudo-potential is "
             "not given, so the bulk law is calibrated; see reports/part3_nanostrength.md for the full discussion).")
    doc.table(
        ["crystal", "sigma1 [GPa] (Table 2)", "-e* (Table 2)", "E [GPa] (Table 2)", "sigma2 [GPa] (Table 2)",
         "e** (Table 2)"],
        [[name, f"{fmt(r.bulk.sigma_c / 1e9)} ({fmt(r.crystal.sigma_c / 1e9)})", f"{fmt(r.bulk.e_c)} ({fmt(r.crystal.e_c)})",
          f"{fmt(r.law.youngs_modulus / 1e9)} ({fmt(r.crystal.E / 1e9)})",
          f"{fmt(r.bulk.sigma_t / 1e9)} ({fmt(r.crystal.sigma_t / 1e9)})", f"{fmt(r.bulk.e_t)} ({fmt(r.crystal.e_t)})"]
         for name, r in a.crystals.items()],
        caption="Bulk strength from eq. (14) on the calibrated law, with Table 2 in brackets.",
    )
    key = f"{o['surface_energy']}/{o['deformation_energy'] if o['surface_energy'] == 'eq16' else 'law'}"
    rows = []
    for name, r in a.crystals.items():
        ft, fc = r.fracture.get(f"{key}/tension"), r.fracture.get(f"{key}/compression")
        if ft is not None and fc is not None:
            rows.append([name, fmt(ft.Y1c), fmt(fc.Y1c), fmt(ft.K1c / 1e6), fmt(fc.K1c / 1e6)])
    if rows:
        doc.table(["crystal", "Y_1c I [N/m]", "Y_1c II [N/m]", "K_1c I [MPa m^1/2]", "K_1c II [MPa m^1/2]"], rows,
                  caption=f"Fracture quantities (Table 3; eqs. (15)-(16), {key}); I tension, II compression.")
    for s in a.studies:
        shown = s.rows[:40]
        cmp_ = s.spec.compare is not None
        doc.table(
            ["crystal", "basis", "l", "m = n", "i", "Phi_i/Phi_0", "sigma1 [GPa]", "sigma2 [GPa]"]
            + (["printed sigma1 / sigma2 [GPa]", "difference"] if cmp_ else []),
            [[r.material, r.geometry.basis, "inf" if r.geometry.l is None else str(r.geometry.l),
              "inf" if r.geometry.m is None else str(r.geometry.m), "-" if r.geometry.i is None else str(r.geometry.i),
              f"{r.factor:.6f}", fmt(r.strength.sigma_c / 1e9), fmt(r.strength.sigma_t / 1e9)]
             + ([f"{r.printed[0]:g} / {r.printed[1]:g}",
                 "{:+.2%} / {:+.2%}".format(*r.differences())] if cmp_ and r.printed is not None else
                (["-", "-"] if cmp_ else []))
             for r in shown],
            caption=f"Study `{s.spec.name}`: {s.spec.title}" + (f" (first 40 of {len(s.rows)} rows)" if len(s.rows) > 40 else ""),
        )
    _, figs = build_report(a, case_path=str(ctx.case.path), stem="part3", elapsed=0.0, command="run")
    for name, blob in figs.items():
        ctx.png(name.removesuffix(".png"), blob, f"Part III: `{name}` (see reports/part3_nanostrength.md for its discussion).")
    ctx.results["nanostrength"] = a.to_json()


register(Step("nanostrength", "Theoretical strength", ("nanostrength",), ("semianalytic.nanostrength.analysis",),
              _has("nanostrength"), _nano_preflight, _nano_run))
