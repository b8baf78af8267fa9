"""A(P), B(P), C(P) at one depth, with phi'_P by differences in P (Part I, eqs. (9), (12)-(14)).

phi'_P needs the potential at neighbouring depths on the *same* panel topology: the layout
of depth P is re-evaluated at P + k h (only the last piece, at the free surface, stretches),
so that each node moves smoothly and a central difference of the nodal values is accurate
to round-off over the step (numerical notes).  Nodes that slide along the surface while the
layout stretches are corrected by the chain rule with their own velocity.

Readings of B (errata item 2a):

- ``body``: phi'_P following a point fixed on the projectile;
- ``literal``: phi'_P at a fixed target point, phi'_lit = phi'_body - dphi/dx (the body
  moves with unit speed in +x);
- ``bernoulli``: the Lagrange-Cauchy integral with the sign of |grad phi|^2 consistent with
  v = -grad(phi):  B = integral (-|grad phi|^2 + 2 phi'_lit) n_x dS, which equals dA/dP.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from semianalytic.bem.panels import LayoutOptions, halfspace_layout
from semianalytic.bem.solve import _SUM, AssemblyCache, SurfaceSolution, plan_assembly, solve_panels
from semianalytic.geometry import Nose

# central stencils (step h): order -> offsets, weights of the first derivative, and weights
# interpolating the value at the centre (which therefore needs no solve of its own)
STENCILS = {
    2: (np.array([-1, 1]), np.array([-0.5, 0.5]), np.array([0.5, 0.5])),
    4: (np.array([-2, -1, 1, 2]), np.array([1 / 12, -2 / 3, 2 / 3, -1 / 12]), np.array([-1 / 6, 2 / 3, 2 / 3, -1 / 6])),
}
STEP = 1e-4  # relative step of the central difference in P (of the local length scale)


@dataclass(frozen=True)
class DepthCoefficients:
    """Coefficients of Part I, eq. (11) at depth P (SI), plus the surface data behind them.

    ``nodes``: dict of arrays at the surface nodes at depth P (target frame): x, r, nx,
    weight (2 pi r ds), phi, grad2 (|grad phi|^2), dphi_dP_body, dphi_dP_literal.
    """

    depth: float
    A: float
    C: float
    B_body: float
    B_literal: float
    B_bernoulli: float
    dA_dP: float
    phi_tip: float
    dphi_tip_dP: float  # following the tip (body reading)
    unknowns: int
    nodes: dict

    def B(self, reading: str = "body") -> float:
        return {"body": self.B_body, "literal": self.B_literal, "bernoulli": self.B_bernoulli}[reading]


def _step(nose: Nose, depth: float) -> float:
    """Difference step: STEP of the smallest length that must not be crossed."""
    scale = min(depth, nose.radius)
    if nose.length > 0:
        scale = min(scale, abs(depth - nose.length) / 3.0) if depth != nose.length else scale
    return STEP * scale


def coefficients_at_depth(
    nose: Nose,
    depth: float,
    options: LayoutOptions = LayoutOptions(),
    fd_order: int = 2,
    step: float | None = None,
    cache: AssemblyCache | None = None,
) -> DepthCoefficients:
    """A, B (three readings), C, dA/dP and phi at the tip, at depth P > 0.

    Part I, eq. (12): A = int phi n_x dS, C = int n_x dS,
    B = int (|grad phi|^2 + 2 phi'_P) n_x dS, over the submerged surface (full contact;
    the region l_P of eq. (15) is checked from the node data, see
    :meth:`~semianalytic.coefficients.table.CoefficientTable.contact_intervals`).

    The potential at P itself is interpolated from the stencil (error O(h^2), about 1e-8
    relative with the default step), so each depth costs two solves.

    ``cache`` (an :class:`~semianalytic.bem.solve.AssemblyCache` kept across the depths of a
    table): the panels that the depth change leaves in place keep their quadrature and
    their block of the matrices; only the rest is planned and integrated again.
    """
    if depth == nose.length:
        raise ValueError("the depth P = L_h is where the layout changes topology; use a nearby depth")
    layout = halfspace_layout(nose, depth, options)
    h = step if step is not None else _step(nose, depth)
    offsets, weights, interp = STENCILS[fd_order]
    panels = layout.panels()
    stencil = [layout.at_depth(depth + k * h).panels(like=panels) for k in offsets]  # the topology shared
    fixed = None
    if cache is not None:
        fixed = cache.match(panels)
        for ps in stencil:
            fixed &= cache.match(ps)
    plan = plan_assembly(panels, fixed)  # the same rules at every depth of the stencil
    sols = [solve_panels(ps, "halfspace", depth=depth + k * h, plan=plan, cache=cache) for k, ps in zip(offsets, stencil)]
    center = SurfaceSolution(
        panels,
        sum(c * s.phi_nodes for c, s in zip(interp, sols)),
        -panels.nodes.tr[: panels.n_primary],
        "halfspace",
        depth=depth,
    )
    return _combine(center, sols, weights, h)


def _combine(center: SurfaceSolution, sols, weights, h) -> DepthCoefficients:
    """Part I, eqs. (9), (12): B = int (+-|grad phi|^2 + 2 phi'_P) n_x dS in the three readings,
    with phi'_P following the body (chain rule for nodes that slide along it) or a target point."""
    s = center.nodes
    flat = [c.flat for c in sols]  # x, r, nx, weight, phi: no surface velocity at the stencil's depths
    dphi_node = sum(w * f[4] for w, f in zip(weights, flat)) / h
    # body-frame node positions x_b = x - P; velocity of each node relative to the body
    vx = sum(w * (f[0] - c.depth) for w, f, c in zip(weights, flat, sols)) / h
    vr = sum(w * f[1] for w, f in zip(weights, flat)) / h
    tx, tr = -s.nr, s.nx
    dphi_body = dphi_node - s.dphi_ds * (tx * vx + tr * vr)
    dphi_lit = dphi_body - s.dphi_dx
    grad2 = s.grad2
    wn = s.weight * s.nx
    A_all = np.array([c.A for c in sols])
    tip = np.array([c.phi_tip for c in sols])
    return DepthCoefficients(
        depth=center.depth,
        A=center.A,
        C=center.C,
        B_body=float(_SUM(wn * (grad2 + 2 * dphi_body), axis=None)),
        B_literal=float(_SUM(wn * (grad2 + 2 * dphi_lit), axis=None)),
        B_bernoulli=float(_SUM(wn * (-grad2 + 2 * dphi_lit), axis=None)),
        dA_dP=float(np.dot(weights, A_all) / h),
        phi_tip=center.phi_tip,
        dphi_tip_dP=float(np.dot(weights, tip) / h),
        unknowns=center.unknowns,
        nodes={
            "x": s.x,
            "r": s.r,
            "nx": s.nx,
            "weight": s.weight,
            "phi": s.phi,
            "grad2": grad2,
            "dphi_dP_body": dphi_body,
            "dphi_dP_literal": dphi_lit,
        },
    )


def normalised(value: float, diameter: float) -> float:
    """4 X/(pi d^2): Abar (a length, errata item 2), Bbar, Cbar (dimensionless)."""
    return 4.0 * value / (math.pi * diameter**2)
