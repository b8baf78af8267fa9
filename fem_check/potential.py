"""Axisymmetric Laplace problem for the velocity potential (Part I, eqs. (6), (7)) by P1/P2 finite elements.

In the meridian plane (x, r) Laplace's equation in axisymmetric form, div(r grad phi) = 0, has
the weak form  int r grad(phi).grad(v) dx dr = int r (dphi/dnu) v ds  with nu the outward
normal of the fluid domain.  Boundary data (Part I, eq. (7), signs of errata item 1b: n is the
body normal pointing into the fluid, n = -nu on the body):

* body: dphi/dn = -n_x, i.e. dphi/dnu = n_x = -nu_x;
* free surface x = 0, hole wall and shank: dphi/dnu = 0; axis r = 0: natural (weight r);
* far boundary R = R_far (a circle about ``domain.far_center``): a Robin condition
  dphi/dR + k phi/R = 0 that is exact for the leading far field phi ~ R^-k:
  k = 2 for a closed body (dipole), k = 1 for the half-space (monopole, errata item 2f),
  k = 0 for a plain Neumann cut-off (wrong; kept to show the error).

Then A = int phi n_x dS (Part I, eq. (12)) is the load functional 2 pi l(phi), which equals
the energy 2 pi a(phi, phi) of the solution, so it converges at twice the rate of the energy
norm (h^2 for P1, h^4 for P2 with curved edges).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse.linalg as spla
from skfem import Basis, BilinearForm, ElementTriP1, ElementTriP2, FacetBasis, Functional, LinearForm
from skfem.helpers import dot, grad

from fem_check.meshing import DomainMesh, moved_mesh
from semianalytic.errors import InputError

FAR_FIELD_EXPONENT = {"dipole": 2.0, "monopole": 1.0, "neumann": 0.0}


@BilinearForm
def _laplace_r(u, v, w):
    return w.x[1] * dot(grad(u), grad(v))


@BilinearForm
def _robin_r(u, v, w):
    xc, rc, k = w["xc"], w["rc"], w["k"]
    R = np.sqrt((w.x[0] - xc) ** 2 + (w.x[1] - rc) ** 2)
    return (k / R) * w.x[1] * u * v


@LinearForm
def _body_load(v, w):
    # dphi/dnu = -nu_x on the body (nu: outward normal of the fluid domain)
    return -w.n[0] * w.x[1] * v


@Functional
def _contact_area(w):
    # C = int n_x dS with n = -nu  (Part I, eq. (12)); 2 pi applied by the caller
    return -w.n[0] * w.x[1]


def probe_matrix(basis: Basis, points: np.ndarray):
    """Sparse matrix evaluating a FEM function of ``basis`` at points (M, 2).

    scikit-fem's ``probes`` has no element finder for quadratic meshes; elements are found on the
    straight-sided vertex mesh (exact away from curved boundary edges) and the isoparametric
    mapping is inverted by ``mapping.invF``.
    """
    from scipy.sparse import coo_matrix
    from skfem import MeshTri1

    x = np.asarray(points, float).T
    mesh = basis.mesh
    lin = MeshTri1(mesh.p[:, : mesh.nvertices] if mesh.p.shape[1] > mesh.nvertices else mesh.p, mesh.t)
    cells = lin.element_finder()(*x)
    pts = basis.mapping.invF(x[:, :, np.newaxis], tind=cells)
    phis = np.array([basis.elem.gbasis(basis.mapping, pts, k, tind=cells)[0] for k in range(basis.Nbfun)]).flatten()
    rows = np.tile(np.arange(x.shape[1], dtype=np.int32), basis.Nbfun)
    cols = basis.element_dofs[:, cells].flatten()
    return coo_matrix((phis, (rows, cols)), shape=(x.shape[1], basis.N)).tocsr()


def mapping_for(mesh):
    """The element mapping of ``mesh``; for curved (P2) meshes an isoparametric mapping whose inverse
    (Newton) accepts the round-off of tiny elements: graded corners have elements of 1e-7 d at
    coordinates of order d, where scikit-fem's absolute tolerance 1e-12 on the sum of the updates
    over an element's points cannot be met (the reference coordinates carry round-off 1e-16 |x|/size)."""
    if mesh.affine:
        return mesh._mapping()
    from skfem.mapping import MappingIsoparametric

    class _RoundoffTolerantMapping(MappingIsoparametric):
        def invF(self, x, tind=None, newton_max_iters=50, newton_tol=1e-12):
            X = np.zeros(x.shape) + 0.5
            # round-off floor of the reference coordinates: |x| eps / element size (per element)
            size = np.sqrt(np.abs(np.linalg.det(np.moveaxis(self.DF(X, tind), (0, 1), (-2, -1))))).min(axis=-1)
            tol = np.maximum(newton_tol, 1e3 * np.finfo(float).eps * np.abs(x).max(axis=(0, 2)) / size)
            for _ in range(newton_max_iters):
                dX = np.einsum("ijkl,jkl->ikl", self.invDF(X, tind), x - self.F(X, tind))
                X = np.clip(X + dX, 0.0, 1.0)
                if (np.abs(dX).max(axis=(0, 2)) < tol).all():
                    return X
            # stalled: accept the round-off floor measured at the final point, in units of the domain
            # (the former fallback, with which every study of reports/fem_verify_* ran)
            size = np.sqrt(np.abs(np.linalg.det(np.moveaxis(self.DF(X, tind), (0, 1), (-2, -1))))).min(axis=-1)
            floor = 1e3 * np.finfo(float).eps * (1 + np.abs(x).max(axis=(0, 2))) / size
            if (np.abs(dX).max(axis=(0, 2)) < np.maximum(floor, 1e-6)).all():
                return X
            raise RuntimeError("inverse element mapping: Newton iteration did not converge")

    return _RoundoffTolerantMapping(mesh, mesh.elem(), mesh.bndelem)


def element_for(order: int):
    if order == 1:
        return ElementTriP1()
    if order == 2:
        return ElementTriP2()
    raise InputError("order", f"FEM order must be 1 or 2; got {order!r}")


@dataclass
class PotentialSolution:
    """FEM solution phi of Part I, eq. (7) on a :class:`DomainMesh`."""

    dm: DomainMesh
    basis: Basis
    phi: np.ndarray
    A: float  # m^3, Part I eq. (12)
    C: float  # m^2, Part I eq. (12)
    far_field: str
    seconds: float
    shift: float = 0.0  # the FEM works in x - shift (see solve_potential)

    @property
    def n_dofs(self) -> int:
        return int(self.basis.N)

    def potential(self, points: np.ndarray) -> np.ndarray:
        """phi at points (M, 2) of (x, r) inside the mesh."""
        pts = np.asarray(points, float) - np.array([self.shift, 0.0])
        return probe_matrix(self.basis, pts) @ self.phi

    def node_value(self, point: tuple[float, float]) -> float:
        """phi at the mesh vertex nearest to ``point`` (a nodal value: the tip, the waterline)."""
        p = self.dm.mesh.p
        i = int(np.argmin((p[0] - point[0]) ** 2 + (p[1] - point[1]) ** 2))
        return float(self.phi[self.basis.nodal_dofs[0, i]])

    def surface(self, tag: str = "body", intorder: int | None = None) -> dict:
        """Quadrature-point data on a boundary: x, r, nx, nr (body normal n = -nu, into the fluid),
        weight (dS including 2 pi r), phi, dphi_ds (along t = (-n_r, n_x)) and grad2 = |grad phi|^2.

        The gradient is rebuilt from the exact Neumann datum (dphi/dn = -n_x on the body, 0 on the
        free surface, the hole wall and the shank) and the tangential
        derivative of the FEM trace, which is more accurate than the FEM normal derivative.
        """
        facets = self.dm.boundaries[tag]
        order = intorder or 2 * self.basis.elem.maxdeg + 2
        fb = FacetBasis(self.basis.mesh, self.basis.elem, facets=facets, intorder=order, mapping=self.basis.mapping,
                        dofs=self.basis.dofs, disable_doflocs=True)
        ph = fb.interpolate(self.phi)
        x, r = np.asarray(fb.global_coordinates())
        x = x + self.shift
        nx, nr = -np.asarray(fb.normals)[0], -np.asarray(fb.normals)[1]
        tx, tr = -nr, nx
        gx, gr = ph.grad
        dphi_ds = tx * gx + tr * gr
        dn = -nx if tag == "body" else np.zeros_like(nx)  # exact Neumann datum (Part I, eq. (7))
        grad2 = dn * dn + dphi_ds * dphi_ds
        dphi_dx = dn * nx + dphi_ds * tx
        weight = 2 * math.pi * r * fb.dx
        return {
            "x": x.ravel(), "r": r.ravel(), "nx": nx.ravel(), "nr": nr.ravel(), "weight": weight.ravel(),
            "phi": np.asarray(ph).ravel(), "dphi_ds": dphi_ds.ravel(), "grad2": grad2.ravel(), "dphi_dx": dphi_dx.ravel(),
        }


def symmetric_lu(K):
    """Sparse LU of a symmetric positive definite matrix (the weighted Laplacian with the Robin far
    field, or its interior block): SuperLU in symmetric mode (a minimum-degree ordering of K + K^T,
    diagonal pivots, which positive definiteness makes safe) has about a third less fill and time
    than its default column ordering for a general matrix.  The same system solved; the solutions
    agree to round-off (relative 1e-13 on the meshes of ``fem_check verify``)."""
    return spla.splu(K.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})


def solve_potential(dm: DomainMesh, far_field: str, order: int | None = None) -> PotentialSolution:
    """Solve Part I, eqs. (6)-(7) on ``dm`` with P``order`` elements (default: the mesh order)."""
    if far_field not in FAR_FIELD_EXPONENT:
        raise InputError("far_field", f"must be one of {sorted(FAR_FIELD_EXPONENT)}; got {far_field!r}")
    t0 = time.perf_counter()
    order = order or dm.order
    elem = element_for(order)
    q = 2 * order + 2  # weight r and curved (quadratic) geometry: one degree above exact for straight edges
    # Work in x - P (tip at the origin): scikit-fem inverts curved facet maps by Newton iterations
    # with an absolute tolerance, which round-off defeats on the tiny tip elements when |x| is
    # thousands of element sizes (deep penetration).  Only x is shifted: the weight r is unchanged.
    shift = float(dm.domain.info.get("depth", 0.0)) if dm.domain.kind == "halfspace" else 0.0
    mesh = moved_mesh(dm.mesh, dm.mesh.doflocs - np.array([[shift], [0.0]])) if shift else dm.mesh
    mapping = mapping_for(mesh)
    basis = Basis(mesh, elem, intorder=q, mapping=mapping)
    K = _laplace_r.assemble(basis)
    # the facet bases reuse the cell basis' dof numbering (Dofs(mesh, elem) again, otherwise) and skip the
    # global dof locations they never read
    body = FacetBasis(mesh, elem, facets=dm.boundaries["body"], intorder=q, mapping=mapping, dofs=basis.dofs,
                      disable_doflocs=True)
    f = _body_load.assemble(body)
    k = FAR_FIELD_EXPONENT[far_field]
    if k > 0:
        far = FacetBasis(mesh, elem, facets=dm.boundaries["far"], intorder=q, mapping=mapping, dofs=basis.dofs,
                         disable_doflocs=True)
        xc, rc = dm.domain.far_center
        K = K + _robin_r.assemble(far, xc=xc - shift, rc=rc, k=k)
    if k == 0:
        # pure Neumann: fix the additive constant by phi = 0 at the far point on the axis
        far_nodes = basis.get_dofs(dm.boundaries["far"]).all()
        K = K.tolil()
        i = int(far_nodes[0])
        K[i, :] = 0
        K[i, i] = 1.0
        K = K.tocsr()
        f[i] = 0.0
    phi = symmetric_lu(K).solve(f) if k > 0 else spla.spsolve(K.tocsc(), f)
    A = 2 * math.pi * float(f @ phi) if k > 0 else 2 * math.pi * float(_body_load.assemble(body) @ phi)
    C = 2 * math.pi * float(_contact_area.assemble(body))
    return PotentialSolution(dm, basis, phi, A, C, far_field, time.perf_counter() - t0, shift)
