"""fem_check's mesh cache keeps the scikit-fem arrays of each gmsh mesh (verify speed, issue 14;
self-verifying entries, issue 27).

The reference is the .msh file read by meshio and matched to facets (the path the arrays
replace): the mesh read from the arrays has the same nodes, elements, tagged facets and pieces,
exactly, and the potential solved on it the same A, bit for bit.  A damaged, truncated, empty or
mismatched entry is discarded with a warning and the mesh made again.
"""

from __future__ import annotations

import numpy as np
import pytest

from fem_check.coefficients import halfspace_mesh
from fem_check.meshing import MeshOptions
from fem_check.potential import solve_potential
from semianalytic.geometry import sphere_nose


def _same(a, b) -> None:
    assert type(a.mesh) is type(b.mesh)
    assert np.array_equal(a.mesh.doflocs, b.mesh.doflocs) and np.array_equal(a.mesh.t, b.mesh.t)
    assert a.boundaries.keys() == b.boundaries.keys() and a.pieces.keys() == b.pieces.keys()
    assert all(np.array_equal(a.boundaries[k], b.boundaries[k]) for k in a.boundaries)
    assert all(np.array_equal(a.pieces[k], b.pieces[k]) for k in a.pieces)


@pytest.mark.parametrize("order", [1, 2])
def test_cached_arrays_give_the_msh_mesh(tmp_path, monkeypatch, order):
    monkeypatch.setenv("FEM_CHECK_MESH_CACHE", str(tmp_path))
    nose, opts = sphere_nose(2.0), MeshOptions(h=0.2, order=order)
    from_msh = halfspace_mesh(nose, 0.5, opts)  # gmsh, then meshio; writes the arrays
    sidecars = sorted(tmp_path.glob("*.npz"))
    assert len(sidecars) == 1
    from_arrays = halfspace_mesh(nose, 0.5, opts)
    _same(from_msh, from_arrays)
    assert solve_potential(from_msh, "monopole").A == solve_potential(from_arrays, "monopole").A

    # a damaged, truncated, empty or foreign entry is discarded with a warning and made again
    good = sidecars[0].read_bytes()
    for bad in (b"not an npz", good[: len(good) // 2], b"", good.replace(b'"key": "', b'"key": "x', 1)):
        sidecars[0].write_bytes(bad)
        with pytest.warns(UserWarning, match="mesh cache: discarded"):
            again = halfspace_mesh(nose, 0.5, opts)
        _same(from_msh, again)
        assert sidecars[0].read_bytes() == good  # rebuilt and stored again
    assert not list(tmp_path.glob("*.msh"))  # gmsh's file stays in a temporary folder
