"""VTK export: files read back with pyvista carry the field that was put in.

1. The exact potential flow around a sphere (semianalytic.exact, independent of the export)
   goes through the meridian grid, the revolution to 3D and meshio; pyvista reads the
   files back and the velocity at every node equals the exact one, and inside cells the
   interpolated velocity (pyvista probe) agrees within the interpolation error.
2. The BEM half-space field (Part I eq. (23)) around the Fig. 5 ogive: the file's velocity
   at sample nodes equals -u grad(phi) of a separate BEM evaluation at the same points.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

pv = pytest.importorskip("pyvista")

from semianalytic import exact  # noqa: E402
from semianalytic.bem import field as bemfield  # noqa: E402
from semianalytic.report import vtk  # noqa: E402

A = 1.0  # sphere radius
U = 2.0  # speed


def _exact_velocity_3d(p):
    """v = -U grad(phi) of the translating sphere at 3D points (x, y, z)."""
    x, y, z = p[:, 0], p[:, 1], p[:, 2]
    r = np.hypot(y, z)
    gx, gr = exact.sphere_gradient(x, r, A)
    with np.errstate(invalid="ignore", divide="ignore"):
        c = np.where(r > 0, y / np.where(r > 0, r, 1), 1.0)
        s = np.where(r > 0, z / np.where(r > 0, r, 1), 0.0)
    return np.column_stack([-U * gx, -U * gr * c, -U * gr * s])


@pytest.fixture(scope="module")
def sphere_files(tmp_path_factory):
    d = tmp_path_factory.mktemp("vtk")
    inside = lambda x, r: x**2 + r**2 <= A**2 * (1 + 1e-9)  # noqa: E731
    g = bemfield.meridian_grid(-3.0, 3.0, 3.0, 41, 21, inside)
    f = bemfield.evaluate_field(
        g,
        lambda p: np.column_stack(exact.sphere_gradient(p[:, 0], p[:, 1], A)),
        U,
        lambda p: exact.sphere_potential(p[:, 0], p[:, 1], A),
    )
    m2 = vtk.write_vtu(vtk.meridian_mesh(f), d / "meridian.vtu")
    m3 = vtk.write_vtu(vtk.revolved_mesh(f, 24), d / "revolved.vtu")
    return m2, m3


def test_meridian_file_holds_the_exact_field(sphere_files):
    mesh = pv.read(sphere_files[0])
    p = np.asarray(mesh.points)
    v = np.asarray(mesh.point_data["velocity_m_s"])
    ref = _exact_velocity_3d(p)  # z = 0: (v_x, v_r, 0)
    np.testing.assert_allclose(v, ref, rtol=1e-12, atol=1e-14)
    assert np.all(p[:, 0] ** 2 + p[:, 1] ** 2 > A**2)  # no node inside the sphere
    np.testing.assert_allclose(mesh.point_data["phi_m"], exact.sphere_potential(p[:, 0], p[:, 1], A), rtol=1e-12)


def test_revolved_file_holds_the_exact_field(sphere_files):
    mesh = pv.read(sphere_files[1])
    p = np.asarray(mesh.points)
    np.testing.assert_allclose(np.asarray(mesh.point_data["velocity_m_s"]), _exact_velocity_3d(p), rtol=1e-12, atol=1e-14)
    # every cell has positive volume (correct hexahedron/wedge node order)
    assert float(np.min(mesh.compute_cell_sizes()["Volume"])) > 0


def test_probe_between_nodes_matches_the_exact_field(sphere_files):
    mesh = pv.read(sphere_files[1])
    rng = np.random.default_rng(0)
    R = rng.uniform(1.6, 2.6, 60)
    th = rng.uniform(0.2, math.pi - 0.2, 60)  # polar angle from +x
    az = rng.uniform(0, 2 * math.pi, 60)
    pts = np.column_stack([R * np.cos(th), R * np.sin(th) * np.cos(az), R * np.sin(th) * np.sin(az)])
    probed = pv.PolyData(pts).sample(mesh)
    assert np.all(np.asarray(probed["vtkValidPointMask"]) == 1)
    got = np.asarray(probed["velocity_m_s"])
    ref = _exact_velocity_3d(pts)
    err = np.linalg.norm(got - ref, axis=1) / np.linalg.norm(ref, axis=1)
    # Linear interpolation error: (h^2/8)|v''|/|v| ~ (0.15^2/8) * 12/R^2 ~ 1.3% at R = 1.6 a, plus the
    # azimuthal chord (dtheta^2/8 = (2 pi/24)^2/8 ~ 0.9%): 4% bounds both with margin.
    assert err.max() < 0.04, err.max()


def test_bem_field_in_the_file(tmp_path):
    from semianalytic.bem import solve_halfspace
    from semianalytic.geometry import ogive_nose

    nose = ogive_nose(7.11e-3, 3.0)
    length, P, u = 71.1e-3, 35.9e-3, 900.0
    field, sol = bemfield.projectile_field(nose, length, P, u, extent=1.5, grid=(13, 7), order=6)
    path = vtk.write_vtu(vtk.revolved_mesh(field, 8), tmp_path / "f.vtu")
    mesh = pv.read(path)
    p = np.asarray(mesh.points)
    v = np.asarray(mesh.point_data["velocity_m_s"])
    assert np.all(np.isfinite(v))
    pick = np.random.default_rng(1).choice(len(p), 25, replace=False)
    r = np.hypot(p[pick, 1], p[pick, 2])
    sep = solve_halfspace(nose, P, order=6)  # a second, separate solve
    g = sep.gradient(np.column_stack([p[pick, 0], r]))
    c = np.where(r > 0, p[pick, 1] / np.where(r > 0, r, 1), 1.0)
    s = np.where(r > 0, p[pick, 2] / np.where(r > 0, r, 1), 0.0)
    ref = np.column_stack([-u * g[:, 0], -u * g[:, 1] * c, -u * g[:, 1] * s])
    # same BEM, same points: equal to round-off of the float64 write/read (1e-10 relative)
    np.testing.assert_allclose(v[pick], ref, rtol=1e-10, atol=1e-10 * np.abs(ref).max())
    # no node inside the projectile or the hole
    inside = bemfield.projectile_inside(nose, length, P)
    assert not np.any(inside(p[:, 0], np.hypot(p[:, 1], p[:, 2])))


def test_fem_field_file(tmp_path):
    """fem_check's FEM potential written as .vtu: read back, it holds the FEM nodal values, and
    near the nose it agrees with the BEM (an independent method) to the FEM's accuracy."""
    from fem_check.api import potential_field
    from fem_check.meshing import MeshOptions, build_mesh, halfspace_domain
    from fem_check.potential import solve_potential
    from semianalytic.bem import solve_halfspace
    from semianalytic.geometry import ogive_nose
    from semianalytic.run.fields import bem_at_vertices

    nose, P, u = ogive_nose(7.11e-3, 3.0), 35.9e-3, 900.0
    opts = MeshOptions(h=0.16, far=8.0)
    sol = solve_potential(build_mesh(halfspace_domain(nose, P, opts), opts), "monopole")
    fem = potential_field(sol)
    path = vtk.write_vtu(vtk.fem_meridian_mesh(fem, u, bem_at_vertices(fem, solve_halfspace(nose, P))), tmp_path / "fem.vtu")
    mesh = pv.read(path)
    vert = sol.basis.nodal_dofs[0]
    shift = np.array([getattr(sol, "shift", 0.0), 0.0])  # fem_check may work in tip-centred x
    np.testing.assert_allclose(np.asarray(mesh.points)[:, :2], sol.basis.doflocs[:, vert].T + shift, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(np.asarray(mesh.point_data["phi_m"]), sol.phi[vert])
    p, diff = np.asarray(mesh.points), np.asarray(mesh.point_data["phi_difference_m"])
    ref = np.asarray(mesh.point_data["phi_bem_m"])
    near = (np.hypot(p[:, 0] - P, p[:, 1]) < 3 * 7.11e-3) & np.isfinite(diff)
    assert near.sum() > 20
    # fem_check's own BEM-FEM agreement target is 1e-3 (A, C); the coarse h = 0.16 d mesh here gives ~3e-4
    assert np.max(np.abs(diff[near])) < 1e-3 * np.max(np.abs(ref[near]))


def test_every_array_and_the_coordinates_carry_their_unit(sphere_files):
    """Every point-data array names its unit (written by hand here: velocity and speed in m/s,
    the potential at unit speed in m, Phi = u phi in m^2/s); the sidecar JSON repeats each
    array's unit and shape and the coordinates' unit; the striking speed of the field survives
    as numeric field data."""
    import json

    expected = {"velocity_m_s": "m/s", "speed_m_s": "m/s", "phi_m": "m", "Phi_m2_s": "m^2/s"}
    for f in sphere_files:
        mesh = pv.read(f)
        assert set(mesh.point_data.keys()) == set(expected)
        side = json.loads(vtk.sidecar_path(f).read_text())
        assert side["file"] == f.name and side["coordinates_unit"] == "m"
        assert {k: side["arrays"][k]["unit"] for k in expected} == expected
        assert side["arrays"]["velocity_m_s"]["shape"] == [mesh.n_points, 3]
        assert float(mesh.field_data["speed_u_m_s"][0]) == U
        assert float(mesh.field_data["coordinates_unit_m"][0]) == 1.0


def test_meshio_reads_the_files(sphere_files):
    """meshio (the other reader the project names) opens every file: no string arrays (meshio
    5.3 exits the interpreter on them), the same points and arrays as pyvista reads."""
    import meshio

    for f in sphere_files:
        m = meshio.read(f)
        p = pv.read(f)
        np.testing.assert_array_equal(m.points, np.asarray(p.points))
        for name in p.point_data.keys():
            np.testing.assert_array_equal(m.point_data[name], np.asarray(p.point_data[name]))
        assert float(m.field_data["speed_u_m_s"][0]) == U


def test_coordinates_in_mm(sphere_files, tmp_path):
    """``coordinates="mm"``: the points are 1000 times the metre file's, the arrays unchanged
    (SI, named with their unit), and ``read_in_mm`` gives the same mm points from both files."""
    import meshio

    m = meshio.read(sphere_files[0])
    mm = vtk.write_vtu(m, tmp_path / "mm.vtu", coordinates="mm")
    got = meshio.read(mm)
    np.testing.assert_allclose(got.points, m.points * 1e3, rtol=1e-15)
    np.testing.assert_array_equal(got.point_data["velocity_m_s"], m.point_data["velocity_m_s"])
    assert float(got.field_data["coordinates_unit_m"][0]) == 1e-3
    np.testing.assert_allclose(np.asarray(vtk.read_in_mm(mm).points), np.asarray(vtk.read_in_mm(sphere_files[0]).points),
                               rtol=1e-15)
