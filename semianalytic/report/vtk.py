"""Velocity fields already computed, as VTK unstructured grids (``.vtu``, written with meshio),
and an off-screen pyvista render.  Nothing here computes a field.

The BEM field comes as a :class:`semianalytic.bem.field.FieldOnGrid` (Part I, eq. (8)/(23)
on a grid of the meridian half-plane; nodes inside the projectile or the entry hole are NaN
and left out with their cells).  It is written twice: as the meridian plane (quads, z = 0,
velocity (v_x, v_r, 0)) and revolved about the x axis (hexahedra, wedges on the axis) with the
3D velocity ``(v_x, v_r cos(theta), v_r sin(theta))`` at ``(x, r cos(theta), r sin(theta))``.
The FEM field comes as fem_check's :class:`fem_check.api.PotentialField` (vertex values).
"""

from __future__ import annotations

import math
import os
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from semianalytic.bem.field import FieldOnGrid

__all__ = [
    "meridian_mesh",
    "revolved_mesh",
    "revolved_surface",
    "write_vtu",
    "fem_meridian_mesh",
    "render_png",
]


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
# FEM fields of fem_check


# --------------------------------------------------------------------------------------
# FEM fields of fem_check


def fem_meridian_mesh(field, u: float, phi_reference=None):
    """A FEM potential field in the meridian plane as a meshio mesh.

    ``field``: vertex values of fem_check (:class:`fem_check.api.PotentialField`: ``points``
    (n, 2) in the target frame [m], ``triangles``, ``phi`` (unit speed) [m], ``gradient`` (n, 2)).
    Point data: ``phi``, ``velocity`` = -u grad(phi) (Part I, eq. (8)) [m/s] and ``speed``;
    with ``phi_reference`` (n,) (e.g. the BEM potential at the same vertices, NaN where not
    defined), also ``phi_bem`` and ``phi_difference`` = FEM - reference.
    """
    import meshio

    pts2 = np.asarray(field.points, float)
    phi = np.asarray(field.phi, float)
    grad = np.asarray(field.gradient, float)
    vel = np.column_stack([-u * grad[:, 0], -u * grad[:, 1], np.zeros(len(phi))])
    pdata = {"phi": phi, "velocity": vel, "speed": np.hypot(vel[:, 0], vel[:, 1])}
    if phi_reference is not None:
        ref = np.asarray(phi_reference, float)
        pdata["phi_bem"] = ref
        pdata["phi_difference"] = phi - ref
    pts = np.column_stack([pts2, np.zeros(len(phi))])
    return meshio.Mesh(pts, [("triangle", np.asarray(field.triangles))], point_data=pdata,
                       field_data={"speed_u_m_s": np.array([u])})


# --------------------------------------------------------------------------------------
# rendering


def quiet_vtk_display_messages() -> None:
    """Silence VTK's own log on stderr (on a headless machine every off-screen render window
    logs "vtkXOpenGLRenderWindow ... bad X server connection" before falling back to
    off-screen rendering, which works): the picture is written either way, and real
    failures still raise."""
    from vtkmodules.vtkCommonCore import vtkLogger, vtkObject

    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)
    vtkObject.GlobalWarningDisplayOff()


def render_png(volume_path, meridian_path, surface_path, png_path, title: str = "", window=(1000, 620)) -> Path:
    """Off-screen pyvista picture: the revolved field cut in half at the meridian plane z = 0,
    coloured by |v|, arrows of the in-plane direction from the meridian grid (mirrored to
    r < 0) and the projectile surface.  Written to ``png_path``."""
    import pyvista as pv

    pv.OFF_SCREEN = True
    quiet_vtk_display_messages()
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
