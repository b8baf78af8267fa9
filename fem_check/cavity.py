"""FEM of the elastic spherical cavity and of the elastic and cracked zones of Part II.

Sign convention of Part II: tension positive, r the radius.  Two discretisations of the
same problems, both independent of the closed forms they are compared with:

* radially symmetric (1D, weight r^2): P2 elements on a geometrically graded line mesh;
* axisymmetric (2D, weight r_perp in the meridian plane): P2 vector elements on a curved
  quadratic gmsh mesh of the quarter annulus, u_r = 0 on the axis, u_x = 0 on the
  symmetry plane x = 0.

Far field: the exterior elastic solution decays like u = k/r^2, for which the traction on a
sphere of radius R is sigma_r = -4 mu u / R exactly; this Robin condition on the outer
boundary replaces the unbounded medium without truncation error.

Problems:

* ``lame``: pressurised cavity, sigma_r(a) = -p (Part II, eqs. (1)-(3) with u(inf) = 0),
  compared with Lame's solution (``semianalytic.cavity.zones.lame_cavity``).
* ``zones``: cracked zone b < r < c with radial stress only (sigma_phi = 0, sigma_r = E du/dr,
  Part II eqs. (9)-(10), errata items 8-9) bonded to the elastic zone r > c, loaded by
  sigma_r(b) = sigma* (eq. (7)); c from eq. (13).  Compared with eqs. (5), (11), (12), and
  checked for the boundary conditions sigma_phi(c+0) = sigma_f (eq. (4)) and
  sigma_r(c) = -2 sigma_f (eq. (8)), which the FEM is not told.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.sparse.linalg as spla
from skfem import (Basis, BilinearForm, ElementLineP2, ElementTriP2, ElementTriP3, ElementTriP4, ElementVector, FacetBasis, LinearForm,
                   MeshLine1, condense, solve)
from skfem.helpers import dot

from fem_check.meshing import MeshOptions, annulus_domain, build_mesh
from semianalytic.errors import InputError


CRACK_REGULARISATION = 1e-6  # fraction of the isotropic stiffness added in the 2D cracked zone


def lame_parameters(E: float, nu: float) -> tuple[float, float]:
    """(lambda, mu) from Young's modulus and Poisson's ratio."""
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


# ------------------------------------------------------------------------------------
# 1D, spherical symmetry


@dataclass
class RadialSolution:
    """FEM fields at sample points (element quadrature points): r, u, sigma_r, sigma_phi."""

    r: np.ndarray
    u: np.ndarray
    sigma_r: np.ndarray
    sigma_phi: np.ndarray
    n_dofs: int
    seconds: float
    nodes: np.ndarray = field(repr=False, default=None)
    u_nodes: np.ndarray = field(repr=False, default=None)


def graded_nodes(r0: float, r1: float, n: int, ratio: float) -> np.ndarray:
    """n elements on [r0, r1], sizes growing geometrically by ``ratio`` overall (smallest at r0)."""
    q = ratio ** (1.0 / max(n - 1, 1))
    sizes = q ** np.arange(n)
    return r0 + (r1 - r0) * np.concatenate([[0.0], np.cumsum(sizes) / sizes.sum()])


def solve_radial(r_in: float, traction: float, E: float, nu: float, outer: float, n_elements: int = 200,
                 cracked_until: float | None = None, ratio: float | None = None) -> RadialSolution:
    """1D spherically symmetric elasticity on [r_in, outer] (Part II, eqs. (1)-(3), weight r^2).

    sigma_r(r_in) = ``traction`` (tension positive: -p for a pressure p), exact Robin far field
    sigma_r(outer) = -4 mu u/outer.  With ``cracked_until = c`` the zone r_in < r < c has radial
    stress only, sigma_r = E du/dr, sigma_phi = 0 (Part II, eqs. (9)-(10), errata 8-9); the mesh
    has a node at c.
    """
    t0 = time.perf_counter()
    lam, mu = lame_parameters(E, nu)
    ratio = ratio or outer / r_in
    if cracked_until is None:
        nodes = graded_nodes(r_in, outer, n_elements, ratio)
    else:
        c = float(cracked_until)
        n1 = max(4, int(round(n_elements * math.log(c / r_in) / math.log(outer / r_in))))
        inner = graded_nodes(r_in, c, n1, c / r_in)
        rest = graded_nodes(c, outer, max(4, n_elements - n1), outer / c)
        nodes = np.concatenate([inner, rest[1:]])
    mesh = MeshLine1.init_tensor(nodes)
    basis = Basis(mesh, ElementLineP2(), intorder=6)
    centroids = 0.5 * (nodes[:-1] + nodes[1:])
    cracked = (centroids < cracked_until) if cracked_until is not None else np.zeros(len(centroids), bool)
    cracked_q = cracked[:, None] * np.ones(basis.X.shape[1])

    @BilinearForm
    def stiffness(u, v, w):
        r = w.x[0]
        du, dv = u.grad[0], v.grad[0]
        sr = (lam + 2 * mu) * du + 2 * lam * u / r
        sp = lam * du + 2 * (lam + mu) * u / r
        iso = sr * dv + 2 * sp * v / r
        crack = E * du * dv
        return np.where(w["cracked"], crack, iso) * r**2

    K = stiffness.assemble(basis, cracked=cracked_q).tolil()
    f = np.zeros(basis.N)
    i_in = int(basis.nodal_dofs[0, 0])
    i_out = int(basis.nodal_dofs[0, -1])
    K[i_out, i_out] += 4 * mu * outer  # Robin: -sigma_r(R) R^2 v(R) = 4 mu u(R) R v(R)
    f[i_in] = -traction * r_in**2  # boundary term -sigma_r(r_in) r_in^2 v(r_in)
    u = spla.spsolve(K.tocsc(), f)
    ui = basis.interpolate(u)
    r = basis.global_coordinates().value[0]
    du = ui.grad[0]
    val = ui.value
    sr = np.where(cracked_q, E * du, (lam + 2 * mu) * du + 2 * lam * val / r)
    sp = np.where(cracked_q, 0.0, lam * du + 2 * (lam + mu) * val / r)
    order = np.argsort(r.ravel())
    return RadialSolution(r.ravel()[order], val.ravel()[order], sr.ravel()[order], sp.ravel()[order], basis.N,
                          time.perf_counter() - t0, nodes, u[basis.nodal_dofs[0]])


# ------------------------------------------------------------------------------------
# 2D axisymmetric


@dataclass
class AxisymmetricSolution:
    """FEM fields at interior quadrature points: x, rho (meridian coordinates), R = |(x, rho)|,
    u_R, sigma_RR, sigma_hoop (out of plane, theta), sigma_psi (in-plane hoop), sigma_Rpsi."""

    x: np.ndarray
    rho: np.ndarray
    R: np.ndarray
    u_R: np.ndarray
    u_psi: np.ndarray
    sigma_RR: np.ndarray
    sigma_theta: np.ndarray
    sigma_psi: np.ndarray
    sigma_Rpsi: np.ndarray
    n_dofs: int
    n_elements: int
    seconds: float


def solve_axisymmetric(a: float, traction: float, E: float, nu: float, outer: float, options: MeshOptions,
                       cracked_until: float | None = None, degree: int = 2) -> AxisymmetricSolution:
    """Axisymmetric elasticity (meridian plane x, rho; weight rho) around a spherical cavity.

    Same problem as :func:`solve_radial`, solved without using spherical symmetry: P2 vector
    elements on a curved quarter-annulus mesh.  In the cracked zone the stress is
    sigma = E e_RR (e_R e_R) (radial stress only, Part II eqs. (9)-(10), errata 8-9).
    """
    t0 = time.perf_counter()
    lam, mu = lame_parameters(E, nu)
    dom = annulus_domain(a, outer, options, interface=cracked_until)
    dm = build_mesh(dom, options)
    # P3/P4 facet dofs need consistently oriented (sorted) element vertices
    mesh = dataclasses.replace(dm.mesh, t=np.sort(dm.mesh.t, axis=0)) if degree > 2 else dm.mesh
    elem = ElementVector({2: ElementTriP2(), 3: ElementTriP3(), 4: ElementTriP4()}[degree])
    basis = Basis(mesh, elem, intorder=2 * degree + 2)
    if cracked_until is not None:
        xc = mesh.p[:, mesh.t].mean(axis=1)
        cracked = np.hypot(xc[0], xc[1]) < cracked_until
    else:
        cracked = np.zeros(mesh.t.shape[1], bool)
    cracked_q = cracked[:, None] * np.ones(basis.X.shape[1])

    def strains(z, rho):
        """(e_xx, e_rhorho, e_thetatheta, e_xrho) of an axisymmetric displacement field."""
        g = z.grad
        return g[0, 0], g[1, 1], z.value[1] / rho, 0.5 * (g[0, 1] + g[1, 0])

    def radial_strain(e, w):
        R = np.sqrt(w.x[0] ** 2 + w.x[1] ** 2)
        nx, nr = w.x[0] / R, w.x[1] / R
        return nx * nx * e[0] + nr * nr * e[1] + 2 * nx * nr * e[3]

    @BilinearForm
    def stiffness(u, v, w):
        eu, ev = strains(u, w.x[1]), strains(v, w.x[1])
        tr = eu[0] + eu[1] + eu[2]
        iso = (lam * tr + 2 * mu * eu[0]) * ev[0] + (lam * tr + 2 * mu * eu[1]) * ev[1] \
            + (lam * tr + 2 * mu * eu[2]) * ev[2] + 4 * mu * eu[3] * ev[3]
        # radial stress only.  That law has no stiffness against non-radial displacements (the 2D
        # problem is singular); a small fraction of the isotropic stiffness regularises it and
        # perturbs the solution by about that fraction (an exploratory check only, see the report)
        crack = E * radial_strain(eu, w) * radial_strain(ev, w) + CRACK_REGULARISATION * iso
        return np.where(w["cracked"], crack, iso) * w.x[1]

    @BilinearForm
    def robin(u, v, w):
        R = np.sqrt(w.x[0] ** 2 + w.x[1] ** 2)
        return (4 * mu / R) * dot(u, w.n) * dot(v, w.n) * w.x[1]

    @LinearForm
    def load(v, w):
        # t = sigma . nu on R = a with nu = -e_R (out of the medium): t = -sigma_RR e_R = traction nu
        return traction * dot(v, w.n) * w.x[1]

    K = stiffness.assemble(basis, cracked=cracked_q)
    far = FacetBasis(mesh, elem, facets=dm.boundaries["far"], intorder=6)
    K = K + robin.assemble(far)
    cav = FacetBasis(mesh, elem, facets=dm.boundaries["cavity"], intorder=6)
    f = load.assemble(cav)
    fixed = np.concatenate([basis.get_dofs(dm.boundaries["axis"]).all(["u^2"]),
                            basis.get_dofs(dm.boundaries["sym"]).all(["u^1"])])
    u = solve(*condense(K, f, D=np.unique(fixed)))
    ui = basis.interpolate(u)
    x, rho = basis.global_coordinates().value
    e = strains(ui, rho)
    R = np.hypot(x, rho)
    nx, nr = x / R, rho / R
    tr = e[0] + e[1] + e[2]
    sxx, srr, stt, sxr = (lam * tr + 2 * mu * e[0], lam * tr + 2 * mu * e[1], lam * tr + 2 * mu * e[2], 2 * mu * e[3])
    eRR = nx * nx * e[0] + nr * nr * e[1] + 2 * nx * nr * e[3]
    sRR = nx * nx * sxx + nr * nr * srr + 2 * nx * nr * sxr
    spsi = nr * nr * sxx + nx * nx * srr - 2 * nx * nr * sxr
    sRpsi = -nx * nr * sxx + nx * nr * srr + (nx * nx - nr * nr) * sxr
    cq = cracked_q.astype(bool)
    sRR = np.where(cq, E * eRR, sRR)
    stt = np.where(cq, 0.0, stt)
    spsi = np.where(cq, 0.0, spsi)
    sRpsi = np.where(cq, 0.0, sRpsi)
    uR = nx * ui.value[0] + nr * ui.value[1]
    upsi = -nr * ui.value[0] + nx * ui.value[1]
    return AxisymmetricSolution(x.ravel(), rho.ravel(), R.ravel(), uR.ravel(), upsi.ravel(), sRR.ravel(),
                                stt.ravel(), spsi.ravel(), sRpsi.ravel(), basis.N, mesh.t.shape[1],
                                time.perf_counter() - t0)
