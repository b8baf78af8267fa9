"""The registry of a ``run``'s analyses: one :class:`Step` each, saying which sections it
needs, the input checks it makes before anything is computed (``preflight``: bad input ->
InputError, exit 2, nothing written) and the function that computes it and hands the results
to the report.  The step modules (:mod:`.bodies`, :mod:`.fields`, :mod:`.part1`, :mod:`.part2`,
:mod:`.parts34`) import this module and :func:`register` their steps; :mod:`.pipeline` imports
them all.  Helpers shared by several steps live here too.

Steps call the models' public functions only; the physics lives in the model packages.
A step whose model package is not installed in this version is listed as skipped.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from semianalytic.case import Case
from semianalytic.errors import InputError
from semianalytic.report.document import fmt
from semianalytic.run.case import ANALYSES, RunSection
from semianalytic.run.context import Context


@dataclass(frozen=True)
class Step:
    name: str
    title: str
    requires: tuple[str, ...]  # case sections
    modules: tuple[str, ...]  # model packages it calls
    applies: Callable[[Case], bool]
    preflight: Callable[[Case, RunSection], None]
    run: Callable[[Context], None]


# --------------------------------------------------------------------------------------
# shared helpers


def _projectile(case: Case):
    from semianalytic.geometry import projectile_from_section

    return projectile_from_section(case.require("projectile"))


def _field_velocity(case: Case, run: RunSection, memo: dict | None = None, depth: float | None = None) -> tuple[float, str]:
    """u for v = -u grad(phi): [run] field_velocity, else the rigid projectile's speed at this
    depth for the first striking velocity (when the penetration step ran), else U_s."""
    if run.field_velocity is not None:
        return run.field_velocity, "[run] field_velocity"
    if case.impact is None:
        return 1.0, "unit speed"
    U = float(case.impact.striking_velocities[0])
    motion = (memo or {}).get("rigid_motion", {}).get(U)
    if motion is not None and depth is not None and depth < motion.final_depth:
        return float(np.interp(depth, motion.P, motion.u)), f"rigid projectile at this depth, U_s = {U:g} m/s"
    return U, "striking velocity U_s"


def bem_options(case: Case) -> dict:
    """order (and refinement, when the case sets it) for the BEM solvers."""
    out = {"order": case.bem.order}
    if case.bem.refinement is not None:
        out["refinement"] = case.bem.refinement
    return out


def _mm(v) -> str:
    return fmt(None if v is None else v * 1e3)


def _coefficient_table(ctx: Context):
    """The case's coefficient table, built (or loaded from the cache) once per run."""
    if "table" not in ctx.memo:
        from semianalytic.cache import coefficients_for_case

        ctx.memo["table"] = coefficients_for_case(ctx.case, "bem", cache_dir=ctx.cache_dir)[0]
    return ctx.memo["table"]



# --------------------------------------------------------------------------------------
# registry


def _has(*sections: str) -> Callable[[Case], bool]:
    return lambda case: all(case.section(s) is not None for s in sections)


def _no_preflight(case: Case, run: RunSection) -> None:
    return None


STEPS: dict[str, Step] = {}

# sections each analysis needs (also for analyses whose model is not installed)
REQUIRES: dict[str, tuple[str, ...]] = {
    "added_mass": ("body",),
    "coefficients": ("projectile",),
    "penetration": ("projectile", "target", "impact"),
    "critical_velocity": ("projectile", "target"),
    "validation": ("projectile", "target", "data"),
    "velocity_field": ("projectile", "target"),
    "fem_field": ("projectile", "target"),
    "cavity": ("material",),
    "ballistic_limit": ("ballistic_limit",),
    "perforation": ("projectile", "target", "impact"),
    "nanostrength": ("nanostrength",),
}


def register(step: Step) -> Step:
    STEPS[step.name] = step
    return step


def select_steps(case: Case, run: RunSection, only=None) -> tuple[list[Step], dict[str, str]]:
    """Steps to run, in the fixed order of :data:`ANALYSES`, and the skipped ones with why.

    Explicitly requested analyses (``[run] analyses`` or ``--only``) must be possible with the
    case's sections (else InputError naming the section); the automatic choice takes every
    step whose sections are present.
    """
    requested = list(only) if only else (list(run.analyses) if run.analyses else None)
    field = "--only" if only else "run.analyses"
    chosen, skipped = [], {}
    for name in ANALYSES:
        step = STEPS.get(name)
        if requested is not None and name not in requested:
            continue
        if requested is not None:
            for sec in REQUIRES[name]:
                if case.section(sec) is None:
                    raise InputError(sec, f"the case has no [{sec}] section, which analysis {name!r} ({field}) needs")
        if step is None:
            raise RuntimeError(f"analysis {name!r} has no registered step (semianalytic/run/)")
        if requested is None and not step.applies(case):
            continue
        chosen.append(step)
    if not chosen:
        raise InputError(field if requested else "case", "nothing to run: no analysis applies to this case")
    return chosen, skipped
