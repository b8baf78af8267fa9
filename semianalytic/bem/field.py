"""The velocity field around a body of revolution on a grid of the meridian half-plane:
Part I, eq. (8)/(23), ``v = -u grad(phi)``.

For the projectile in the half-space target, phi comes from the BEM
(:func:`semianalytic.bem.solve_halfspace`) at depth P (target frame: free surface x = 0, tip
at x = P; Figs. 12-13); nodes inside the projectile or the entry hole are left out (NaN).
:func:`evaluate_field` takes the field as a callable ``gradient(points (M, 2)) -> (M, 2)``,
so the same code evaluates an exact solution (tests) or the BEM.  Writing the result as VTK
is :mod:`semianalytic.report.vtk`'s job.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from semianalytic.bem.solve import SurfaceSolution
    from semianalytic.geometry import Nose

__all__ = [
    "MeridianGrid",
    "FieldOnGrid",
    "meridian_grid",
    "evaluate_field",
    "projectile_inside",
    "projectile_outline",
    "field_window",
    "projectile_field",
]


@dataclass(frozen=True)
class MeridianGrid:
    """Tensor grid of the meridian half-plane; ``fluid[i, j]`` marks nodes in the target."""

    x: np.ndarray  # (nx,) [m]
    r: np.ndarray  # (nr,) [m], r[0] = 0 (the axis)
    fluid: np.ndarray  # (nx, nr) bool

    @property
    def points(self) -> np.ndarray:
        """All nodes as (nx*nr, 2) of (x, r), x slowest."""
        X, R = np.meshgrid(self.x, self.r, indexing="ij")
        return np.column_stack([X.ravel(), R.ravel()])


@dataclass(frozen=True)
class FieldOnGrid:
    """Velocity (and potential) at the grid nodes; NaN outside the fluid.  SI units."""

    grid: MeridianGrid
    vx: np.ndarray  # (nx, nr) [m/s]
    vr: np.ndarray  # (nx, nr) [m/s]
    phi: np.ndarray | None  # (nx, nr) unit-speed potential [m]
    speed_u: float  # projectile speed u [m/s] used in v = -u grad(phi)
    depth: float | None = None  # P [m]


Inside = Callable[[np.ndarray, np.ndarray], np.ndarray]  # inside(x, r) -> bool array


def meridian_grid(x0: float, x1: float, r1: float, nx: int, nr: int, inside: Inside | None = None) -> MeridianGrid:
    """Grid on [x0, x1] x [0, r1]; ``inside(x, r) -> bool array`` marks non-fluid nodes."""
    if not (x1 > x0 and r1 > 0 and nx >= 2 and nr >= 2):
        raise ValueError("empty grid")
    x = np.linspace(x0, x1, nx)
    r = np.linspace(0.0, r1, nr)
    X, R = np.meshgrid(x, r, indexing="ij")
    fluid = np.ones_like(X, dtype=bool) if inside is None else ~np.asarray(inside(X, R), dtype=bool)
    return MeridianGrid(x, r, fluid)


def evaluate_field(
    grid: MeridianGrid,
    gradient: Callable[[np.ndarray], np.ndarray],
    u: float,
    potential: Callable[[np.ndarray], np.ndarray] | None = None,
    depth: float | None = None,
    chunk: int = 2000,
) -> FieldOnGrid:
    """v = -u grad(phi) (Part I, eq. (8)/(23)) at the fluid nodes, in chunks of points."""
    pts = grid.points
    mask = grid.fluid.ravel()
    vx = np.full(len(pts), np.nan)
    vr = np.full(len(pts), np.nan)
    ph = np.full(len(pts), np.nan) if potential is not None else None
    idx = np.flatnonzero(mask)
    for s in range(0, len(idx), chunk):
        sel = idx[s : s + chunk]
        g = np.asarray(gradient(pts[sel]), dtype=float)
        vx[sel] = -u * g[:, 0]
        vr[sel] = -u * g[:, 1]
        if potential is not None and ph is not None:
            ph[sel] = np.asarray(potential(pts[sel]), dtype=float)
    shape = grid.fluid.shape
    return FieldOnGrid(grid, vx.reshape(shape), vr.reshape(shape), None if ph is None else ph.reshape(shape), u, depth)


# --------------------------------------------------------------------------------------
# the projectile in the target


def projectile_inside(nose: Nose, length: float, depth: float, tol: float = 1e-9) -> Inside:
    """``inside(x, r)`` for the projectile of total ``length`` (nose + shank) with its tip at
    x = depth, and the entry hole behind it (x < depth - length, r < d/2): the non-fluid part."""
    prof = np.vstack([seg_pts for seg_pts in _nose_profile(nose)])
    s_back = -prof[:, 0]  # distance behind the tip
    order = np.argsort(s_back, kind="stable")
    s_back, r_prof = s_back[order], prof[order, 1]
    R = 0.5 * nose.diameter
    L_h = nose.length

    def inside(x: np.ndarray, r: np.ndarray) -> np.ndarray:
        x, r = np.asarray(x, float), np.asarray(r, float)
        s = depth - x
        rp = np.where(s <= L_h, np.interp(s, s_back, r_prof), R)
        body = (s >= -tol * R) & (s <= length) & (r <= rp * (1 + tol) + tol * R)
        hole = (x >= 0) & (s > length) & (r <= R * (1 + tol))
        out: np.ndarray = body | hole
        return out

    return inside


def _nose_profile(nose: Nose, n: int = 400) -> Iterator[np.ndarray]:
    for seg in nose.segments:
        t = np.linspace(seg.t0, seg.t1, n)
        x, r = seg.point(t)  # type: ignore[no-untyped-call]  # geometry.py is not annotated yet
        yield np.column_stack([np.asarray(x, float) * np.ones_like(t), np.asarray(r, float) * np.ones_like(t)])


def projectile_outline(nose: Nose, length: float, depth: float) -> np.ndarray:
    """Closed meridian outline (x, r) of the projectile in the target frame (tip at x = depth)."""
    prof = np.vstack(list(_nose_profile(nose, 120)))
    R = 0.5 * nose.diameter
    tail = np.array([[-length, R], [-length, 0.0]])
    out = np.vstack([prof, tail])
    out[:, 0] += depth
    return out


def field_window(nose: Nose, length: float, depth: float, extent: float) -> tuple[float, float, float]:
    """(x0, x1, r1): ``extent`` diameters around the nose, clipped to the target x >= 0."""
    d = nose.diameter
    x0 = max(0.0, depth - nose.length - extent * d)
    x1 = depth + extent * d
    r1 = max(extent * d, 0.75 * d)
    return x0, x1, r1


def projectile_field(
    nose: Nose,
    length: float,
    depth: float,
    u: float,
    *,
    extent: float = 2.0,
    grid: tuple[int, int] = (49, 25),
    order: int = 8,
    refinement: float | None = None,
    solution: SurfaceSolution | None = None,
) -> tuple[FieldOnGrid, SurfaceSolution]:
    """BEM velocity field around the projectile at depth P: Part I, eq. (23).

    Returns ``(field, solution)``; ``solution`` is the :func:`semianalytic.bem.solve_halfspace`
    result (pass one in to reuse it).
    """
    from semianalytic.bem import solve_halfspace

    opts = {"order": order} if refinement is None else {"order": order, "refinement": refinement}
    sol = solution if solution is not None else solve_halfspace(nose, depth, **opts)
    x0, x1, r1 = field_window(nose, length, depth, extent)
    g = meridian_grid(x0, x1, r1, grid[0], grid[1], projectile_inside(nose, length, depth))
    return evaluate_field(g, sol.gradient, u, sol.potential, depth=depth), sol
