"""The velocity field of `run --out` in pyvista and meshio, with axes in millimetres.

Every `.vtu` names its arrays' units (`velocity_m_s`, `speed_m_s`, `phi_m`) and has a
`.units.json` beside it; the coordinates are in metres, so a render at projectile scale reads
"0.0" on every tick. Write the file in mm (`write_vtu(mesh, path, coordinates="mm")`) or read it
in mm (`read_in_mm`); the arrays keep their SI units. Here: the exact potential flow around a
sphere (semianalytic.exact), exported and read back both ways.
"""

import json
import tempfile
from pathlib import Path

import meshio
import numpy as np

from semianalytic import exact
from semianalytic.bem import field as bemfield
from semianalytic.report import vtk

a = 5e-3  # sphere radius [m]
grid = bemfield.meridian_grid(-3 * a, 3 * a, 3 * a, 31, 16, lambda x, r: x**2 + r**2 <= a**2 * (1 + 1e-9))
field = bemfield.evaluate_field(grid, lambda p: np.column_stack(exact.sphere_gradient(p[:, 0], p[:, 1], a)), 800.0,
                                lambda p: exact.sphere_potential(p[:, 0], p[:, 1], a))
with tempfile.TemporaryDirectory() as tmp:
    path = vtk.write_vtu(vtk.meridian_mesh(field), Path(tmp) / "meridian.vtu")
    mesh = meshio.read(path)  # meshio and pyvista both read it
    units = json.loads(vtk.sidecar_path(path).read_text())
    print("arrays:", {name: units["arrays"][name]["unit"] for name in mesh.point_data})
    print(f"x from {mesh.points[:, 0].min():.4f} to {mesh.points[:, 0].max():.4f} {units['coordinates_unit']}")
    in_mm = vtk.read_in_mm(path)  # a pyvista mesh in mm, ready for show_bounds and a mm scale bar
    print(f"in mm: x from {in_mm.bounds[0]:.1f} to {in_mm.bounds[1]:.1f} mm; "
          f"max speed {np.max(in_mm.point_data['speed_m_s']):.0f} m/s")
