"""Peer penetration models, on the same projectile and target inputs, for comparison with
Part I:

* Forrestal's rigid-projectile cavity-expansion formula (Forrestal, Okajima, Luk 1988;
  Forrestal, Luk, Rosenberg, Brar 1992; Piekutowski et al. 1999): the nose is loaded by the
  spherical-cavity radial stress at the normal velocity V n_x,
      sigma_r / Y = A + B sqrt(rho/Y) V_n + C (rho/Y) V_n^2      (three-term form, Warren &
                                                                  Forrestal 1998)
  or the two-term form sigma_r/Y = A + B (rho/Y) V^2 (:meth:`CavityLaw.two_term`), so the
  axial force is F = pi a^2 Y (A + B N_1 sqrt(rho/Y) V + C N_2 (rho/Y) V^2) with the nose
  factors N_1 = int n_x^2 dS / (pi a^2) and N_2 = int n_x^3 dS / (pi a^2) (frictionless;
  N_2 = (8 psi - 1)/(24 psi^2) for a tangent ogive, 1/2 for a hemisphere), and
      P = (m / (pi a^2)) int_0^V_s v dv / (A Y + B N_1 sqrt(rho Y) v + C N_2 rho v^2)
  in closed form.
* Chen & Li (2002), dimensionless: impact function I = M V^2 / (d^3 A Y), geometry function
  N = M / (B N* rho d^3); X/d = (2/pi) N ln[(1 + I/N) / (1 + k pi/(4N))] + k for X/d > k,
  X/d = sqrt((1 + k pi/(4N)) / (1 + I/N) (4k/pi) I) for X/d <= k (crater depth k d; k = 0 for
  metal targets, where the formula is the two-term Forrestal result).
* Alekseevskii-Tate eroding rod: rho_p L dv/dt = -Y_p, dL/dt = -(v - u), dP/dt = u,
  (1/2) rho_p (v - u)^2 + Y_p = (1/2) rho_t u^2 + R_t; once erosion stops (v = u) the rod
  decelerates rigidly, rho_p L dv/dt = -(rho_t v^2/2 + R_t) (Part IV, eq. (1)).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

__all__ = [
    "ogive_nose_factor",
    "nose_factors",
    "CavityLaw",
    "forrestal_depth",
    "chen_li_depth",
    "TateResult",
    "tate_penetration",
]


def ogive_nose_factor(psi: float) -> float:
    """N* = (8 psi - 1) / (24 psi^2) of a frictionless tangent ogive (psi = 0.5: hemisphere, 1/2)."""
    return (8.0 * psi - 1.0) / (24.0 * psi**2)


@functools.cache
def _gauss_legendre_64() -> tuple[np.ndarray, np.ndarray]:
    """The 64-point Gauss-Legendre rule on [-1, 1], computed once (an eigenvalue problem each time
    otherwise: nose_factors runs once per model and shot set)."""
    u, w = np.polynomial.legendre.leggauss(64)
    u.setflags(write=False)
    w.setflags(write=False)
    return u, w


def nose_factors(nose) -> tuple[float, float]:
    """(N_1, N_2) = (int n_x^2 dS, int n_x^3 dS) / (pi a^2) over a geometry.Nose (quadrature)."""
    u, w = _gauss_legendre_64()
    n1 = n2 = 0.0
    for seg in nose.segments:
        edges = np.asarray(seg.knots) if hasattr(seg, "knots") else np.linspace(seg.t0, seg.t1, 9)
        for a, b in zip(edges[:-1], edges[1:]):
            t = 0.5 * (a + b) + 0.5 * (b - a) * u
            x, r = seg.point(t)
            dx, dr = seg.derivative(t)
            ds = np.hypot(dx, dr)
            with np.errstate(invalid="ignore", divide="ignore"):
                nx = np.where(ds > 0, dr / ds, 0.0)  # normal (t_r, -t_x) into the target, n_x > 0 on a nose
            dS = 2.0 * np.pi * r * ds * 0.5 * (b - a) * w
            n1 += float(np.sum(nx**2 * dS))
            n2 += float(np.sum(nx**3 * dS))
    area = math.pi * nose.radius**2
    return n1 / area, n2 / area


@dataclass(frozen=True)
class CavityLaw:
    """sigma_r / Y = A + B sqrt(rho/Y) V + C (rho/Y) V^2 (spherical cavity at speed V).  Y [Pa]."""

    yield_stress: float
    A: float
    B: float
    C: float

    @classmethod
    def two_term(cls, yield_stress: float, A: float, B: float) -> CavityLaw:
        """sigma_r / Y = A + B (rho/Y) V^2 (Forrestal's two-term form)."""
        return cls(yield_stress, A, 0.0, B)


def _int_v_over_quadratic(alpha, beta, gamma, U):
    """int_0^U v / (alpha + beta v + gamma v^2) dv, alpha > 0, beta, gamma >= 0 (closed form)."""
    U = np.asarray(U, float)
    if gamma == 0.0:
        if beta == 0.0:
            return U**2 / (2.0 * alpha)
        return U / beta - alpha / beta**2 * np.log1p(beta * U / alpha)
    log_part = np.log1p((beta * U + gamma * U**2) / alpha) / (2.0 * gamma)
    if beta == 0.0:
        return log_part
    disc = 4.0 * alpha * gamma - beta**2
    if disc > 0:
        q = math.sqrt(disc)
        J = 2.0 / q * (np.arctan((2.0 * gamma * U + beta) / q) - math.atan(beta / q))
    elif disc < 0:
        q = math.sqrt(-disc)
        J = np.log((2.0 * gamma * U + beta - q) * (beta + q) / ((2.0 * gamma * U + beta + q) * (beta - q))) / q
    else:
        J = 2.0 / beta - 2.0 / (2.0 * gamma * U + beta)
    return log_part - beta / (2.0 * gamma) * J


def forrestal_depth(mass: float, diameter: float, target_density: float, law: CavityLaw, U, N1: float, N2: float):
    """Forrestal's rigid-projectile depth of penetration [m] (module docstring), vectorised in U."""
    a2 = (0.5 * diameter) ** 2
    Y, rho = law.yield_stress, target_density
    alpha = law.A * Y
    beta = law.B * N1 * math.sqrt(rho * Y)
    gamma = law.C * N2 * rho
    return (mass / (math.pi * a2) * _int_v_over_quadratic(alpha, beta, gamma, U))[()]


def chen_li_depth(mass: float, diameter: float, target_density: float, static_resistance: float, B: float,
                  N_star: float, U, k: float = 0.0):
    """Chen & Li (2002) dimensionless depth of penetration [m] (module docstring).

    static_resistance = A Y [Pa] (A f_c for concrete), B the dynamic coefficient of the cavity
    law, N_star the nose factor, k the crater depth in calibres.
    """
    U = np.asarray(U, float)
    d = diameter
    I = mass * U**2 / (d**3 * static_resistance)
    N = mass / (B * N_star * target_density * d**3)
    kk = 1.0 + k * math.pi / (4.0 * N)
    deep = 2.0 / math.pi * N * np.log((1.0 + I / N) / kk) + k
    shallow = np.sqrt(kk / (1.0 + I / N) * (4.0 * k / math.pi) * I)
    return (d * np.where(deep > k, deep, shallow))[()]


@dataclass(frozen=True)
class TateResult:
    """Alekseevskii-Tate outcome: depth [m], residual rod length [m], time [s], whether it eroded,
    and the velocity at which erosion stopped (0 if it never did, NaN if it never eroded)."""

    depth: float
    residual_length: float
    time: float
    eroded: bool
    transition_velocity: float


def tate_penetration(length: float, rod_density: float, rod_strength: float, target_density: float,
                     target_resistance: float, V: float, *, rtol: float = 1e-10) -> TateResult:
    """Alekseevskii-Tate penetration of a rod of length L at striking velocity V (module docstring):
    the one home of the equations, :mod:`semianalytic.penetration.regime` (the quadrature in v and its
    time integral); ``rtol`` is accepted for compatibility (the quadrature's error is below 1e-9)."""
    from semianalytic.penetration import regime as rg

    d, r, eroded = rg.eroding_depth_per_length(V, density=rod_density, target_density=target_density,
                                               target_resistance=target_resistance, rod_strength=rod_strength)
    t = rg.eroding_time_per_length(V, density=rod_density, target_density=target_density,
                                   target_resistance=target_resistance, rod_strength=rod_strength)
    eroded = bool(eroded)
    v_e = float(rg._erosion_end_array(rod_density, rod_strength, target_density, target_resistance))
    residual = float(r) * length
    if eroded and residual < 1e-9 * length:
        residual = 0.0
    trans = math.nan if not eroded else (v_e if rod_strength > target_resistance and residual > 0 else 0.0)
    return TateResult(float(d) * length, residual, float(t) * length, eroded, trans)


def tate_interface_velocity(v, rho_p, Y_p, rho_t, R_t):
    """u of the eroding rod (:func:`semianalytic.penetration.regime.tate_interface_velocity`)."""
    from semianalytic.penetration.regime import tate_interface_velocity as home

    return home(v, rho_p, Y_p, rho_t, R_t)
