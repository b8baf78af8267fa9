"""Stress and displacement fields of the three zones of Part II (spherical symmetry).

Sign convention: tension positive, SI units, r the current radius.  All functions are
vectorised over ``r``.  ``material`` is anything with ``youngs_modulus``,
``poisson_ratio`` and ``tensile_strength`` (a :class:`~semianalytic.cavity.BrittleMaterial`).

Zones (Part II, Fig. 1):
  r >= c       elastic, eq. (5)
  b <= r <= c  cracked / dilatant, radial stress only, eqs. (9)-(12) (errata items 8, 9)
  a <= r <= b  comminuted, porous-incompressible, eqs. (23)-(24)
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "lame_cavity",
    "elastic_zone",
    "cracked_zone",
    "comminuted_zone",
    "crack_front_ratio",
    "front_strains",
]


def lame_cavity(r, a, pressure, E, nu):
    """Pressurised spherical cavity (radius ``a``, internal pressure ``pressure`` > 0 in
    compression) in an infinite linear-elastic medium: the classical Lame solution.

    u = (1 + nu) p a^3 / (2 E r^2),  sigma_r = -p (a/r)^3,  sigma_phi = p/2 (a/r)^3.

    It solves Part II, eqs. (1)-(3) with u(inf) = 0 and sigma_r(a) = -p; eq. (5) is this
    solution with c = a and p = 2 sigma_f.  Returns ``(u, sigma_r, sigma_phi)``.
    """
    r = np.asarray(r, dtype=float)
    ratio3 = (a / r) ** 3
    u = (1.0 + nu) * pressure * a**3 / (2.0 * E * r**2)
    return u, -pressure * ratio3, 0.5 * pressure * ratio3


def elastic_zone(r, c, material):
    """Elastic region r >= c (Part II, eq. (5)).

    u = (1 + nu) sigma_f c^3 / (E r^2),  sigma_r = -2 sigma_f (c/r)^3,
    sigma_phi = sigma_f (c/r)^3.  The hoop stress reaches sigma_f at the fracture front
    r = c (eq. (4)); the mean stress -(sigma_r + 2 sigma_phi)/3 vanishes (errata item 7).
    Returns ``(u, sigma_r, sigma_phi)``.
    """
    E, nu, sf = material.youngs_modulus, material.poisson_ratio, material.tensile_strength
    r = np.asarray(r, dtype=float)
    ratio3 = (c / r) ** 3
    u = (1.0 + nu) * sf * c**3 / (E * r**2)
    return u, -2.0 * sf * ratio3, sf * ratio3


def cracked_zone(r, b, c, sigma_star, material):
    """Cracked, dilatant region b <= r <= c (Part II, eqs. (11)-(12)).

    Radial stress only (sigma_phi = sigma_theta = 0 in the whole zone, errata item 8):
    sigma_r = sigma* (b/r)^2 from eq. (9), and sigma_r = E du/dr (eq. (10) corrected,
    errata item 9) integrated with u(c) = (1 + nu) sigma_f c / E (eq. (6)):

    u = -(sigma*/E) b (b/r - b/c) + sigma_f (1 + nu) c / E.

    ``sigma_star`` < 0 is the radial stress at r = b + 0.  Returns ``(u, sigma_r)``.
    """
    E, nu, sf = material.youngs_modulus, material.poisson_ratio, material.tensile_strength
    r = np.asarray(r, dtype=float)
    sigma_r = sigma_star * (b / r) ** 2
    u = -(sigma_star / E) * b * (b / r - b / c) + sf * (1.0 + nu) * c / E
    return u, sigma_r


def comminuted_zone(r, b, sigma_star, theta_k):
    """Comminuted (pulverised) region a <= r <= b (Part II, eqs. (23)-(24)).

    sigma_r = sigma* (b/r)^(2 alpha), alpha = 3 theta_k / 2, and
    sigma_phi = (1 - 3 theta_k / 2) sigma_r.  Returns ``(sigma_r, sigma_phi)``.
    """
    r = np.asarray(r, dtype=float)
    alpha = 1.5 * theta_k
    sigma_r = sigma_star * (b / r) ** (2.0 * alpha)
    return sigma_r, (1.0 - alpha) * sigma_r


def crack_front_ratio(sigma_star, tensile_strength):
    """c/b = sqrt(-sigma* / (2 sigma_f)) (Part II, eq. (13)); > 1 only if -sigma* > 2 sigma_f."""
    return np.sqrt(-sigma_star / (2.0 * tensile_strength))


def front_strains(sigma_star, material):
    """Strains at r = b + 0 (Part II, eq. (14), with errata item 10: the root is
    sqrt(2 sigma_f / (-sigma*)), not sqrt(2 sigma_f / HM)).

    Returns a dict with ``e_r`` = sigma*/E, ``e_phi`` = u(b)/b, ``e_c`` = e_r + 2 e_phi (volume
    strain) and ``gamma_c`` = sqrt(2/3) |e_r - e_phi| (shear-strain intensity).
    """
    E, nu, sf = material.youngs_modulus, material.poisson_ratio, material.tensile_strength
    x = -sigma_star
    s = np.sqrt(2.0 * sf / x)  # = b/c
    e_r = sigma_star / E
    e_phi = (x / E) * (1.0 - 0.5 * (1.0 - nu) * s)
    e_c = (x / E) * (1.0 - (1.0 - nu) * s)
    gamma_c = np.sqrt(2.0 / 3.0) * (x / E) * (2.0 - 0.5 * (1.0 - nu) * s)
    return {"e_r": e_r, "e_phi": e_phi, "e_c": e_c, "gamma_c": gamma_c}
