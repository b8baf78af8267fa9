"""Final depths of Part I, eq. (11) for many (m, rho, R_t, U_s) on one coefficient table, as arrays.

The Monte-Carlo path of the sweeps: every sample has its own projectile mass m,
target density rho, resistance R_t and striking velocity U_s, all on the same nose (one A, B, C
table).  In w = u^2 with P as the variable eq. (11) is linear (see
:mod:`semianalytic.penetration.motion`): w(P) = e^(-F) (U_s^2 - G), with
F = int B/(r + A) dP and G = (R_t/rho) G_r, G_r = int 2 C e^F/(r + A) dP, r = m/rho.  All
samples share one set of panels and Chebyshev nodes (the coefficients are evaluated once): the
profiles of a few mass-to-density ratios come from the one integrator of eq. (11) in P,
:func:`semianalytic.penetration.motion.reduced_profiles`, and P_f from its one root finder
(:meth:`~semianalytic.penetration.motion.DepthProfile.stop`).  Pure: SI floats and arrays.
"""

from __future__ import annotations

import numpy as np

from semianalytic.errors import ConvergenceError, ModelError
from semianalytic.penetration.motion import reduced_profiles

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
        raise ModelError("mass, target density and resistance must be positive, U0 non-negative")
    r = m / rho
    g = U**2 / R * rho  # G_r(P_f) = U^2 rho / R_t
    uniq = np.unique(r)
    if uniq.size <= n_ratio:
        r_k = uniq
        W = (r[:, None] == r_k[None, :]).astype(float)
    else:
        r_k, W = chebyshev_weights(r, float(r.min()), float(r.max()), n_ratio)
    out = np.zeros(r.size)
    # P_f is analytic in r at fixed g: solve on each profile, then interpolate in r
    for k, prof in enumerate(reduced_profiles(coefficients, r_k, float(g.max()))):
        use = W[:, k] != 0
        if not use.any():
            continue
        root = prof.stop(np.sqrt(g[use]))
        if not root.success:
            raise ConvergenceError(f"eq. (11) in P: the final depth did not converge for {int(np.sum(~root.converged))} samples")
        out[use] += W[use, k] * root.x
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
