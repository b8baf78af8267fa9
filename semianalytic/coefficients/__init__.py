"""Drag coefficients A(P), B(P), C(P) of the equation of motion (Part I, eqs. (11)-(14)).

``A`` is the added-mass volume (m^3; added mass = rho A), ``B`` the velocity-squared drag
area (m^2) and ``C`` the projected contact area (m^2); all depend on the nose shape and the
depth P only (errata item 1b).  Anything exposing ``A(P)``, ``B(P)``, ``C(P)`` (floats or
arrays in, same shape out, SI) is a :class:`DragCoefficients`: the BEM table
(:class:`~semianalytic.coefficients.table.CoefficientTable`) or the constant stand-in below.

Readings of B (errata item 2a): ``body`` (default; phi'_P following a point fixed on the
projectile), ``literal`` (phi'_P at a fixed target point, as eq. (9) defines it) and
``bernoulli`` (Lagrange-Cauchy integral with the corrected sign; B = dA/dP).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

READINGS = ("body", "literal", "bernoulli")


@runtime_checkable
class DragCoefficients(Protocol):
    """A(P) [m^3], B(P) [m^2], C(P) [m^2] of Part I, eq. (11), and the nose diameter [m]."""

    diameter: float

    def A(self, P): ...

    def B(self, P): ...

    def C(self, P): ...


@dataclass(frozen=True)
class ConstantCoefficients:
    """Depth-independent A, B, C: the stand-in under which Part I, eq. (11) has the
    closed-form solution of Part IV, eqs. (2)-(3) (errata items 22-24)."""

    A_m3: float
    B_m2: float
    C_m2: float
    diameter: float

    @classmethod
    def from_normalised(cls, A_bar: float, B_bar: float, C_bar: float, diameter: float):
        """From Abar = 4A/(pi d^2) [m], Bbar and Cbar (dimensionless), as the paper quotes them."""
        area = np.pi * diameter**2 / 4
        return cls(A_bar * area, B_bar * area, C_bar * area, diameter)

    def A(self, P):
        return np.full_like(np.asarray(P, dtype=float), self.A_m3)[()]

    def B(self, P):
        return np.full_like(np.asarray(P, dtype=float), self.B_m2)[()]

    def C(self, P):
        return np.full_like(np.asarray(P, dtype=float), self.C_m2)[()]
