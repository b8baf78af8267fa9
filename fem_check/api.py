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

__all__ = ["MeshOptions", "PotentialField", "halfspace_potential_field", "potential_field", "verify"]

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


def verify(case, depths=None, *, h: float = 0.04, quick: bool = False, study_h=(0.16, 0.08, 0.04, 0.02),
           grading: float | None = None, quiet: bool = False) -> dict:
    """FEM against BEM for a case: what ``python -m fem_check verify CASE --json --no-report`` prints.

    Parameters
    ----------
    case : semianalytic.case.Case or str or os.PathLike
        A loaded case or a case file, with a ``[body]`` (added mass) or a ``[projectile]``
        (A, B, C of its nose in the half-space, Part I eq. (12)).
    depths : sequence of float, optional
        Depths of the tip in nose lengths L_h (default that of the command: ``verify.DEFAULT_DEPTHS``).
    h : float
        FEM element size on the body over the diameter, in [0.005, 0.5] (default 0.04).
    quick : bool
        Skip the convergence, refinement and far-field studies.
    study_h : sequence of float
        Element sizes over d of the refinement study on cornered noses (at least three, decreasing).
    grading : float, optional
        Corner grading of the FEM meshes in [0, 1] (default 0.4).
    quiet : bool
        No progress on stderr.

    Returns
    -------
    dict
        The verification payload: ``max_rel_diff`` and per depth ``depths`` rows (half-space), or
        ``added_mass_fem``, ``added_mass_bem``, ``added_mass_exact`` (body).
    """
    from pathlib import Path

    from fem_check.verify import DEFAULT_DEPTHS, _jsonable, verify_case
    from semianalytic.errors import InputError
    from semianalytic.guards import check_case, check_fem

    if not hasattr(case, "projectile"):
        from semianalytic.case import load_case

        case = load_case(Path(case))
    if not 0.005 <= h <= 0.5:
        raise InputError("h", f"element size over d must lie in [0.005, 0.5]; got {h!r}")
    depths = DEFAULT_DEPTHS if depths is None else tuple(float(v) for v in np.atleast_1d(depths))
    if not depths or any(not (np.isfinite(v) and v > 0) for v in depths):
        raise InputError("depths", f"depths (in nose lengths) must be positive; got {depths!r}")
    study_h = tuple(float(v) for v in study_h)
    if len(study_h) < 3 or any(not 0.005 <= v <= 0.5 for v in study_h) or any(b >= a for a, b in zip(study_h, study_h[1:])):
        raise InputError("study_h", f"need at least three decreasing sizes in [0.005, 0.5]; got {study_h!r}")
    if grading is not None and not 0 <= grading <= 1:
        raise InputError("grading", f"must lie in [0, 1]; got {grading!r}")
    if case.body is None and case.projectile is None:
        raise InputError("case", "needs a [body] or a [projectile] section")
    check_case(case)
    check_fem(case, h, depths)
    return _jsonable(verify_case(case, depths, h=h, quick=quick, study_h=study_h, grading=grading, quiet=quiet))
