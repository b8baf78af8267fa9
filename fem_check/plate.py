"""The plate domain: Part I's potential problem with a back face, by finite elements (issue 23, item 2).

The target occupies 0 <= x <= H around a nose at depth P (tip at x = P, moving in +x).  Boundary
conditions as :mod:`semianalytic.bem.slab`: dphi/dn = 0 on the front face x = 0 and on the hole
wall (Part I, eq. (7)), phi = 0 on the back face x = H (a free surface of the impulsive flow;
this project's own choice), dphi/dn = -n_x on the wetted body.  In the slab phi decays like
exp(-pi r/(2H)) (the lowest mode cos(pi x/(2H)) K0(pi r/(2H))), so the domain is cut at the
radius R_far = d/2 + FAR_MODES * 2H/pi with phi = 0 there: the truncation error is below
exp(-FAR_MODES) relative.  For P > H the body crosses the back face at the radius r_c and the
wetted surface ends there (a corner of the fluid with an angle < pi/2: no grading needed).

Boundary tags: ``body`` (Neumann -n_x), ``wall`` and ``free`` (0), ``axis`` (natural), ``back``
and ``far`` (Dirichlet phi = 0).  A = int phi n_x dS is the load functional 2 pi l(phi), which
equals the energy (phi = 0 on the Dirichlet part): it converges at twice the rate of the energy norm.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from skfem import Basis, FacetBasis, condense

from fem_check.meshing import Domain, MeshOptions, Piece, _line, _nose_waterline, build_mesh, moved_mesh, singular_corners
from fem_check.potential import _body_load, _contact_area, _laplace_r, element_for, mapping_for, symmetric_lu
from semianalytic.errors import InputError
from semianalytic.geometry import Nose

FAR_MODES = 20.0  # exp(-20) = 2e-9: the Dirichlet cut-off of the slab's exponentially decaying field


def plate_domain(nose: Nose, depth: float, thickness: float, options: MeshOptions) -> Domain:
    """The plate 0 <= x <= H minus the nose at depth P (0 < P < H + L_h), cut at R_far."""
    H, d, Rb, Lh = thickness, nose.diameter, nose.radius, nose.length
    if not (H > 0 and 0 < depth < H + Lh):
        raise InputError("depth", f"must lie in (0, H + L_h) for a plate of thickness H; got {depth!r} m")
    Rf = Rb + FAR_MODES * 2.0 * H / math.pi
    tol = 1e-9 * max(Lh, Rb)
    through = depth > H
    pointed = nose.tip_half_angle() < 0.5 * math.pi - 1e-6
    pieces: list[tuple[str, Piece]] = []
    refine: list[tuple[float, float]] = []
    segs = nose.segments
    # the back end of the wetted nose: the tip, or the cut at body x = H - P
    if through:
        j, t_cut = _nose_waterline(nose, depth - H)  # the nose point at body x = H - P
        rc = float(segs[j].point(t_cut)[1])
        pieces.append(("back", _line((H, rc), (H, Rf))))
        refine.append((H, rc))
    else:
        j, t_cut = 0, segs[0].t0
        pieces.append(("axis", _line((depth, 0.0), (H, 0.0))))
        pieces.append(("back", _line((H, 0.0), (H, Rf))))
        if not pointed:
            refine.append((depth, 0.0))
    pieces.append(("far", _line((H, Rf), (0.0, Rf))))
    if depth < Lh - tol:
        k, tw = _nose_waterline(nose, depth)
        rw = float(segs[k].point(tw)[1])
        pieces.append(("free", _line((0.0, Rf), (0.0, rw))))
        refine.append((0.0, rw))
        first = (k, tw)
    else:
        k = len(segs) - 1
        pieces.append(("free", _line((0.0, Rf), (0.0, Rb))))
        if depth > Lh + tol:
            pieces.append(("wall", _line((0.0, Rb), (depth - Lh, Rb))))
            refine.append((0.0, Rb))
        refine.append((depth - Lh, Rb))
        first = (k, segs[k].t1)
    # body pieces from the front end (waterline or shoulder) back to the tip or the cut
    body = []
    for i in range(first[0], j - 1, -1):
        t_start = first[1] if i == first[0] else segs[i].t1
        t_end = t_cut if i == j else segs[i].t0
        body.append(Piece(segs[i], t_start, t_end, depth))
    for p in body:
        pieces.append(("body", p))
    for p in body[1:]:
        refine.append(p.start)
    info = {"depth": depth, "thickness": H, "nose_length": Lh, "diameter": d}
    tips = ((depth, 0.0),) if (pointed and not through) else ()
    return Domain("plate", tuple(pieces), (0.0, 0.0), Rf, d, tuple(tuple(map(float, p)) for p in refine), info,
                  tip_points=tips, corners=singular_corners(pieces))


@dataclass(frozen=True)
class PlatePotential:
    """FEM A and C of Part I, eq. (12) for a nose in a plate; dA/dP (= B_bernoulli, errata item 2a)
    when asked for (nan otherwise)."""

    depth: float
    thickness: float
    A: float  # m^3
    C: float  # m^2
    n_dofs: int
    seconds: float
    dA_dP: float = math.nan  # m^2


def _solve(dm, depth: float):
    """(A, C, dofs) on the plate mesh ``dm`` (nose tip at x = depth)."""
    # work in x - P (tip at the origin), as fem_check.potential does for the half-space
    mesh = moved_mesh(dm.mesh, dm.mesh.doflocs - np.array([[depth], [0.0]]))
    mapping = mapping_for(mesh)
    elem = element_for(dm.order)
    q = 2 * dm.order + 2
    basis = Basis(mesh, elem, intorder=q, mapping=mapping)
    K = _laplace_r.assemble(basis)
    fb = FacetBasis(mesh, elem, facets=dm.boundaries["body"], intorder=q, mapping=mapping, dofs=basis.dofs,
                    disable_doflocs=True)
    f = _body_load.assemble(fb)
    fixed = np.unique(np.concatenate([basis.get_dofs(dm.boundaries[t]).all() for t in ("back", "far")]))
    phi = np.zeros(basis.N)
    Kc, fc, _, I = condense(K, f, D=fixed)
    phi[I] = symmetric_lu(Kc).solve(fc)
    return 2 * math.pi * float(f @ phi), 2 * math.pi * float(_contact_area.assemble(fb)), int(basis.N)


def _plate_motion(dm, eps: float):
    """Boundary nodes and their positions for the nose moved from P to P + eps, the tip inside the
    plate and the nose fully in (L_h < P <= H - eps): the body translates, the axis between the tip
    and the back face and the hole wall stretch, the faces and the far boundary stay."""
    info = dm.domain.info
    P, H, Lh = info["depth"], info["thickness"], info["nose_length"]
    pos = dm.mesh.doflocs
    nodes_all, new_all = [], []
    for idx, facets in dm.pieces.items():
        tag = dm.domain.loop[idx][0]
        nodes = dm.facet_nodes(facets)
        x, r = pos[0, nodes].copy(), pos[1, nodes].copy()
        if tag == "axis":
            x = P + eps + (x - P) * (H - P - eps) / (H - P)
        elif tag == "wall":
            x = x * (P + eps - Lh) / (P - Lh)
        elif tag == "body":
            x = x + eps
        nodes_all.append(nodes)
        new_all.append(np.vstack([x, r]))
    nodes, first = np.unique(np.concatenate(nodes_all), return_index=True)
    return nodes, np.hstack(new_all)[:, first]


def plate_potential(nose: Nose, depth: float, thickness: float, options: MeshOptions | None = None,
                    derivative: bool = False, step: float = 2e-4) -> PlatePotential:
    """Solve the plate problem (module docstring) with P2 (``options.order``) elements; A is the
    load functional (= the energy), C the integral of n_x over the wetted body.  ``derivative``:
    also dA/dP by a central shape difference (the mesh moved with the nose, same topology; step
    ``step`` L_h), for a nose fully in the plate with its tip inside (L_h < P < H)."""
    from fem_check.coefficients import moved_meshes

    options = options or MeshOptions()
    t0 = time.perf_counter()
    dom = plate_domain(nose, depth, thickness, options)
    dm = build_mesh(dom, options)
    A, C, n = _solve(dm, depth)
    dA = math.nan
    if derivative:
        Lh = nose.length
        eps = step * Lh
        if not (Lh + 2 * eps < depth < thickness - 2 * eps):
            raise InputError("depth", "the FEM dA/dP of a plate needs the nose fully in and its tip inside (L_h < P < H)")
        plus, minus = moved_meshes(dm, [eps, -eps], motion=_plate_motion)
        dA = (_solve(plus, depth + eps)[0] - _solve(minus, depth - eps)[0]) / (2 * eps)
    return PlatePotential(depth, thickness, A, C, n, time.perf_counter() - t0, dA)
