"""The sweep kernel of plates (issue 23 item 6): residual velocity and ballistic limit per case.

A case with a plate (``[target] thickness`` or ``[[target.layers]]``) swept over any key,
``target.thickness`` included (``--vary target.thickness=10:30:5 mm``): per case the layered
coefficients and the mass (:func:`semianalytic.commands.perforate.evaluate.perforation_setup`, the plate
tables cached on disk), then for its striking velocities (the fast key, evaluated together)
the residual velocity (:func:`semianalytic.perforation.residual_velocity`: Part I, eq. (11)
through the plate; 0 where it stops) and, once per case, the ballistic limit with its error
estimate (:func:`semianalytic.perforation.ballistic_limit`, bisection on eq. (11); the upper
bracket doubled from the largest striking velocity until it perforates, at most 20 km/s).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from semianalytic.case import Case
from semianalytic.errors import InputError
from semianalytic.sweep.kernels import CavityKernel, PenetrationKernel
from semianalytic.sweep.spec import VELOCITY_KEY, SweepSpec

MAX_UPPER = 20e3  # m/s: the largest upper bracket tried for the ballistic limit


def has_plate(case: Case) -> bool:
    """True when the case's target is a plate or layers (not the half-space)."""
    t = case.target
    return t is not None and (getattr(t, "thickness", None) is not None or bool(getattr(t, "layers", None)))


def plate_ballistic_limit(setup, start: float):
    """(V_bl, its error) [m/s] of a :class:`~semianalytic.commands.perforate.evaluate.PerforationSetup`:
    the model's own search (:func:`semianalytic.perforation.ballistic_limit_search`, up to the
    rigid-projectile limit ``setup.v_max``); NaN where nothing perforates inside the model's range
    (issue 37: never a number for an unperforated design).  ``start`` is kept for the callers."""
    from semianalytic.perforation import ballistic_limit_search

    bl = ballistic_limit_search(setup.coefficients, setup.mass, setup.v_max)
    if bl.bound == "lower":
        return float("nan"), float("nan")
    return float(bl.value), float(bl.error)


@dataclass(frozen=True)
class PerforationKernel(CavityKernel):
    """Residual velocity and ballistic limit of a plate (see the module docstring).  From the
    cavity kernel only its protocol's no-op parts: no keys on arrays, no resource shared between
    cases (``prepare`` returns None; the plate tables are cached on disk by the perforation package)."""

    cache_dir: str | None = None
    ballistic: bool = True  # the ballistic limit per case (a bisection; off: the residual velocities only)
    name: str = "perforation"
    fast_keys: frozenset = frozenset({VELOCITY_KEY})
    seconds_per_case: float = 5e-2  # a V_r curve on cached tables; a new thickness builds its plate table
    columns: tuple[str, ...] = ("residual_velocity_m_s", "perforated", "ballistic_limit_m_s",
                                "ballistic_limit_error_m_s")

    def complete_spec(self, case: Case, spec: SweepSpec) -> SweepSpec:
        case.require("projectile")
        if not has_plate(case):
            raise InputError("target.thickness", "the perforation sweep needs a plate case: [target] thickness = "
                                                 "'20 mm' (or [[target.layers]])")
        return PenetrationKernel.complete_spec(self, case, spec)  # the case's velocities as the innermost axis

    def check_fast(self, key: str, values: np.ndarray) -> None:
        v = np.asarray(values, float)
        if not np.all(np.isfinite(v) & (v > 0)):
            raise InputError("impact.striking_velocity", "must be positive (m/s)")

    def evaluate(self, case: Case, resource, fast) -> dict[str, np.ndarray]:
        from semianalytic.commands.perforate.evaluate import perforation_setup
        from semianalytic.perforation import residual_velocity

        U = np.atleast_1d(np.asarray(fast.get(VELOCITY_KEY), float))
        setup = perforation_setup(case, self.cache_dir)
        vr = np.asarray(residual_velocity(setup.coefficients, setup.mass, U), float)
        v_bl, err = plate_ballistic_limit(setup, float(np.max(U))) if self.ballistic else (np.nan, np.nan)
        return {
            "residual_velocity_m_s": vr,
            "perforated": vr > 0,
            "ballistic_limit_m_s": np.array([v_bl]),
            "ballistic_limit_error_m_s": np.array([err]),
        }
