"""Longitudinal oscillations of a free rod loaded suddenly at one end (Part I, section 2).

The rod of Part I, eq. (24): length L, diameter d, Young's modulus E_p, density rho_p; the
end x = 0 is free, a compressive stress sigma_0 > 0 is applied suddenly at x = L at t = 0
(the braking force N = sigma_0 pi d^2 / 4 of the target).  Displacements are measured along
+x, so the rod is pushed towards -x and w < 0 (the paper's sign).

Two evaluations of the same solution are offered:

* the paper's Fourier series, eq. (24) (``terms=n``), and
* its closed (d'Alembert) form (``terms=None``, the default), obtained by summing the series
  exactly with S(theta) = sum_i cos(i theta)/i^2 = pi^2/6 - pi theta/2 + theta^2/4 on
  [0, 2 pi] (periodic, even).  No truncation, so it is exact to round-off.

Energies (errata item 5): the paper's W2 of eq. (29) grows linearly in t; the energy of the
exact solution's vibration about its rigid-body motion is bounded and periodic
(period 2L/c_0), between 0 and pi d^2 sigma_0^2 L / (8 E_p).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = [
    "Rod",
    "displacement",
    "velocity",
    "strain",
    "end_velocity",
    "end_displacement",
    "elastic_end_displacement",
    "vibrational_energy",
    "max_vibrational_energy",
    "paper_W2",
]


@dataclass(frozen=True)
class Rod:
    """A uniform elastic rod (Part I, section 2).

    length         L [m]
    diameter       d [m]
    youngs_modulus E_p [Pa]
    density        rho_p [kg/m^3]
    """

    length: float
    diameter: float
    youngs_modulus: float
    density: float

    def __post_init__(self):
        for name in ("length", "diameter", "youngs_modulus", "density"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"Rod.{name} must be a positive finite number; got {value!r}")

    @property
    def c0(self) -> float:
        """Bar sound speed c_0 = sqrt(E_p / rho_p) [m/s] (after Part I, eq. (24))."""
        return math.sqrt(self.youngs_modulus / self.density)

    @property
    def area(self) -> float:
        """Cross-section pi d^2 / 4 [m^2]."""
        return math.pi * self.diameter**2 / 4.0

    @property
    def mass(self) -> float:
        """rho_p A L [kg]."""
        return self.density * self.area * self.length

    @property
    def period(self) -> float:
        """Period of the forced oscillation, tau = 2 L / c_0 [s] (text before Part I, eq. (25))."""
        return 2.0 * self.length / self.c0


# --------------------------------------------------------------------------------------
# exact sums of the series of eq. (24)


def _S(theta):
    """sum_{i>=1} cos(i theta) / i^2 (periodic, even): pi^2/6 - pi th/2 + th^2/4, th = theta mod 2 pi."""
    th = np.mod(theta, 2.0 * np.pi)
    return np.pi**2 / 6.0 - np.pi * th / 2.0 + th**2 / 4.0


def _dS(theta, side=0):
    """d/dtheta of :func:`_S` = -sum sin(i theta)/i, a sawtooth (th - pi)/2, th = theta mod 2 pi.

    At its jumps (theta = 2 k pi) ``side`` picks the value: -1 the left limit, +1 the right
    limit, 0 the mid-value 0 (what the series converges to).  One-sided limits give the
    strain at the rod's ends as the limit from inside the rod (boundary values).
    """
    theta = np.asarray(theta, float)
    side = np.broadcast_to(np.asarray(side), theta.shape)
    right = np.mod(theta, 2.0 * np.pi)  # in [0, 2 pi)
    left = 2.0 * np.pi - np.mod(-theta, 2.0 * np.pi)  # in (0, 2 pi]
    mid = np.where(right == 0.0, np.pi, right)
    th = np.where(side < 0, left, np.where(side > 0, right, mid))
    return (th - np.pi) / 2.0


def _series(rod: Rod, x, t):
    """sum (-1)^i / i^2 [1 - cos(i pi c0 t / L)] cos(i pi x / L), summed exactly."""
    a = np.pi * x / rod.length
    b = np.pi * rod.c0 * t / rod.length
    # (-1)^i cos(i a) = cos(i (a + pi)); cos(i a) cos(i b) = [cos(i(a+b)) + cos(i(a-b))]/2
    return _S(a + np.pi) - 0.5 * (_S(a + b + np.pi) + _S(a - b + np.pi))


def _series_dx(rod: Rod, x, t):
    """d/dx of :func:`_series`."""
    a = np.pi * x / rod.length
    b = np.pi * rod.c0 * t / rod.length
    k = np.pi / rod.length
    # one-sided limits at the ends (from inside the rod), the mid-value at interior fronts
    side = np.where(x >= rod.length, -1, np.where(x <= 0.0, 1, 0))
    return k * (_dS(a + np.pi, side) - 0.5 * (_dS(a + b + np.pi, side) + _dS(a - b + np.pi, side)))


def _series_dt(rod: Rod, x, t):
    """d/dt of :func:`_series`."""
    a = np.pi * x / rod.length
    b = np.pi * rod.c0 * t / rod.length
    k = np.pi * rod.c0 / rod.length
    # at a front (and at t = 0 at the loaded end) the value just after it has passed: the
    # right limit in t (theta_1 = a + b + pi grows with t, theta_2 = a - b + pi decreases)
    return k * (-0.5) * (_dS(a + b + np.pi, 1) - _dS(a - b + np.pi, -1))


def _truncated(rod: Rod, x, t, terms: int, kind: str):
    """The paper's series, eqs. (24) and (27), truncated after ``terms`` terms."""
    if int(terms) < 1:
        raise ValueError(f"terms must be a positive integer; got {terms!r}")
    i = np.arange(1, int(terms) + 1, dtype=float)
    x = np.asarray(x, float)[..., None]
    t = np.asarray(t, float)[..., None]
    sign = (-1.0) ** i
    a = i * np.pi * x / rod.length
    b = i * np.pi * rod.c0 * t / rod.length
    if kind == "w":
        return np.sum(sign / i**2 * (1 - np.cos(b)) * np.cos(a), axis=-1)
    if kind == "dx":
        return np.sum(-sign / i**2 * (1 - np.cos(b)) * np.sin(a) * (i * np.pi / rod.length), axis=-1)
    return np.sum(sign / i**2 * np.sin(b) * (i * np.pi * rod.c0 / rod.length) * np.cos(a), axis=-1)


# --------------------------------------------------------------------------------------
# displacement, velocity, strain (eqs. (24), (25), (27))


def displacement(rod: Rod, sigma0: float, x, t, terms: int | None = None):
    """w(x, t) of Part I, eq. (24) [m]; x in [0, L] (free end at 0, loaded end at L), t >= 0.

    w = -{ sigma0 t^2 / (2 rho_p L)
           + 2 sigma0 L / (pi^2 E_p) sum (-1)^i/i^2 [1 - cos(i pi c0 t/L)] cos(i pi x/L) }.
    ``terms=None``: the series summed exactly (d'Alembert form); ``terms=n``: the paper's
    series truncated after n terms.  Vectorised (x and t broadcast).
    """
    x, t = np.broadcast_arrays(np.asarray(x, float), np.asarray(t, float))
    rigid = sigma0 * t**2 / (2.0 * rod.density * rod.length)
    s = _series(rod, x, t) if terms is None else _truncated(rod, x, t, terms, "w")
    return -(rigid + 2.0 * sigma0 * rod.length / (np.pi**2 * rod.youngs_modulus) * s)[()]


def velocity(rod: Rod, sigma0: float, x, t, terms: int | None = None):
    """dw/dt of Part I, eq. (24) [m/s]; at a wave front the value just after it has passed."""
    x, t = np.broadcast_arrays(np.asarray(x, float), np.asarray(t, float))
    rigid = sigma0 * t / (rod.density * rod.length)
    s = _series_dt(rod, x, t) if terms is None else _truncated(rod, x, t, terms, "dt")
    return -(rigid + 2.0 * sigma0 * rod.length / (np.pi**2 * rod.youngs_modulus) * s)[()]


def strain(rod: Rod, sigma0: float, x, t, terms: int | None = None):
    """Longitudinal strain dw/dx of Part I, eq. (27):

    dw/dx = 2 sigma0 / (pi E_p) sum (-1)^i / i [1 - cos(i pi c0 t / L)] sin(i pi x / L).
    """
    x, t = np.broadcast_arrays(np.asarray(x, float), np.asarray(t, float))
    s = _series_dx(rod, x, t) if terms is None else _truncated(rod, x, t, terms, "dx")
    return -(2.0 * sigma0 * rod.length / (np.pi**2 * rod.youngs_modulus) * s)[()]


def end_displacement(rod: Rod, sigma0: float, t):
    """w(L, t) [m]: equals -sigma0 c0 t / E_p only for t <= 2L/c0 (eq. (25); errata item 5)."""
    return displacement(rod, sigma0, rod.length, t)


def end_velocity(rod: Rod, sigma0: float, t):
    """dw/dt at the loaded end x = L [m/s]; -sigma0 c0 / E_p while t < 2L/c0 (Part I, eq. (25))."""
    return velocity(rod, sigma0, rod.length, t)


def elastic_end_displacement(rod: Rod, sigma0: float, t):
    """Magnitude of the loaded end's displacement relative to the rigid-body motion [m] (>= 0):

    |w(L, t)| - sigma0 t^2 / (2 rho_p L) = (2 sigma0 L / (pi^2 E_p)) sum_i [1 - cos(i pi c0 t / L)] / i^2,
    a periodic function of period 2L/c0 between 0 and sigma0 L / (2 E_p) (errata item 5).
    """
    t = np.asarray(t, float)
    b = np.pi * rod.c0 * t / rod.length
    s = np.pi**2 / 6.0 - _S(b)  # sum (1 - cos(i b)) / i^2
    return (2.0 * sigma0 * rod.length / (np.pi**2 * rod.youngs_modulus) * s)[()]


# --------------------------------------------------------------------------------------
# energies (eq. (29) and errata item 5)


def vibrational_energy(rod: Rod, sigma0: float, t):
    """Energy of the exact rod solution (24) about its rigid-body motion [J] (errata item 5).

    Total mechanical energy (kinetic + strain) = work of the end force N |w(L, t)|, minus
    the rigid-body kinetic energy (N t)^2 / (2 m), which leaves N times the elastic part of
    the end displacement: bounded, periodic with period 2L/c0, between 0 (at t = 2kL/c0,
    when the rod is unstrained and moves as a whole) and pi d^2 sigma0^2 L / (8 E_p).
    """
    N = sigma0 * rod.area
    return N * elastic_end_displacement(rod, sigma0, t)


def max_vibrational_energy(rod: Rod, sigma0: float) -> float:
    """pi d^2 sigma0^2 L / (8 E_p) [J]: the maximum of :func:`vibrational_energy` (at t = L/c0)."""
    return math.pi * rod.diameter**2 * sigma0**2 * rod.length / (8.0 * rod.youngs_modulus)


def paper_W2(rod: Rod, sigma0: float, t):
    """The paper's oscillation energy, Part I, eq. (29): W2 = pi d^2 sigma0^2 c0 t / (8 E_p) [J].

    Grows without bound in t; errata item 5 explains why the exact solution does not.
    """
    t = np.asarray(t, float)
    return (math.pi * rod.diameter**2 * sigma0**2 * rod.c0 * t / (8.0 * rod.youngs_modulus))[()]
