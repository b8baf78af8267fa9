"""Final depths of Part I, eq. (11) for many (m, rho, R_t, U_s) on one coefficient table, as arrays.

The Monte-Carlo path of the sweeps (issue 14): every sample has its own projectile mass m,
target density rho, resistance R_t and striking velocity U_s, all on the same nose (one A, B, C
table).  In w = u^2 with P as the variable eq. (11) is linear (see
:mod:`semianalytic.penetration.motion`): w(P) = e^(-F) (U_s^2 - G), with
F = int rho B/(m + rho A) dP and G = R_t G_1, G_1 = int 2 C e^F/(m + rho A) dP.  All samples
share one set of panels and Chebyshev nodes (the coefficients are evaluated once), F and G_1 are
integrated spectrally as rows of arrays for a few mass-to-density ratios (see
:func:`final_depths`), and P_f solves G_1(P_f) = U_s^2 / R_t by cubic Hermite interpolation
between the bracketing nodes (G_1 and its exact derivative at both), refined by Newton on that
cubic.  Pure: SI floats and arrays.
"""

from __future__ import annotations

import numpy as np

from semianalytic.penetration.motion import _NODES, _Q, _X, ConstantCoefficientSolution, _panels, deep_coefficients

__all__ = ["final_depths", "chebyshev_weights", "critical_velocities"]


def chebyshev_weights(x, lo: float, hi: float, n: int):
    """(nodes, W): the n Chebyshev-Lobatto points of [lo, hi] and the barycentric interpolation
    weights W (len(x), n), so that f(x) ~ W @ f(nodes) for f smooth on [lo, hi]."""
    x = np.asarray(x, float)
    j = np.arange(n)
    nodes = lo + 0.5 * (hi - lo) * (np.cos(np.pi * j / (n - 1)) + 1.0)
    bw = (-1.0) ** j
    bw[0] *= 0.5
    bw[-1] *= 0.5
    with np.errstate(divide="ignore", invalid="ignore"):
        c = bw[None, :] / (x[:, None] - nodes[None, :])
    hit = ~np.isfinite(c)
    rows = hit.any(axis=1)
    c[rows] = hit[rows].astype(float)
    return nodes, c / c.sum(axis=1, keepdims=True)


def final_depths(coefficients, mass, target_density, resistance_pa, U0, *, n_ratio: int = 8) -> np.ndarray:
    """P_f [m] of eq. (11) per sample (1-D arrays broadcast together; see the module docstring).

    F depends on m and rho only through r = m/rho, and G_1 = G_r / rho with
    G_r = int 2 C e^F/(r + A) dP; both are computed for the distinct r (at most ``n_ratio`` of
    them) or on ``n_ratio`` Chebyshev points of r and P_f interpolated in r (analytic in r): 8
    points give 1e-10 relative for a +-8 % spread of m/rho (against motion.final_depth, sample by sample).
    """
    m, rho, R, U = np.broadcast_arrays(*(np.asarray(v, float).ravel() for v in (mass, target_density, resistance_pa, U0)))
    if np.any(~(m > 0)) or np.any(~(rho > 0)) or np.any(~(R > 0)) or np.any(~(U >= 0)):
        raise ValueError("mass, target density and resistance must be positive, U0 non-negative")
    r = m / rho
    g = U**2 / R * rho  # G_r(P_f) = U^2 rho / R_t
    uniq = np.unique(r)
    if uniq.size <= n_ratio:
        r_k = uniq
        W = (r[:, None] == r_k[None, :]).astype(float)
    else:
        r_k, W = chebyshev_weights(r, float(r.min()), float(r.max()), n_ratio)
    P, F_k, G_k = _profiles(coefficients, r_k, g_max=g.max())
    A = np.asarray(coefficients.A(P), float)
    C = np.asarray(coefficients.C(P), float)
    out = np.zeros(r.size)
    # P_f is analytic in r at fixed g: solve on each profile, then interpolate in r
    for k in range(r_k.size):
        use = W[:, k] != 0
        if not use.any():
            continue
        G = np.maximum.accumulate(G_k[k])
        dG = 2.0 * C * np.exp(F_k[k]) / (r_k[k] + A)
        out[use] += W[use, k] * _solve_hermite(P, G, dG, g[use])
    return np.where(g == 0, 0.0, out)


def critical_velocities(yield_stress: float, youngs_modulus: float, density, mass, diameter: float, A: float, B: float,
                        C: float, target_density, resistance_pa, phi: float = 1.0) -> np.ndarray:
    """U_sC [m/s] of Part I, eqs. (33)/(36) (eq. (34) below, eq. (35) for the reduced strengths), per sample (arrays broadcast together).

    Y_c = phi Y_p; Ybar_p = (1 + rho A/m) Y_c, Rbar_t = (C/a) R_t, Bbar = B/a with a = pi d^2/4;
    U_sC = Y_c c_0/E_p + sqrt(2 (Ybar_p - Rbar_t) / (rho Bbar)) if Ybar_p >= Rbar_t (eq. (33)),
    else Y_c c_0/E_p (eq. (34)); c_0 = sqrt(E_p/rho_p).  The array form of
    :func:`semianalytic.penetration.critical.critical_velocity` (deep-limit A, B, C)."""
    from semianalytic.penetration.critical import reduced_strengths

    rho_p, m, rho, R = (np.asarray(v, float) for v in (density, mass, target_density, resistance_pa))
    Yc = phi * yield_stress
    area = np.pi * diameter**2 / 4.0
    Ybar, Rbar = reduced_strengths(Yc, R, A=A, C=C, mass=m, diameter=diameter, target_density=rho)  # eq. (35)
    elastic = Yc * np.sqrt(youngs_modulus / rho_p) / youngs_modulus
    if not B / area > 0:  # no velocity term (the 'bernoulli' reading at depth): no real root, as critical_velocity
        return np.where(Ybar < Rbar, elastic, np.inf)
    excess = np.maximum(Ybar - Rbar, 0.0)
    return np.where(Ybar < Rbar, elastic, elastic + np.sqrt(2.0 / (rho * (B / area)) * excess))


def _profiles(coefficients, r_k, g_max):
    """Nodes P and F, G_r (rows: the ratios r_k) of the module docstring, integrated until G_r
    passes every sample's target."""
    A8, B8, C8 = deep_coefficients(coefficients)
    d = float(coefficients.diameter)
    scale = ConstantCoefficientSolution(A8, B8, C8, float(r_k.max()), 1.0, 1.0, float(np.sqrt(g_max))).final_depth
    max_len = (scale + 2.0 * d) / 40.0  # as motion.depth_profile: a fortieth of the deepest stop
    breaks = np.asarray(getattr(coefficients, "depth", np.empty(0)), float).ravel()
    P_to = 1.5 * (scale + 2.0 * d)
    n = r_k.size
    edges = np.array([0.0])
    Fs, Gs, Ps = [], [], []
    F0 = np.zeros(n)
    G0 = np.zeros(n)
    for _ in range(60):
        new = _panels(breaks, P_to, max_len, start=edges[-1])
        a, b = new[:-1], new[1:]
        h = 0.5 * (b - a)
        nodes = a[:, None] + h[:, None] * (_X + 1.0)[None, :]  # (panels, nodes)
        A = np.asarray(coefficients.A(nodes), float)
        B = np.asarray(coefficients.B(nodes), float)
        C = np.asarray(coefficients.C(nodes), float)
        M = r_k[:, None, None] + A[None]  # (ratios, panels, nodes): (m + rho A)/rho
        Floc = h[None, :, None] * ((B[None] / M) @ _Q.T)
        F = F0[:, None, None] + np.concatenate([np.zeros((n, 1)), np.cumsum(Floc[:, :, -1], axis=1)[:, :-1]], axis=1)[:, :, None] + Floc
        Gloc = h[None, :, None] * ((2.0 * C[None] * np.exp(F) / M) @ _Q.T)
        G = G0[:, None, None] + np.concatenate([np.zeros((n, 1)), np.cumsum(Gloc[:, :, -1], axis=1)[:, :-1]], axis=1)[:, :, None] + Gloc
        Fs.append(F.reshape(n, -1))
        Gs.append(G.reshape(n, -1))
        Ps.append(nodes.ravel())
        edges = np.concatenate([edges, new[1:]])
        F0, G0 = F[:, -1, -1], G[:, -1, -1]
        if np.all(G0 > g_max * (1 + 1e-9)):
            break
        P_to = edges[-1] * 2.0
    else:
        raise RuntimeError("eq. (11) in P: G did not reach U0^2 for every sample")
    P = np.concatenate(Ps)
    F = np.concatenate(Fs, axis=1)
    G = np.concatenate(Gs, axis=1)
    keep = np.concatenate([[True], np.diff(P) > 0])  # panel ends appear twice
    return P[keep], F[:, keep], G[:, keep]


def _solve_hermite(P, G, dG, g):
    """P_f with G(P_f) = g (G increasing on the nodes P): cubic Hermite between the bracketing
    nodes (values and exact slopes), Newton on that cubic."""
    k = np.clip(np.searchsorted(G, g, side="left"), 1, P.size - 1)
    p0, p1 = P[k - 1], P[k]
    h = p1 - p0
    y0, y1 = G[k - 1], G[k]
    d0, d1 = dG[k - 1] * h, dG[k] * h
    with np.errstate(invalid="ignore", divide="ignore"):
        s = np.clip(np.where(y1 > y0, (g - y0) / (y1 - y0), 0.5), 0.0, 1.0)
    for _ in range(8):
        s2, s3 = s * s, s * s * s
        y = y0 * (2 * s3 - 3 * s2 + 1) + d0 * (s3 - 2 * s2 + s) + y1 * (-2 * s3 + 3 * s2) + d1 * (s3 - s2)
        dy = y0 * (6 * s2 - 6 * s) + d0 * (3 * s2 - 4 * s + 1) + y1 * (-6 * s2 + 6 * s) + d1 * (3 * s2 - 2 * s)
        with np.errstate(invalid="ignore", divide="ignore"):
            step = np.where(dy > 0, (y - g) / dy, 0.0)
        s = np.clip(s - step, 0.0, 1.0)
        if np.max(np.abs(step), initial=0.0) < 1e-14:
            break
    return p0 + s * h
