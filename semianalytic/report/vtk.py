"""Velocity fields as VTK unstructured grids (``.vtu``, written with meshio) and an
off-screen pyvista render.

The field is Part I, eq. (8)/(23): ``v = -u grad(phi)`` with phi from the BEM
(:func:`semianalytic.bem.solve_halfspace`), on a grid of the meridian half-plane (x, r)
around the projectile at depth P (target frame: free surface x = 0, tip at x = P; Figs.
12-13).  Nodes inside the projectile or the entry hole are left out (their cells too).
The grid is written twice: as the meridian plane (quads, z = 0, velocity (v_x, v_r, 0)) and
revolved about the x axis (hexahedra, wedges on the axis) with the 3D velocity
``(v_x, v_r cos(theta), v_r sin(theta))`` at ``(x, r cos(theta), r sin(theta))``.

Everything here takes the field as a callable ``gradient(points (M, 2)) -> (M, 2)``, so the
same code exports an exact solution (tests) or a FEM field.
"""

from __future__ import annotations

import math
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

__all__ = [
    "MeridianGrid",
    "FieldOnGrid",
    "meridian_grid",
    "evaluate_field",
    "meridian_mesh",
    "revolved_mesh",
    "revolved_surface",
    "write_vtu",
    "projectile_inside",
    "projectile_field",
    "fem_meridian_mesh",
    "render_png",
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


def meridian_grid(x0: float, x1: float, r1: float, nx: int, nr: int, inside: Callable | None = None) -> MeridianGrid:
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
        if potential is not None:
            ph[sel] = np.asarray(potential(pts[sel]), dtype=float)
    shape = grid.fluid.shape
    return FieldOnGrid(grid, vx.reshape(shape), vr.reshape(shape), None if ph is None else ph.reshape(shape), u, depth)


def _quad_cells(fluid: np.ndarray) -> np.ndarray:
    """(i, j) of the grid cells whose four nodes are all in the fluid."""
    ok = fluid[:-1, :-1] & fluid[1:, :-1] & fluid[1:, 1:] & fluid[:-1, 1:]
    return np.argwhere(ok)


def _field_data(field: FieldOnGrid) -> dict:
    fd = {"speed_u_m_s": np.array([field.speed_u])}
    if field.depth is not None:
        fd["depth_m"] = np.array([field.depth])
    return fd


def meridian_mesh(field: FieldOnGrid):
    """The meridian plane as a meshio mesh: quads in z = 0, point data velocity (m/s),
    speed |v| (m/s), phi (m, unit speed) and Phi = u phi (m^2/s)."""
    import meshio

    g = field.grid
    nx, nr = g.fluid.shape
    X, R = np.meshgrid(g.x, g.r, indexing="ij")
    used = np.zeros(nx * nr, dtype=bool)
    cells = _quad_cells(g.fluid)
    node = lambda i, j: i * nr + j  # noqa: E731
    quads = np.column_stack(
        [node(cells[:, 0], cells[:, 1]), node(cells[:, 0] + 1, cells[:, 1]),
         node(cells[:, 0] + 1, cells[:, 1] + 1), node(cells[:, 0], cells[:, 1] + 1)]
    )
    used[quads.ravel()] = True
    new = -np.ones(nx * nr, dtype=np.int64)
    new[used] = np.arange(used.sum())
    pts = np.column_stack([X.ravel(), R.ravel(), np.zeros(nx * nr)])[used]
    vel = np.column_stack([field.vx.ravel(), field.vr.ravel(), np.zeros(nx * nr)])[used]
    pdata = {"velocity": vel, "speed": np.hypot(vel[:, 0], vel[:, 1])}
    if field.phi is not None:
        pdata["phi"] = field.phi.ravel()[used]
        pdata["Phi"] = field.speed_u * pdata["phi"]
    return meshio.Mesh(pts, [("quad", new[quads])], point_data=pdata, field_data=_field_data(field))


def revolved_mesh(field: FieldOnGrid, segments: int = 24):
    """The grid revolved about the x axis: hexahedra, and wedges for the cells on the axis.

    Node (x, r, theta_k) -> (x, r cos theta_k, r sin theta_k), theta_k = 2 pi k / segments;
    nodes on the axis are shared.  Velocity (v_x, v_r cos theta, v_r sin theta).
    """
    import meshio

    g = field.grid
    nx, nr = g.fluid.shape
    S = int(segments)
    th = 2 * math.pi * np.arange(S) / S
    # node numbering: axis nodes (i, 0) once, ring nodes (i, j>=1, k)
    axis_id = np.arange(nx)
    ring0 = nx

    def rid(i, j, k):
        return ring0 + (i * (nr - 1) + (j - 1)) * S + (k % S)

    n_nodes = nx + nx * (nr - 1) * S
    pts = np.empty((n_nodes, 3))
    vel = np.empty((n_nodes, 3))
    phi = np.empty(n_nodes)
    pts[axis_id] = np.column_stack([g.x, np.zeros(nx), np.zeros(nx)])
    vel[axis_id] = np.column_stack([field.vx[:, 0], np.zeros(nx), np.zeros(nx)])
    phi[axis_id] = field.phi[:, 0] if field.phi is not None else np.nan
    I, J, K = np.meshgrid(np.arange(nx), np.arange(1, nr), np.arange(S), indexing="ij")
    ids = rid(I, J, K).ravel()
    rr, tt = g.r[J].ravel(), th[K].ravel()
    pts[ids] = np.column_stack([g.x[I].ravel(), rr * np.cos(tt), rr * np.sin(tt)])
    vrr = field.vr[I, J].ravel()
    vel[ids] = np.column_stack([field.vx[I, J].ravel(), vrr * np.cos(tt), vrr * np.sin(tt)])
    phi[ids] = field.phi[I, J].ravel() if field.phi is not None else np.nan

    cells = _quad_cells(g.fluid)
    hexes, wedges = [], []
    k = np.arange(S)
    for i, j in cells:
        if j == 0:
            # triangle (axis, ring(1, k+1), ring(1, k)) at x_i and at x_{i+1}
            # (VTK wedge: the first triangle's right-hand normal points away from the second)
            wedges.append(np.column_stack([
                np.full(S, axis_id[i]), rid(i, 1, k + 1), rid(i, 1, k),
                np.full(S, axis_id[i + 1]), rid(i + 1, 1, k + 1), rid(i + 1, 1, k),
            ]))
        else:
            hexes.append(np.column_stack([
                rid(i, j, k), rid(i + 1, j, k), rid(i + 1, j + 1, k), rid(i, j + 1, k),
                rid(i, j, k + 1), rid(i + 1, j, k + 1), rid(i + 1, j + 1, k + 1), rid(i, j + 1, k + 1),
            ]))
    blocks = []
    if wedges:
        blocks.append(("wedge", np.vstack(wedges)))
    if hexes:
        blocks.append(("hexahedron", np.vstack(hexes)))
    # drop unused nodes (inside the projectile)
    used = np.zeros(n_nodes, dtype=bool)
    for _, c in blocks:
        used[c.ravel()] = True
    new = -np.ones(n_nodes, dtype=np.int64)
    new[used] = np.arange(used.sum())
    blocks = [(t, new[c]) for t, c in blocks]
    vel = vel[used]
    pdata = {"velocity": vel, "speed": np.linalg.norm(vel, axis=1)}
    if field.phi is not None:
        pdata["phi"] = phi[used]
        pdata["Phi"] = field.speed_u * phi[used]
    return meshio.Mesh(pts[used], blocks, point_data=pdata, field_data=_field_data(field))


def revolved_surface(profile: np.ndarray, segments: int = 48):
    """A surface of revolution (quads) from a meridian polyline (m, 2) of (x, r)."""
    import meshio

    prof = np.asarray(profile, float)
    m, S = len(prof), int(segments)
    th = 2 * math.pi * np.arange(S) / S
    pts = np.column_stack([
        np.repeat(prof[:, 0], S), np.outer(prof[:, 1], np.cos(th)).ravel(), np.outer(prof[:, 1], np.sin(th)).ravel()
    ])
    i, k = np.meshgrid(np.arange(m - 1), np.arange(S), indexing="ij")
    i, k = i.ravel(), k.ravel()
    quads = np.column_stack([i * S + k, (i + 1) * S + k, (i + 1) * S + (k + 1) % S, i * S + (k + 1) % S])
    return meshio.Mesh(pts, [("quad", quads)])


def write_vtu(mesh, path: str | os.PathLike) -> Path:
    """Write ``mesh`` as binary ``.vtu`` atomically (temporary file in the folder, then rename)."""
    import meshio

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=".vtu", dir=path.parent)
    os.close(fd)
    from semianalytic.io import _umask

    os.chmod(tmp, 0o666 & ~_umask())
    try:
        meshio.write(tmp, mesh, file_format="vtu", binary=True)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


# --------------------------------------------------------------------------------------
# the projectile in the target


def projectile_inside(nose, length: float, depth: float, tol: float = 1e-9):
    """``inside(x, r)`` for the projectile of total ``length`` (nose + shank) with its tip at
    x = depth, and the entry hole behind it (x < depth - length, r < d/2): the non-fluid part."""
    prof = np.vstack([seg_pts for seg_pts in _nose_profile(nose)])
    s_back = -prof[:, 0]  # distance behind the tip
    order = np.argsort(s_back, kind="stable")
    s_back, r_prof = s_back[order], prof[order, 1]
    R = 0.5 * nose.diameter
    L_h = nose.length

    def inside(x, r):
        x, r = np.asarray(x, float), np.asarray(r, float)
        s = depth - x
        rp = np.where(s <= L_h, np.interp(s, s_back, r_prof), R)
        body = (s >= -tol * R) & (s <= length) & (r <= rp * (1 + tol) + tol * R)
        hole = (x >= 0) & (s > length) & (r <= R * (1 + tol))
        return body | hole

    return inside


def _nose_profile(nose, n: int = 400):
    for seg in nose.segments:
        t = np.linspace(seg.t0, seg.t1, n)
        x, r = seg.point(t)
        yield np.column_stack([np.asarray(x, float) * np.ones_like(t), np.asarray(r, float) * np.ones_like(t)])


def projectile_outline(nose, length: float, depth: float) -> np.ndarray:
    """Closed meridian outline (x, r) of the projectile in the target frame (tip at x = depth)."""
    prof = np.vstack(list(_nose_profile(nose, 120)))
    R = 0.5 * nose.diameter
    tail = np.array([[-length, R], [-length, 0.0]])
    out = np.vstack([prof, tail])
    out[:, 0] += depth
    return out


def field_window(nose, length: float, depth: float, extent: float) -> tuple[float, float, float]:
    """(x0, x1, r1): ``extent`` diameters around the nose, clipped to the target x >= 0."""
    d = nose.diameter
    x0 = max(0.0, depth - nose.length - extent * d)
    x1 = depth + extent * d
    r1 = max(extent * d, 0.75 * d)
    return x0, x1, r1


def projectile_field(
    nose,
    length: float,
    depth: float,
    u: float,
    *,
    extent: float = 2.0,
    grid: tuple[int, int] = (49, 25),
    order: int = 8,
    refinement: float | None = None,
    solution=None,
):
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


# --------------------------------------------------------------------------------------
# FEM fields of fem_check


def fem_meridian_mesh(solution, u: float, reference=None, exclude_tags=("body", "wall")):
    """A fem_check :class:`~fem_check.potential.PotentialSolution` in the meridian plane as a
    meshio mesh: the mesh's vertices (x, r, 0), its triangles, point data ``phi`` (FEM, unit
    speed) [m], ``velocity`` = -u grad(phi) (L2 projection of the FEM gradient onto the FEM
    space, Part I eq. (8)) [m/s] and ``speed``.  With ``reference`` (a BEM solution with
    ``potential(points)``), also ``phi_bem`` and ``phi_difference`` = FEM - BEM at the vertices
    off the surfaces in ``exclude_tags`` (NaN on them: the BEM field is singular there).
    """
    import meshio

    basis = solution.basis
    vert = basis.nodal_dofs[0]
    # fem_check may solve in x - shift (tip-centred); the file is in the target frame
    shift = float(getattr(solution, "shift", 0.0))
    pts2 = basis.doflocs[:, vert].T + np.array([shift, 0.0])
    tri = solution.dm.mesh.t[:3].T
    ip = basis.interpolate(solution.phi)
    gx = basis.project(ip.grad[0])[vert]
    gr = basis.project(ip.grad[1])[vert]
    phi = solution.phi[vert]
    vel = np.column_stack([-u * gx, -u * gr, np.zeros(len(vert))])
    pdata = {"phi": phi, "velocity": vel, "speed": np.hypot(vel[:, 0], vel[:, 1])}
    if reference is not None:
        on = np.zeros(len(vert), dtype=bool)
        for tag in exclude_tags:
            if tag in solution.dm.boundaries:
                nodes = solution.dm.facet_nodes(solution.dm.boundaries[tag])
                on[nodes[nodes < len(vert)]] = True
        ref = np.full(len(vert), np.nan)
        ref[~on] = reference.potential(pts2[~on])
        pdata["phi_bem"] = ref
        pdata["phi_difference"] = phi - ref
    pts = np.column_stack([pts2, np.zeros(len(vert))])
    return meshio.Mesh(pts, [("triangle", tri)], point_data=pdata, field_data={"speed_u_m_s": np.array([u])})


# --------------------------------------------------------------------------------------
# rendering


def render_png(volume_path, meridian_path, surface_path, png_path, title: str = "", window=(1000, 620)) -> Path:
    """Off-screen pyvista picture: the revolved field cut in half at the meridian plane z = 0,
    coloured by |v|, arrows of the in-plane direction from the meridian grid (mirrored to
    r < 0) and the projectile surface.  Written to ``png_path``."""
    import pyvista as pv

    pv.OFF_SCREEN = True
    vol = pv.read(str(volume_path))
    half = vol.clip(normal=(0.0, 0.0, 1.0), origin=(0.0, 0.0, 0.0))
    p = pv.Plotter(off_screen=True, window_size=list(window))
    p.set_background("white")
    speed_all = np.asarray(vol.point_data["speed"])
    top = float(np.nanpercentile(speed_all, 98)) if speed_all.size else 1.0
    p.add_mesh(half, scalars="speed", cmap="viridis", show_scalar_bar=True, clim=[0.0, max(top, 1e-30)],
               scalar_bar_args={"title": "speed |v| [m/s]", "color": "black", "vertical": True,
                                "position_x": 0.86, "position_y": 0.15, "height": 0.7})
    mer = pv.read(str(meridian_path))
    if mer.n_points:
        step = max(1, mer.n_points // 300)
        pts = np.asarray(mer.points)[::step]
        vel = np.asarray(mer.point_data["velocity"])[::step]
        pts = np.vstack([pts, pts * [1.0, -1.0, 1.0]])
        vel = np.vstack([vel, vel * [1.0, -1.0, 1.0]])
        span = float(np.ptp(vol.points[:, 0]))
        pts[:, 2] += 0.01 * span  # just above the cut face, towards the camera
        speed = np.linalg.norm(vel, axis=1)
        arrows_src = pv.PolyData(pts)
        arrows_src.point_data["direction"] = vel / np.where(speed > 0, speed, 1.0)[:, None]
        p.add_mesh(arrows_src.glyph(orient="direction", scale=False, factor=0.035 * span), color="white")
    if surface_path is not None:
        surf = pv.read(str(surface_path))
        surf = surf.clip(normal=(0.0, 0.0, 1.0), origin=(0.0, 0.0, 0.0))
        p.add_mesh(surf, color="lightgrey", smooth_shading=True)
    if title:
        p.add_text(title, font_size=10, color="black")
    p.view_xy()
    p.reset_camera(bounds=vol.bounds)
    p.camera.zoom(1.1)
    png_path = Path(png_path)
    png_path.parent.mkdir(parents=True, exist_ok=True)
    p.screenshot(str(png_path))
    p.close()
    return png_path
