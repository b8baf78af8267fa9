"""Elastic projectile of Part I, section 2: quasi-rigid start, oscillation energies and the
corrected penetration (eqs. (26), (28)-(30')).

* Quasi-rigid start (26): U_0 = U_s - sigma_0 c_0 / E_p, sigma_0 = 4N/(pi d^2).  The braking
  force N is taken as the paper does in (26)/(33): constant, at the start of penetration,
  from eq. (11) with the deep-limit coefficients, N = m (rho B u^2/2 + C R_t)/(m + rho A) at
  u = U_0 (solved together with (26): a quadratic in U_0).
* W1 (28), the energy of lateral compression, e(p_l) = pi d^2 (1 - nu_p) p_l^2 / (4 E_p) per
  unit length over the submerged length min(P, L): "neglect" (the paper's calculations),
  "bound" (p_l = sigma_0, the paper's upper estimate), "static" (p_l = R_t, the static part
  of eq. (9), which is what remains on the shank) or "pressure" (p_l = p_c of eq. (9) at the
  surface nodes of a BEM table with ``pressure_profile``; time domain only).
* W2: "paper", eq. (29), W2 = pi d^2 sigma_0^2 c_0 t / (8 E_p) (grows with t), or
  "exact-rod", the vibration energy of the exact rod solution (24) (bounded; errata item 5).
* Corrected velocity (30)/(30'): u = sqrt(ubar^2 - 2 (W1 + W2)/m), until t* where
  m ubar^2 = 2 (W1 + W2); P = int_0^t* u dt and Delta P = P - Pbar < 0.

:func:`solve_elastic` evaluates this in the time domain from the quasi-rigid history of
:func:`~semianalytic.penetration.motion.solve_motion`; the vectorised evaluation over many
striking velocities is :func:`semianalytic.penetration.curve.penetration_curve` (the two
check each other in the tests).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from semianalytic.penetration import rod as rodmod
from semianalytic.penetration.motion import MotionResult, deep_coefficients, eq11_acceleration, solve_motion

__all__ = [
    "W2_MODELS",
    "W1_MODELS",
    "W1_TIME_DOMAIN",
    "axial_stress",
    "start_force_coefficients",
    "quasi_rigid_start",
    "lateral_energy",
    "lateral_energy_from_profile",
    "oscillation_energy",
    "corrected_velocity",
    "ElasticResult",
    "solve_elastic",
]

W2_MODELS = ("paper", "exact-rod")
from semianalytic.penetration.options import W1_MODELS  # noqa: E402,F401 (a leaf module: a cheap --help)

W1_TIME_DOMAIN = W1_MODELS + ("pressure",)  # + eq. (9)'s pressure from the BEM table


def axial_stress(N, diameter: float):
    """sigma_0 = 4N / (pi d^2) [Pa] (Part I, text after eq. (25) and eq. (31))."""
    return 4.0 * np.asarray(N, float) / (math.pi * diameter**2)


def start_force_coefficients(coefficients, mass, target_density, resistance_pa) -> tuple[float, float]:
    """(alpha, beta) with sigma_0(u) = alpha u^2 + beta: the axial stress of the deep-limit
    braking force N(u) = m (rho B u^2/2 + C R_t)/(m + rho A) (eq. (11)), over pi d^2/4."""
    A, B, C = deep_coefficients(coefficients)
    area = math.pi * float(coefficients.diameter) ** 2 / 4.0
    # N = -m du/dt of eq. (11): its velocity term per unit u^2 and its strength term
    return (-mass * eq11_acceleration(A, B, 0.0, mass, target_density, resistance_pa, 1.0) / area,
            -mass * eq11_acceleration(A, 0.0, C, mass, target_density, resistance_pa, 0.0) / area)


def quasi_rigid_start(U_s, c0: float, youngs_modulus: float, alpha: float, beta: float):
    """(U_0, sigma_0) from Part I, eq. (26) with sigma_0 = alpha U_0^2 + beta (see
    :func:`start_force_coefficients`): the root of gamma alpha U_0^2 + U_0 - (U_s - gamma beta) = 0,
    gamma = c_0/E_p.  U_0 = 0 (no penetration) when U_s <= gamma beta.  Vectorised in U_s."""
    U_s = np.asarray(U_s, float)
    g = c0 / youngs_modulus
    q = U_s - g * beta
    U0 = np.where(q > 0, 2.0 * q / (1.0 + np.sqrt(1.0 + 4.0 * g * alpha * np.maximum(q, 0.0))), 0.0)
    return U0[()], (alpha * U0**2 + beta)[()]


def lateral_energy(kind: str, P, *, sigma0, resistance_pa: float, rod: rodmod.Rod, poisson_ratio: float):
    """W1 of Part I, eq. (28) [J] at depth P: e(p_l) min(P, L) with p_l per ``kind`` (module docstring)."""
    P = np.asarray(P, float)
    if kind == "neglect":
        return np.zeros_like(P)[()]
    if kind == "bound":
        p_l = np.asarray(sigma0, float)
    elif kind == "static":
        p_l = resistance_pa
    else:
        raise ValueError(f"W1 model must be one of {W1_MODELS}; got {kind!r}")
    e = math.pi * rod.diameter**2 * (1.0 - poisson_ratio) / (4.0 * rod.youngs_modulus) * np.square(p_l)
    return (e * np.minimum(P, rod.length))[()]


def lateral_energy_from_profile(x, p_c, P: float, rod: rodmod.Rod, poisson_ratio: float) -> float:
    """W1 of Part I, eq. (28) from a contact-pressure profile (p_l = p_c, sin(alpha) = 1) [J].

    ``x``, ``p_c``: target-frame abscissae (tip at x = max(x)) and pressures of the surface
    nodes of a tabulated depth; the integral runs over the distance s behind the tip from 0 to
    min(P, L), the last pressure continued where P exceeds the tabulated depth.
    """
    x, p_c = np.asarray(x, float), np.asarray(p_c, float)
    s = x.max() - x
    order = np.argsort(s)
    s, q = s[order], p_c[order] ** 2
    end = min(P, rod.length)
    inside = s <= end
    s_in, q_in = s[inside], q[inside]
    total = float(np.sum(0.5 * (q_in[1:] + q_in[:-1]) * np.diff(s_in))) if len(s_in) > 1 else 0.0
    if len(s_in) and end > s_in[-1]:
        q_end = np.interp(end, s, q) if end < s[-1] else q[-1]
        total += 0.5 * (q_in[-1] + q_end) * (end - s_in[-1])
    e = math.pi * rod.diameter**2 * (1.0 - poisson_ratio) / (4.0 * rod.youngs_modulus)
    return e * total


def oscillation_energy(kind: str, rod: rodmod.Rod, sigma0, t):
    """W2 [J]: "paper" = eq. (29); "exact-rod" = vibration energy of the exact solution (24)."""
    if kind == "paper":
        return rodmod.paper_W2(rod, sigma0, t)
    if kind == "exact-rod":
        return rodmod.vibrational_energy(rod, sigma0, t)
    raise ValueError(f"W2 model must be one of {W2_MODELS}; got {kind!r}")


def corrected_velocity(u_bar, W, mass: float):
    """Part I, eq. (30) (eq. (30') when W = W2): u = ubar sqrt(1 - 2W/(m ubar^2)), 0 past the stop."""
    u_bar = np.asarray(u_bar, float)
    return np.sqrt(np.maximum(u_bar**2 - 2.0 * np.asarray(W, float) / mass, 0.0))[()]


@dataclass(frozen=True, eq=False)
class ElasticResult:
    """Penetration of the elastic projectile for one striking velocity (SI units).

    U_s, U0 (quasi-rigid start, eq. (26)), sigma0; t_star (stop, m ubar^2 = 2 W), final_depth
    (P of eq. (30)), quasi_rigid (the :class:`MotionResult` for ubar), delta_P = P - Pbar.
    ``velocity(t)``, ``depth(t)`` and ``energy(t)`` (W1 + W2) for plots.
    """

    U_s: float
    U0: float
    sigma0: float
    t_star: float
    final_depth: float
    quasi_rigid: MotionResult
    w1: str
    w2: str
    _energy: object = field(repr=False)

    @property
    def delta_P(self) -> float:
        return self.final_depth - self.quasi_rigid.final_depth

    def energy(self, t):
        return self._energy(np.asarray(t, float))

    def velocity(self, t):
        t = np.asarray(t, float)
        _, ub = self.quasi_rigid.at(t)
        return np.where(t <= self.t_star, corrected_velocity(ub, self.energy(t), self.quasi_rigid.mass), 0.0)[()]

    def depth(self, t):
        """P(t) = int_0^t u (vectorised; the same panel quadrature as the final depth)."""
        t = np.asarray(t, float)
        return _depths(self, np.minimum(t.ravel(), self.t_star), self._rod).reshape(t.shape)[()]  # type: ignore[attr-defined]


def _panel_edges(t_end: float, rod: rodmod.Rod) -> np.ndarray:
    """Panel ends for the quadrature of u: the kinks of the exact-rod energy (multiples of L/c0)."""
    step = rod.length / rod.c0
    k = np.arange(1, int(t_end / step) + 1) * step
    return np.unique(np.concatenate([[0.0], k[k < t_end], [t_end]]))


_GX, _GW = np.polynomial.legendre.leggauss(12)


def _depths(res: ElasticResult, t_ends: np.ndarray, rod: rodmod.Rod) -> np.ndarray:
    """int_0^t u dt for each t in ``t_ends`` (<= t*): Gauss panels between the kinks, the last
    panel mapped t = a + (b - a)(1 - (1 - x)^2) because u ~ sqrt(t* - t) at the stop."""
    t_ends = np.asarray(t_ends, float)
    if res.t_star <= 0:
        return np.zeros_like(t_ends)
    edges = _panel_edges(res.t_star, rod)
    x = 0.5 * (_GX + 1.0)
    a, b = edges[:-1, None], edges[1:, None]
    last = np.zeros((len(edges) - 1, 1), bool)
    last[-1] = True
    tn = np.where(last, a + (b - a) * (1.0 - (1.0 - x) ** 2), a + (b - a) * x)
    wn = np.where(last, 0.5 * _GW * 2.0 * (b - a) * (1.0 - x), 0.5 * _GW * (b - a))
    panel = np.sum(wn * res.velocity(tn.ravel()).reshape(tn.shape), axis=1)
    cum = np.concatenate([[0.0], np.cumsum(panel)])
    k = np.clip(np.searchsorted(edges, t_ends, side="right") - 1, 0, len(edges) - 2)
    full = t_ends >= res.t_star
    lo = edges[k][:, None]
    hi = t_ends[:, None]
    tp = lo + (hi - lo) * x[None, :]
    wp = 0.5 * _GW[None, :] * (hi - lo)
    part = np.sum(wp * res.velocity(tp.ravel()).reshape(tp.shape), axis=1)
    return np.where(full, cum[-1], cum[k] + part)


def solve_elastic(
    coefficients,
    mass: float,
    target_density: float,
    resistance_pa: float,
    U_s: float,
    rod: rodmod.Rod,
    *,
    poisson_ratio: float = 0.29,
    w2: str = "paper",
    w1: str = "neglect",
    rtol: float = 1e-10,
    quasi_rigid: MotionResult | None = None,
) -> ElasticResult:
    """The elastic projectile of Part I, eqs. (26), (28)-(30'), in the time domain.

    ``rod`` carries L, d, E_p, rho_p of the projectile (as the cylinder of eq. (24)).
    ``quasi_rigid``: a solution of eq. (11) from the start velocity U_0 of eq. (26) to reuse
    (e.g. from an earlier call's ``.quasi_rigid``); it must start at that U_0.
    """
    if w2 not in W2_MODELS:
        raise ValueError(f"w2 must be one of {W2_MODELS}; got {w2!r}")
    if w1 not in W1_TIME_DOMAIN:
        raise ValueError(f"w1 must be one of {W1_TIME_DOMAIN}; got {w1!r}")
    if w1 == "pressure" and not hasattr(coefficients, "pressure_profile"):
        raise ValueError("w1 = 'pressure' needs coefficients with a pressure_profile (the BEM table)")
    alpha, beta = start_force_coefficients(coefficients, mass, target_density, resistance_pa)
    U0, sigma0 = quasi_rigid_start(U_s, rod.c0, rod.youngs_modulus, alpha, beta)
    U0, sigma0 = float(U0), float(sigma0)
    if quasi_rigid is not None:
        if not math.isclose(quasi_rigid.U0, U0, rel_tol=1e-12, abs_tol=1e-12):
            raise ValueError(f"quasi_rigid starts at {quasi_rigid.U0!r} m/s, eq. (26) gives U_0 = {U0!r} m/s")
        qr = quasi_rigid
    else:
        qr = solve_motion(coefficients, mass, target_density, resistance_pa, U0, rtol=rtol)

    if w1 == "pressure":  # eq. (28) with eq. (9)'s pressure, sampled in time and interpolated
        ts = np.linspace(0.0, qr.penetration_time, 201)
        Ps, us = qr.at(ts)
        A, B, C = (np.asarray(f(Ps), float) for f in (coefficients.A, coefficients.B, coefficients.C))
        dus = eq11_acceleration(A, B, C, mass, target_density, resistance_pa, us**2)
        W1s = np.array([
            lateral_energy_from_profile(*coefficients.pressure_profile(P, target_density, u, du, resistance_pa), P, rod, poisson_ratio)
            for P, u, du in zip(Ps, us, dus)
        ])

        def W1(t, P):
            return np.interp(t, ts, W1s)
    else:
        def W1(t, P):
            return lateral_energy(w1, P, sigma0=sigma0, resistance_pa=resistance_pa, rod=rod, poisson_ratio=poisson_ratio)

    def energy(t):
        P, _ = qr.at(t)
        return oscillation_energy(w2, rod, sigma0, t) + W1(t, P)

    def g(t):  # m ubar^2 - 2 W
        _, ub = qr.at(t)
        return mass * ub**2 - 2.0 * energy(t)

    T = qr.penetration_time
    if T == 0.0:
        t_star = 0.0
    else:
        grid = np.unique(np.concatenate([qr.t, np.linspace(0.0, T, 4001), _panel_edges(T, rod)]))
        vals = g(grid)
        idx = np.flatnonzero(vals <= 0.0)
        if len(idx) == 0 or idx[0] == 0:
            t_star = T if len(idx) == 0 else 0.0
        else:
            from scipy.optimize import brentq  # loaded on use (start-up time)

            j = idx[0]
            t_star = T if vals[j] == 0.0 and j == len(grid) - 1 else brentq(g, grid[j - 1], grid[j], xtol=1e-16, rtol=1e-15)
    res = ElasticResult(U_s=float(U_s), U0=U0, sigma0=sigma0, t_star=float(t_star), final_depth=0.0,
                        quasi_rigid=qr, w1=w1, w2=w2, _energy=energy)
    object.__setattr__(res, "_rod", rod)
    object.__setattr__(res, "final_depth", float(_depths(res, np.array([res.t_star]), rod)[0]))
    return res
