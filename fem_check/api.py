"""fem_check's public API for :mod:`semianalytic`: what the ``run`` pipeline may call.

:func:`halfspace_potential_field` solves the potential problem of Part I, eq. (7) around a
projectile at depth P with the FEM (gmsh mesh of the meridian half-plane, P2 elements with
curved edges, monopole Robin far field, errata item 2f) and returns its vertex values as plain
arrays (:class:`PotentialField`), ready to be written as VTK by :mod:`semianalytic.report.vtk`.
:func:`potential_field` does the same for an already solved
:class:`~fem_check.potential.PotentialSolution`.

This is the only module of fem_check that :mod:`semianalytic` imports (from
:mod:`semianalytic.run.fields`; import contract in pyproject.toml).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["MeshOptions", "PotentialField", "halfspace_potential_field", "potential_field"]

from fem_check.meshing import MeshOptions  # noqa: E402 (re-exported: the mesh parameters)


@dataclass(frozen=True)
class PotentialField:
    """Vertex values of a FEM potential in the meridian plane (SI, target frame).

    points (n, 2) of (x, r) [m]; triangles (m, 3) vertex indices; phi (n,) unit-speed potential
    [m]; gradient (n, 2) grad(phi) (L2 projection of the FEM gradient onto the FEM space);
    on_surface (n,) vertices on the body or the wall (where the BEM field is singular);
    dofs, A [m^3] and C [m^2] of Part I, eq. (12).
    """

    points: np.ndarray
    triangles: np.ndarray
    phi: np.ndarray
    gradient: np.ndarray
    on_surface: np.ndarray
    dofs: int
    A: float
    C: float


def potential_field(solution, surface_tags=("body", "wall")) -> PotentialField:
    """The vertex values of a :class:`~fem_check.potential.PotentialSolution`."""
    basis = solution.basis
    vert = basis.nodal_dofs[0]
    # the FEM may solve in x - shift (tip-centred); the field is in the target frame
    shift = float(getattr(solution, "shift", 0.0))
    points = basis.doflocs[:, vert].T + np.array([shift, 0.0])
    ip = basis.interpolate(solution.phi)
    gradient = np.column_stack([basis.project(ip.grad[0])[vert], basis.project(ip.grad[1])[vert]])
    on = np.zeros(len(vert), dtype=bool)
    for tag in surface_tags:
        if tag in solution.dm.boundaries:
            nodes = solution.dm.facet_nodes(solution.dm.boundaries[tag])
            on[nodes[nodes < len(vert)]] = True
    return PotentialField(points, solution.dm.mesh.t[:3].T, solution.phi[vert], gradient, on,
                          solution.n_dofs, float(solution.A), float(solution.C))


def halfspace_potential_field(nose, depth: float, options: MeshOptions | None = None) -> PotentialField:
    """FEM potential around ``nose`` with its tip at depth P [m] in the half-space (Part I, eq. (7))."""
    from fem_check.meshing import build_mesh, halfspace_domain
    from fem_check.potential import solve_potential

    opts = options if options is not None else MeshOptions()
    return potential_field(solve_potential(build_mesh(halfspace_domain(nose, depth, opts), opts), "monopole"))
