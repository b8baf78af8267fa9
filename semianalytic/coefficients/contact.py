"""The contact region of Part I, eq. (15) and the coefficients of the wetted part.

The contact pressure of eq. (9) at a surface node is

    p_c = rho phi du/dt + q rho u^2/2 + R_t,   q = |grad phi|^2 + 2 phi'_P

(``body`` and ``literal`` readings; ``bernoulli``: q = -|grad phi|^2 + 2 phi'_P, errata item
2a).  Where p_c <= 0 the target separates from the nose (eq. (15)); with separation the
force on the projectile is the pressure integrated over the wetted part only, so eq. (11)
takes

    A_w = int_wet phi n_x dS,  B_w = int_wet q n_x dS,  C_w = int_wet n_x dS,

which depend on u and du/dt as well as on P.  du/dt itself follows from eq. (11) with these
coefficients: the wetted set is found by a fixed-point iteration started from full contact
(:func:`semianalytic.penetration.motion.separated_acceleration`, beside eq. (11)).
Everything comes from the surface solution stored with each table knot (no solve per time
step); between knots the wetted coefficients are interpolated linearly in P.
"""

from __future__ import annotations

import numpy as np

__all__ = ["pressure_terms", "contact_pressure", "wetted_coefficients"]


def pressure_terms(nodes: dict, reading: str):
    """(phi, q) at the surface nodes: p_c = rho phi du/dt + q rho u^2/2 + R_t (Part I, eq. (9))."""
    if reading == "body":
        q = nodes["grad2"] + 2 * nodes["dphi_dP_body"]
    elif reading == "literal":
        q = nodes["grad2"] + 2 * nodes["dphi_dP_literal"]
    else:
        q = -nodes["grad2"] + 2 * nodes["dphi_dP_literal"]
    return nodes["phi"], q


def contact_pressure(phi, q, rho: float, du_dt, u2, R_t: float):
    """p_c = rho phi du/dt + q rho u^2/2 + R_t [Pa] of Part I, eq. (9) (u2 = u^2; broadcasting)."""
    return rho * phi * du_dt + q * rho * u2 / 2 + R_t


def wetted_coefficients(nodes: dict, reading: str, wet=None) -> tuple[float, float, float]:
    """(A_w, B_w, C_w) = int_wet (phi, q, 1) n_x dS over the wetted nodes (all by default), Part I,
    eqs. (11), (15).  The fixed point of the wetted set, which needs eq. (11), is
    :func:`semianalytic.penetration.motion.separated_acceleration`."""
    phi, q = pressure_terms(nodes, reading)
    wn = nodes["weight"] * nodes["nx"]
    if wet is not None:
        wn = wn * wet
    return float(np.sum(wn * phi)), float(np.sum(wn * q)), float(np.sum(wn))
