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


def _field_data(field) -> dict:
    fd = {"speed_u_m_s": np.array([field.speed_u])}
    if field.depth is not None:
        fd["depth_m"] = np.array([field.depth])
    return fd


def _as_quads(field):
    """``(points (n, 2), quads (m, 4) counter-clockwise in (x, r), vx, vr, phi or None)`` of a
    field on a tensor grid (:class:`~semianalytic.bem.field.FieldOnGrid`: the cells whose four
    nodes are in the fluid) or on a body-fitted quad mesh (any object with ``points``,
    ``quads``, ``vx``, ``vr``, ``phi``: e.g. the ``run`` pipeline's BodyFittedField)."""
    if hasattr(field, "grid"):
        g = field.grid
        nx, nr = g.fluid.shape
        X, R = np.meshgrid(g.x, g.r, indexing="ij")
        cells = _quad_cells(g.fluid)
        node = lambda i, j: i * nr + j  # noqa: E731
        quads = np.column_stack(
            [node(cells[:, 0], cells[:, 1]), node(cells[:, 0] + 1, cells[:, 1]),
             node(cells[:, 0] + 1, cells[:, 1] + 1), node(cells[:, 0], cells[:, 1] + 1)]
        )
        phi = None if field.phi is None else field.phi.ravel()
        return np.column_stack([X.ravel(), R.ravel()]), quads, field.vx.ravel(), field.vr.ravel(), phi
    return (np.asarray(field.points, float), np.asarray(field.quads, np.int64), np.asarray(field.vx, float),
            np.asarray(field.vr, float), None if field.phi is None else np.asarray(field.phi, float))


def meridian_mesh(field):
    """The meridian plane as a meshio mesh: quads in z = 0, point data velocity (m/s),
    speed |v| (m/s), phi (m, unit speed) and Phi = u phi (m^2/s)."""
    import meshio

    pts2, quads, vx, vr, phi = _as_quads(field)
    n = len(pts2)
    used = np.zeros(n, dtype=bool)
    used[quads.ravel()] = True
    new = -np.ones(n, dtype=np.int64)
    new[used] = np.arange(used.sum())
    pts = np.column_stack([pts2, np.zeros(n)])[used]
    vel = np.column_stack([vx, vr, np.zeros(n)])[used]
    pdata = {"velocity": vel, "speed": np.hypot(vel[:, 0], vel[:, 1])}
    if phi is not None:
        pdata["phi"] = phi[used]
        pdata["Phi"] = field.speed_u * pdata["phi"]
    return meshio.Mesh(pts, [("quad", new[quads])], point_data=pdata, field_data=_field_data(field))


def revolved_mesh(field, segments: int = 24):
    """The meridian quads revolved about the x axis: hexahedra, and wedges for the cells with
    an edge on the axis.

    Node (x, r, theta_k) -> (x, r cos theta_k, r sin theta_k), theta_k = 2 pi k / segments;
    nodes on the axis (r = 0) are shared.  Velocity (v_x, v_r cos theta, v_r sin theta).
    """
    import meshio

    pts2, quads, vx, vr, phi = _as_quads(field)
    S = int(segments)
    th = 2 * math.pi * np.arange(S) / S
    n = len(pts2)
    on_axis = pts2[:, 1] == 0.0
    # numbering: each axis node once, every other node once per azimuthal segment
    first = np.empty(n, dtype=np.int64)
    first[on_axis] = np.arange(on_axis.sum())
    n_axis = int(on_axis.sum())
    first[~on_axis] = n_axis + np.arange((~on_axis).sum()) * S

    def nid(a, k):
        """Id of meridian node(s) ``a`` in segment(s) ``k``."""
        return np.where(on_axis[a], first[a], first[a] + (k % S))

    n_nodes = n_axis + int((~on_axis).sum()) * S
    pts = np.empty((n_nodes, 3))
    vel = np.empty((n_nodes, 3))
    ph = np.full(n_nodes, np.nan)
    ax = np.flatnonzero(on_axis)
    pts[first[ax]] = np.column_stack([pts2[ax, 0], np.zeros(len(ax)), np.zeros(len(ax))])
    vel[first[ax]] = np.column_stack([vx[ax], np.zeros(len(ax)), np.zeros(len(ax))])
    if phi is not None:
        ph[first[ax]] = phi[ax]
    ring = np.flatnonzero(~on_axis)
    A, K = np.meshgrid(ring, np.arange(S), indexing="ij")
    ids = (first[A] + K).ravel()
    rr, tt = pts2[A, 1].ravel(), th[K].ravel()
    pts[ids] = np.column_stack([pts2[A, 0].ravel(), rr * np.cos(tt), rr * np.sin(tt)])
    vrr = vr[A].ravel()
    vel[ids] = np.column_stack([vx[A].ravel(), vrr * np.cos(tt), vrr * np.sin(tt)])
    if phi is not None:
        ph[ids] = phi[A].ravel()

    k = np.arange(S)
    hexes, wedges = [], []
    n_axis_nodes = on_axis[quads].sum(axis=1)
    for q, m in zip(quads, n_axis_nodes):
        if m == 0:
            a, b, c, d = q
            hexes.append(np.column_stack([nid(a, k), nid(b, k), nid(c, k), nid(d, k),
                                          nid(a, k + 1), nid(b, k + 1), nid(c, k + 1), nid(d, k + 1)]))
        elif m == 2:
            # rotate so that the axis edge comes first: (a, b) on the axis (+x for a CCW quad),
            # c, d off it; VTK wedge: triangle (a, d_{k+1}, d_k), then (b, c_{k+1}, c_k)
            while not (on_axis[q[0]] and on_axis[q[1]]):
                q = np.roll(q, 1)
            a, b, c, d = q
            wedges.append(np.column_stack([np.full(S, first[a]), nid(d, k + 1), nid(d, k),
                                           np.full(S, first[b]), nid(c, k + 1), nid(c, k)]))
        else:
            raise ValueError("a meridian cell touches the axis at one node only (or lies on it)")
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
    if phi is not None:
        pdata["phi"] = ph[used]
        pdata["Phi"] = field.speed_u * ph[used]
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


# The unit of every array the writers here produce (point data and field data), and of the
# coordinates; written into each .vtu as string field data (``units``, ``coordinates_unit``).
UNITS = {
    "coordinates": "m",
    "velocity": "m/s",
    "speed": "m/s",
    "phi": "m (potential at unit striking speed)",
    "Phi": "m^2/s",
    "phi_bem": "m (potential at unit striking speed)",
    "phi_difference": "m (potential at unit striking speed)",
    "speed_u_m_s": "m/s",
    "depth_m": "m",
}


def _field_data_xml(mesh) -> str:
    """A VTK XML ``<FieldData>`` block: the mesh's field data (meshio's VTU writer drops it)
    and, as strings, the unit of the coordinates and of every array (:data:`UNITS`)."""
    from xml.sax.saxutils import quoteattr

    def strings(name: str, values: list[str]) -> str:
        codes = " ".join(" ".join(str(b) for b in v.encode("utf-8")) + " 0" for v in values)
        return (f'<DataArray type="String" Name={quoteattr(name)} NumberOfTuples="{len(values)}" format="ascii">'
                f"{codes}</DataArray>")

    names = ["coordinates", *mesh.point_data, *(mesh.field_data or {})]
    arrays = [strings("units", [f"{n}: {UNITS.get(n, 'dimensionless')}" for n in names]),
              strings("coordinates_unit", [UNITS["coordinates"]])]
    for name, value in (mesh.field_data or {}).items():
        v = np.atleast_1d(np.asarray(value, float))
        arrays.append(f'<DataArray type="Float64" Name={quoteattr(name)} NumberOfTuples="{v.size}" format="ascii">'
                      + " ".join(repr(float(x)) for x in v) + "</DataArray>")
    return "<FieldData>\n" + "\n".join(arrays) + "\n</FieldData>\n"


def write_vtu(mesh, path: str | os.PathLike) -> Path:
    """Write ``mesh`` as binary ``.vtu`` atomically (temporary file in the folder, then rename),
    with the units of its coordinates and arrays as field data (:data:`UNITS`)."""
    import meshio

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=".vtu", dir=path.parent)
    os.close(fd)
    from semianalytic.io import _umask

    os.chmod(tmp, 0o666 & ~_umask())
    try:
        meshio.write(tmp, mesh, file_format="vtu", binary=True)
        text = Path(tmp).read_text(encoding="ascii")
        at = text.index("<UnstructuredGrid>") + len("<UnstructuredGrid>\n")
        Path(tmp).write_text(text[:at] + _field_data_xml(mesh) + text[at:], encoding="ascii")
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
    """Off-screen pyvista picture: the revolved body-fitted field cut in half at the meridian
    plane z = 0 (the volume conforms to the projectile, so the field is clipped at the body),
    coloured by |v| on the scale of :func:`semianalytic.report.figures.speed_scale` (log where
    the range is wide, never clipped at the top), well-spaced arrows of the in-plane direction
    (a regular lattice sampled in the meridian mesh, mirrored to r < 0) and the projectile
    surface.  Written to ``png_path``."""
    import pyvista as pv

    from semianalytic.report.figures import speed_scale

    pv.OFF_SCREEN = True
    quiet_vtk_display_messages()
    vol = pv.read(str(volume_path))
    half = vol.clip(normal=(0.0, 0.0, 1.0), origin=(0.0, 0.0, 0.0))
    p = pv.Plotter(off_screen=True, window_size=list(window))
    p.set_background("white")
    speed_all = np.asarray(vol.point_data["speed"])
    norm, extend, _ = speed_scale(speed_all)
    log = type(norm).__name__ == "LogNorm"
    # VTK's fonts lack '|': a plain title (the old "speed |v|" rendered as "speed ᵛ")
    bar = {"title": "speed [m/s]" + (", log scale" if log else ""), "color": "black", "vertical": True,
           "position_x": 0.86, "position_y": 0.15, "height": 0.7, "fmt": "%.3g"}
    p.add_mesh(half, scalars="speed", cmap="viridis", show_scalar_bar=True, clim=[norm.vmin, norm.vmax],
               log_scale=log, scalar_bar_args=bar)
    mer = pv.read(str(meridian_path))
    if mer.n_points:
        b = mer.bounds
        span = float(b[1] - b[0])
        step = span / 28.0
        gx, gy = np.meshgrid(np.arange(b[0] + 0.5 * step, b[1], step), np.arange(0.5 * step, b[3], step), indexing="ij")
        lattice = pv.PolyData(np.column_stack([gx.ravel(), gy.ravel(), np.zeros(gx.size)]))
        probed = lattice.sample(mer)
        ok = np.asarray(probed["vtkValidPointMask"]) == 1
        pts = np.asarray(probed.points)[ok]
        vel = np.asarray(probed["velocity"])[ok]
        pts = np.vstack([pts, pts * [1.0, -1.0, 1.0]])
        vel = np.vstack([vel, vel * [1.0, -1.0, 1.0]])
        pts[:, 2] += 0.01 * span  # just above the cut face, towards the camera
        speed = np.linalg.norm(vel, axis=1)
        arrows_src = pv.PolyData(pts)
        arrows_src.point_data["direction"] = vel / np.where(speed > 0, speed, 1.0)[:, None]
        p.add_mesh(arrows_src.glyph(orient="direction", scale=False, factor=0.6 * step), color="white")
    if surface_path is not None:
        # the whole projectile: in parallel projection it covers exactly its own cut section
        p.add_mesh(pv.read(str(surface_path)), color="lightgrey", smooth_shading=True)
    if title:
        import textwrap

        p.add_text("\n".join(textwrap.wrap(title, 70)) + "\naxes: x, depth [m] (horizontal); r, radius [m] (vertical)",
                   font_size=9, color="black")  # VTK drops the vertical axis title in a 2D view
    # axes with their unit and a length scale (the coordinates are in metres; labelled in mm)
    b = vol.bounds
    x_lo = 0.0 if abs(b[0]) < 1e-12 else float(b[0])  # the free surface x = 0, not -3e-18
    p.show_bounds(bounds=[x_lo, b[1], -b[3], b[3], 0.0, 0.0], xtitle="x, depth [m]", ytitle="r, radius [m]", ztitle="",
                  location="outer", ticks="outside", font_size=9, color="black", fmt="%.3g", show_zaxis=False,
                  show_zlabels=False)
    span = float(b[1] - b[0])
    bar_len = 10.0 ** math.floor(math.log10(max(span / 4.0, 1e-12)))  # 1, 10, 100 ... mm: about a quarter of the window
    y0 = -0.92 * float(b[3])
    x0 = float(b[1]) - 1.1 * bar_len
    p.add_mesh(pv.Line((x0, y0, 0.02 * span), (x0 + bar_len, y0, 0.02 * span)), color="white", line_width=5)
    p.add_point_labels([(x0 + 0.5 * bar_len, y0 + 0.09 * float(b[3]), 0.02 * span)], [f"{bar_len * 1e3:g} mm"], font_size=12,
                       text_color="white", shape=None, show_points=False, always_visible=True)
    p.view_xy()
    p.enable_parallel_projection()
    p.reset_camera(bounds=vol.bounds)
    p.camera.zoom(0.95)  # room for the axes' titles
    png_path = Path(png_path)
    png_path.parent.mkdir(parents=True, exist_ok=True)
    p.screenshot(str(png_path))
    p.close()
    return png_path
