"""All Part I results of one case for the ``penetrate`` command: final depth and time of the
rigid, quasi-rigid and elastic projectiles (eq. (11); eqs. (26), (29)/(30'); errata item 5),
the critical impact velocity U_sC (eqs. (33)/(36)), the peer models and, with a ``[data]``
section, the dynamic yield stress from a measured U_sC (Appendix) and the measured depths.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from semianalytic.errors import InputError

__all__ = ["evaluate_case", "contact_summary", "one_verdict"]

PART1_DEPTH_KEYS = {"rigid": "depth_rigid_m", "quasi_rigid": "depth_quasi_rigid_m", "elastic": "depth_elastic_m",
                    "elastic_exact_rod": "depth_elastic_exact_rod_m"}


def one_verdict(result: dict) -> dict:
    """One verdict per striking velocity (issue 36 item 7), in place: ``regime`` is the verdict
    and every diagnostic follows it.

    * With a regimes posterior (``regime_probability``), the verdict is the posterior's most
      probable regime where its model holds, else the rule's label; the rule's labels stay in
      ``regime_rule_labels`` and ``regime_source`` says which gave each verdict ("posterior" or
      "rule").  Where the posterior's verdict is rigid or eroding, ``depth_m`` is that regime's
      depth (the Part I model, the eroding rod).
    * ``yields`` is ``regime != "rigid"`` (the projectile yields exactly where the verdict says it
      is no longer rigid); Part I's own criterion U_s >= U_sC (eqs. (33)/(36)), which the
      verdict's rule need not use, is kept as the diagnostic ``part1_critical_exceeded``.
    * ``valid``: a rigid-projectile model is valid only where the verdict is rigid, the eroding
      rod never where it is rigid.
    Returns ``result`` with note lines added to ``warnings`` where a diagnostic differs from the
    verdict."""
    regime = list(result.get("regime_rule_labels", result["regime"]))  # idempotent: a second call starts again
    U = result["striking_velocity_m_s"]
    n = len(regime)
    source = ["rule"] * n
    notes = []
    prob = result.get("regime_probability")
    if prob:
        result["regime_rule_labels"] = list(regime)
        names = list(prob)
        part1 = result.get(PART1_DEPTH_KEYS.get(result.get("part1_model"), ""), [None] * n)
        depth = list(result["depth_m"])
        for i in range(n):
            p = [prob[k][i] for k in names]
            if all(x is not None and math.isfinite(x) for x in p):
                verdict = names[max(range(len(p)), key=lambda k: p[k])]
                source[i] = "posterior"
                if verdict != regime[i]:
                    regime[i] = verdict
                    if verdict == "rigid":
                        depth[i] = part1[i]
                    elif verdict == "eroding":
                        depth[i] = result["depth_eroding_m"][i]
        moved = [f"{U[i]:.0f}" for i in range(n) if regime[i] != result["regime_rule_labels"][i]]
        if moved:
            notes.append(f"note: regime: the posterior's most probable regime is the verdict; it differs from the "
                         f"{result.get('regime_rule')} rule's label at U_s = {', '.join(moved)} m/s (regime_rule_labels)")
        result["depth_m"] = depth
    result["regime"] = regime
    result["regime_source"] = source
    usc = [bool(x) for x in result.get("part1_critical_exceeded", result.get("yields", [False] * n))]
    result["part1_critical_exceeded"] = usc
    result["yields"] = [r != "rigid" for r in regime]
    odd = [f"{U[i]:.0f}" for i in range(n) if usc[i] and regime[i] == "rigid"]
    if odd and result.get("regime_rule") != "nose_length":
        uc = result.get("critical_velocity_m_s", [None])[0]
        notes.append(f"note: diagnostic: U_s >= Part I's U_sC = {uc:.0f} m/s (eqs. (33)/(36)) at U_s = {', '.join(odd)} "
                     f"m/s, where the verdict is rigid: the {result.get('regime_rule')} rule does not use U_sC "
                     "(part1_critical_exceeded)")
    valid = result.get("valid") or {}
    for k, v in valid.items():
        if k in ("regime_aware",):
            continue
        if k == "eroding":
            valid[k] = [bool(x) and r != "rigid" for x, r in zip(v, regime)]
        else:
            valid[k] = [bool(x) and r == "rigid" for x, r in zip(v, regime)]
    result["warnings"] = [*(w for w in result.get("warnings", []) if not w.startswith(_VERDICT_NOTES)), *notes]
    return result


_VERDICT_NOTES = ("note: regime: the posterior's", "note: diagnostic: U_s >= Part I's")


def contact_summary(setup, U, profile=None) -> dict:
    """``contact`` (the mode) and ``separation_onset_m``: per striking velocity, the first depth
    at which the full-contact pressure of eq. (9) would separate (eq. (15)), or None.
    ``profile``: the full-contact depth profile covering U, if at hand."""
    from semianalytic.penetration.motion import DepthProfile, depth_profile, separation_onset

    coef = setup.coefficients
    if not hasattr(coef, "nodes"):
        return {"contact": setup.contact, "separation_onset_m": [None] * len(U)}
    prof = profile if isinstance(profile, DepthProfile) else depth_profile(
        coef, setup.mass, setup.target_density, setup.resistance_pa, float(np.max(U)))
    return {"contact": setup.contact,
            "separation_onset_m": separation_onset(coef, setup.mass, setup.target_density, setup.resistance_pa, prof, U)}


def evaluate_case(case, coefficients, *, w1: str = "neglect", velocities=None, part1_model: str | None = None,
                  regime_rule: str | None = None) -> dict:
    """All results of one case as a JSON-able dict (SI units in the keys).  The regime-aware
    keys (regime, depth_m, depth_eroding_m, transition_velocity_m_s, valid, warnings) come from
    :func:`.regime_setup.regime_prediction` with the Part I model ``part1_model``."""
    from semianalytic.penetration import critical as crit
    from semianalytic.penetration.curve import PenetrationSetup, penetration_curve
    from semianalytic.penetration.motion import deep_coefficients
    from semianalytic.penetration.resistance import resistance_from_case
    from semianalytic.penetration.validation import error_statistics, load_shots, peer_depths, predict_shots, rigid_regime_shots

    setup = PenetrationSetup.from_case(case, coefficients, require_material=False)
    if setup.rod is None:
        raise InputError("projectile.youngs_modulus", "missing: the elastic projectile needs it (e.g. '210 GPa')")
    data = case.section("data")
    out: dict = {"case": str(case.path) if case.path else case.title, "title": case.title}
    if data is not None and data.critical_velocity is not None:
        phi = setup.phi
        psec = case.projectile
        if psec.buckling == "johnson-euler":
            lam = crit.slenderness(setup.rod.length, setup.rod.diameter)
            phi = lambda Y: float(crit.johnson_euler_phi(lam, psec.youngs_modulus, Y))  # noqa: E731
        Y_inv = crit.yield_stress_from_critical_velocity(data.critical_velocity, setup.critical_inputs(), phi)
        out["measured_critical_velocity_m_s"] = data.critical_velocity
        out["yield_stress_from_critical_velocity_Pa"] = Y_inv
        if setup.yield_stress is None:
            setup = dataclasses.replace(setup, yield_stress=Y_inv)
            if psec.buckling != "none":
                setup = dataclasses.replace(setup, phi=phi(Y_inv) if callable(phi) else phi)
    if setup.yield_stress is None:
        raise InputError("projectile.yield_stress", "missing: U_sC needs the dynamic yield stress (e.g. '1.5 GPa') "
                         "or a measured [data] critical_velocity")
    U = np.asarray(case.impact.striking_velocities if velocities is None else velocities, float)
    from semianalytic.penetration.curve import curve_profile

    prof = curve_profile(setup, float(np.max(U)))  # one integration of eq. (11) in P for the curve and its estimate
    res = penetration_curve(setup, U, w1=w1, profile=prof)
    A, B, C = deep_coefficients(coefficients)
    area = math.pi * setup.rod.diameter**2 / 4
    resistance = resistance_from_case(case)
    out.update(
        {
            "resistance_model": resistance.name,
            "resistance_equation": resistance.equation,
            "resistance_Pa": setup.resistance_pa,
            "mass_kg": setup.mass,
            "length_m": setup.rod.length,
            "yield_stress_Pa": setup.yield_stress,
            "buckling_factor": setup.phi,
            "deep_A_bar_m": A / area,
            "deep_B_bar": B / area,
            "deep_C_bar": C / area,
            "w1": w1,
        }
    )
    for key, val in res.items():
        out[key] = np.asarray(val).tolist()
    from semianalytic.penetration.accuracy import depth_error_estimate

    out["depth_error_estimate_m"] = depth_error_estimate(setup, U, res, w1=w1, profile=prof)
    out.update(contact_summary(setup, U, prof))
    pe = peer_depths(case, setup, U)
    out["depth_forrestal_m"] = pe["forrestal"].tolist()
    out["depth_chen_li_m"] = pe["chen_li"].tolist()
    from semianalytic.penetration.regime_setup import DEFAULT_PART1_MODEL, DEFAULT_REGIME_RULE, regime_prediction

    rule = regime_rule or DEFAULT_REGIME_RULE

    out.update(regime_prediction(case, setup, U, res, pe, part1_model=part1_model or DEFAULT_PART1_MODEL, rule=rule))
    if not np.all(res["converged"]):  # never silent: the CLI prints every warning line on stderr
        bad = [f"{u:g}" for u, ok in zip(U, res["converged"]) if not ok]
        out["warnings"] = [*out.get("warnings", []), f"eq. (11): an iterative solve did not converge at "
                           f"{len(bad)} striking velocities ({', '.join(bad[:3])} m/s ...); see 'converged'"]
    one_verdict(out)
    if data is not None and data.file is not None:
        rows = predict_shots(case, coefficients, rigid_regime_shots(case, load_shots(case)), w1=w1)
        out["validation"] = {"shots": rows, "statistics": error_statistics(rows)}
        if data.response_column:  # every shot: recorded against predicted regime (issue 12, item 4)
            from semianalytic.penetration.regime_setup import regime_validation

            rv = regime_validation(case, coefficients, part1_model=part1_model or DEFAULT_PART1_MODEL, velocities=U, loo=False, w1=w1, rule=rule)  # noqa: E501
            out["validation"]["regimes"] = {k: rv[k] for k in ("rows", "confusion", "recorded", "yield_check", "erosion_check", "errors")}
    return out
