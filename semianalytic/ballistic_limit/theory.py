"""Ballistic limit of a rigid projectile (Part IV, section 2, eqs. (1)-(6)).

Equation of motion (1) of a non-deforming rod of length L_p and density rho_p in a target of
density rho_t and static resistance R:

    rho_p L_p du/dt = -rho_t u^2 / 2 - R,  u(0) = u_s,   a^2 = 2 R / rho_t.

Closed forms: u(t) (2) with the corrected denominator a + u_s tan(gamma) (errata 22), P(u)
(3) with the integrand u du (errata 23), P(t) in the corrected form of errata 24, and the
ballistic limit V_cr (5) with alpha = rho_t h_t / (rho_p L_p) (5').  Three resistances:
R(1) = HM delta_H, R(2) = R(3) delta_H and R(3) = Y (2/3 + ln(2E/(3Y))) (eq. (6); errata 6:
this is not Part I, eq. (16)).  HM = HV / sin(68 deg) (Meyer from Vickers, errata 25).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "VICKERS_HALF_ANGLE",
    "meyer_hardness",
    "resistance_part4",
    "resistance_R1",
    "resistance_R2",
    "resistance_R3",
    "alpha",
    "eq1_deceleration",
    "quadratic_drag_stop_time",
    "quadratic_drag_velocity",
    "quadratic_drag_depth_at_time",
    "quadratic_drag_depth_at_velocity",
    "speed_scale",
    "stop_time",
    "velocity_at_time",
    "depth_at_velocity",
    "depth_at_time",
    "ballistic_limit",
    "stopping_thickness",
]

# Angle between a face of the Vickers pyramid and its axis (136 deg / 2): the one home of the 68-degree
# constant and of the Meyer conversion below (penetration/hardness.py and ballistic_limit/indentation.py use them).
VICKERS_HALF_ANGLE = math.radians(68.0)


def meyer_hardness(HV):
    """Meyer hardness (load / projected area) from Vickers hardness (load / facet area):
    HM = HV / sin(68 deg) = 1.0785 HV (errata item 25; used in R(1) of Table 2)."""
    return np.asarray(HV, dtype=float)[()] / math.sin(VICKERS_HALF_ANGLE)


def resistance_part4(Y, E):
    """R = Y (2/3 + ln(2E/(3Y))): Part IV, eq. (6) (= R(3) of Table 2).  Y, E in Pa.

    Errata item 6: this is not Part I, eq. (16) at nu = 1/2; both are kept under their own
    equation numbers.
    """
    Y = np.asarray(Y, dtype=float)
    return (Y * (2.0 / 3.0 + np.log(2.0 * np.asarray(E, dtype=float) / (3.0 * Y))))[()]


resistance_R3 = resistance_part4


def resistance_R1(HV, delta_H, hardness: str = "meyer"):
    """R(1) = HM delta_H (Part IV, Table 2).  ``hardness='meyer'`` uses HM = HV/sin(68 deg)
    (errata 25); ``'vickers'`` uses HM = HV, which is what the paper's three soft-Al rows need."""
    if hardness == "meyer":
        HM = meyer_hardness(HV)
    elif hardness == "vickers":
        HM = np.asarray(HV, dtype=float)[()]
    else:
        raise ValueError(f"hardness must be 'meyer' or 'vickers'; got {hardness!r}")
    return HM * delta_H


def resistance_R2(Y, E, delta_H):
    """R(2) = Y (2/3 + ln(2E/(3Y))) delta_H (Part IV, Table 2)."""
    return resistance_part4(Y, E) * delta_H


def alpha(rho_t, h_t, rho_p, L_p):
    """alpha = rho_t h_t / (rho_p L_p), the areal-mass ratio of target and rod (Part IV, eq. (5'))."""
    return rho_t * h_t / (rho_p * L_p)


def eq1_deceleration(u, R, rho_t, rho_p, L_p):
    """-du/dt of Part IV, eq. (1): (rho_t u^2 / 2 + R) / (rho_p L_p) [m/s^2] (the right-hand side
    that the closed forms below integrate)."""
    u = np.asarray(u, dtype=float)
    return ((0.5 * rho_t * u**2 + R) / (rho_p * L_p))[()]


# The closed forms of du/dt = -k (u^2 + a^2), u(0) = u_s: Part IV, eqs. (2)-(4) (k = rho_t / (2 rho_p
# L_p), a^2 = 2 R / rho_t) and Part I, eq. (11) with constant coefficients (k = rho B / (2 (m + rho A)),
# a^2 = 2 C R_t / (rho B)).  Their one home: every path calls these.

def quadratic_drag_stop_time(u_s, a, k):
    """t* = arctan(u_s / a) / (a k): the time at which u = 0 (Part IV, from eq. (2))."""
    return math.atan(u_s / a) / (a * k)


def quadratic_drag_velocity(t, u_s, a, k):
    """u(t) = a (u_s - a tan(gamma)) / (a + u_s tan(gamma)), gamma = a k t (Part IV, eq. (2) with the
    corrected denominator, errata item 22); 0 once the rod has stopped."""
    t = np.asarray(t, dtype=float)
    gamma_stop = math.atan(u_s / a)
    gamma = np.minimum(a * k * t, gamma_stop)
    tg = np.tan(gamma)
    u = np.maximum(a * (u_s - a * tg) / (a + u_s * tg), 0.0)
    return np.where(gamma >= gamma_stop, 0.0, u)[()]


def quadratic_drag_depth_at_time(t, u_s, a, k):
    """P(t) = ln(cos(gamma) + (u_s / a) sin(gamma)) / k, gamma = a k t, up to the stop (Part IV,
    after eq. (3), errata item 24); constant afterwards."""
    t = np.asarray(t, dtype=float)
    gamma = np.minimum(a * k * t, math.atan(u_s / a))
    return (np.log(np.cos(gamma) + (u_s / a) * np.sin(gamma)) / k)[()]


def quadratic_drag_depth_at_velocity(u, u_s, a, k):
    """P(u) = ln((a^2 + u_s^2) / (a^2 + u^2)) / (2 k) (Part IV, eq. (3), errata item 23), written
    as (ln(1 + (u_s/a)^2) - ln(1 + (u/a)^2)) / (2 k): no cancellation for a >> u_s, and 0 for a = inf."""
    u = np.asarray(u, dtype=float)
    return ((np.log1p((u_s / a) ** 2) - np.log1p((u / a) ** 2)) / (2.0 * k))[()]


def _k(rho_t, rho_p, L_p):
    """k = rho_t / (2 rho_p L_p) of Part IV, eq. (1) written as du/dt = -k (u^2 + a^2)."""
    return rho_t / (2.0 * rho_p * L_p)


def speed_scale(R, rho_t):
    """a = sqrt(2 R / rho_t) of Part IV, eq. (2) [m/s]."""
    return math.sqrt(2.0 * R / rho_t)


def stop_time(u_s, R, rho_t, rho_p, L_p):
    """Time at which u = 0: t* = (2 rho_p L_p / (a rho_t)) arctan(u_s / a), from eq. (2)."""
    return quadratic_drag_stop_time(u_s, speed_scale(R, rho_t), _k(rho_t, rho_p, L_p))


def velocity_at_time(t, u_s, R, rho_t, rho_p, L_p):
    """u(t) of Part IV, eq. (2) with the corrected denominator (errata item 22):

    u = a (u_s - a tan(gamma)) / (a + u_s tan(gamma)),  gamma = a rho_t t / (2 L_p rho_p),

    valid until the rod stops (gamma = arctan(u_s/a)); 0 afterwards.
    """
    return quadratic_drag_velocity(t, u_s, speed_scale(R, rho_t), _k(rho_t, rho_p, L_p))


def depth_at_velocity(u, u_s, R, rho_t, rho_p, L_p):
    """P(u) = (rho_p L_p / rho_t) ln((a^2 + u_s^2)/(a^2 + u^2)): Part IV, eq. (3) (the integrand
    is 2 rho_p L_p u du / (rho_t (a^2 + u^2)), errata item 23; the printed result is right)."""
    return quadratic_drag_depth_at_velocity(u, u_s, math.sqrt(2.0 * R / rho_t), _k(rho_t, rho_p, L_p))


def depth_at_time(t, u_s, R, rho_t, rho_p, L_p):
    """P(t) = (2 rho_p L_p / rho_t) ln(cos(gamma) + (u_s/a) sin(gamma)) for gamma <= arctan(u_s/a)
    (Part IV, after eq. (3), in the corrected form of errata item 24); constant afterwards."""
    return quadratic_drag_depth_at_time(t, u_s, speed_scale(R, rho_t), _k(rho_t, rho_p, L_p))


def ballistic_limit(h_t, R, rho_t, rho_p, L_p):
    """V_cr = sqrt((2R/rho_t) (exp(alpha) - 1)), alpha = rho_t h_t/(rho_p L_p): Part IV, eq. (5)."""
    al = alpha(rho_t, np.asarray(h_t, dtype=float), rho_p, L_p)
    return np.sqrt(2.0 * np.asarray(R, dtype=float) / rho_t * np.expm1(al))[()]


def stopping_thickness(V, R, rho_t, rho_p, L_p):
    """h_t = (rho_p L_p / rho_t) ln(1 + V^2/a^2): the plate a rod striking at V just stops in
    (Part IV, eq. (4))."""
    return depth_at_velocity(0.0, V, R, rho_t, rho_p, L_p)
