"""Exact potential-flow solutions used as references (independent of any discretisation).

Convention of Part I (errata item 1b): the body moves with unit speed in +x, the fluid
velocity is v = -grad(phi), and dphi/dn = -n_x on the body with n pointing into the fluid.
Then A = integral of phi n_x dS is the added mass divided by the fluid density.
"""

from __future__ import annotations

import math

import numpy as np


def sphere_added_mass_coefficient() -> float:
    """Added mass of a sphere over rho V: exactly 1/2."""
    return 0.5


def sphere_potential(x, r, radius: float):
    """phi = (a^3/2) cos(theta)/R^2 = (a^3/2) x/R^3 outside a sphere of radius a (unit speed, +x)."""
    x, r = np.asarray(x, float), np.asarray(r, float)
    R2 = x * x + r * r
    return 0.5 * radius**3 * x / R2**1.5


def sphere_gradient(x, r, radius: float):
    """(dphi/dx, dphi/dr) of :func:`sphere_potential`."""
    x, r = np.asarray(x, float), np.asarray(r, float)
    R2 = x * x + r * r
    c = 0.5 * radius**3
    return c * (1.0 / R2**1.5 - 3 * x * x / R2**2.5), c * (-3 * x * r / R2**2.5)


def spheroid_added_mass_coefficient(length: float, diameter: float) -> float:
    """Lamb's added-mass coefficient k1 = alpha0/(2 - alpha0) of a spheroid moving along its axis.

    Prolate (length > diameter, eccentricity e = sqrt(1 - b^2/a^2)):
    alpha0 = 2(1 - e^2)/e^3 (artanh(e) - e).  Oblate (length < diameter, e = sqrt(1 - a^2/b^2)):
    alpha0 = 2/e^2 (1 - sqrt(1 - e^2) arcsin(e)/e)... in the form of Lamb, Hydrodynamics, art. 373.
    On the surface the exact potential is phi = k1 x (x from the centre).
    """
    a, b = 0.5 * length, 0.5 * diameter
    if math.isclose(a, b, rel_tol=1e-12):
        return 0.5
    if a > b:
        e = math.sqrt(1.0 - (b / a) ** 2)
        alpha0 = 2.0 * (1.0 - e * e) / e**3 * (math.atanh(e) - e)
    else:
        # oblate spheroid moving along its symmetry (short) axis
        e = math.sqrt(1.0 - (a / b) ** 2)
        alpha0 = 2.0 / (e * e) * (1.0 - math.sqrt(1.0 - e * e) * math.asin(e) / e)
    return alpha0 / (2.0 - alpha0)


def spheroid_surface_potential(x, length: float, diameter: float):
    """Exact surface potential phi = k1 x on a spheroid centred on the origin (unit speed, +x)."""
    return spheroid_added_mass_coefficient(length, diameter) * np.asarray(x, float)
