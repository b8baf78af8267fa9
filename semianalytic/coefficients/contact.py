"""The contact region of Part I, eq. (15) and the coefficients of the wetted part.

The contact pressure of eq. (9) at a surface node is

    p_c = rho phi du/dt + q rho u^2/2 + R_t,   q = |grad phi|^2 + 2 phi'_P

(``body`` and ``literal`` readings; ``bernoulli``: q = -|grad phi|^2 + 2 phi'_P, errata item
2a).  Where p_c <= 0 the target separates from the nose (eq. (15)); with separation the
force on the projectile is the pressure integrated over the wetted part only, so eq. (11)
takes

    A_w = int_wet phi n_x dS,  B_w = int_wet q n_x dS,  C_w = int_wet n_x dS,

which depend on u and du/dt as well as on P.  du/dt itself follows from eq. (11) with these
coefficients: the wetted set is found by a fixed-point iteration started from full contact.
Everything comes from the surface solution stored with each table knot (no solve per time
step); between knots the wetted coefficients are interpolated linearly in P.
"""

from __future__ import annotations

import numpy as np

__all__ = ["pressure_terms", "separated_acceleration"]


def pressure_terms(nodes: dict, reading: str):
    """(phi, q) at the surface nodes: p_c = rho phi du/dt + q rho u^2/2 + R_t (Part I, eq. (9))."""
    if reading == "body":
        q = nodes["grad2"] + 2 * nodes["dphi_dP_body"]
    elif reading == "literal":
        q = nodes["grad2"] + 2 * nodes["dphi_dP_literal"]
    else:
        q = -nodes["grad2"] + 2 * nodes["dphi_dP_literal"]
    return nodes["phi"], q


def separated_acceleration(nodes: dict, reading: str, mass: float, rho: float, u: float, R_t: float, iterations: int = 20):
    """du/dt of Part I, eq. (11) with the coefficients of the wetted part (eq. (15)), and
    (A_w, B_w, C_w): fixed point from full contact (the wetted set usually settles in 2-3 steps)."""
    phi, q = pressure_terms(nodes, reading)
    wn_all = nodes["weight"] * nodes["nx"]
    wet = np.ones(len(phi), bool)
    a = 0.0
    coef = (0.0, 0.0, 0.0)
    for _ in range(iterations):
        wn = wn_all * wet
        A, B, C = float(np.sum(wn * phi)), float(np.sum(wn * q)), float(np.sum(wn))
        a = -(0.5 * rho * B * u * u + C * R_t) / (mass + rho * A)
        coef = (A, B, C)
        new = (rho * phi * a + q * rho * u * u / 2 + R_t) > 0
        if np.array_equal(new, wet):
            break
        wet = new
    return a, coef
