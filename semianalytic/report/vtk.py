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
    pass

__all__ = [
    "meridian_mesh",
    "revolved_mesh",
    "revolved_surface",
    "write_vtu",
    "sidecar_path",
    "in_coordinates",
    "fem_meridian_mesh",
    "read_in_mm",
    "render_png",
]


def _quad_cells(fluid: np.ndarray) -> np.ndarray:
    """(i, j) of the grid cells whose four nodes are all in the fluid."""
    ok = fluid[:-1, :-1] & fluid[1:, :-1] & fluid[1:, 1:] & fluid[:-1, 1:]
    return np.argwhere(ok)


def _field_data(field) -> dict:
    fd = {"speed_u_m_s": np.array([float(field.speed_u)])}
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
    """The meridian plane as a meshio mesh: quads in z = 0, point data ``velocity_m_s``,
    ``speed_m_s`` (|v|), ``phi_m`` (the potential at unit speed) and ``Phi_m2_s`` (u phi)."""
    import meshio

    pts2, quads, vx, vr, phi = _as_quads(field)
    n = len(pts2)
    used = np.zeros(n, dtype=bool)
    used[quads.ravel()] = True
    new = -np.ones(n, dtype=np.int64)
    new[used] = np.arange(used.sum())
    pts = np.column_stack([pts2, np.zeros(n)])[used]
    vel = np.column_stack([vx, vr, np.zeros(n)])[used]
    pdata = {"velocity_m_s": vel, "speed_m_s": np.hypot(vel[:, 0], vel[:, 1])}
    if phi is not None:
        pdata["phi_m"] = phi[used]
        pdata["Phi_m2_s"] = field.speed_u * pdata["phi_m"]
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
    pdata = {"velocity_m_s": vel, "speed_m_s": np.linalg.norm(vel, axis=1)}
    if phi is not None:
        pdata["phi_m"] = ph[used]
        pdata["Phi_m2_s"] = field.speed_u * ph[used]
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


# The unit and meaning of every array the writers here produce (point data and field data).
# The unit is also the suffix of the array's name (``velocity_m_s``), so every VTK reader
# (meshio, pyvista, ParaView) shows it; the sidecar JSON beside each file (:func:`sidecar_path`)
# repeats it with the coordinates' unit.  Only numeric arrays go into the files: meshio 5.3
# rejects VTK string arrays ("Illegal data type 'String'").
ARRAYS = {
    "velocity_m_s": ("m/s", "target velocity v = -u grad(phi), Part I eq. (8); 3 components (x, y, z)"),
    "speed_m_s": ("m/s", "|v|"),
    "phi_m": ("m", "velocity potential at unit striking speed"),
    "Phi_m2_s": ("m^2/s", "velocity potential Phi = u phi"),
    "phi_bem_m": ("m", "BEM potential at unit speed at the FEM vertices (NaN on the body and the wall)"),
    "phi_difference_m": ("m", "FEM minus BEM potential at unit speed"),
    "speed_u_m_s": ("m/s", "projectile speed u of the field (field data)"),
    "depth_m": ("m", "depth of the tip P below the free surface (field data)"),
    "coordinates_unit_m": ("m", "length of one coordinate unit in metres (1 for m, 0.001 for mm; field data)"),
}
COORDINATE_UNITS = {"m": 1.0, "mm": 1e-3}


def _field_data_xml(mesh) -> str:
    """A VTK XML ``<FieldData>`` block of the mesh's (numeric) field data: meshio's VTU writer
    drops field data, and meshio and pyvista both read Float64 arrays back."""
    from xml.sax.saxutils import quoteattr

    arrays = []
    for name, value in (mesh.field_data or {}).items():
        v = np.atleast_1d(np.asarray(value, float))
        arrays.append(f'<DataArray type="Float64" Name={quoteattr(name)} NumberOfTuples="{v.size}" format="ascii">'
                      + " ".join(repr(float(x)) for x in v) + "</DataArray>")
    return "<FieldData>\n" + "\n".join(arrays) + "\n</FieldData>\n"


def sidecar_path(path: str | os.PathLike) -> Path:
    """The JSON beside a ``.vtu`` (``name.vtu`` -> ``name.units.json``) naming the unit and the
    meaning of the coordinates and of every array in it."""
    path = Path(path)
    return path.with_name(path.stem + ".units.json")


def sidecar(mesh, filename: str, coordinates: str = "m") -> dict:
    """The sidecar's content: the file name (no folder), the coordinates' unit and, per array,
    its unit, meaning and shape."""
    def entry(name, value, where):
        unit, what = ARRAYS.get(name, ("1", "dimensionless"))
        return {"unit": unit, "description": what, "association": where, "shape": list(np.shape(value))}

    arrays = {n: entry(n, v, "point") for n, v in mesh.point_data.items()}
    arrays.update({n: entry(n, np.atleast_1d(v), "field") for n, v in (mesh.field_data or {}).items()})
    return {"file": filename, "coordinates_unit": coordinates,
            "coordinates": "x along the axis from the free surface into the target, (y, z) across it",
            "arrays": arrays}


def in_coordinates(mesh, coordinates: str = "m"):
    """``mesh`` with its coordinates in ``coordinates`` (``"m"`` or ``"mm"``): the points are
    scaled, the arrays keep their SI units (named in their names), and field data
    ``coordinates_unit_m`` records one coordinate unit in metres."""
    import meshio

    if coordinates not in COORDINATE_UNITS:
        from semianalytic.errors import InputError

        raise InputError("coordinates", f"{coordinates!r} is not one of {', '.join(COORDINATE_UNITS)}")
    scale = COORDINATE_UNITS[coordinates]
    fd = dict(mesh.field_data or {})
    fd["coordinates_unit_m"] = np.array([scale])
    return meshio.Mesh(np.asarray(mesh.points, float) / scale, mesh.cells, point_data=dict(mesh.point_data),
                       field_data=fd)


def write_vtu(mesh, path: str | os.PathLike, coordinates: str = "m") -> Path:
    """Write ``mesh`` as binary ``.vtu`` atomically (temporary file in the folder, then rename),
    its numeric field data included, and its sidecar JSON (:func:`sidecar_path`).

    Parameters
    ----------
    mesh : meshio.Mesh
        Coordinates in metres; arrays named with their unit (:data:`ARRAYS`).
    path : str or os.PathLike
        The ``.vtu`` file.
    coordinates : {"m", "mm"}
        Unit of the coordinates written (``"mm"`` gives readable axis ticks at projectile scale).

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    import meshio

    from semianalytic.io import _umask, atomic_write_json

    mesh = in_coordinates(mesh, coordinates)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=".vtu", dir=path.parent)
    os.close(fd)
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
    atomic_write_json(sidecar_path(path), sidecar(mesh, path.name, coordinates))
    return path


# --------------------------------------------------------------------------------------
# FEM fields of fem_check


def fem_meridian_mesh(field, u: float, phi_reference=None):
    """A FEM potential field in the meridian plane as a meshio mesh.

    ``field``: vertex values of fem_check (:class:`fem_check.api.PotentialField`: ``points``
    (n, 2) in the target frame [m], ``triangles``, ``phi`` (unit speed) [m], ``gradient`` (n, 2)).
    Point data: ``phi_m``, ``velocity_m_s`` = -u grad(phi) (Part I, eq. (8)) and ``speed_m_s``;
    with ``phi_reference`` (n,) (e.g. the BEM potential at the same vertices, NaN where not
    defined), also ``phi_bem_m`` and ``phi_difference_m`` = FEM - reference.
    """
    import meshio

    pts2 = np.asarray(field.points, float)
    phi = np.asarray(field.phi, float)
    grad = np.asarray(field.gradient, float)
    vel = np.column_stack([-u * grad[:, 0], -u * grad[:, 1], np.zeros(len(phi))])
    pdata = {"phi_m": phi, "velocity_m_s": vel, "speed_m_s": np.hypot(vel[:, 0], vel[:, 1])}
    if phi_reference is not None:
        ref = np.asarray(phi_reference, float)
        pdata["phi_bem_m"] = ref
        pdata["phi_difference_m"] = phi - ref
    pts = np.column_stack([pts2, np.zeros(len(phi))])
    return meshio.Mesh(pts, [("triangle", np.asarray(field.triangles))], point_data=pdata,
                       field_data={"speed_u_m_s": np.array([float(u)])})


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


def read_in_mm(path):
    """A ``.vtu`` of :func:`write_vtu` read with pyvista, its coordinates in mm whatever unit
    they were written in (field data ``coordinates_unit_m``; metres when absent), so that axis
    ticks and a scale bar read in mm.  The arrays keep their SI units."""
    import pyvista as pv

    mesh = pv.read(str(path))
    unit_m = float(np.asarray(mesh.field_data["coordinates_unit_m"])[0]) if "coordinates_unit_m" in mesh.field_data else 1.0
    mesh.points = np.asarray(mesh.points, float) * (unit_m / 1e-3)
    return mesh


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
    vol = read_in_mm(volume_path)
    half = vol.clip(normal=(0.0, 0.0, 1.0), origin=(0.0, 0.0, 0.0))
    p = pv.Plotter(off_screen=True, window_size=list(window))
    p.set_background("white")
    speed_all = np.asarray(vol.point_data["speed_m_s"])
    norm, extend, _ = speed_scale(speed_all)
    log = type(norm).__name__ == "LogNorm"
    # VTK's fonts lack '|': a plain title (the old "speed |v|" rendered as "speed ᵛ")
    bar = {"title": "speed [m/s]" + (", log scale" if log else ""), "color": "black", "vertical": True,
           "position_x": 0.86, "position_y": 0.15, "height": 0.7, "fmt": "%.3g"}
    p.add_mesh(half, scalars="speed_m_s", cmap="viridis", show_scalar_bar=True, clim=[norm.vmin, norm.vmax],
               log_scale=log, scalar_bar_args=bar)
    mer = read_in_mm(meridian_path)
    if mer.n_points:
        b = mer.bounds
        span = float(b[1] - b[0])
        step = span / 28.0
        gx, gy = np.meshgrid(np.arange(b[0] + 0.5 * step, b[1], step), np.arange(0.5 * step, b[3], step), indexing="ij")
        lattice = pv.PolyData(np.column_stack([gx.ravel(), gy.ravel(), np.zeros(gx.size)]))
        probed = lattice.sample(mer)
        ok = np.asarray(probed["vtkValidPointMask"]) == 1
        pts = np.asarray(probed.points)[ok]
        vel = np.asarray(probed["velocity_m_s"])[ok]
        pts = np.vstack([pts, pts * [1.0, -1.0, 1.0]])
        vel = np.vstack([vel, vel * [1.0, -1.0, 1.0]])
        pts[:, 2] += 0.01 * span  # just above the cut face, towards the camera
        speed = np.linalg.norm(vel, axis=1)
        arrows_src = pv.PolyData(pts)
        arrows_src.point_data["direction"] = vel / np.where(speed > 0, speed, 1.0)[:, None]
        p.add_mesh(arrows_src.glyph(orient="direction", scale=False, factor=0.6 * step), color="white")
    if surface_path is not None:
        # the whole projectile: in parallel projection it covers exactly its own cut section
        p.add_mesh(read_in_mm(surface_path), color="lightgrey", smooth_shading=True)
    if title:
        import textwrap

        p.add_text("\n".join(textwrap.wrap(title, 70)) + "\naxes: x, depth [mm] (horizontal); r, radius [mm] (vertical)",
                   font_size=9, color="black")  # VTK drops the vertical axis title in a 2D view
    # axes with their unit and a length scale, both in mm (the meshes were read in mm)
    b = vol.bounds
    x_lo = 0.0 if abs(b[0]) < 1e-9 else float(b[0])  # the free surface x = 0, not -3e-15
    p.show_bounds(bounds=[x_lo, b[1], -b[3], b[3], 0.0, 0.0], xtitle="x, depth [mm]", ytitle="r, radius [mm]", ztitle="",
                  location="outer", ticks="outside", font_size=9, color="black", fmt="%.3g", show_zaxis=False,
                  show_zlabels=False)
    span = float(b[1] - b[0])
    bar_len = 10.0 ** math.floor(math.log10(max(span / 4.0, 1e-9)))  # 1, 10, 100 ... mm: about a quarter of the window
    y0 = -0.92 * float(b[3])
    x0 = float(b[1]) - 1.1 * bar_len
    p.add_mesh(pv.Line((x0, y0, 0.02 * span), (x0 + bar_len, y0, 0.02 * span)), color="white", line_width=5)
    p.add_point_labels([(x0 + 0.5 * bar_len, y0 + 0.09 * float(b[3]), 0.02 * span)], [f"{bar_len:g} mm"], font_size=12,
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
