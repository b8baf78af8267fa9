"""Verification studies behind the ``penetrate --report`` document (numbers only; the report module
formats them): the time integration of Part I, eq. (11) under tolerance refinement against the
integration in P, the wall times of the curves, and the histories of Figs. 9-11."""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass

import numpy as np

__all__ = ["ToleranceStudy", "tolerance_study", "curve_timings", "Histories", "histories"]


@dataclass(frozen=True)
class ToleranceStudy:
    """``rows``: (rtol, final depth [m], rel. change of the depth and of the time against rtol 1e-12,
    steps); ``reference``: the rtol 1e-12 MotionResult; ``spectral_depth``: the integration in P [m]."""

    rows: list[tuple[float, float, float, float, int]]
    reference: object
    spectral_depth: float


def tolerance_study(coef, mass: float, target_density: float, resistance_pa: float, U: float = 1000.0,
                    rtols=(1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)) -> ToleranceStudy:
    """solve_ivp (DOP853, event u = 0) at each ``rtol`` against rtol 1e-12, and the spectral
    integration in P (:func:`semianalytic.penetration.motion.final_depth`) against the same."""
    from semianalytic.penetration.motion import final_depth, solve_motion

    ref = solve_motion(coef, mass, target_density, resistance_pa, U, rtol=1e-12)
    rows = []
    for rtol in rtols:
        r = solve_motion(coef, mass, target_density, resistance_pa, U, rtol=rtol)
        rows.append((rtol, r.final_depth, abs(r.final_depth / ref.final_depth - 1),
                     abs(r.penetration_time / ref.penetration_time - 1), len(r.t)))
    Pf = float(final_depth(coef, mass, target_density, resistance_pa, U))
    return ToleranceStudy(rows, ref, Pf)


def curve_timings(setup, case, coef, w1, repeats: int = 3) -> dict[str, float]:
    """Best-of-``repeats`` wall times [s]: a 50-velocity penetration_curve, the 50-velocity
    evaluate_case without the [data] comparison, and 1000 rigid final depths (single run)."""
    from semianalytic.commands.penetrate.evaluate import evaluate_case
    from semianalytic.penetration.curve import penetration_curve
    from semianalytic.penetration.motion import final_depth

    def best(fn) -> float:
        out = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            fn()
            out.append(time.perf_counter() - t0)
        return min(out)

    U = np.linspace(400.0, 1800.0, 50)
    t_curve = best(lambda: penetration_curve(setup, U, w1=w1))
    t0 = time.perf_counter()
    final_depth(coef, setup.mass, setup.target_density, setup.resistance_pa, np.linspace(300.0, 2000.0, 1000))
    t_rigid = time.perf_counter() - t0
    U50 = np.linspace(500.0, 3000.0, 50)
    no_data = dataclasses.replace(case, sections={k: v for k, v in case.sections.items() if k != "data"})
    t_all = best(lambda: evaluate_case(no_data, coef, w1=w1, velocities=U50))
    return {"curve_50": t_curve, "evaluate_50": t_all, "rigid_1000": t_rigid}


@dataclass(frozen=True)
class Histories:
    """The rigid (1), quasi-rigid (2) and elastic (3: paper's W2; exact-rod W2) solutions at one
    striking velocity ``U`` [m/s] (Figs. 9-11)."""

    U: float
    rigid: object
    paper_w2: object
    exact_rod_w2: object

    @property
    def quasi_rigid(self):
        return self.paper_w2.quasi_rigid


def histories(setup, coef, U: float, w1, default_poisson_ratio: float = 0.29) -> Histories:
    """Part I, eq. (11) in time (rtol 1e-10) and the elastic projectile of eqs. (24)-(30') with both
    W2 readings, for one case at striking velocity ``U``."""
    from semianalytic.penetration.elastic import solve_elastic
    from semianalytic.penetration.motion import solve_motion

    rigid = solve_motion(coef, setup.mass, setup.target_density, setup.resistance_pa, U, rtol=1e-10)
    nu = setup.poisson_ratio if setup.poisson_ratio is not None else default_poisson_ratio
    args = (coef, setup.mass, setup.target_density, setup.resistance_pa, U, setup.rod)
    ep = solve_elastic(*args, poisson_ratio=nu, w2="paper", w1=w1)
    er = solve_elastic(*args, poisson_ratio=nu, w2="exact-rod", w1=w1)
    return Histories(U, rigid, ep, er)
