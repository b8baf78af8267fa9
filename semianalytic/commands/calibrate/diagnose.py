"""Why does the physically consistent model over-predict the rigid shots? (issue 12, item 5)

For the case's shots and those of the transfer cases (same target), the relative error
(predicted - measured)/measured of the quasi-rigid and exact-rod elastic models under one
change at a time, none fitted to the shots:

* the B reading (errata item 2a): ``body`` (default), ``literal`` (eq. (9) as printed);
* W1 of eq. (28): neglected (default), ``bound``, ``static``;
* the contact region: the BEM table from first contact (default) against the paper's
  constant deep-penetration coefficients from the surface on;
* the strength: the case's Y against the data authors' quasi-static 276 MPa;

and the velocity trend of the error (least-squares slope per km/s), which separates a wrong
static resistance (a constant relative shift at high velocity) from a wrong dynamic term
(an error growing with U).  Also the coefficient of rho U^2 in the deep-penetration
nose pressure of each model: Part I B/(2 pi a^2) (per reading), Forrestal's C N_2 with the
data authors' cavity-expansion constants, and the incompressible cavity expansion 3/2 N_2.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from semianalytic.errors import InputError

__all__ = ["diagnose"]

MODELS = ("quasi_rigid", "elastic_exact_rod")


def _errors(case, coefficients, w1="neglect", resistance_pa=None):
    from semianalytic.penetration.validation import load_shots, predict_shots

    shots = load_shots(case)
    if resistance_pa is None:
        rows = predict_shots(case, coefficients, shots, w1=w1)
    else:
        from semianalytic.penetration.curve import PenetrationSetup, penetration_curve

        rows = []
        for s in shots:
            setup = dataclasses.replace(PenetrationSetup.from_case(case, coefficients, mass=s.mass), resistance_pa=resistance_pa)
            res = penetration_curve(setup, [s.velocity], w1=w1)
            rows.append({"velocity_m_s": s.velocity, "measured_m": s.depth,
                         **{m: float(res[f"depth_{m}_m"][0]) for m in MODELS}})
    U = np.array([r["velocity_m_s"] for r in rows])
    return U, {m: np.array([(r[m] - r["measured_m"]) / r["measured_m"] for r in rows]) for m in MODELS}


def _summary(parts):
    """parts: [(U, {model: e})] per case -> per model: per-case means, pooled mean, mean |e|, slope."""
    out = {}
    for m in MODELS:
        U = np.concatenate([p[0] for p in parts])
        e = np.concatenate([p[1][m] for p in parts])
        out[m] = {
            "per_case_mean": [float(np.mean(p[1][m])) for p in parts],
            "mean": float(np.mean(e)),
            "mean_abs": float(np.mean(np.abs(e))),
            "slope_per_km_s": float(np.polyfit(U / 1e3, e, 1)[0]),
            "n": int(e.size),
        }
    return out


def diagnose(cases_with_coefficients, paper_coefficients) -> dict:
    """The study of the module docstring.  ``cases_with_coefficients``: [(case, BEM table)];
    ``paper_coefficients``: [the paper's constant coefficients per case] (same order)."""
    from semianalytic.geometry import nose_from_section
    from semianalytic.penetration.motion import deep_coefficients
    from semianalytic.penetration.peers import nose_factors
    from semianalytic.penetration.resistance import elastic_plastic_resistance, resistance_from_case

    variants = []

    def add(label, what, fn):
        try:
            parts = [fn(case, coef, paper) for (case, coef), paper in zip(cases_with_coefficients, paper_coefficients)]
        except (ValueError, ArithmeticError, InputError) as exc:  # a variant the models cannot evaluate
            variants.append({"label": label, "what": what, "error": str(exc)})
            return
        variants.append({"label": label, "what": what, "models": _summary(parts)})

    add("baseline", "BEM table, B reading 'body', W1 neglected, the case's Y", lambda c, t, p: _errors(c, t))
    add("B literal", "B reading 'literal' (eq. (9) as printed, about twice 'body')",
        lambda c, t, p: _errors(c, t.with_reading("literal")))
    add("W1 bound", "W1 of eq. (28) with p_l = sigma_0", lambda c, t, p: _errors(c, t, w1="bound"))
    add("W1 static", "W1 of eq. (28) with p_l = R_t", lambda c, t, p: _errors(c, t, w1="static"))
    add("no contact region", "the paper's constant deep Abar, Bbar, Cbar from the surface on",
        lambda c, t, p: _errors(c, p))

    def y276(case, table, paper):
        res = resistance_from_case(case)
        if res.name != "elastic-plastic":
            raise InputError("target.resistance.model", "the Y = 276 MPa variant needs the elastic-plastic model")
        return _errors(case, table, resistance_pa=elastic_plastic_resistance(276e6, res.youngs_modulus, res.poisson_ratio))

    add("Y = 276 MPa", "the data authors' quasi-static yield stress in eq. (16)", y276)
    case, table = cases_with_coefficients[0]
    psec = case.require("projectile")
    area = math.pi * psec.diameter**2 / 4
    N1, N2 = nose_factors(nose_from_section(psec))
    data = case.section("data")
    dyn = {
        "Part I, B reading 'body': B/(2 pi a^2)": deep_coefficients(table)[1] / area / 2,
        "Part I, B reading 'literal'": deep_coefficients(table.with_reading("literal"))[1] / area / 2,
        "cavity expansion, incompressible: 3/2 N_2": 1.5 * N2,
    }
    if data is not None and data.cavity_C is not None:
        dyn["Forrestal, the data authors' constants: C N_2"] = data.cavity_C * N2
    return {"cases": [c.title for c, _ in cases_with_coefficients], "variants": variants,
            "dynamic_coefficients": dyn, "nose_factor_N2": N2}


def reading_cross_validation(case, table, transfer, models=MODELS, reading: str = "literal", progress: bool = False) -> dict:
    """Calibration, leave-one-out and transfer split of ``models`` with the B reading
    ``reading`` (the other inputs unchanged): whether the reading chosen on the case's shots
    also predicts the transfer cases' shots, which it was not chosen on."""
    from semianalytic.commands.calibrate.evaluate import calibrate_case, cross_validate

    res = calibrate_case(case, table.with_reading(reading), models=list(models))
    cv = cross_validate(case, table.with_reading(reading), res, [(c, t.with_reading(reading)) for c, t in transfer],
                        progress=progress)
    return {"reading": reading, "models": list(models), "cross_validation": cv,
            "posterior_summary": {m: res["posterior"]["models"][m]["summary"] for m in models}}
