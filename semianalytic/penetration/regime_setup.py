"""The regime-aware prediction of a case (the glue between the case and :mod:`.regime`).

* :func:`eroding_inputs`: the eroding rod's SI inputs from ``[projectile]`` and
  ``[target.resistance]``, with the stated defaults: ``[projectile] dynamic_yield_stress``
  (Y_p of the eroding rod) defaults to ``[projectile] yield_stress`` (the Y_p of U_sC, eqs.
  (33)/(36)); ``[target.resistance] eroding_resistance`` (R_t of the eroding rod) defaults to
  the R_t of the case's resistance model at the projectile's diameter (the R_t of Part I).
* :func:`regime_prediction`: per striking velocity the regime, the regime-aware depth, the
  eroding depth, the transition velocities, per model the validity (``valid``) and the
  warnings ``penetrate`` prints on stderr.
* :func:`predict_regimes`, :func:`confusion`, :func:`leave_one_out_eroding`: the shots of a
  ``[data]`` file (all recorded responses) against the predicted regimes and the eroding depths.

The data's responses map onto the regimes by :data:`RESPONSE_REGIME`: rigid -> rigid; curved,
exited, turned_around, broken -> deforming (the projectile yielded, bent or broke but did not
erode); eroded, broken_eroding -> eroding.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from semianalytic.errors import InputError
from semianalytic.penetration import peers
from semianalytic.penetration import regime as rg
from semianalytic.penetration.nose_load import NOSE_LOADS, nose_load_of

__all__ = [
    "RESPONSE_REGIME",
    "PART1_MODELS",
    "DEFAULT_PART1_MODEL",
    "VALIDITY_MODELS",
    "ErodingInputs",
    "eroding_inputs",
    "regime_prediction",
    "predict_regimes",
    "confusion",
    "leave_one_out_eroding",
]

from semianalytic.penetration.validation import RESPONSE_REGIME  # noqa: E402  (the data labels, defined with the data reader)

PART1_MODELS = ("rigid", "quasi_rigid", "elastic", "elastic_exact_rod")
DEFAULT_PART1_MODEL = "elastic_exact_rod"  # the physically consistent Part I projectile (errata item 5)
# models whose depths carry a validity flag: the rigid-projectile family and the eroding rod
VALIDITY_MODELS = (*PART1_MODELS, "forrestal", "chen_li", "eroding")
_LABEL = {
    "rigid": "rigid projectile (eq. (11))",
    "quasi_rigid": "quasi-rigid projectile (eqs. (11)+(26))",
    "elastic": "elastic projectile, paper's W2 (eqs. (29), (30'))",
    "elastic_exact_rod": "elastic projectile, exact-rod W2 (errata 5)",
    "forrestal": "Forrestal (rigid projectile, cavity expansion)",
    "chen_li": "Chen & Li (rigid projectile)",
    "eroding": "eroding rod (Alekseevskii-Tate)",
}


@dataclass(frozen=True)
class ErodingInputs:
    """SI inputs of :func:`semianalytic.penetration.regime.eroding_depth` (mass per shot)."""

    length: float
    nose_length: float
    diameter: float
    density: float
    target_density: float
    target_resistance: float
    rod_strength: float
    defaults: tuple[str, ...] = ()

    def kwargs(self, **override) -> dict:
        d = dict(length=self.length, nose_length=self.nose_length, diameter=self.diameter, density=self.density,
                 target_density=self.target_density, target_resistance=self.target_resistance,
                 rod_strength=self.rod_strength)
        d.update(override)
        return d


def eroding_inputs(case, setup) -> ErodingInputs:
    """The eroding rod of a case (defaults in the module docstring; ``defaults`` says which were used)."""
    from semianalytic.geometry import nose_from_section, projectile_from_section

    psec = case.require("projectile")
    projectile = projectile_from_section(psec)
    nose = nose_from_section(psec)
    density = psec.density if psec.density is not None else setup.mass / projectile.volume()
    used = []
    Y_p = psec.dynamic_yield_stress
    if Y_p is None:
        Y_p = setup.yield_stress
        if Y_p is None:
            raise InputError("projectile.dynamic_yield_stress", "missing: the eroding rod needs its dynamic yield stress "
                                                                "(e.g. '1.6 GPa'; default: projectile.yield_stress)")
        used.append(f"projectile.dynamic_yield_stress not given: the eroding rod uses Y_p = projectile.yield_stress "
                    f"= {Y_p / 1e6:.0f} MPa (default)")
    R_t = getattr(case.target.resistance, "eroding_resistance", None)
    if R_t is None:
        R_t = setup.resistance_pa
        used.append(f"target.resistance.eroding_resistance not given: the eroding rod uses the Part I R_t = "
                    f"{R_t / 1e6:.0f} MPa (default)")
    if not nose.length < projectile.length:
        raise InputError("projectile.length", f"the rod ({projectile.length * 1e3:.4g} mm: shank_length + nose) must "
                                              f"be longer than its nose ({nose.length * 1e3:.4g} mm); give a shank_length > 0")
    return ErodingInputs(float(projectile.length), float(nose.length), float(psec.diameter), float(density),
                         float(case.target.density), float(R_t), float(Y_p), tuple(used))


def _velocities(U, mask) -> str:
    from semianalytic.errors import summarise

    return summarise(np.asarray(U)[mask].tolist())  # 1000 velocities: count, range, ends


REGIME_RULES = ("nose_load", "meyer", "tate_tabor", "nose_length")
"""How ``penetrate`` labels the regimes without a posterior.  ``meyer`` (default, chosen by the
leave-one-material-out transfer of reports/validation_regimes.md, the ``Options()`` default of
semianalytic/calibration/regimes.py): rigid while Tate's (1967) tip pressure (1/2) rho_t U^2 + R_t
stays below the rod's static Meyer hardness H_M (the mean pressure of plastic indentation, Tabor
1951; from the hardness, or from the yield stress through Pavlina & Van Tyne's eq. (4) inverted):
no fitted constant; the depth is Part I's (a bent rod with its nose) until the tip pressure
reaches b H_M (b = :data:`.regime.DEFAULT_BREAKUP_FACTOR`, the breakup: the rod turns round or
breaks; this project's own criterion with a fitted factor), the Alekseevskii-Tate rod's (Y_p = f
sigma_u, R_t of Part I) beyond; eroding once the pressure reaches 3 f sigma_u (Tabor's constraint
on the dynamic ultimate strength).  ``tate_tabor`` (the previous default): rigid while Tate's (1967) tip pressure (1/2) rho_t U^2 + R_t
stays below the constrained dynamic yield stress C Y_p (C = 3, Tabor 1951), eroding once it reaches
C f sigma_u (the dynamic ultimate strength), the Alekseevskii-Tate rod (Y_p = f sigma_u, R_t of
Part I) giving the depth beyond the onset; the combination of Tate's criterion with Tabor's factor
is this project's reading of the two published relations.  ``nose_length``: the earlier rule (U_sC
of Part I, eqs. (33)/(36), then the shank eroded down to the nose length; this project's own),
kept as a named option; it lost on transfer.  ``nose_load`` (the default, the ``Options()`` default of
the regimes calibration, chosen by the leave-one-steel-out transfer among the model sets that order the
noses and whose eroded depth rises with velocity): the transitions are where the dynamic load of the
case's own nose reaches kappa (S - s_0), S = H_M, b H_M, e H_M (:mod:`.nose_load`); the depth is Forrestal's
rigid-nose depth while rigid and for a bent rod that keeps its nose (U_s < U_b; the peer of ``penetrate``,
the data authors' cavity constants where ``[data]`` gives them, else A Y = R_t, B = 3/2), and the
Alekseevskii-Tate rod's from U_b with Tate's (1986) R_t and the rod's static ultimate strength
(:data:`.regime.ROD_FLOW_FACTOR`)."""
DEFAULT_REGIME_RULE = "nose_load"
NOSE_LOAD_DEFAULTS = {"nose_load": "part1", "kappa": 0.10, "breakup_factor": 1.2, "erosion_factor": 1.6}
"""The stated constants of ``nose_load`` without a posterior: the load of Part I's coefficients and
kappa, b, e rounded between the posterior medians fitted on each steel of Piekutowski et al. (1999)
(reports/validation_regimes.md, where each is scored on the other steel)."""


def rod_strengths(case, setup) -> tuple[float, float, float, float]:
    """(dynamic yield stress, dynamic ultimate strength [Pa], dynamic factor f, static Meyer
    hardness [Pa], Tabor 1951 via :func:`.hardness.meyer_hardness_from_vickers`) of the projectile.

    With ``[projectile] hardness`` the yield stress is already f sigma_y(HV) (case layer) and the
    ultimate strength is f sigma_u(HV) (ASTM E140, Pavlina & Van Tyne 2008, eqs. (4)-(5)).  With a
    ``yield_stress`` only, it is read as f sigma_y of a steel (f = ``dynamic_factor`` default) and
    sigma_u follows through the Vickers hardness eq. (4) implies (eq. (4) inverted, then eq. (5))."""
    from semianalytic.penetration.hardness import (
        DEFAULT_DYNAMIC_FACTOR,
        meyer_hardness_from_vickers,
        parse_hardness,
        ultimate_strength_from_vickers,
        vickers_from_rockwell_c,
        vickers_from_yield_stress,
    )

    psec = case.projectile
    f = float(getattr(psec, "dynamic_factor", None) or DEFAULT_DYNAMIC_FACTOR)
    Y = setup.yield_stress
    if Y is None:
        raise InputError("projectile.yield_stress", "missing: the regimes need the projectile's strength "
                                                    "(yield_stress, e.g. '1.5 GPa', or hardness, e.g. '38 HRC')")
    if getattr(psec, "hardness", None) is not None:
        HV = float(vickers_from_rockwell_c(parse_hardness(psec.hardness)))
    else:
        HV = float(vickers_from_yield_stress(Y / f))
    return float(Y), float(f * ultimate_strength_from_vickers(HV)), f, float(meyer_hardness_from_vickers(HV))


def _tate_or_part1_resistance(case, setup) -> tuple[float, str]:
    """R_t of the eroding rod: Tate (1986) from the target's yield stress and Young's modulus, else
    the Part I R_t of the case's resistance model."""
    res = case.target.resistance
    if hasattr(res, "youngs_modulus") and hasattr(res, "yield_stress"):
        return rg.tate_resistance(res.yield_stress, res.youngs_modulus), "Tate (1986), Y_t (2/3 + ln(0.57 E_t/Y_t))"
    return float(setup.resistance_pa), "Part I (the case's resistance model)"


def case_nose_loads(case, setup, law=None) -> dict:
    """{kind: NoseLoad} of the case's nose and target (:mod:`.nose_load`): Part I's deep-limit
    Bbar, Cbar and R_t of the case's coefficients; the cavity-expansion law of the Forrestal peer
    (:func:`.validation.peer_inputs`: the data authors' constants where ``[data]`` gives them, else
    A Y = R_t, B = 3/2) with the nose factors N_1, N_2 of the actual nose."""
    from semianalytic.geometry import nose_from_section
    from semianalytic.penetration.validation import peer_inputs

    ci = setup.critical_inputs()
    area = math.pi * ci.diameter**2 / 4.0
    N1, N2 = peers.nose_factors(nose_from_section(case.require("projectile")))
    if law is None:
        law, _ = peer_inputs(case, setup)
    kw = dict(Bbar=ci.B / area, Cbar=ci.C / area, resistance=ci.resistance_pa, target_density=ci.target_density,
              cavity=law, N1=N1, N2=N2)
    return {k: nose_load_of(k, **kw) for k in NOSE_LOADS}


def _regimes_choices(case) -> dict:
    """The case's ``[regimes]`` keys (sections/regimes.py), {} without the section."""
    sec = case.section("regimes") if hasattr(case, "section") else None
    return sec.choices() if sec is not None else {}


def _nose_load_labels(case, setup, U, ei: ErodingInputs):
    """``regime_labels`` of the ``nose_load`` rule (:data:`REGIME_RULES`, :data:`NOSE_LOAD_DEFAULTS`)."""
    from semianalytic.penetration.hardness import parse_hardness, ultimate_strength_from_vickers, vickers_from_rockwell_c
    from semianalytic.penetration.nose_load import transition_velocity

    d = NOSE_LOAD_DEFAULTS
    ch = _regimes_choices(case)
    _, _, f, H_M = rod_strengths(case, setup)
    L = case_nose_loads(case, setup)[ch.get("nose_load", d["nose_load"])]
    k = d["kappa"]
    U_y = float(transition_velocity(k, H_M, L.static, L.linear, L.quadratic))
    U_e = max(U_y, float(transition_velocity(k, d["erosion_factor"] * H_M, L.static, L.linear, L.quadratic)))
    U_b = float(np.clip(transition_velocity(k, d["breakup_factor"] * H_M, L.static, L.linear, L.quadratic), U_y, U_e))
    psec = case.projectile
    notes = [x for x in ei.defaults if "dynamic_yield_stress" not in x and "eroding_resistance" not in x]
    Y_p, R_t = ei.rod_strength, ei.target_resistance
    if psec.dynamic_yield_stress is None:
        if getattr(psec, "hardness", None) is not None:
            HV = float(vickers_from_rockwell_c(parse_hardness(psec.hardness)))
        else:
            from semianalytic.penetration.hardness import vickers_from_yield_stress

            HV = float(vickers_from_yield_stress(setup.yield_stress / f))
        from semianalytic.penetration.hardness import yield_stress_from_vickers

        if ch.get("rod_strength") == "static_yield":
            Y_p, what = rg.ROD_FLOW_FACTOR * float(yield_stress_from_vickers(HV)), "static yield stress"
            eq = "(4)"
        else:
            Y_p, what, eq = rg.ROD_FLOW_FACTOR * float(ultimate_strength_from_vickers(HV)), "static ultimate strength", "(5)"
        notes.append(f"projectile.dynamic_yield_stress not given: the eroding rod uses Y_p = its {what} "
                     f"from the hardness = {Y_p / 1e6:.0f} MPa (Pavlina & Van Tyne 2008, eq. {eq}; factor "
                     f"{rg.ROD_FLOW_FACTOR:g})")
    if getattr(case.target.resistance, "eroding_resistance", None) is None:
        if ch.get("resistance") == "part1":
            R_t, src = float(setup.resistance_pa), "Part I, eq. (16) ([regimes] resistance)"
        else:
            R_t, src = _tate_or_part1_resistance(case, setup)
        notes.append(f"target.resistance.eroding_resistance not given: the eroding rod uses R_t = {R_t / 1e6:.0f} MPa ({src})")
    ei = ErodingInputs(**{**ei.__dict__, "rod_strength": float(Y_p), "target_resistance": float(R_t),
                          "defaults": tuple(notes)})
    return rg.classify_regimes(U, U_y, U_e), U_y, U_e, ei, U_b


def regime_labels(case, setup, U, rule: str = DEFAULT_REGIME_RULE):
    """(regimes per velocity, U_y, U_e [m/s], the eroding rod's inputs, U_b [m/s]: where the depth
    becomes the eroding rod's) by the rule ``rule`` (:data:`REGIME_RULES`); the one place both
    ``penetrate`` and ``penetrate --posterior`` label."""
    if rule not in REGIME_RULES:
        raise InputError("--regime-rule", f"must be one of {', '.join(REGIME_RULES)}; got {rule!r}")
    U = np.atleast_1d(np.asarray(U, float))
    ei = eroding_inputs(case, setup)
    U_b = None
    if rule == "nose_load":
        return _nose_load_labels(case, setup, U, ei)
    if rule in ("tate_tabor", "meyer"):
        Y_dyn, Yu_dyn, f, H_M = rod_strengths(case, setup)
        R1 = setup.resistance_pa  # the onset criteria are about the rigid nose: Part I's R_t
        rho_t = ei.target_density
        if rule == "meyer":
            U_y = float(rg.tate_erosion_velocity(H_M, R1, rho_t))
        else:
            U_y = float(rg.tate_erosion_velocity(Y_dyn, R1, rho_t, rg.TABOR_CONSTRAINT))
        U_e = max(U_y, float(rg.tate_erosion_velocity(Yu_dyn, R1, rho_t, rg.TABOR_CONSTRAINT)))
        U_b = (float(rg.breakup_velocity(rg.DEFAULT_BREAKUP_FACTOR, H_M, R1, rho_t, U_y, U_e))
               if rule == "meyer" else U_y)
        if case.projectile.dynamic_yield_stress is None:  # the eroding rod flows at its ultimate strength
            ei = ErodingInputs(**{**ei.__dict__, "rod_strength": Yu_dyn,
                                  "defaults": tuple(d for d in ei.defaults if "dynamic_yield_stress" not in d)
                                  + (f"projectile.dynamic_yield_stress not given: the eroding rod uses Y_p = f sigma_u "
                                     f"= {Yu_dyn / 1e6:.0f} MPa (f = {f:g}, Pavlina & Van Tyne 2008)",)})
    else:
        U_y = float(setup.critical_velocity())
        U_e = rg.erosion_onset_velocity(U_y, **ei.kwargs(mass=setup.mass))
    return rg.classify_regimes(U, U_y, U_e), U_y, U_e, ei, U_b


def regime_prediction(case, setup, U, curve: dict, peers: dict | None = None, *,
                      part1_model: str = DEFAULT_PART1_MODEL, rule: str = DEFAULT_REGIME_RULE) -> dict:
    """Regime-aware results at the striking velocities ``U`` (``curve`` from penetration_curve,
    ``peers`` the Forrestal / Chen-Li depths): JSON-able dict with ``regime``, ``depth_m``,
    ``depth_eroding_m``, ``transition_velocity_m_s`` (U_y = U_sC, rigid -> deforming),
    ``erosion_velocity_m_s`` (U_e, -> eroding), ``residual_length_eroding_m``, ``part1_model``,
    ``eroding_inputs``, ``valid`` (per model, a list of booleans) and ``warnings`` (lines)."""
    if part1_model not in PART1_MODELS:
        raise InputError("--part1-model", f"must be one of {', '.join(PART1_MODELS)}; got {part1_model!r}")
    U = np.atleast_1d(np.asarray(U, float))
    part1 = np.asarray(curve[f"depth_{part1_model}_m"], float)
    regimes, U_y, U_e, ei, U_b = regime_labels(case, setup, U, rule)
    er = rg.eroding_depth(U, **ei.kwargs(mass=setup.mass))
    reg = np.asarray(regimes)
    if rule == "nose_load":  # Part I while rigid, Forrestal's rigid-nose depth while bent, eroding from U_b
        if peers is None or "forrestal" not in peers:
            from semianalytic.penetration.validation import peer_depths

            peers = {**(peers or {}), **peer_depths(case, setup, U)}
        ch = _regimes_choices(case)
        pick = {"forrestal": np.asarray(peers["forrestal"], float), "part1": part1}
        rigid = pick[ch.get("rigid_depth", "forrestal")]  # the transfer's choice: Forrestal for both
        bent = pick[ch.get("deformed_depth", "forrestal")]
        depth = np.where(U < U_y, rigid, np.where(U < U_b, bent, er.depth))
    elif rule in ("tate_tabor", "meyer"):  # Part I below U_b, the eroding rod beyond (tate_tabor: U_b = U_y)
        depth = np.where(U < U_b, part1, er.depth)
    else:
        depth = rg.regime_depth(regimes, part1, er.depth)
    rigid_ok = reg == "rigid"
    valid = {k: rigid_ok.tolist() for k in PART1_MODELS}
    if peers is not None:
        valid.update({k: rigid_ok.tolist() for k in ("forrestal", "chen_li")})
    if rule in ("tate_tabor", "meyer", "nose_load"):
        valid["eroding"] = (U >= U_b).tolist()
        valid["regime_aware"] = [True] * len(reg)
    else:
        valid["eroding"] = (reg == "eroding").tolist()
        valid["regime_aware"] = (reg != "deforming").tolist()  # depth_m: no model holds in the deforming band
    warnings = []
    U_sC = float(curve["critical_velocity_m_s"][0])
    if U_sC == math.inf and setup.rod is not None:  # eq. (33) without a real root
        from semianalytic.penetration.critical import no_real_root_reason

        reason = no_real_root_reason(setup.critical_inputs())
        if reason is not None:
            warnings.append(f"U_sC: {reason}" + ("; every striking velocity is labelled rigid, which only reflects "
                                                  "this reading, not the projectile" if rule == "nose_length" else
                                                  "; the regimes (Tate's criterion) do not use U_sC"))
    if np.any(~rigid_ok):
        why = (f"U_s >= U_sC = {U_y:.0f} m/s: the projectile yields (Part I, eqs. (33)/(36))" if rule == "nose_length" else
               f"U_s >= U_y = {U_y:.0f} m/s: the tip pressure (1/2) rho_t U^2 + R_t reaches the rod's Meyer hardness "
               "(Tate 1967, Tabor 1951): the nose yields" if rule == "meyer" else
               f"U_s >= U_y = {U_y:.0f} m/s: the dynamic load of the nose reaches kappa (H_M - s_0) "
               f"(kappa = {NOSE_LOAD_DEFAULTS['kappa']:g}, penetration/nose_load.py): the nose yields" if rule == "nose_load" else
               f"U_s >= U_y = {U_y:.0f} m/s: the tip pressure (1/2) rho_t U^2 + R_t reaches 3 Y_p (Tate 1967, Tabor 1951): "
               "the nose yields")
        for k in valid:
            if k not in ("eroding", "regime_aware"):
                warnings.append(f"{_LABEL[k]}: depth outside the model's validity at U_s = {_velocities(U, ~rigid_ok)} m/s; {why}")
    bad_eroding = (U < U_b) if rule in ("tate_tabor", "meyer", "nose_load") else (reg != "eroding")
    if np.any(bad_eroding):
        why = ((f"U_s < U_y = {U_y:.0f} m/s: the projectile stays rigid" if rule == "tate_tabor" else
                f"U_s < U_b = {U_b:.0f} m/s: the rod keeps its nose (rigid, or bent but not broken)" if rule in ("meyer", "nose_load") else
                f"U_s < U_e = {U_e:.0f} m/s: the eroding rod keeps more than its nose length, the projectile is "
                "rigid or deforming, not eroding") if math.isfinite(U_e) else "no erosion predicted")
        warnings.append(f"{_LABEL['eroding']}: depth outside the model's validity at U_s = "
                        f"{_velocities(U, bad_eroding)} m/s; {why}")
    if rule == "nose_length" and np.any(reg == "deforming"):
        warnings.append(f"regime-aware depth_m at U_s = {_velocities(U, reg == 'deforming')} m/s (deforming band "
                        f"{U_y:.0f} <= U_s < {U_e:.0f} m/s): no model holds; the {_LABEL[part1_model]} depth is given "
                        "as the upper bound, depth_eroding_m is the lower bound")
    notes = list(ei.defaults) if np.any(reg != "rigid") else []
    if rule == "nose_load" and ei.rod_strength > ei.target_resistance and np.any(U >= U_b):
        warnings.append(f"{_LABEL['eroding']}: Y_p = {ei.rod_strength / 1e6:.0f} MPa > R_t = {ei.target_resistance / 1e6:.0f} MPa: "
                        "the eroded depth falls with the striking velocity towards the hydrodynamic limit from above "
                        "(the measured eroded depths of steel rods into aluminium rise)")
    return {
        "regime": regimes,
        "depth_m": depth.tolist(),
        "depth_eroding_m": er.depth.tolist(),
        "residual_length_eroding_m": er.residual_length.tolist(),
        "transition_velocity_m_s": U_y,
        "erosion_velocity_m_s": U_e,
        "breakup_velocity_m_s": U_b,
        "breakup_factor": (rg.DEFAULT_BREAKUP_FACTOR if rule == "meyer" else
                           NOSE_LOAD_DEFAULTS["breakup_factor"] if rule == "nose_load" else None),
        "nose_load": ({k: v for k, v in NOSE_LOAD_DEFAULTS.items()} if rule == "nose_load" else None),
        "part1_model": part1_model,
        "regime_rule": rule,
        "eroding_inputs": {"rod_strength_Pa": ei.rod_strength, "target_resistance_Pa": ei.target_resistance,
                           "rod_length_m": rg.eroding_rod_length(ei.length, ei.nose_length, ei.diameter, ei.density, setup.mass)},
        "valid": valid,
        "warnings": [f"warning: {w}" for w in warnings] + [f"note: {n}" for n in notes],
    }


def predict_regimes(case, coefficients, shots, *, part1_model: str = DEFAULT_PART1_MODEL, w1: str = "neglect",
                    rule: str = DEFAULT_REGIME_RULE) -> list[dict]:
    """Per shot (each with its own mass): recorded response and regime, predicted regime, the
    regime-aware, Part I and eroding depths and the measured depth (NaN where the data give only
    a channel length)."""
    from semianalytic.penetration.curve import PenetrationSetup, penetration_curve

    data = case.require("data")
    col = data.response_column
    base = PenetrationSetup.from_case(case, coefficients)
    rows = []
    for shot in shots:
        setup = base if shot.mass is None else PenetrationSetup.from_case(case, coefficients, mass=shot.mass)
        curve = penetration_curve(setup, [shot.velocity], w1=w1)
        pred = regime_prediction(case, setup, [shot.velocity], curve, part1_model=part1_model, rule=rule)
        response = shot.row.get(col, "") if col else ""
        if col and response not in RESPONSE_REGIME:
            raise InputError("data.response_column", f"shot {shot.id}: response {response!r} is not one of "
                                                     f"{', '.join(RESPONSE_REGIME)}")
        rows.append({
            "shot": shot.id,
            "velocity_m_s": shot.velocity,
            "mass_kg": setup.mass,
            "measured_m": shot.depth,
            "response": response,
            "recorded_regime": RESPONSE_REGIME.get(response),
            "predicted_regime": pred["regime"][0],
            "depth_m": pred["depth_m"][0],
            "part1_m": float(curve[f"depth_{part1_model}_m"][0]),
            "rigid_m": float(curve["depth_rigid_m"][0]),
            "eroding_m": pred["depth_eroding_m"][0],
            "transition_velocity_m_s": pred["transition_velocity_m_s"],
            "erosion_velocity_m_s": pred["erosion_velocity_m_s"],
        })
    return rows


def confusion(rows) -> dict[str, dict[str, int]]:
    """Counts {recorded regime: {predicted regime: n}} over the shots with a recorded response."""
    out = {r: {p: 0 for p in rg.REGIMES} for r in rg.REGIMES}
    for row in rows:
        if row["recorded_regime"] is not None:
            out[row["recorded_regime"]][row["predicted_regime"]] += 1
    return out


def fit_eroding_parameters(ei: ErodingInputs, shots, start=None) -> tuple[float, float]:
    """(R_t, Y_p) [Pa] of the eroding rod by least squares on log depth over ``shots``
    (objects with velocity, depth, mass), from ``start`` (default: the case's values)."""
    from scipy.optimize import least_squares

    x0 = np.log(start if start is not None else (ei.target_resistance, ei.rod_strength))

    def resid(x):
        R, Y = np.exp(x)
        return np.array([math.log(float(rg.eroding_depth(s.velocity, **ei.kwargs(target_resistance=R, rod_strength=Y, mass=s.mass)).depth[0]))  # noqa: E501
                         - math.log(s.depth) for s in shots])

    sol = least_squares(resid, x0, bounds=(np.log([1e7, 1e7]), np.log([2e10, 2e10])), x_scale=1.0, diff_step=1e-4)
    return tuple(float(v) for v in np.exp(sol.x))


def leave_one_out_eroding(ei: ErodingInputs, shots) -> list[dict]:
    """Leave-one-out: for each shot, (R_t, Y_p) fitted on the others and the predicted depth."""
    out = []
    for i, s in enumerate(shots):
        rest = [t for j, t in enumerate(shots) if j != i]
        R, Y = fit_eroding_parameters(ei, rest)
        P = float(rg.eroding_depth(s.velocity, **ei.kwargs(target_resistance=R, rod_strength=Y, mass=s.mass)).depth[0])
        out.append({"shot": s.id, "velocity_m_s": s.velocity, "measured_m": s.depth, "predicted_m": P,
                    "target_resistance_Pa": R, "rod_strength_Pa": Y, "error": (P - s.depth) / s.depth})
    return out


def recorded_transitions(rows) -> dict[str, float]:
    """From the shots (sorted by velocity): the last rigid and first non-rigid velocity, the last
    non-eroding and first eroding one (NaN where the data have none)."""
    rows = sorted(rows, key=lambda r: r["velocity_m_s"])
    nan = math.nan

    def first(pred):
        return next((r["velocity_m_s"] for r in rows if pred(r)), nan)

    def last(pred):
        return next((r["velocity_m_s"] for r in reversed(rows) if pred(r)), nan)

    measured = [r for r in rows if math.isfinite(r["measured_m"])]
    drops = [(a["measured_m"] - b["measured_m"], a["velocity_m_s"], b["velocity_m_s"]) for a, b in zip(measured, measured[1:])]
    drop = max(drops) if drops else (nan, nan, nan)
    return {
        "depth_drop_below_m_s": drop[1],  # the largest fall of the measured depth between consecutive shots
        "depth_drop_above_m_s": drop[2],
        "last_rigid_m_s": last(lambda r: r["recorded_regime"] == "rigid"),
        "first_non_rigid_m_s": first(lambda r: r["recorded_regime"] != "rigid"),
        "last_non_eroding_m_s": last(lambda r: r["recorded_regime"] != "eroding"),
        "first_eroding_m_s": first(lambda r: r["recorded_regime"] == "eroding"),
    }


def transition_check(predicted: float, below: float, above: float, tolerance: float = 0.10) -> dict:
    """Whether a predicted transition lies between the recorded ``below`` and ``above`` velocities,
    or within ``tolerance`` (relative) of the nearer one; the signed distance relative to it."""
    if not (math.isfinite(predicted) and math.isfinite(below) and math.isfinite(above)):
        return {"between": False, "within_tolerance": False, "distance": math.nan}
    if below <= predicted <= above:
        return {"between": True, "within_tolerance": True, "distance": 0.0}
    ref = below if predicted < below else above
    d = (predicted - ref) / ref
    return {"between": False, "within_tolerance": abs(d) <= tolerance, "distance": d}


def regime_validation(case, coefficients, *, part1_model: str = DEFAULT_PART1_MODEL, velocities=None,
                      loo: bool = True, w1: str = "neglect", rule: str = DEFAULT_REGIME_RULE) -> dict:
    """Everything the regimes report shows for one case with a ``[data]`` file and a
    ``response_column``: the shots (all responses) against the predicted regimes, the confusion
    counts, the recorded and predicted transitions, per recorded regime the errors of the
    regime-aware depth, the leave-one-out eroding fit on the eroding shots and the curves at
    ``velocities`` (for the mean shot mass)."""
    from semianalytic.penetration.curve import PenetrationSetup, penetration_curve
    from semianalytic.penetration.validation import load_shots

    shots = load_shots(case, require_depth=False)
    rows = predict_regimes(case, coefficients, shots, part1_model=part1_model, w1=w1, rule=rule)
    masses = [r["mass_kg"] for r in rows]
    setup = PenetrationSetup.from_case(case, coefficients, mass=float(np.mean(masses)) if masses else None)
    U = np.linspace(300.0, 3200.0, 146) if velocities is None else np.asarray(velocities, float)
    curve = penetration_curve(setup, U, w1=w1)
    pred = regime_prediction(case, setup, U, curve, part1_model=part1_model, rule=rule)
    rec = recorded_transitions(rows)
    errors = {}
    for reg in rg.REGIMES:
        sel = [r for r in rows if r["recorded_regime"] == reg and math.isfinite(r["measured_m"])]
        if sel:
            e = np.array([(r["depth_m"] - r["measured_m"]) / r["measured_m"] for r in sel])
            e1 = np.array([(r["part1_m"] - r["measured_m"]) / r["measured_m"] for r in sel])
            e2 = np.array([(r["eroding_m"] - r["measured_m"]) / r["measured_m"] for r in sel])
            errors[reg] = {"n": len(sel), "mean": float(e.mean()), "mean_abs": float(np.abs(e).mean()),
                           "max_abs": float(np.abs(e).max()), "part1_mean_abs": float(np.abs(e1).mean()),
                           "eroding_mean_abs": float(np.abs(e2).mean())}
    out = {
        "rows": rows,
        "confusion": confusion(rows),
        "recorded": rec,
        "yield_check": transition_check(pred["transition_velocity_m_s"], rec["last_rigid_m_s"], rec["first_non_rigid_m_s"]),
        "erosion_check": transition_check(pred["erosion_velocity_m_s"], rec["last_non_eroding_m_s"], rec["first_eroding_m_s"]),
        "drop_check": transition_check(pred["erosion_velocity_m_s"], rec["depth_drop_below_m_s"], rec["depth_drop_above_m_s"]),
        "errors": errors,
        "curve": {"U": U, "rigid": curve["depth_rigid_m"], "part1": np.asarray(curve[f"depth_{part1_model}_m"]),
                  "depth": np.asarray(pred["depth_m"]), "eroding": np.asarray(pred["depth_eroding_m"]),
                  "regime": pred["regime"]},
        "prediction": {k: pred[k] for k in ("transition_velocity_m_s", "erosion_velocity_m_s", "eroding_inputs", "part1_model")},
        "mass_kg": setup.mass,
    }
    mid = 0.5 * (rec["last_rigid_m_s"] + rec["first_non_rigid_m_s"])
    if math.isfinite(mid) and setup.rod is not None:  # the Appendix's inverse problem at the recorded transition
        from semianalytic.penetration.critical import yield_stress_from_critical_velocity

        out["recorded_transition_m_s"] = mid
        out["yield_stress_for_recorded_transition_Pa"] = yield_stress_from_critical_velocity(mid, setup.critical_inputs(), setup.phi)
    eroded = [s for s, r in zip(shots, rows) if r["recorded_regime"] == "eroding" and math.isfinite(s.depth)]
    if loo and len(eroded) >= 3:
        ei = eroding_inputs(case, setup)
        loo_rows = leave_one_out_eroding(ei, eroded)
        R, Y = fit_eroding_parameters(ei, eroded)
        default = [(r["eroding_m"] - r["measured_m"]) / r["measured_m"] for r in rows
                   if r["recorded_regime"] == "eroding" and math.isfinite(r["measured_m"])]
        out["eroding_fit"] = {
            "loo": loo_rows,
            "loo_mean_abs": float(np.mean([abs(r["error"]) for r in loo_rows])),
            "all_shots": {"target_resistance_Pa": R, "rod_strength_Pa": Y},
            "default_mean_abs": float(np.mean(np.abs(default))),
        }
    return out
