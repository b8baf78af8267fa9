"""Axisymmetric boundary-element solver for the velocity potential of Part I.

``solve_body`` treats a closed body of revolution in unbounded fluid; ``solve_halfspace``
a nose penetrating the half-space target x >= 0 to depth P (mirror method of Part I,
eqs. (21)-(22)).  Both return a :class:`~semianalytic.bem.solve.SurfaceSolution` with phi
on the surface, the coefficients A and C of eq. (12), and the potential and velocity
field anywhere in the fluid (eq. (23)).
"""

from __future__ import annotations

from semianalytic.bem.panels import LayoutOptions, body_panels, halfspace_layout
from semianalytic.bem.solve import SurfaceSolution, solve_panels
from semianalytic.geometry import Meridian, Nose

__all__ = ["solve_body", "solve_halfspace", "SurfaceSolution", "LayoutOptions", "unknowns_body", "unknowns_halfspace"]


def solve_body(meridian: Meridian, order: int = 8, refinement: float = 1.0, levels: int = 12) -> SurfaceSolution:
    """phi on a closed body moving with unit speed along +x in unbounded fluid."""
    ps = body_panels(meridian, LayoutOptions(order, refinement, levels))
    return solve_panels(ps, "body", volume=meridian.volume())


def solve_halfspace(nose: Nose, depth: float, order: int = 8, refinement: float = 1.0, levels: int = 12) -> SurfaceSolution:
    """phi on a nose at depth P in the target x >= 0 (tip at x = P), free surface x = 0."""
    layout = halfspace_layout(nose, depth, LayoutOptions(order, refinement, levels))
    return solve_panels(layout.panels(), "halfspace", depth=depth)


def unknowns_body(meridian: Meridian, order: int = 8, refinement: float = 1.0, levels: int = 12) -> int:
    """Number of unknowns (rows of the dense BEM matrix) of :func:`solve_body`, from the
    layout alone (no assembly; milliseconds): memory ~ 16 N^2 bytes for the two matrices."""
    return body_panels(meridian, LayoutOptions(order, refinement, levels)).n_primary * order


def unknowns_halfspace(nose: Nose, depth: float, order: int = 8, refinement: float = 1.0, levels: int = 12) -> int:
    """Number of unknowns of :func:`solve_halfspace` (and of each solve of a coefficient
    row) at depth P, from the layout alone (no assembly)."""
    layout = halfspace_layout(nose, depth, LayoutOptions(order, refinement, levels))
    return sum(len(p.panels) for p in layout.pieces) * order
