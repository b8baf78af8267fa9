"""Pure pieces of the nose-shape optimisation: constraints and objectives (SI floats).

A design changes the nose; the shank then follows the constraint:

- fixed mass m0 (density rho_p given): pi R^2 L_c rho_p + V_nose rho_p = m0, so
  L_c = (m0 / rho_p - V_nose) / (pi R^2); infeasible when the nose alone is heavier than m0;
- fixed total length L0: L_c = L0 - L_h; infeasible when the nose is longer than L0;
- both: L_c = L0 - L_h and the mass is held at m0 (the projectile's density follows);
- none: the starting design's shank length L_c is kept.

Objectives (minimised): ``depth``: minus the mean final depth over the striking velocities
(Part I, eq. (11); rigid, or the elastic projectile with the exact-rod energy, errata item 5);
``deep_drag``: the deep-penetration drag Bbar = 4 B / (pi d^2) (Part I, eq. (13), deep limit).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

OBJECTIVES = ("depth", "deep_drag")
CONSTRAINTS = ("mass", "length", "caliber")
DEPTH_MODELS = ("rigid", "exact-rod")


class Infeasible(ValueError):
    """The design cannot meet a constraint (the message says which and why)."""

    def __init__(self, constraint: str, message: str):
        super().__init__(message)
        self.constraint = constraint


@dataclass(frozen=True)
class ShankChoice:
    """The cylindrical length L_c [m] and the mass override [kg] (None: density x volume)."""

    shank_length: float
    mass: float | None


def shank_for_constraints(
    nose_volume: float,
    nose_length: float,
    diameter: float,
    *,
    start_shank: float,
    density: float | None,
    mass: float | None = None,
    length: float | None = None,
) -> ShankChoice:
    """The shank that meets the constraints (see the module docstring).

    ``mass``: fixed total mass m0 [kg] (needs ``density`` unless ``length`` is fixed too);
    ``length``: fixed total length L0 [m].  Raises :class:`Infeasible`.
    """
    area = math.pi * (0.5 * diameter) ** 2
    if length is not None:
        shank = length - nose_length
        if shank < -1e-12 * length:
            raise Infeasible("length", f"the nose (L_h = {nose_length * 1e3:.4g} mm) is longer than the fixed length "
                                       f"{length * 1e3:.4g} mm")
        return ShankChoice(max(shank, 0.0), mass)
    if mass is not None:
        if density is None:
            raise Infeasible("mass", "a fixed mass with a free length needs projectile.density")
        shank = (mass / density - nose_volume) / area
        if shank < 0:
            raise Infeasible("mass", f"the nose alone weighs {density * nose_volume * 1e3:.4g} g, more than the fixed "
                                     f"mass {mass * 1e3:.4g} g")
        return ShankChoice(shank, None)
    return ShankChoice(start_shank, None)


def depth_objective(depths) -> float:
    """Minus the mean final depth [m] over the striking velocities (minimised = deepest on average)."""
    d = np.asarray(depths, float)
    if d.size == 0 or not np.all(np.isfinite(d)):
        return math.inf
    return -float(np.mean(d))


def deep_drag(B_deep: float, diameter: float) -> float:
    """Bbar = 4 B / (pi d^2) of the deep-penetration limit (Part I, eq. (13) normalised as in Fig. 8)."""
    return float(B_deep) / (math.pi * 0.25 * diameter**2)


def quantise(x, low, high, resolution: float):
    """Round each design variable to ``resolution`` of its range (repeat designs hit the caches)."""
    x, low, high = (np.asarray(v, float) for v in (x, low, high))
    step = resolution * (high - low)
    q = low + np.round((x - low) / step) * step
    return np.clip(q, low, high)


def confirmation_grid(best, low, high, n: int, half_width: float):
    """A grid of n points per variable over best +- half_width x range (clipped to the bounds):
    list of points and the grid spacing per variable."""
    best, low, high = (np.asarray(v, float) for v in (best, low, high))
    h = half_width * (high - low)
    lo, hi = np.maximum(best - h, low), np.minimum(best + h, high)
    axes = [np.linspace(a, b, n) for a, b in zip(lo, hi)]
    mesh = np.meshgrid(*axes, indexing="ij")
    pts = np.column_stack([m.ravel() for m in mesh])
    spacing = (hi - lo) / max(n - 1, 1)
    return pts, spacing
