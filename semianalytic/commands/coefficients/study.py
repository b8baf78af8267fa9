"""Studies behind the coefficient reports: the certified tables against direct BEM solves at
random depths, their cost, and the effect of the contact region of eq. (15) on the depths.

Called by ``python -m semianalytic bench-bem`` (which writes the reports) and by the tests.
"""

from __future__ import annotations

import math
import time

import numpy as np

__all__ = ["VELOCITIES", "fig5_projectiles", "fig5_tables", "separation_velocity", "separation_onsets", "STUDY_NOSES", "study_nose", "random_depths", "table_error_study", "certified_timing", "contact_effect",  # noqa: E501
           "reach_depths", "reach_study"]


VELOCITIES = np.linspace(100.0, 2500.0, 49)  # the striking velocities of the contact study [m/s]


def fig5_projectiles():
    """The two Fig. 5 projectiles (d = 7.11 mm, L_c = 59.3 mm; densities of the Fig. 14/15 shots)."""
    from semianalytic.geometry import Projectile, ogive_nose, sphere_nose

    return [
        ("ogive", Projectile(ogive_nose(7.11e-3, 3.0), 59.3e-3, 8020.0)),
        ("sphere", Projectile(sphere_nose(7.11e-3), 59.3e-3, 8000.0)),
    ]


def fig5_tables(n_depths: int | None = None):
    """(name, projectile, coefficient table) of the Fig. 5 projectiles: the certified tables, or
    ``n_depths`` fixed depths."""
    from semianalytic.coefficients.table import coefficient_table

    return [(name, proj, coefficient_table(proj.nose, n_depths=n_depths) if n_depths else coefficient_table(proj.nose))
            for name, proj in fig5_projectiles()]


def separation_velocity(table, mass: float, rho: float, R_t: float, reading: str, depths):
    """Lowest velocity (of VELOCITIES) at which p_c <= 0 somewhere on the nose (eq. (15)),
    with du/dt from eq. (11) at that depth and velocity; None if the contact stays full.
    Returns (velocity, depth, separated interval in target-frame x)."""
    from semianalytic.penetration.motion import eq11_acceleration

    for u in VELOCITIES:
        for P in depths:
            du_dt = eq11_acceleration(table.A(P), table.B(P, reading), table.C(P), mass, rho, R_t, u * u)
            sep = table.contact_intervals(P, rho, u, du_dt, R_t, reading)
            if sep:
                return float(u), float(P), sep[0]
    return None


def separation_onsets(table, mass: float, rho: float, R_t: float) -> dict:
    """reading -> phase of entry -> :func:`separation_velocity` over the table's knots of that phase
    (entry P < L_h, shoulder at the surface L_h < P < 1.1 L_h, nose in P >= 1.1 L_h)."""
    from semianalytic.coefficients import READINGS

    P, Lh = table.depth, table.nose_length
    phases = (("entry, P < L_h", P[P < Lh]), ("shoulder at the surface, L_h < P < 1.1 L_h", P[(P > Lh) & (P < 1.1 * Lh)]),
              ("nose in, P >= 1.1 L_h", P[P >= 1.1 * Lh]))
    return {r: {name: separation_velocity(table, mass, rho, R_t, r, d) for name, d in phases} for r in READINGS}


def study_nose(kind: str, diameter: float = 7.11e-3):
    """The noses of the table studies (Fig. 5 ogive and sphere; 30-degree cone; flat; a table nose)."""
    from semianalytic import geometry as g

    if kind == "ogive":
        return g.ogive_nose(diameter, 3.0)
    if kind == "sphere":
        return g.sphere_nose(diameter)
    if kind == "cone":
        return g.cone_nose(diameter, math.radians(30.0))
    if kind == "flat":
        return g.flat_nose(diameter)
    if kind == "table":
        pts = [[0, 0], [2e-3, 1.8e-3], [4e-3, 2.7e-3], [6e-3, 3.2e-3], [8e-3, 0.5 * diameter]]
        return g.table_nose([(x * diameter / 7.11e-3, r * diameter / 7.11e-3) for x, r in pts], diameter)
    raise ValueError(f"unknown study nose {kind!r}")


STUDY_NOSES = ("ogive", "sphere", "cone", "flat", "table")


def random_depths(nose, n: int, seed: int) -> np.ndarray:
    """Seeded random depths: a third in 0.9-1.3 L_h (just past the shoulder, where the
    coefficients change fastest), the rest log-uniform from 0.01 to 200 nose lengths."""
    rng = np.random.default_rng(seed)
    L = nose.depth_unit
    k = n // 3
    near = rng.uniform(0.9, 1.3, k)
    far = np.exp(rng.uniform(math.log(0.01), math.log(200.0), n - k))
    return np.sort(np.concatenate([near, far])) * L


def table_error_study(nose, table, depths) -> dict:
    """Per coefficient (A, B_body, B_literal, B_bernoulli, C): the largest |interpolated -
    direct| over the depths relative to the coefficient's largest magnitude, and the smallest
    ratio of the table's error estimate to that actual difference."""
    from semianalytic.coefficients.table import CONTROLLED, direct_coefficients

    rows = direct_coefficients(nose, depths, order=table.options["order"], refinement=table.options["refinement"],
                               levels=table.options["levels"])
    scale = table.max_abs
    out = {}
    for q in CONTROLLED:
        direct = np.array([r[q] for r in rows])
        interp = np.asarray(table._eval(q, np.asarray(depths, float)))
        actual = np.abs(interp - direct)
        est = np.asarray(table.error(q, np.asarray(depths, float)))
        out[q] = {
            "max_rel_error": float(np.max(actual) / scale[q]),
            "min_estimate_ratio": float(np.min(est / np.maximum(actual, 1e-300))),
            "bounded": int(np.sum(est >= actual)),
            "n": len(depths),
        }
    return out


def reach_depths(nose, n: int = 1000, seed: int = 1000) -> np.ndarray:
    """The check of tight tables: n seeded random depths, a third in 0.9-1.3 L_h, the rest
    log-uniform from 1e-6 to 300 nose lengths (below the first knot and past the default range too)."""
    rng = np.random.default_rng(seed)
    L = nose.depth_unit
    k = n // 3
    return np.sort(np.concatenate([rng.uniform(0.9, 1.3, k) * L,
                                   np.exp(rng.uniform(math.log(1e-6), math.log(300.0), n - k)) * L]))


def reach_study(kind: str, tolerance: float = 1e-8, n: int = 1000, seed: int = 1000) -> dict:
    """A certified table of a study nose at ``tolerance`` with the default options (the depth
    range extending itself as the deep limit needs), and :func:`table_error_study` at
    :func:`reach_depths`: knots, solves' time, whether the range extended, noise-limited
    intervals, and per coefficient the largest error and the smallest estimate/error ratio."""
    import warnings

    from semianalytic.coefficients.table import coefficient_table

    nose = study_nose(kind)
    t = time.process_time()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the range extending itself warns; recorded below
        table = coefficient_table(nose, tolerance=tolerance)
    build = time.process_time() - t
    t = time.process_time()
    study = table_error_study(nose, table, reach_depths(nose, n, seed))
    return {"nose": kind, "knots": len(table.depth), "cpu_table_s": build, "cpu_check_s": time.process_time() - t,
            "max_depth_nose_lengths": table.options.get("max_depth_nose_lengths", 300.0),
            "noise_limited": table.options.get("noise_limited_intervals", 0), "study": study}


def certified_timing(kind: str, repeats: int = 2, tolerance: float = 1e-5) -> dict:
    """Best wall time of a certified table and of the legacy 60-depth table, in the same run."""
    from semianalytic.coefficients.table import coefficient_table

    nose = study_nose(kind)
    best = {"certified": math.inf, "fixed60": math.inf}
    table = None
    for _ in range(repeats):
        t = time.perf_counter()
        table = coefficient_table(nose, tolerance=tolerance)
        best["certified"] = min(best["certified"], time.perf_counter() - t)
        t = time.perf_counter()
        coefficient_table(nose, n_depths=60, bem_error=False)
        best["fixed60"] = min(best["fixed60"], time.perf_counter() - t)
    return {"nose": kind, "knots": len(table.depth), **best}


def contact_effect(case_paths, cache_dir=None) -> list[dict]:
    """Depths of each case with full contact and with the contact region of eq. (15)
    (``separated``), the relative change, and where the full-contact pressure would separate."""
    import dataclasses

    from semianalytic.cache import coefficients_for_case
    from semianalytic.case import load_case
    from semianalytic.commands.penetrate.evaluate import contact_summary
    from semianalytic.penetration.curve import PenetrationSetup, penetration_curve

    out = []
    for path in case_paths:
        case = load_case(path)
        table = coefficients_for_case(case, "bem", cache_dir=cache_dir)[0]
        setup = PenetrationSetup.from_case(case, table, require_material=False)
        U = np.asarray(case.impact.striking_velocities, float)
        elastic = setup.rod is not None and setup.yield_stress is not None
        t = time.perf_counter()
        full = penetration_curve(dataclasses.replace(setup, contact="full"), U, elastic=elastic)
        t_full = time.perf_counter() - t
        t = time.perf_counter()
        sep = penetration_curve(dataclasses.replace(setup, contact="separated"), U, elastic=elastic)
        t_sep = time.perf_counter() - t
        onset = contact_summary(setup, U)["separation_onset_m"]
        rel = {k: float(np.nanmax(np.abs(sep[k] / full[k] - 1.0))) if np.any(np.isfinite(full[k])) else math.nan
               for k in ("depth_rigid_m", "depth_elastic_exact_rod_m")}
        out.append({"case": str(path), "velocities": len(U), "separating": sum(p is not None for p in onset),
                    "onset_velocity_m_s": min((u for u, p in zip(U, onset) if p is not None), default=None),
                    "max_rel_change_rigid": rel["depth_rigid_m"], "max_rel_change_elastic_exact_rod": rel["depth_elastic_exact_rod_m"],
                    "time_full_s": t_full, "time_separated_s": t_sep})
    return out
