"""What ``calibrate`` and ``penetrate --posterior`` compute, from validated cases.

* :func:`calibrate_case`: the posterior of the calibrated target parameters and the
  discrepancy scale for every chosen model (:mod:`.sampler`), the posterior predictive at the
  calibration shots and on a velocity grid, and the JSON posterior.
* :func:`cross_validate`: leave-one-out by exact refits (each shot predicted by the posterior
  of the others) and the transfer split (predict the shots of other cases with the same
  target), per model: mean and RMS error of the predictive median, mean |error|, coverage of
  the central 50% and 90% predictive intervals, mean log predictive density of ln P.
* :func:`predict_with_posterior`: predictive depth quantiles of any case (nose, mass, length
  may differ) from a posterior file whose target matches the case's.

The eroding rod (``--model eroding``, issue 17 item 3) is calibrated in a run of its own, on the
shots recorded eroded, and ``penetrate`` takes ``--posterior`` twice (a rigid-shot posterior and
an eroding one) rather than one file holding both.  Why: the two share no parameter and no shot
(Part I's target strength on the rigid shots; the rod's R_t and Y_p on the eroded ones), so their
joint posterior is the product of the two and nothing is lost by sampling them apart; each file
keeps one data set, one shot selection, its diagnostics and its cross-validation; and a user can
pair any rigid-shot posterior with any eroding one of the same target (each is checked against
the case: target density and resistance model, and for the eroding rod the projectile's density
and the value of a parameter held fixed).  ``depth_quantiles_m["regime_aware"]`` takes at each
striking velocity the quantiles of the model of the regime ``penetrate`` predicts there (the same
``regime`` labels, from the case's parameters): the ``--part1-model`` (else the first
rigid-projectile model in the files) below the erosion onset U_e, in the deforming band as the
upper bound like ``depth_m``, and the eroding rod from U_e; NaN where no file holds the model
needed, with a warning.  Posterior files: format version 2 (per-model ``parameters``, the eroding
record); version 1 files are still read.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from semianalytic.calibration.models import (
    MODELS,
    DepthModelInputs,
    ErodingDepths,
    ShotSet,
    ThetaColumn,
    build_surrogate,
)
from semianalytic.calibration.names import ERODING, ERODING_KEYS
from semianalytic.calibration.sampler import (
    Problem,
    ResistanceMap,
    log_predictive_density,
    mixture_quantiles,
    sample_posterior,
)
from semianalytic.errors import InputError
from semianalytic.sections.calibration import (
    POSTERIOR_FORMAT,
    POSTERIOR_VERSION,
    CalibrationSection,
    check_models,
    default_parameter,
    load_shot_set,
    parameter_kind,
    parse_prior,
    read_posterior,
)

__all__ = ["calibrate_case", "cross_validate", "predict_with_posterior", "QUANTILES"]

QUANTILES = (0.05, 0.25, 0.5, 0.75, 0.95)
SURROGATE_NODES = 16  # Chebyshev nodes in ln R_t over the prior range (see the tests for its accuracy)
PREDICTION_NODES = 6  # over the narrower posterior range
STORED_DRAWS = 1000
ERODING_PREDICTION_DRAWS = 500  # draws of the eroding rod per prediction (see _quantiles_at)
LOO_STEPS = 500  # per refit, a quarter discarded: 32 walkers x 375 steps / tau ~ 20 -> ~600 effective draws


@dataclass(frozen=True)
class Target:
    """The case-side description of what a posterior is about."""

    inputs: DepthModelInputs
    resistance: ResistanceMap
    density: float
    resistance_model: str
    fixed: dict


def _target(case, coefficients, keys, cavity_shape=None, models=MODELS) -> Target:
    from semianalytic.geometry import nose_from_section
    from semianalytic.penetration import peers
    from semianalytic.penetration.curve import PenetrationSetup
    from semianalytic.penetration.resistance import resistance_from_case

    setup = PenetrationSetup.from_case(case, coefficients, require_material=False)
    psec = case.require("projectile")
    needs_rod = [m for m in models if m in ("quasi_rigid", "elastic", "elastic_exact_rod")]
    if needs_rod and setup.rod is None:
        raise InputError("projectile.youngs_modulus", f"missing: the {needs_rod[0]} model needs the projectile's "
                                                      "Young's modulus (e.g. '210 GPa')")
    resistance = resistance_from_case(case)
    fields = tuple(k.rsplit(".", 1)[-1] for k in keys)
    if cavity_shape is None:
        data = case.section("data")
        if data is not None and data.cavity_A is not None:
            cavity_shape = (data.cavity_A, 0.0, data.cavity_B) if data.cavity_C is None else (
                data.cavity_A, data.cavity_B, data.cavity_C)
        else:
            cavity_shape = (1.0, 0.0, 1.5)  # A Y = R_t, incompressible two-term law (penetration.validation)
    inputs = DepthModelInputs(setup, peers.nose_factors(nose_from_section(psec)), tuple(map(float, cavity_shape)))
    fixed = {f.name: float(getattr(resistance, f.name)) for f in dataclasses.fields(resistance)
             if f.name not in fields and isinstance(getattr(resistance, f.name), (int, float))}
    return Target(inputs, ResistanceMap(resistance, fields, float(psec.diameter)), float(setup.target_density),
                  resistance.name, fixed)


def _eroding_defaults(case, coefficients) -> dict:
    """The case's values of the eroding rod's parameters (with regime_setup's stated defaults)."""
    from semianalytic.penetration.curve import PenetrationSetup
    from semianalytic.penetration.regime_setup import eroding_inputs

    ei = eroding_inputs(case, PenetrationSetup.from_case(case, coefficients, require_material=False))
    return {ERODING_KEYS[0]: ei.target_resistance, ERODING_KEYS[1]: ei.rod_strength}


def _settings(case, models, parameters, coefficients=None):
    sec = case.section("calibration") or CalibrationSection()
    from semianalytic.penetration.resistance import resistance_from_case

    resistance = resistance_from_case(case)
    models = check_models(models or sec.models or MODELS)
    eroding = models == (ERODING,)
    # the case's [calibration] parameters of this kind of model (eroding rod or target resistance)
    listed = [k for k in (sec.parameters or []) if (k in ERODING_KEYS) == eroding] or None
    default = list(ERODING_KEYS) if eroding else [default_parameter(resistance)]
    keys = list(dict.fromkeys(parameters or listed or default))
    for key in keys:
        parameter_kind(key, resistance, eroding=eroding)
    for key in sec.prior:  # a prior of a parameter not calibrated now is unused, but must name a parameter
        try:
            parameter_kind(key, resistance, eroding=key in ERODING_KEYS)
        except InputError as exc:
            raise InputError(f"calibration.prior.{key}", exc.message) from None
    values = _eroding_defaults(case, coefficients) if eroding else {}
    priors, units = [], []
    for key in keys:
        kind, unit, scale = parameter_kind(key, resistance, eroding=eroding)
        text = sec.prior.get(key)
        if text is None:
            value = values[key] if eroding else float(getattr(resistance, key.rsplit(".", 1)[-1]))
            text = f"lognormal({value / scale:.6g} {unit}, 0.5)" if kind != "dimensionless" else f"lognormal({value:.6g}, 0.5)"
        priors.append(parse_prior(text, kind, f"calibration.prior.{key}"))
        units.append((unit, scale, text))
    sigma_prior = parse_prior(sec.discrepancy, "dimensionless", "calibration.discrepancy")
    return sec, models, tuple(keys), tuple(priors), sigma_prior, units


def _range(resistance: ResistanceMap, priors, q=1e-3) -> tuple[float, float]:
    """R_t range covering the priors' central 1 - 2q (the posterior is truncated outside)."""
    levels = np.linspace(q, 1 - q, 9)
    grids = np.meshgrid(*[np.asarray(p.ppf(levels), float) for p in priors], indexing="ij")
    theta = np.column_stack([g.ravel() for g in grids])
    if len(theta) > 4096:
        theta = theta[np.random.default_rng(0).choice(len(theta), 4096, replace=False)]
    R = resistance(theta)
    R = R[np.isfinite(R)]
    if R.size < 2 or not R.max() > R.min():
        raise InputError("calibration.prior", "the priors give no range of the resistance R_t to calibrate on")
    return float(R.min()), float(R.max())


def _stats(q: np.ndarray, lpd: np.ndarray, measured: np.ndarray) -> dict:
    """Per-split statistics from predictive quantiles q (len(QUANTILES), n)."""
    e = (q[2] - measured) / measured
    return {
        "n": int(len(measured)),
        "mean_error": float(np.mean(e)),
        "rms_error": float(math.sqrt(np.mean(e * e))),
        "mean_abs_error": float(np.mean(np.abs(e))),
        "coverage_50": float(np.mean((q[1] <= measured) & (measured <= q[3]))),
        "coverage_90": float(np.mean((q[0] <= measured) & (measured <= q[4]))),
        "mean_log_predictive_density": float(np.mean(lpd)),
    }


def _predict(target: Target, models, shots: ShotSet, draws: dict, n_nodes: int = PREDICTION_NODES) -> dict:
    """{model: (quantiles (len(QUANTILES), n_shots), mu (n_s, n_shots))} from posterior draws
    {model: (theta, sigma)} for a shot set of ``target``'s projectile."""
    R_by = {m: target.resistance(draws[m][0]) for m in models}
    allR = np.concatenate([r[np.isfinite(r)] for r in R_by.values()])
    if allR.size == 0:
        raise InputError("target.resistance", "the posterior's parameters give no valid resistance R_t for this case")
    lo, hi = float(allR.min()) * (1 - 1e-6), float(allR.max()) * (1 + 1e-6)
    sur = build_surrogate(target.inputs, models, shots, lo, hi, n_nodes)
    out = {}
    for m in models:
        ok = np.isfinite(R_by[m])
        mu = sur[m].log_depth(R_by[m][ok])
        sigma = draws[m][1][ok]
        out[m] = (mixture_quantiles(mu, sigma, QUANTILES), mu, sigma)
    return out


def _posterior_json(case, target: Target, keys, units, sigma_prior_text, shots, posts: dict, fits: dict,
                    eroding: dict | None = None) -> dict:
    data = case.require("data")
    models = {}
    for m, post in posts.items():
        n = len(post.sigma)
        idx = np.unique(np.linspace(0, n - 1, min(n, STORED_DRAWS)).astype(int))
        samples = {k: post.theta[idx, j].tolist() for j, k in enumerate(keys)}
        samples["resistance_Pa"] = post.resistance[idx].tolist()
        samples["sigma"] = post.sigma[idx].tolist()
        summary = {}
        for name, arr in [*((k, post.theta[:, j]) for j, k in enumerate(keys)), ("resistance_Pa", post.resistance),
                          ("sigma", post.sigma)]:
            qs = np.percentile(arr, [5, 50, 95])
            summary[name] = {"mean": float(np.mean(arr)), "sd": float(np.std(arr)), "q05": qs[0], "q50": qs[1],
                             "q95": qs[2]}
        q = fits[m]
        models[m] = {
            "parameters": list(keys),
            "samples": samples,
            "summary": summary,
            "mode": dict(zip([*keys, "sigma"], post.mode)),
            "diagnostics": {
                "acceptance_fraction": post.acceptance_fraction,
                "autocorrelation_time": dict(zip([*keys, "sigma"], post.autocorrelation_time)),
                "effective_sample_size": post.effective_sample_size,
                "walkers": post.n_walkers, "steps": post.n_steps, "burn": post.n_burn,
                "draws_stored": int(len(idx)),
                "chains": (post.diagnostics or {}).get("chains"),
                "r_hat": {k: v["r_hat"] for k, v in ((post.diagnostics or {}).get("parameters") or {}).items()},
                "ess_bulk": {k: v["ess_bulk"] for k, v in ((post.diagnostics or {}).get("parameters") or {}).items()},
                "ess_tail": {k: v["ess_tail"] for k, v in ((post.diagnostics or {}).get("parameters") or {}).items()},
                "warnings": list((post.diagnostics or {}).get("warnings") or []),
            },
            "fit": {f"{p:g}": q[k].tolist() for k, p in enumerate(QUANTILES)},
        }
        if m == ERODING:
            models[m]["eroding"] = dict(eroding)
    return {
        "format": POSTERIOR_FORMAT,
        "version": POSTERIOR_VERSION,
        "case": str(case.path) if case.path else case.title,
        "title": case.title,
        "target": {"density_kg_m3": target.density, "resistance_model": target.resistance_model,
                   "resistance_fixed": target.fixed},
        "parameters": [{"key": k, "unit": "SI", "display_unit": u[0], "prior": u[2]} for k, u in zip(keys, units)],
        "discrepancy": {"model": "ln P_measured = ln P_model + eps, eps ~ N(0, sigma^2)", "prior": sigma_prior_text},
        "shots_used": "recorded eroding" if eroding is not None else "recorded rigid (all selected without a response column)",
        "cavity_shape": list(target.inputs.cavity_shape),
        "projectile": projectile_signature(case),
        "data": {
            "file": data.file, "source": data.source, "select": data.select,
            "shots": [{"id": i, "velocity_m_s": float(v), "depth_m": float(d), "mass_kg": float(mm)}
                      for i, v, d, mm in zip(shots.ids, shots.velocity, shots.depth, shots.mass)],
        },
        "models": models,
    }


TRANSFER_SIGMA = {"rigid": 0.024, "quasi_rigid": 0.029, "elastic": 0.034, "elastic_exact_rod": 0.029,
                  "forrestal": 0.047, "chen_li": 0.050}
"""Depth scatter added (in quadrature, ln depth) per rigid-projectile model when a ``calibrate``
posterior is applied to another projectile than the one it was fitted on (nose, diameter,
density, strength): the transfer inflation measured on the bundled data,
sqrt(mean e_T^2 - mean e_LOO^2), e = ln(measured / predictive median), the VAR 4340 posterior
predicting the AerMet 100 shots (T) against its own leave-one-out (reports/calibration_piekutowski1999/
cross_validation.json, 7 shots each; tests/test_posterior_transfer.py recomputes them).  A
measurement for another steel on the same nose: no second nose's shots are bundled, so this is a
floor for a transfer to another nose, not a bound."""


def projectile_signature(case) -> dict:
    """What a ``calibrate`` posterior's projectile was: nose, crh, diameter, density, yield stress."""
    p = case.require("projectile")
    return {"nose": p.nose, "crh": getattr(p, "crh", None), "diameter_m": p.diameter,
            "density_kg_m3": getattr(p, "density", None), "yield_stress_Pa": getattr(p, "yield_stress", None)}


def _projectile_transfer(case, raw: dict) -> list[str]:
    """What differs between the posterior's projectile (``raw["projectile"]``) and the case's."""
    theirs = raw.get("projectile")
    if not isinstance(theirs, dict):
        return []
    mine = projectile_signature(case)
    out = []
    for k, v in theirs.items():
        w = mine.get(k)
        same = v == w or (isinstance(v, (int, float)) and isinstance(w, (int, float)) and math.isclose(v, w, rel_tol=1e-9))
        if not same:
            out.append(f"{k} = {v!r} (the case: {w!r})")
    return out


def _problem(keys, priors, sigma_prior, resistance, surrogate, depth):
    return Problem(keys, priors, sigma_prior, resistance, surrogate, depth)


def _eroding_depths(case, coefficients, keys, shots: ShotSet, fixed: dict | None = None) -> tuple[ErodingDepths, dict]:
    """The eroding rod of ``case`` for ``shots`` (L_0 per shot mass) with R_t and Y_p taken from
    theta (columns of ``keys``) or fixed (``fixed``, else the case's values); and its record
    for the posterior file."""
    from semianalytic.penetration.curve import PenetrationSetup
    from semianalytic.penetration.regime import eroding_rod_length
    from semianalytic.penetration.regime_setup import eroding_inputs

    ei = eroding_inputs(case, PenetrationSetup.from_case(case, coefficients, require_material=False))
    values = {ERODING_KEYS[0]: ei.target_resistance, ERODING_KEYS[1]: ei.rod_strength}
    values.update(fixed or {})
    cols = [ThetaColumn(keys.index(k) if k in keys else None, float(values[k])) for k in ERODING_KEYS]
    L0 = np.array([eroding_rod_length(ei.length, ei.nose_length, ei.diameter, ei.density, float(m)) for m in shots.mass])
    depths = ErodingDepths(np.asarray(shots.velocity, float), L0, ei.density, ei.target_density, cols[0], cols[1])
    record = {"projectile_density_kg_m3": ei.density,
              "fixed": {k: float(values[k]) for k in ERODING_KEYS if k not in keys},
              "rod": "Alekseevskii-Tate rod: the cylinder of the projectile's mass and diameter (penetration.regime)"}
    return depths, record


def _quantiles_at(depths, draws) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(quantiles (len(QUANTILES), n), mu, sigma) of the posterior predictive of ``depths``
    (an ErodingDepths) at draws (theta, sigma), vectorised over draws; at most
    :data:`ERODING_PREDICTION_DRAWS` draws, evenly thinned: the Monte-Carlo error of a 5 %
    quantile of a predictive of ln-sd ~0.1 from 500 independent draws is about 1 % (less here:
    each draw enters as its exact log-normal), far inside the 90 % interval's width of ~30 %."""
    theta, sigma = draws
    if len(sigma) > ERODING_PREDICTION_DRAWS:
        idx = np.linspace(0, len(sigma) - 1, ERODING_PREDICTION_DRAWS).astype(int)
        theta, sigma = np.asarray(theta)[idx], np.asarray(sigma)[idx]
    mu = depths.log_depth_theta(theta)
    ok = np.all(np.isfinite(mu), axis=1)
    return mixture_quantiles(mu[ok], sigma[ok], QUANTILES), mu[ok], sigma[ok]


def calibrate_case(case, coefficients, *, models=None, parameters=None, progress: bool = False,
                   steps: int | None = None) -> dict:
    """Calibrate (see the module docstring).  Returns {"posterior": JSON dict, "shots": ShotSet,
    "fits": {model: quantiles}, "curves": {...}, "histograms": {...}, "settings": {...}}.
    ``models`` all of the rigid-projectile family (calibrated on the shots recorded rigid) or
    only ``eroding`` (on the shots recorded eroding)."""
    import time

    t0, c0 = time.perf_counter(), time.process_time()
    sec, models, keys, priors, sigma_prior, units = _settings(case, models, parameters, coefficients)
    eroding = models == (ERODING,)
    target = _target(case, coefficients, keys, models=() if eroding else models)
    shots = load_shot_set(case, target.inputs.setup.mass, regime=ERODING if eroding else "rigid")
    record = None
    if eroding:
        depths, record = _eroding_depths(case, coefficients, keys, shots)
        depth_models = {ERODING: depths}
        fast = depths.resistance
        lo = hi = None
    else:
        lo, hi = _range(target.resistance, priors)
        depth_models = build_surrogate(target.inputs, models, shots, lo, hi, SURROGATE_NODES)
        fast = target.resistance
        if len(priors) == 1 and priors[0].positive:
            fast = fast.tabulated(float(priors[0].ppf(1e-4)), float(priors[0].ppf(1 - 1e-4)))
    posts, fits = {}, {}
    for m in models:
        problem = _problem(keys, priors, sigma_prior, fast, depth_models[m], shots.depth)
        posts[m] = sample_posterior(problem, walkers=sec.walkers, steps=steps or sec.steps, burn=min(sec.burn, (steps or sec.steps) // 2),
                                    seed=sec.seed, progress=progress)
        mu = depth_models[m].log_depth_theta(posts[m].theta, fast)
        fits[m] = mixture_quantiles(mu, posts[m].sigma, QUANTILES)
    # predictive curves on a velocity grid at the mean shot mass
    grid = np.linspace(0.85 * shots.velocity.min(), 1.1 * shots.velocity.max(), 21)
    grid_shots = ShotSet(grid, np.full(grid.shape, float(np.mean(shots.mass))), np.full(grid.shape, np.nan),
                         tuple(f"U{k}" for k in range(len(grid))))
    draws = {m: (posts[m].theta, posts[m].sigma) for m in models}
    if eroding:
        pred = {ERODING: _quantiles_at(_eroding_depths(case, coefficients, keys, grid_shots)[0], draws[ERODING])}
    else:
        pred = _predict(target, models, grid_shots, draws)
    curves = {"velocity_m_s": grid.tolist(), "mass_kg": float(np.mean(shots.mass)),
              "models": {m: {f"{p:g}": pred[m][0][k].tolist() for k, p in enumerate(QUANTILES)} for m in models}}
    histograms = {}
    for m in models:
        h = {}
        for j, k in enumerate(keys):
            dens, edges = np.histogram(posts[m].theta[:, j], bins=30, density=True)
            h[k] = {"centres": (0.5 * (edges[1:] + edges[:-1])).tolist(), "density": dens.tolist()}
        dens, edges = np.histogram(posts[m].sigma, bins=30, density=True)
        h["sigma"] = {"centres": (0.5 * (edges[1:] + edges[:-1])).tolist(), "density": dens.tolist()}
        histograms[m] = h
    posterior = _posterior_json(case, target, keys, units, sec.discrepancy, shots, posts, fits, record)
    return {
        "posterior": posterior,
        "shots": shots,
        "curves": curves,
        "histograms": histograms,
        "timing_s": {"wall": time.perf_counter() - t0, "cpu": time.process_time() - c0},
        "settings": {"models": list(models), "parameters": list(keys), "units": units, "R_range_Pa": (lo, hi),
                     "surrogate_nodes": SURROGATE_NODES, "discrepancy_prior": sec.discrepancy, "eroding": eroding},
        "_internal": {"target": target, "surrogates": depth_models, "posts": posts, "priors": priors,
                      "sigma_prior": sigma_prior, "section": sec,
                      "resistance": fast, "coefficients": coefficients},
    }


def check_target(case, target_obj: dict, keys) -> None:
    """Refuse (InputError, exit 2) a case whose target differs from the posterior's."""
    from semianalytic.penetration.resistance import resistance_from_case

    rho = float(case.require("target").density)
    rho_post = float(target_obj["density_kg_m3"])
    if not math.isclose(rho, rho_post, rel_tol=1e-9):
        raise InputError("target.density", f"the posterior was calibrated on a target of {rho_post:g} kg/m^3; "
                                           f"the case has {rho:g} kg/m^3")
    res = resistance_from_case(case)
    if res.name != target_obj["resistance_model"]:
        raise InputError("target.resistance.model", f"the posterior was calibrated with the "
                                                    f"'{target_obj['resistance_model']}' resistance; the case has '{res.name}'")
    names = {f.name for f in dataclasses.fields(res)}
    for key in keys:
        if key not in ERODING_KEYS and key.rsplit(".", 1)[-1] not in names:
            raise InputError(key, "the case's resistance model has no such parameter")
    for k, v in target_obj["resistance_fixed"].items():
        here = getattr(res, k, None)
        if here is None or not math.isclose(float(here), float(v), rel_tol=1e-9):
            raise InputError(f"target.resistance.{k}", f"the posterior was calibrated with {k} = {v:g} (SI); "
                                                       f"the case has {here!r}")


def cross_validate(case, coefficients, result: dict, transfer=(), *, progress: bool = False,
                   loo_steps: int | None = None) -> dict:
    """Leave-one-out (exact refits) and transfer splits for every model of ``result``
    (from :func:`calibrate_case`).  ``transfer``: [(case, coefficients)] with the same target."""
    import time

    from tqdm import tqdm

    t0, c0 = time.perf_counter(), time.process_time()
    it = result["_internal"]
    target, surrogates, posts = it["target"], it["surrogates"], it["posts"]
    sec = it["section"]
    keys = tuple(result["settings"]["parameters"])
    shots: ShotSet = result["shots"]
    models = result["settings"]["models"]
    steps = loo_steps or LOO_STEPS
    out = {"loo": {}, "transfer": {}, "loo_steps": steps}
    n = len(shots)
    bar = tqdm(total=len(models) * n, desc="leave-one-out refits", disable=not progress, file=None, leave=False)
    for m in models:
        sur = surrogates[m]
        q = np.empty((len(QUANTILES), n))
        lpd = np.empty(n)
        for i in range(n):
            keep = np.array([k for k in range(n) if k != i])
            problem = _problem(keys, it["priors"], it["sigma_prior"], it["resistance"], sur.subset(keep), shots.depth[keep])
            post = sample_posterior(problem, walkers=sec.walkers, steps=steps, burn=steps // 4, seed=sec.seed + i + 1,
                                    start=posts[m].mode_u)
            mu = sur.subset([i]).log_depth_theta(post.theta, it["resistance"])
            q[:, i] = mixture_quantiles(mu, post.sigma, QUANTILES)[:, 0]
            lpd[i] = log_predictive_density(mu, post.sigma, shots.depth[i : i + 1])[0]
            bar.update()
        out["loo"][m] = {"statistics": _stats(q, lpd, shots.depth),
                         "shots": {"id": list(shots.ids), "measured_m": shots.depth.tolist(),
                                   **{f"{p:g}": q[k].tolist() for k, p in enumerate(QUANTILES)}}}
    bar.close()
    out["timing_s"] = {"loo_wall": time.perf_counter() - t0, "loo_cpu": time.process_time() - c0}
    for tcase, tcoef in transfer:
        t1, c1 = time.perf_counter(), time.process_time()
        check_target(tcase, result["posterior"]["target"], keys)
        eroding = result["settings"].get("eroding", False)
        ttarget = _target(tcase, tcoef, keys, cavity_shape=target.inputs.cavity_shape, models=() if eroding else models)
        tshots = load_shot_set(tcase, ttarget.inputs.setup.mass, minimum=1, regime=ERODING if eroding else "rigid")
        draws = {m: (posts[m].theta, posts[m].sigma) for m in models}
        if eroding:
            record = result["posterior"]["models"][ERODING]["eroding"]
            check_eroding(tcase, tcoef, record, keys)
            pred = {ERODING: _quantiles_at(_eroding_depths(tcase, tcoef, keys, tshots, record["fixed"])[0], draws[ERODING])}
        else:
            pred = _predict(ttarget, models, tshots, draws)
        entry = {"case": str(tcase.path) if tcase.path else tcase.title, "title": tcase.title, "models": {}}
        for m in models:
            q, mu, sigma = pred[m]
            lpd = log_predictive_density(mu, sigma, tshots.depth)
            entry["models"][m] = {"statistics": _stats(q, lpd, tshots.depth),
                                  "shots": {"id": list(tshots.ids), "velocity_m_s": tshots.velocity.tolist(),
                                            "measured_m": tshots.depth.tolist(),
                                            **{f"{p:g}": q[k].tolist() for k, p in enumerate(QUANTILES)}}}
        entry["timing_s"] = {"wall": time.perf_counter() - t1, "cpu": time.process_time() - c1}
        out["transfer"][entry["case"]] = entry
    return out


def check_eroding(case, coefficients, record: dict, keys) -> None:
    """Refuse (InputError, exit 2) a case whose projectile differs from the one an eroding
    posterior was calibrated for: the rod's Y_p is a projectile property (its density stands for
    the material), and a parameter held fixed in the calibration must have the same value here."""
    from semianalytic.penetration.curve import PenetrationSetup
    from semianalytic.penetration.regime_setup import eroding_inputs

    ei = eroding_inputs(case, PenetrationSetup.from_case(case, coefficients, require_material=False))
    rho = float(record["projectile_density_kg_m3"])
    if not math.isclose(ei.density, rho, rel_tol=1e-9):
        raise InputError("projectile.density", f"the eroding posterior was calibrated for a rod of {rho:g} kg/m^3 "
                                               f"(its Y_p is that material's); the case's projectile has {ei.density:g} kg/m^3")
    here = {ERODING_KEYS[0]: ei.target_resistance, ERODING_KEYS[1]: ei.rod_strength}
    for k, v in record["fixed"].items():
        if not math.isclose(here[k], float(v), rel_tol=1e-9):
            raise InputError(k, f"the eroding posterior was calibrated with {k} = {v / 1e6:g} MPa held fixed; the case "
                                f"has {here[k] / 1e6:g} MPa")


def _regime_aware(case, coefficients, U, quantiles: dict, part1_model: str | None) -> tuple[dict, dict, list[str]]:
    """The regime-aware predictive quantiles at ``U``: per velocity the quantiles of the model
    that holds in the case's predicted regime (penetration.regime_setup.regime_labels, the same
    labels as ``penetrate``'s ``regime``): a rigid-projectile model while the projectile is rigid,
    the eroding rod beyond the breakup (default rule ``meyer``, as ``depth_m``).  Returns
    ({quantile: list}, {"regime": [...], "rigid_model": name, "eroding_model": name}, warnings)."""
    from semianalytic.penetration.curve import PenetrationSetup
    from semianalytic.penetration.regime_setup import DEFAULT_PART1_MODEL, DEFAULT_REGIME_RULE, PART1_MODELS, regime_labels

    setup = PenetrationSetup.from_case(case, coefficients, require_material=False)
    warnings = []
    if setup.rod is None or setup.yield_stress is None:
        return {}, {}, ["warning: posterior: no regime-aware intervals: the regimes need the projectile's youngs_modulus and "
                        "yield_stress (U_sC of Part I, eqs. (33)/(36))"]
    regimes, _, _, _, U_b = regime_labels(case, setup, U)  # the labels of penetrate's regime (default rule)
    eroding_band = (list(np.asarray(U, float) >= U_b) if DEFAULT_REGIME_RULE in ("tate_tabor", "meyer")
                    else [r == "eroding" for r in regimes])
    order = [part1_model or DEFAULT_PART1_MODEL, *PART1_MODELS, *MODELS]
    rigid = next((m for m in order if m in quantiles and m != ERODING), None)
    ero = ERODING if ERODING in quantiles else None
    nan = [math.nan] * len(U)
    out = {}
    for p in QUANTILES:
        key = f"{p:g}"
        r_q = quantiles[rigid][key] if rigid else nan
        e_q = quantiles[ero][key] if ero else nan
        out[key] = [e if band else r for band, r, e in zip(eroding_band, r_q, e_q)]
    for label, model, mask in (("rigid", rigid, [not b for b in eroding_band]), ("eroding", ero, eroding_band)):
        if model is None and any(mask):
            at = ", ".join(f"{u:.0f}" for u, k in zip(U, mask) if k)
            how = "calibrate --model eroding" if label == "eroding" else "calibrate on the rigid shots"
            warnings.append(f"posterior: no {label} model in the posterior file(s): the regime-aware intervals at U_s = "
                            f"{at} m/s are NaN; add --posterior with a file of {how}")
    if rigid is not None and part1_model is not None and rigid != part1_model:
        warnings.append(f"posterior: {part1_model} is not in the posterior file(s); the regime-aware intervals below "
                        f"the erosion onset use {rigid}")
    return out, {"regime": regimes, "rigid_model": rigid, "eroding_model": ero}, [f"warning: {w}" for w in warnings]


def check_posterior_files(paths) -> None:
    """Every check of ``--posterior`` files that needs no case, before anything is computed: a
    regimes posterior by :func:`.regimes.load_regimes_file`, any other by :func:`.case.read_posterior`
    (draws finite, one per draw, inside their priors' support); InputError naming the file."""
    from semianalytic.calibration.regimes import is_regimes_posterior, load_regimes_file

    for one in paths:
        if is_regimes_posterior(one):
            load_regimes_file(one)
        else:
            read_posterior(one)


def predict_with_posterior(case, coefficients, path, velocities=None, *, part1_model: str | None = None) -> dict:
    """{"depth_quantiles_m": {model: {"0.05": [...], "0.5": [...], "0.95": [...], ...}}} at the
    case's striking velocities (or ``velocities``), with the case's projectile (mass from its
    geometry and density) and the posterior's target parameters.

    ``path``: one posterior file or several (e.g. one of the rigid-shot models and one of the
    eroding rod; a model may appear in one file only).  ``depth_quantiles_m`` also holds
    ``"regime_aware"``: per velocity the quantiles of the model of its predicted regime
    (:func:`_regime_aware`; the model names in ``posterior_regime_aware``).  ``warnings``:
    lines for stderr."""
    from semianalytic.calibration.regimes import is_regimes_posterior, predict_case

    paths = [path] if isinstance(path, (str, bytes)) or not hasattr(path, "__iter__") else list(path)
    U = np.asarray(case.require("impact").striking_velocities if velocities is None else velocities, float)
    quantiles, seen = {}, {}
    transfer_models, transfer_notes = {}, []
    regime_files = [p for p in paths if is_regimes_posterior(p)]
    if len(regime_files) > 1:
        raise InputError("--posterior", f"two regimes posteriors ({regime_files[0]} and {regime_files[1]}); give one")
    for one in paths:
        if one in regime_files:
            continue
        post = read_posterior(one)
        keys = post["parameters"]
        check_target(case, post["target"], keys)
        models = tuple(post["models"])
        for m in models:
            if m in seen:
                raise InputError("--posterior", f"model {m!r} is in two posterior files ({seen[m]} and {one})")
            seen[m] = str(one)
        draws = {m: (post["models"][m]["theta"], post["models"][m]["sigma"]) for m in models}
        rigid = tuple(m for m in models if m != ERODING)
        differs = _projectile_transfer(case, post["raw"]) if rigid else []
        if differs:
            added = {m: TRANSFER_SIGMA.get(m, max(TRANSFER_SIGMA.values())) for m in rigid}
            for m in rigid:
                draws[m] = (draws[m][0], np.sqrt(draws[m][1] ** 2 + added[m] ** 2))
            transfer_models[str(one)] = {"reasons": differs, "sigma_added": added}
            transfer_notes.append(f"note: posterior {one}: fitted for another projectile ({', '.join(differs)}): a transfer; "
                                  "the depth scatter sigma of each rigid-projectile model is widened in quadrature by its "
                                  "transfer inflation measured on the bundled data ("
                                  + ", ".join(f"{m} {v:.3f}" for m, v in added.items()) + ")")
        if rigid:
            target = _target(case, coefficients, keys, cavity_shape=post["cavity_shape"], models=rigid)
            shots = ShotSet(U, np.full(U.shape, target.inputs.setup.mass), np.full(U.shape, np.nan),
                            tuple(str(k) for k in range(len(U))))
            pred = _predict(target, rigid, shots, draws)
            quantiles.update({m: {f"{p:g}": pred[m][0][k].tolist() for k, p in enumerate(QUANTILES)} for m in rigid})
        if ERODING in models:
            record = post["models"][ERODING]["eroding"]
            mkeys = post["models"][ERODING]["parameters"]
            check_eroding(case, coefficients, record, mkeys)
            from semianalytic.penetration.curve import PenetrationSetup

            mass = PenetrationSetup.from_case(case, coefficients, require_material=False).mass
            shots = ShotSet(U, np.full(U.shape, mass), np.full(U.shape, np.nan), tuple(str(k) for k in range(len(U))))
            q = _quantiles_at(_eroding_depths(case, coefficients, mkeys, shots, record["fixed"])[0], draws[ERODING])[0]
            quantiles[ERODING] = {f"{p:g}": q[k].tolist() for k, p in enumerate(QUANTILES)}
    extra = {}
    if regime_files:  # issue 22: the regime mixture replaces the per-regime pick
        rp = predict_case(case, coefficients, regime_files[0], U)
        aware, warnings = rp["quantiles"], rp["warnings"]
        info = {"model": "regimes", "options": rp["options"], "file": str(regime_files[0])}
        extra = {"regime_probability": rp["regime_probability"], "regime_model_holds": rp["model_holds"],
                 "regime_notes": rp["notes"], "posterior_transfer": rp["transfer"],
                 "regime_transition_velocities_m_s": rp["transition_velocities_m_s"],
                 "regime_transition_intervals_90_m_s": rp["transition_intervals_90_m_s"]}
    else:
        aware, info, warnings = _regime_aware(case, coefficients, U, quantiles, part1_model)
    if aware:
        quantiles["regime_aware"] = aware
    warnings = [*transfer_notes, *warnings]
    if transfer_models:
        extra["posterior_transfer_models"] = transfer_models
    return {
        "depth_quantiles_m": quantiles,
        "posterior_file": ", ".join(map(str, paths)),
        "posterior_regime_aware": info,
        **extra,
        "warnings": warnings,
    }
