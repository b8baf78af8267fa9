"""Drag coefficients A, B, C (Part I, eq. (12)) and added masses from FEM potentials.

Half-space (nose at depth P, target frame, errata item 1b):

* A = int phi n_x dS and C = int n_x dS over the wetted nose (Part I, eq. (12)).
* B (Part I, eqs. (9), (12)) in the three readings of errata item 2a, from three
  surface integrals over the wetted nose and one derivative in P:

      G = int |grad phi|^2 n_x dS,   H = int (dphi/dx) n_x dS,   Q = int (D phi/D P) n_x dS,

  where D/DP follows a point fixed on the projectile.  Q comes from dA/dP: differentiating
  A(P) = int phi n_x dS over the wetted part of the body gives
  dA/dP = Q + 2 pi phi_w r_w |dr/dx|_w, the last term (waterline, only while P < L_h) from the
  growth of the wetted surface.  dA/dP itself is a central difference of A between solves at
  P - eps and P + eps on the *same* mesh topology, the nodes moved with the body (a shape
  finite difference: no remeshing noise).  Since phi'_P at a fixed target point is
  D phi/D P - dphi/dx:

      B_body      = G + 2 Q                       (default; errata 2a "body")
      B_literal   = G + 2 (Q - H)                 (phi'_P at a fixed target point, as I-(9))
      B_bernoulli = -G + 2 (Q - H)                (Lagrange-Cauchy with the corrected sign)

  and errata 2a's identity B_bernoulli = dA/dP is then checked, not assumed.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np
from skfem import Basis, BilinearForm
from skfem.helpers import dot, grad

from fem_check.meshing import DomainMesh, MeshOptions, Piece, body_domain, build_mesh, halfspace_domain
from fem_check.potential import PotentialSolution, element_for, solve_potential, symmetric_lu
from semianalytic.geometry import Meridian, Nose


@BilinearForm
def _laplace(u, v, w):
    return dot(grad(u), grad(v))


def _boundary_motion(dm: DomainMesh, eps: float) -> tuple[np.ndarray, np.ndarray]:
    """Boundary geometry nodes and their positions for the nose moved from P to P + eps."""
    dom = dm.domain
    info = dom.info
    P, Lh, Rf = info["depth"], info["nose_length"], dom.far_radius
    pos = dm.mesh.doflocs
    nodes_all, new_all = [], []
    shallow = P < Lh * (1 - 1e-9)
    if shallow:
        from fem_check.meshing import _nose_waterline

        nose = info["nose"]
        k, tw = _nose_waterline(nose, P + eps)
        if k != info["waterline_segment"]:
            raise RuntimeError("the depth step crosses a joint of the nose profile; use a smaller step")
        rw, rw_new = info["waterline_radius"], float(nose.segments[k].point(tw)[1])
    for idx, facets in dm.pieces.items():
        tag = dom.loop[idx][0]
        nodes = dm.facet_nodes(facets)
        x, r = pos[0, nodes].copy(), pos[1, nodes].copy()
        if tag == "axis":
            x = P + eps + (x - P) * (Rf - P - eps) / (Rf - P)
        elif tag == "free" and shallow:
            r = rw_new + (r - rw) * (Rf - rw_new) / (Rf - rw)
        elif tag == "wall":
            x = x * (P + eps - Lh) / (P - Lh)
        elif tag == "body":
            x = x + eps
            if shallow:
                w = np.abs(pos[0, nodes]) < 1e-12 * Rf
                x[w], r[w] = 0.0, rw_new
                if dm.order == 2:
                    _recentre_waterline_edges(dm, facets, nodes, x, r, Piece(nose.segments[k], nose.segments[k].t0,
                                                                           nose.segments[k].t1, P + eps))
        nodes_all.append(nodes)
        new_all.append(np.vstack([x, r]))
    nodes = np.concatenate(nodes_all)
    new = np.hstack(new_all)
    # nodes shared by two pieces must get one position: keep the first (they agree at joints)
    nodes, first = np.unique(nodes, return_index=True)
    return nodes, new[:, first]


def _recentre_waterline_edges(dm: DomainMesh, facets, nodes, x, r, curve: Piece) -> None:
    """Put the mid-node of each curved edge ending at the moved waterline vertex back on the moved
    nose, halfway between the edge's ends (otherwise the waterline vertex slides along x = 0 while
    the mid-node moves with the body, and the curved edge distorts)."""
    xy = dm.mesh.doflocs
    for f in facets:
        a, b = dm.mesh.facets[:, f]
        ia, ib = np.searchsorted(nodes, a), np.searchsorted(nodes, b)
        if not (abs(xy[0, a]) < 1e-12 * dm.domain.far_radius or abs(xy[0, b]) < 1e-12 * dm.domain.far_radius):
            continue
        im = np.searchsorted(nodes, dm.mesh.dofs.facet_dofs[0, f])
        mid = 0.5 * np.array([x[ia] + x[ib], r[ia] + r[ib]])
        x[im], r[im] = curve.project(mid[None, :])[0]


def moved_meshes(dm: DomainMesh, steps, motion=None) -> list[DomainMesh]:
    """The meshes of depths P + eps (eps in ``steps``) with the topology of ``dm``: harmonic extension
    of the boundary motion (``motion(dm, eps)``, default the half-space's), one factorisation of the
    Laplacian shared by all steps."""
    basis = Basis(dm.mesh, element_for(dm.order))
    if not np.allclose(basis.doflocs, dm.mesh.doflocs):
        raise RuntimeError("geometry nodes and FEM dofs are numbered differently")
    K = _laplace.assemble(basis).tocsr()
    lu, Kib, interior, out = None, None, None, []
    for eps in steps:
        nodes, new = (motion or _boundary_motion)(dm, eps)
        if lu is None:
            interior = np.setdiff1d(np.arange(basis.N), nodes)
            lu = symmetric_lu(K[interior][:, interior])  # the Laplacian's interior block: symmetric positive definite
            Kib = K[interior][:, nodes]
            first_nodes = nodes
        elif not np.array_equal(nodes, first_nodes):
            raise RuntimeError("the moved boundary nodes differ between depth steps")
        disp_b = new - dm.mesh.doflocs[:, nodes]
        doflocs = dm.mesh.doflocs.copy()
        doflocs[:, nodes] = new
        for c in range(2):
            doflocs[c, interior] += lu.solve(-(Kib @ disp_b[c]))
        info = dict(dm.domain.info, depth=dm.domain.info["depth"] + eps)
        moved = dm.with_doflocs(doflocs)
        out.append(dataclasses.replace(moved, domain=dataclasses.replace(dm.domain, info=info)))
    return out


@dataclass(frozen=True)
class HalfspaceCoefficients:
    """FEM coefficients at one depth (SI: m, m^3, m^2)."""

    depth: float
    A: float
    C: float
    B_body: float
    B_literal: float
    B_bernoulli: float
    dA_dP: float
    phi_tip: float
    G: float  # int |grad phi|^2 n_x dS, as used in the B readings (G_surface or G_shape)
    H: float  # int dphi/dx n_x dS
    Q: float  # int D phi/DP n_x dS
    n_dofs: int
    n_elements: int
    seconds: float
    G_surface: float = math.nan  # G from the FEM surface gradient
    G_shape: float = math.nan  # G from the shape derivative: 2 (Q - H) - dA/dP (errata 2a identity)
    G_source: str = "surface"  # which one the B readings use

    def B(self, reading: str = "body") -> float:
        return {"body": self.B_body, "literal": self.B_literal, "bernoulli": self.B_bernoulli}[reading]


def depth_scale(nose: Nose) -> float:
    """The length scale of depths: the tables' depth unit (L_h, or the radius of a nose shorter
    than its radius; ``Nose.depth_unit``), so that ``--depths`` means the same on both sides."""
    return nose.depth_unit


def halfspace_mesh(nose: Nose, depth: float, options: MeshOptions) -> DomainMesh:
    dom = halfspace_domain(nose, depth, options)
    dm = build_mesh(dom, options)
    info = dict(dom.info, nose=nose)
    return dataclasses.replace(dm, domain=dataclasses.replace(dom, info=info))


def _waterline_edge(dm: DomainMesh) -> float:
    """Length of the shortest mesh edge at the waterline vertex (inf when the nose is fully wetted)."""
    info = dm.domain.info
    if "waterline_segment" not in info:
        return math.inf
    p = dm.mesh.p
    i = int(np.argmin(p[0] ** 2 + (p[1] - info["waterline_radius"]) ** 2))
    edges = dm.mesh.facets[:, np.any(dm.mesh.facets == i, axis=0)]
    return float(np.min(np.hypot(*(p[:, edges[0]] - p[:, edges[1]]))))


def singular_wetted_corners(dm: DomainMesh) -> list:
    """Corners of the wetted body where |grad phi| is unbounded (ring corners with lambda < 1)."""
    return [c for c in dm.domain.corners if not c.on_axis and c.exponent < 1.0]


BREAK_STEP = 0.02  # largest shape-difference step over the distance to a breakpoint (measured: 1e-6 in B)


def _breakpoint_distance(nose: Nose, depth: float) -> float:
    """Distance from P to the nearest breakpoint of the coefficients (inf if none)."""
    from semianalytic.coefficients.table import breakpoints

    return min((abs(depth - b) for b in breakpoints(nose)), default=math.inf)


def halfspace_coefficients(nose: Nose, depth: float, options: MeshOptions | None = None,
                           step: float = 2e-4, far_field: str = "monopole", g_source: str = "auto",
                           step_scale: float = 1.0) -> HalfspaceCoefficients:
    """A, B (three readings), C, dA/dP and phi_tip of Part I, eq. (12) by FEM at depth P.

    G = int |grad phi|^2 n_x dS two ways: ``G_surface`` from the FEM surface gradient, and
    ``G_shape`` = 2 (Q - H) - dA/dP, the value that makes errata 2a's identity B_bernoulli =
    dA/dP hold (Q and dA/dP are shape derivatives of the energy A, H a linear functional of the
    trace: all converge at the rate of A).  At a ring corner of exponent lambda < 1 (a flat nose's
    rim: 2/3; a cone's shoulder: pi/(pi + beta)) |grad phi|^2 ~ rho^(2 lambda - 2) on the face, and
    the elements touching the corner miss a part ~ rho_min^(2 lambda - 1) of G_surface, which a
    graded mesh cannot shrink fast (rho_min^(1/3) at a flat rim).  ``g_source="auto"`` takes
    G_shape there and G_surface elsewhere (where |G_surface - G_shape| checks the identity).

    ``step``: the depth step of the shape finite difference, as a fraction of L_h (of the radius
    for a flat nose, :func:`depth_scale`), and at most BREAK_STEP of the distance to the nearest
    breakpoint of the depth axis (a corner or joint of the nose, or the shoulder, reaching the free
    surface: there A(P) goes like a non-integer power of the distance, and the O(eps^2) error of the
    central difference is ~ (eps/distance)^2; issue 27: a cone at 1.001 L_h had eps = 0.2 of it and
    B off by 8.7e-5).  ``step_scale`` multiplies the step so chosen (0.5: the same solve with half
    the step, for an estimate of its error, :func:`fem_check.refinement.refinement_study`).
    """
    options = options or MeshOptions()
    t0 = time.perf_counter()
    dm = halfspace_mesh(nose, depth, options)
    sol = solve_potential(dm, far_field)
    # the waterline vertex slides along x = 0 while the nose moves by eps: the elements at it shear by
    # about eps, so eps stays well below the smallest of them (graded waterline corners are tiny)
    # (at a breakpoint itself the distance is 0: the derivative is one-sided there, the cap does not apply)
    to_break = _breakpoint_distance(nose, depth)
    eps = min(step * depth_scale(nose), 0.05 * _waterline_edge(dm), BREAK_STEP * to_break if to_break > 0 else math.inf)
    eps *= step_scale
    plus, minus = moved_meshes(dm, [eps, -eps])
    Ap = solve_potential(plus, far_field).A
    Am = solve_potential(minus, far_field).A
    dA = (Ap - Am) / (2 * eps)
    s = sol.surface("body")
    G = float(np.sum(s["weight"] * s["grad2"] * s["nx"]))
    H = float(np.sum(s["weight"] * s["dphi_dx"] * s["nx"]))
    waterline = 0.0
    info = dm.domain.info
    if depth < nose.length * (1 - 1e-9):
        seg = nose.segments[info["waterline_segment"]]
        dx, dr = (float(v) for v in seg.derivative(info["waterline_t"]))
        rw = info["waterline_radius"]
        phi_w = sol.node_value((0.0, rw))
        waterline = 2 * math.pi * phi_w * rw * abs(dr) / abs(dx)
    Q = dA - waterline
    G_surface, G_shape = G, 2 * (Q - H) - dA
    if g_source == "auto":
        g_source = "shape" if singular_wetted_corners(dm) else "surface"
    if g_source not in ("surface", "shape"):
        raise ValueError(f"g_source must be 'auto', 'surface' or 'shape'; got {g_source!r}")
    G = G_shape if g_source == "shape" else G_surface
    return HalfspaceCoefficients(
        depth=depth, A=sol.A, C=sol.C, B_body=G + 2 * Q, B_literal=G + 2 * (Q - H),
        B_bernoulli=-G + 2 * (Q - H), dA_dP=dA, phi_tip=sol.node_value((depth, 0.0)),
        G=G, H=H, Q=Q, n_dofs=sol.n_dofs, n_elements=int(dm.mesh.t.shape[1]),
        seconds=time.perf_counter() - t0, G_surface=G_surface, G_shape=G_shape, G_source=g_source,
    )


@dataclass(frozen=True)
class AddedMass:
    """FEM added mass of a closed body in unbounded fluid."""

    A: float  # m^3 (added mass / rho)
    volume: float  # m^3
    n_dofs: int
    n_elements: int
    seconds: float  # solve only (mesh from cache or not)
    mesh_seconds: float

    @property
    def coefficient(self) -> float:
        """Added-mass coefficient A / V."""
        return self.A / self.volume


def body_added_mass(meridian: Meridian, options: MeshOptions | None = None, far_field: str = "dipole",
                    use_cache: bool = True) -> AddedMass:
    """Added mass of a closed body (Part I, eq. (12) for A with the unbounded-fluid problem)."""
    options = options or MeshOptions()
    t0 = time.perf_counter()
    dm = build_mesh(body_domain(meridian, options), options, use_cache=use_cache)
    t1 = time.perf_counter()
    sol: PotentialSolution = solve_potential(dm, far_field)
    return AddedMass(sol.A, meridian.volume(), sol.n_dofs, int(dm.mesh.t.shape[1]), time.perf_counter() - t1, t1 - t0)


def solved_once(memo: dict | None, nose, depth: float, options: MeshOptions):
    """:func:`halfspace_coefficients` of (nose, depth, options), computed once per ``memo`` (one
    command: the refinement study repeats some of the comparison's solves)."""
    if memo is None:
        return halfspace_coefficients(nose, depth, options)
    key = (id(nose), depth, options)
    if key not in memo:
        memo[key] = (nose, halfspace_coefficients(nose, depth, options))  # the nose kept: its id stays its own
    return memo[key][1]
