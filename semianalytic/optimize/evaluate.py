"""Evaluate nose designs (BEM in the loop) and drive the optimiser on the sweep's dask layer.

One design: the case with the design's overrides and the constrained shank
(:func:`~semianalytic.optimize.case.design_case`) -> the A, B, C table of its nose from the
per-user cache, keyed by the geometry hash (:func:`semianalytic.cache.coefficients_for_case`;
built by the BEM when absent) -> the objective (:mod:`~semianalytic.optimize.model`).

Optimisers (``method``):

- ``grid-pattern`` (default): the coarse grid below, then a compass search (a generalised
  pattern search: Torczon 1997; with bounds Lewis & Torczon 1999; review: Kolda, Lewis &
  Torczon, SIAM Review 45, 2003) from its best point: each poll evaluates the 2k points
  u +- h e_j of the current point together (in parallel on the workers), moves to the best if
  it improves, else halves h, from half a grid step down to ``resolution``.  Derivative-free
  and bounded like the simplex, but a poll's designs are independent, so both workers stay
  busy (Nelder-Mead evaluates one design at a time); converges to a point where no
  coordinate step of the finest size improves the objective (on a smooth objective, a
  stationary point, or a bound for a monotone one).  scipy has no parallel-poll pattern search.
- ``grid-nm``: a coarse grid over the bounds (``coarse`` points per variable, all
  designs evaluated in parallel on the dask workers), then scipy's Nelder-Mead with bounds
  from the grid's best point (initial simplex half a grid step wide, in coordinates scaled
  to [0, 1] per variable; stops when the simplex is within ``resolution`` of each range and
  the objectives within ``tol`` relative).  Why: the nose problems have one or two smooth
  parameters, where a grid of a few designs per variable finds the basin (and every corner of
  the bounds, where the optimum of a monotone objective lies) and a simplex converges in a few
  tens of designs; it needs no gradients (the BEM's panel layout changes with the geometry, so
  the objective has small discretisation steps that spoil finite differences) and keeps to
  the bounds.  The simplex is sequential (one design at a time), the grid is not.
- ``de``: scipy's ``differential_evolution``, bounded, ``vectorized=True`` with deferred
  updating: each generation's population is evaluated in parallel; no polish (same reason
  as the gradients).  More designs (popsize x variables per generation) for problems with
  several basins.

Designs are rounded to ``resolution`` of each range, so the search re-uses designs (memo
here) and their tables (disk cache).  The optimum is then checked on a finer grid around it,
and, when the design tables are lighter than the case's (``table_overrides``), re-evaluated
on the case's own tables (the objective's table error, reported).
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from semianalytic.errors import InputError
from semianalytic.optimize.case import Problem, design_case
from semianalytic.optimize.model import (
    CONFIRM_KNOTS_PER_PIECE,
    PLATE_OBJECTIVES,
    Infeasible,
    confirmation_grid,
    deep_drag,
    depth_objective,
    quantise,
)

PENALTY = 1.0e3  # objective of an invalid or infeasible design (objectives are O(0.1) in SI)
_SHAPE_KEYS = ("projectile.crh", "projectile.half_angle", "projectile.corner_radius", "projectile.meplat_diameter",
               "projectile.tip_radius", "projectile.exponent", "projectile.nose_length", "projectile.control_radii")
CLASSIC_NOSES: dict[str, dict[str, Any]] = {
    name: {**dict.fromkeys(_SHAPE_KEYS), **shape}  # None: the case's other shape keys removed (sharp tips)
    for name, shape in {
        "hemisphere": {"projectile.nose": "sphere"},
        "ogive crh 3": {"projectile.nose": "ogive", "projectile.crh": 3.0},
        # the cone as long as the crh-3 ogive: tan(half angle) = (1/2) / sqrt(3 - 1/4)
        "cone (ogive-3 length)": {"projectile.nose": "cone",
                                  "projectile.half_angle": f"{math.degrees(math.atan(0.5 / math.sqrt(2.75)))!r} deg"},
    }.items()
}


def evaluate_design(problem: Problem, overrides: Mapping[str, Any], cache_dir: str | None = None) -> dict:
    """One design's record: objective, depths, deep drag, mass, lengths, nose outline, status.

    Runs on a dask worker or inline; never raises for a bad design (status invalid/infeasible).
    """
    from semianalytic.cache import coefficients_for_case
    from semianalytic.geometry import projectile_from_section

    t0 = time.perf_counter()
    rec: dict[str, Any] = {"overrides": dict(overrides), "status": "ok", "message": "", "objective": PENALTY}
    try:
        case = design_case(problem, overrides)
        psec = case.require("projectile")
        proj = projectile_from_section(psec)
        rec.update(
            nose=psec.nose, mass_kg=proj.mass if (psec.density or psec.mass) else None, length_m=proj.length,
            shank_length_m=proj.shank_length, nose_length_m=proj.nose_length,
            outline_m=np.asarray(proj.nose.meridian().sample(24)).round(12).tolist(),
        )
        if problem.objective == "deep_drag":  # the deep limit alone: a few solves at depth, no table
            lim = deep_limit_of_case(case, proj.nose)
            rec["deep_drag_Bbar"] = deep_drag(lim.values[f"B_{case.coefficients.reading}"], psec.diameter)
            rec["bem_depths_solved"] = lim.solves
        elif problem.objective in PLATE_OBJECTIVES:  # the plate's tables only (no half-space table)
            rec.update(plate_objective(problem, case, cache_dir))
        elif problem.objective == "depth" and problem.depth_knots and not problem.table_overrides:
            rec.update(depth_record(problem, case, proj.nose, cache_dir))  # only the depths it reads
        else:
            table = coefficients_for_case(case, "bem", cache_dir=cache_dir)[0]
            rec["deep_drag_Bbar"] = deep_drag(table.deep_limit()[1], psec.diameter)
        if problem.objective in PLATE_OBJECTIVES or "depths_m" in rec:
            pass
        elif problem.objective == "depth":
            depths = _depths(problem, case, table)
            rec["depths_m"] = [float(v) for v in depths]
            rec["objective"] = depth_objective(depths)
        else:
            rec["objective"] = rec["deep_drag_Bbar"]
        if not math.isfinite(rec["objective"]):
            rec.update(status="error", message="objective not finite", objective=PENALTY)
    except Infeasible as exc:
        rec.update(status="infeasible", message=f"--constraint {exc.constraint}: {exc}")
    except InputError as exc:
        rec.update(status="invalid", message=str(exc))
    except Exception as exc:  # one failing design must not stop the search
        rec.update(status="error", message=f"{type(exc).__name__}: {exc}")
    rec["seconds"] = time.perf_counter() - t0
    return rec


def _depths(problem: Problem, case, coefficients) -> np.ndarray:
    """The final depths at the problem's striking velocities (Part I, eq. (11); rigid, or the
    elastic projectile with the exact-rod energy, errata item 5)."""
    from semianalytic.penetration.curve import PenetrationSetup, penetration_curve

    exact = problem.depth_model == "exact-rod"
    setup = PenetrationSetup.from_case(case, coefficients, require_material=exact)
    res = penetration_curve(setup, np.asarray(problem.velocities), elastic=exact)
    return np.asarray(res["depth_elastic_exact_rod_m" if exact else "depth_rigid_m"], float)


def depth_record(problem: Problem, case, nose, cache_dir=None, per_piece: int | None = None) -> dict:
    """The ``depth`` objective from the depths it reads alone (issue 24): the deep limit from four
    solves (:func:`~semianalytic.optimize.model.deep_limit`, 2 to 16 nose lengths), the deepest
    final depth with those constant A, B, C (Part I, eq. (11)), the table range P_max
    (:func:`~semianalytic.optimize.model.depth_range`) and a coefficient table over [0, P_max]
    alone (:func:`~semianalytic.optimize.model.depth_knots`, ``per_piece`` knots per smooth piece;
    default ``problem.depth_knots``), cached like any table; when a final depth lies past P_max
    the range is widened to 1.5 times it and the table rebuilt.  Returns the record's fields."""
    from semianalytic.cache import cached_coefficient_table, case_table_request
    from semianalytic.coefficients import ConstantCoefficients
    from semianalytic.optimize.model import deep_limit, depth_knots, depth_range

    cs = case.coefficients
    _, kw = case_table_request(case)
    bem = {k: kw[k] for k in ("order", "refinement") if k in kw}
    lim = deep_limit(nose, max_depth_nose_lengths=16.0, max_solves=4, strict=False, **bem)
    B = lim.values[f"B_{cs.reading}"]
    const = ConstantCoefficients(lim.values["A"], B, lim.values["C"], nose.diameter)
    import dataclasses

    rigid = dataclasses.replace(problem, depth_model="rigid")
    estimate = float(np.max(_depths(rigid, case, const)))
    P_max = depth_range(estimate, nose.length)
    per_piece = per_piece or problem.depth_knots
    for _ in range(3):
        knots = depth_knots(nose, P_max, per_piece)
        table = cached_coefficient_table(nose, cache_dir, depths=knots, bem_error=False, **bem).with_reading(cs.reading)
        depths = _depths(problem, case, table)
        deepest = float(np.max(depths)) if np.all(np.isfinite(depths)) else math.inf
        if deepest <= P_max:
            break
        P_max = 1.5 * deepest if math.isfinite(deepest) else 2.0 * P_max
    else:
        raise RuntimeError(f"the final depth {deepest:.4g} m stays past the table range {P_max:.4g} m")
    return {"deep_drag_Bbar": deep_drag(B, nose.diameter), "depths_m": [float(v) for v in depths],
            "objective": depth_objective(depths), "table_range_m": P_max, "table_knots": len(knots),
            "deep_estimate_m": estimate, "bem_depths_solved": lim.solves + len(table.depth)}


def plate_objective(problem: Problem, case, cache_dir=None) -> dict:
    """``ballistic_limit``: V_bl of Part I, eq. (11) through the plate found by the model itself
    (:func:`semianalytic.perforation.ballistic_limit_search`, up to the rigid-projectile limit),
    minimised; ``residual_velocity``: minus the mean V_r over the striking velocities
    (:func:`semianalytic.perforation.residual_velocity`).  A design not perforated inside the model's
    range (or stopped at every velocity) raises :class:`Infeasible` (issue 37: never a number)."""
    from semianalytic.commands.perforate.evaluate import perforation_setup
    from semianalytic.perforation import residual_velocity

    setup = perforation_setup(case, cache_dir)
    out: dict = {"plate_thickness_m": setup.thickness}
    if problem.objective == "residual_velocity":
        vr = np.asarray(residual_velocity(setup.coefficients, setup.mass, np.asarray(problem.velocities, float)), float)
        out["residual_velocities_m_s"] = vr.tolist()
        if not np.any(vr > 0):  # issue 37: a design not perforated is infeasible, never a number
            raise Infeasible("residual_velocity", "the plate stops the projectile at every striking velocity "
                             "(no residual velocity to minimise)")
        out["objective"] = -float(np.mean(vr))
        return out
    from semianalytic.perforation.model import ballistic_limit_search

    bl = ballistic_limit_search(setup.coefficients, setup.mass, setup.v_max)
    if bl.bound == "lower":  # issue 37: not perforated inside the model's range
        raise Infeasible("ballistic_limit", f"not perforated inside the model's range: {bl.reason}")
    out.update(objective=bl.value, ballistic_limit_m_s=bl.value, ballistic_limit_error_m_s=bl.error)
    return out


def deep_limit_of_case(case, nose):
    """:func:`~semianalytic.optimize.model.deep_limit` with the case's BEM and table options."""
    from semianalytic.optimize.model import deep_limit

    cs = case.coefficients
    kw = dict(order=case.bem.order, tolerance=cs.tolerance, max_depth_nose_lengths=cs.max_depth_nose_lengths,
              strict=cs.depths is None)
    if getattr(case.bem, "refinement", None) is not None:
        kw["refinement"] = case.bem.refinement
    try:
        return deep_limit(nose, **kw)
    except ValueError as exc:
        raise InputError("coefficients.max_depth_nose_lengths", str(exc)) from None


@dataclass
class Evaluator:
    """Evaluates lists of designs, in parallel on a dask client or inline; remembers them."""

    problem: Problem
    client: Any = None
    cache_dir: str | None = None
    on_done: Callable[[int], None] | None = None
    memo: dict = field(default_factory=dict)
    history: list = field(default_factory=list)

    def map(self, designs: list[Mapping[str, Any]], phase: str, generation: int = 0, x=None) -> list[dict]:
        keys = [json.dumps(d, sort_keys=True) for d in designs]
        todo = list(dict.fromkeys(k for k in keys if k not in self.memo))
        if todo:
            if self.client is None:
                for k in todo:
                    self.memo[k] = evaluate_design(self.problem, json.loads(k), self.cache_dir)
                    if self.on_done:
                        self.on_done(1)
            else:
                from dask.distributed import as_completed

                futs = {self.client.submit(evaluate_design, self.problem, json.loads(k), self.cache_dir, pure=False): k
                        for k in todo}
                for fut in as_completed(futs):
                    self.memo[futs[fut]] = fut.result()
                    if self.on_done:
                        self.on_done(1)
        out = []
        for i, k in enumerate(keys):
            rec = dict(self.memo[k])
            rec.update(phase=phase, generation=generation, new=k in todo and k not in keys[:i])
            if x is not None:
                rec["x"] = [float(v) for v in x[i]]
            self.history.append(rec)
            out.append(rec)
        return out


def _start_x(problem: Problem) -> list[float] | None:
    """The case's own value of each design variable (None if a key is absent from the case)."""
    from semianalytic.case import parse_case

    raw = json.loads(problem.raw_json)
    case = parse_case(raw)
    psec = case.require("projectile")
    x = []
    from semianalytic.optimize.case import control_index

    for v in problem.variables:
        k = control_index(v.key)
        val = psec.control_radii[k] if k is not None else getattr(psec, v.key.split(".", 1)[1], None)
        if val is None:
            val = 0.0 if v.unit == "m" else None
        if val is None:
            return None
        x.append(float(val))
    return x


def _grid_nelder_mead(batch, k: int, coarse: int, resolution: float, tol: float, maxfev: int):
    """Coarse grid, then Nelder-Mead with bounds (module docstring); ``batch(U, phase)`` evaluates
    designs given in [0, 1]^k coordinates and returns their objectives.  Returns a summary dict."""
    from scipy.optimize import minimize

    U, u0, f0 = _coarse_grid(batch, k, coarse)
    h = 0.5 / (coarse - 1)  # half a grid step: the simplex starts inside the grid cell of the best point
    simplex = [u0] + [u0 + np.where(np.arange(k) == j, h if u0[j] + h <= 1.0 else -h, 0.0) for j in range(k)]
    res = minimize(lambda u: float(batch(np.atleast_2d(u), "search")[0]), u0, method="Nelder-Mead",
                   bounds=[(0.0, 1.0)] * k,
                   options={"initial_simplex": np.array(simplex), "xatol": resolution,
                            "fatol": tol * max(abs(f0), 1e-300), "maxfev": maxfev})
    return {"method": "coarse grid + scipy.optimize.minimize(Nelder-Mead, bounds)", "coarse": coarse,
            "maxfev": maxfev, "nfev": int(res.nfev) + len(U), "nit": int(res.nit), "message": str(res.message),
            "success": bool(res.success)}


def _coarse_grid(batch, k: int, coarse: int):
    axes = [np.linspace(0.0, 1.0, coarse)] * k
    U = np.column_stack([m.ravel() for m in np.meshgrid(*axes, indexing="ij")])
    f = batch(U, "grid")
    i = int(np.argmin(f))
    return U, U[i], float(f[i])


def _grid_pattern(batch, k: int, coarse: int, resolution: float, max_polls: int):
    """Coarse grid, then a compass (pattern) search from its best point (module docstring): each poll
    evaluates the 2k points u +- h e_j (clipped to the bounds) together; the best one that improves
    becomes u, else h is halved; from half a grid step down to ``resolution`` of each range."""
    U, u, f = _coarse_grid(batch, k, coarse)
    h = 0.5 / (coarse - 1)
    polls = moves = 0
    while h >= resolution and polls < max_polls:
        pts = np.clip(np.vstack([u + s * h * np.eye(k)[j] for j in range(k) for s in (1.0, -1.0)]), 0.0, 1.0)
        pts = np.unique(pts[np.any(np.abs(pts - u) > 0.5 * resolution, axis=1)], axis=0)
        polls += 1
        if len(pts):
            fs = batch(pts, "search")
            j = int(np.argmin(fs))
            if fs[j] < f:
                u, f = pts[j], float(fs[j])
                moves += 1
                continue
        h *= 0.5
    done = h < resolution
    return {"method": "coarse grid + compass search (polls of 2 x variables designs in parallel)", "coarse": coarse,
            "max_polls": max_polls, "polls": polls, "moves": moves, "final_step": h,
            "message": "step below the resolution" if done else
            "stopped at --maxfev polls", "success": bool(done)}


def known_result(problem: Problem, best_x) -> dict | None:
    """The optimum of a power-law or spline nose against the known minimum-drag exponent
    (:data:`~semianalytic.optimize.model.NEWTONIAN_MIN_DRAG_EXPONENT`): the power law's own
    exponent, or the exponent of the power law nearest the spline's meridian
    (:func:`~semianalytic.optimize.model.fitted_exponent`, on 400 points).  None for other noses."""
    from semianalytic.geometry import nose_from_section
    from semianalytic.optimize.model import NEWTONIAN_MIN_DRAG_EXPONENT, NEWTONIAN_SOURCE, fitted_exponent

    try:
        nose = nose_from_section(design_case(problem, problem.overrides(best_x)).require("projectile"))
    except (InputError, Infeasible):
        return None
    if nose.kind == "power":
        n, how = float(nose.parameters["exponent"]), "the optimum's exponent"
    elif nose.kind == "spline":
        x, r = nose.segments[0].point(np.linspace(0.0, 1.0, 401))
        n, how = fitted_exponent(-np.asarray(x), r, nose.length, nose.radius), \
            "the exponent of the power law nearest the optimum's meridian (least squares in r)"
    else:
        return None
    return {"exponent": n, "how": how, "reference_exponent": NEWTONIAN_MIN_DRAG_EXPONENT, "source": NEWTONIAN_SOURCE,
            "relative_difference": (n - NEWTONIAN_MIN_DRAG_EXPONENT) / NEWTONIAN_MIN_DRAG_EXPONENT}


def finer_bem(problem: Problem) -> tuple:
    """The finer BEM of the optimum's check: two Gauss points more per panel and twice the panels
    of the case's (order 8, refinement 0.3 by default: order 10, refinement 0.6)."""
    bem = json.loads(problem.raw_json).get("bem") or {}
    order, refinement = int(bem.get("order", 8)), float(bem.get("refinement") or 0.3)
    return (("bem.order", min(order + 2, 16)), ("bem.refinement", min(2.0 * refinement, 8.0)))


def finer_check(problem: Problem, best_x, low, high, cache_dir, n: int, half_width: float) -> dict | None:
    """The optimum checked on a finer BEM (:func:`finer_bem`: order + 2, twice the panels): the
    objective at the optimum and at its neighbours one confirmation-grid step away along each
    variable, re-solved; confirmed when no neighbour beats the optimum there, and, along each
    variable, the vertex of the parabola through the three (the finer optimum, this project's own
    check).  Only for ``deep_drag`` (a few solves per design); None otherwise."""
    import dataclasses

    if problem.objective != "deep_drag":
        return None
    extra = finer_bem(problem)
    fine = dataclasses.replace(problem, table_overrides=tuple(problem.table_overrides) + extra)
    best_x = np.asarray(best_x, float)
    step = 2.0 * half_width * (np.asarray(high) - np.asarray(low)) / max(n - 1, 1)
    f0 = evaluate_design(fine, problem.overrides(best_x), cache_dir)
    if f0["status"] != "ok":
        return {"status": f0["status"], "message": f0["message"]}
    out = {"bem": dict(extra), "objective": f0["objective"], "variables": [], "confirmed": True}
    for j in range(len(best_x)):
        fs, xs = [], []
        for sgn in (-1.0, 1.0):
            x = best_x.copy()
            x[j] = float(np.clip(x[j] + sgn * step[j], low[j], high[j]))
            if x[j] == best_x[j]:
                continue
            r = evaluate_design(fine, problem.overrides(x), cache_dir)
            if r["status"] == "ok":
                fs.append(r["objective"])
                xs.append(x[j])
        better = [f for f in fs if f < f0["objective"]]
        vertex = None
        if len(fs) == 2:
            (a, c), (fa, fc), b, fb = xs, fs, best_x[j], f0["objective"]
            den = (b - a) * (fb - fc) - (b - c) * (fb - fa)
            if den != 0.0:
                vertex = float(b - 0.5 * ((b - a) ** 2 * (fb - fc) - (b - c) ** 2 * (fb - fa)) / den)
        out["variables"].append({"x": xs, "objective": fs, "parabola_vertex": vertex, "step": float(step[j])})
        out["confirmed"] = out["confirmed"] and not better
    return out


def optimise(
    problem: Problem,
    *,
    client=None,
    cache_dir: str | None = None,
    method: str = "grid-pattern",
    coarse: int = 5,
    maxfev: int = 60,
    popsize: int = 5,
    maxiter: int = 12,
    tol: float = 1e-5,
    seed: int = 0,
    resolution: float = 1e-3,
    confirm: int = 5,
    confirm_half_width: float = 0.04,
    classic_noses: bool = True,
    finer_bem: bool = True,
    on_done: Callable[[int], None] | None = None,
) -> dict:
    """Search the problem's bounds (``method``: see the module docstring), then the confirmation
    grid, the optimum on the case's own tables (with lighter design tables) and the classic noses.
    Returns a plain dict (the optimum, the start, the grid, the classics, the history)."""
    t0 = time.perf_counter()
    low, high = np.array(problem.low), np.array(problem.high)
    ev = Evaluator(problem, client, cache_dir, on_done)
    start = _start_x(problem)
    start_rec = None
    if start is not None:
        xs = np.clip(start, low, high)
        start_rec = ev.map([problem.overrides(xs)], "start", 0, [xs])[0]
    gen = {"n": 0}

    def objective(X):  # X: (n_variables, population)
        pts = quantise(np.atleast_2d(X).T, low, high, resolution)
        recs = ev.map([problem.overrides(p) for p in pts], "search", gen["n"], pts)
        gen["n"] += 1
        return np.array([r["objective"] if r["status"] == "ok" else PENALTY for r in recs])

    if method == "de":
        from scipy.optimize import differential_evolution

        x0 = None if start is None else np.clip(start, low, high)
        res = differential_evolution(
            objective, list(zip(low, high)), popsize=popsize, maxiter=maxiter, tol=tol, seed=seed, polish=False,
            vectorized=True, updating="deferred", init="latinhypercube", x0=x0,
        )
        info = {"method": "scipy.optimize.differential_evolution (vectorized, deferred, no polish)",
                "popsize": popsize, "maxiter": maxiter, "nfev": int(res.nfev), "message": str(res.message),
                "success": bool(res.success)}
    elif method in ("grid-pattern", "grid-nm"):
        def batch(U, phase):
            pts = quantise(low + np.atleast_2d(U) * (high - low), low, high, resolution)
            recs = ev.map([problem.overrides(p) for p in pts], phase, gen["n"], pts)
            gen["n"] += 1
            return np.array([r["objective"] if r["status"] == "ok" else PENALTY for r in recs])

        if method == "grid-nm":
            info = _grid_nelder_mead(batch, len(low), coarse, resolution, tol, maxfev)
        else:
            info = _grid_pattern(batch, len(low), coarse, resolution, maxfev)
    else:
        raise InputError("--method", f"must be grid-pattern, grid-nm or de; got {method!r}")
    info.update(tol=tol, seed=seed, resolution=resolution, generations=gen["n"])
    info.setdefault("nfev", sum(1 for r in ev.history if r["phase"] in ("grid", "search")))
    # the optimum: the best design the search evaluated (the optimiser's own answer is one of them)
    searched = [r for r in ev.history if r["phase"] in ("search", "grid") and r["status"] == "ok"]
    if not searched:
        why = sorted({r["message"] for r in ev.history if r["status"] == "infeasible"})[:1]
        raise InputError("--vary", "no design within the bounds could be evaluated (see history: all invalid)"
                         + (f"; every design infeasible, e.g. {why[0]}" if why else ""))
    objs = [r["objective"] for r in searched]
    if (problem.objective in PLATE_OBJECTIVES and len(objs) > 1
            and max(objs) - min(objs) <= 1e-6 * max(max(abs(v) for v in objs), 1e-300)):
        raise InputError("--objective", f"{problem.objective} is the same ({objs[0]:.6g}, within 1e-6) for every design "
                         "evaluated: flat over the bounds, no optimum to report (change the striking velocities or the bounds)")
    best_x = np.asarray(min(searched, key=lambda r: r["objective"])["x"])
    best = ev.map([problem.overrides(best_x)], "optimum", gen["n"], [best_x])[0]
    search_seconds = time.perf_counter() - t0
    n_search = len({json.dumps(r["overrides"], sort_keys=True) for r in ev.history})

    grid = None
    confirm_designs = 0  # designs evaluated on the confirmation's finer tables (their own memo)
    if confirm >= 2:
        pts, spacing = confirmation_grid(best_x, low, high, confirm, confirm_half_width)
        ev_confirm, confirm_knots, ref = ev, None, best
        if problem.objective == "depth" and problem.depth_knots and not problem.table_overrides:
            # the optimum confirmed on finer tables (twice the knots per piece, at least CONFIRM_KNOTS_PER_PIECE)
            import dataclasses

            confirm_knots = max(CONFIRM_KNOTS_PER_PIECE, 2 * problem.depth_knots)
            ev_confirm = Evaluator(dataclasses.replace(problem, depth_knots=confirm_knots), client, cache_dir, on_done)
            ref = ev_confirm.map([problem.overrides(best_x)], "confirm", gen["n"], [best_x])[0]
        recs = ev_confirm.map([problem.overrides(p) for p in pts], "confirm", gen["n"], pts)
        if ev_confirm is not ev:
            ev.history += ev_confirm.history
            confirm_designs = len(ev_confirm.memo)
        f = np.array([r["objective"] if r["status"] == "ok" else PENALTY for r in recs])
        k = int(np.argmin(f))
        steps = np.abs(pts[k] - best_x) / np.where(spacing > 0, spacing, 1.0)
        grid = {
            "n_per_variable": confirm,
            "half_width_of_range": confirm_half_width,
            "spacing": spacing.tolist(),
            "best_x": pts[k].tolist(),
            "best_objective": float(f[k]),
            "optimum_objective": float(ref["objective"]),
            "distance_in_grid_steps": steps.tolist(),
            # confirmed: no grid point beats the optimum by more than the objective's numerical noise
            # (relative 1e-6: the BEM tables are converged to about that, see reports/bem_convergence.md),
            # or the grid's best is within one grid step of the optimum
            "confirmed": bool(f[k] >= ref["objective"] - 1e-6 * abs(ref["objective"]) or np.all(steps <= 1.0 + 1e-9)),
            "depth_knots": confirm_knots,
            "points": [{"x": p.tolist(), "objective": float(fi), "status": r["status"]} for p, fi, r in zip(pts, f, recs)],
        }
    own_tables = None
    reads_depths = problem.objective == "depth" and bool(problem.depth_knots) and not problem.table_overrides
    if problem.table_overrides or reads_depths:  # the optimum again on the case's own tables: the design tables' error
        import dataclasses

        own = evaluate_design(dataclasses.replace(problem, table_overrides=(), depth_knots=0), problem.overrides(best_x),
                              cache_dir)
        if own["status"] == "ok":
            own_tables = {"objective": own["objective"], "design_tables_objective": best["objective"],
                          "relative_difference": abs(best["objective"] - own["objective"]) / abs(own["objective"]),
                          "seconds": own["seconds"], "table_overrides": dict(problem.table_overrides)}
            if reads_depths:
                own_tables["depth_knots"] = problem.depth_knots
    finer = finer_check(problem, best_x, low, high, cache_dir, max(confirm, 5), confirm_half_width) if finer_bem else None
    known = known_result(problem, best_x)
    classic = {}
    if classic_noses:
        recs = ev.map(list(CLASSIC_NOSES.values()), "classic", gen["n"])
        classic = dict(zip(CLASSIC_NOSES, recs))
    return {
        "variables": [{"key": v.key, "low": v.low, "high": v.high, "unit": v.unit} for v in problem.variables],
        "objective": problem.objective,
        "depth_model": problem.depth_model,
        "constraints": list(problem.constraints),
        "fixed_mass_kg": problem.fixed_mass,
        "fixed_length_m": problem.fixed_length,
        "striking_velocities_m_s": list(problem.velocities),
        "optimizer": info,
        "own_tables_check": own_tables,
        "finer_check": finer,
        "optimum": {**best, "x": best_x.tolist()},
        "start": start_rec,
        "confirmation": grid,
        "classic": classic,
        "known_result": known,
        "n_designs_search": n_search,
        "n_designs_total": len(ev.memo) + confirm_designs,
        "seconds_search": search_seconds,
        "seconds_total": time.perf_counter() - t0,
        "history": ev.history,
    }
