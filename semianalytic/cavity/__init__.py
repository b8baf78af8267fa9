"""Part II: spherical cavity expansion in a brittle material (elastic, cracked/dilatant and
comminuted zones), with the corrections of errata items 7-20.

Public API::

    from semianalytic.cavity import BrittleMaterial, solve_cavity
    result = solve_cavity(BrittleMaterial(373.14e9, 0.232, 0.262e9, 2.62e9, 231.8e9))
    result.cavity_pressure   # R_r of eq. (34), Pa

``cavity_resistance(material)`` gives R_r as a target resistance for the Part I dynamics;
``resistance_from_case(case)`` reads it from a case's ``[material]`` section.
Field solutions are in :mod:`semianalytic.cavity.zones`.
"""

from semianalytic.cavity.material import BrittleMaterial
from semianalytic.cavity.model import (
    CavityResult,
    FixedPointDivergence,
    cavity_resistance,
    fixed_point_iteration,
    solve_cavity,
)

__all__ = [
    "BrittleMaterial",
    "CavityResult",
    "FixedPointDivergence",
    "cavity_resistance",
    "fixed_point_iteration",
    "resistance_from_case",
    "solve_cavity",
]


def resistance_from_case(case) -> float:
    """R_r [Pa] (Part II, eq. (34)) for the ``[material]`` section of a loaded case, with the
    section's ``solver``: the brittle-cavity target-resistance choice for the Part I dynamics."""
    section = case.require("material")
    return cavity_resistance(BrittleMaterial.from_section(section), section.solver)
