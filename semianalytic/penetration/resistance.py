"""Target resistance R_t: the quasi-static spherical-cavity pressure of Part I, eqs. (16)-(19),
and Part IV, eq. (6).

Each model is a frozen dataclass with ``pressure(diameter)`` -> R_t [Pa] (only the limestone
model, eq. (19), depends on the projectile; the others ignore the argument).  The case-file
table ``[target.resistance]`` (its schema lives in :mod:`semianalytic.sections.penetration`) picks
one by its ``model`` key:

=================  ==================================  ==========================================
model              equation                            keys (units)
=================  ==================================  ==========================================
elastic-plastic    Part I, eq. (16)                    yield_stress, youngs_modulus, poisson_ratio
brittle            Part I, eq. (17)                    compressive_strength, tensile_strength,
                                                       youngs_modulus, poisson_ratio, alpha
hardening          Part I, eq. (18)                    yield_stress, youngs_modulus,
                                                       hardening_exponent (n, 0 <= n < 1)
limestone          Part I, eq. (19) (Frew)             psi, phi, reference_diameter (2 a_0)
                                                       (defaults 607 MPa, 86 MPa, 25.4 mm)
part4              Part IV, eq. (6)                    yield_stress, youngs_modulus
cavity             Part II (brittle cavity model)      youngs_modulus, poisson_ratio,
                                                       tensile_strength, compressive_strength,
                                                       bulk_modulus (optional), initial_porosity
constant           a given R_t                         value
=================  ==================================  ==========================================

Pure models: SI floats in, SI floats out; no schema, no units, no case files.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from semianalytic.errors import InputError

if TYPE_CHECKING:
    from semianalytic.cavity.material import BrittleMaterial

__all__ = [
    "elastic_plastic_resistance",
    "brittle_resistance",
    "hardening_integral",
    "hardening_resistance",
    "limestone_resistance",
    "part4_resistance",
    "ElasticPlastic",
    "Brittle",
    "Hardening",
    "Limestone",
    "Part4",
    "Cavity",
    "Constant",
    "Resistance",
    "resistance_from_case",
    "MODELS",
]


# --------------------------------------------------------------------------------------
# closed forms (pure functions, SI)


def _log(x):
    return math.log(x) if np.ndim(x) == 0 else np.log(x)  # floats as before (ValueError <= 0); arrays


def _sqrt(x):
    return math.sqrt(x) if np.ndim(x) == 0 else np.sqrt(x)


def elastic_plastic_resistance(Y: float, E: float, nu: float) -> float:
    """Part I, eq. (16): R_t = (2/3) Y (1 + ln(E / (3 Y (1 - nu)))) [Pa] (elastic-perfectly plastic).
    Floats or arrays (Monte Carlo on arrays)."""
    return 2.0 / 3.0 * Y * (1.0 + _log(E / (3.0 * Y * (1.0 - nu))))


def brittle_resistance(Y: float, sigma_f: float, E: float, nu: float, alpha: float) -> float:
    """Part I, eq. (17): R_t = Y [E / (3 Y (1 - (1 - nu) sqrt(sigma_f / (2 Y))))]^(2 alpha / 3) [Pa].

    Y: strength in uniaxial compression, sigma_f: tensile strength, alpha: characteristic of
    the fractured medium (ref. [23] of Part I).  Needs (1 - nu) sqrt(sigma_f / (2 Y)) < 1.
    Floats or arrays (Monte Carlo on arrays).
    """
    q = 1.0 - (1.0 - nu) * _sqrt(sigma_f / (2.0 * Y))
    if not np.all(q > 0):
        raise ValueError("(1 - nu) sqrt(tensile_strength / (2 compressive_strength)) must be below 1 in eq. (17)")
    return Y * (E / (3.0 * Y * q)) ** (2.0 * alpha / 3.0)


def hardening_integral(Y: float, E: float, n: float) -> float:
    """I of Part I, eq. (18): I = int_0^{1 - 3Y/(2E)} (-ln x)^n / (1 - x) dx.

    Evaluated as int_{s0}^inf s^n / (e^s - 1) ds with x = e^(-s), s0 = -ln(1 - 3Y/(2E)): the
    logarithmic end x -> 0 becomes an exponentially decaying tail and the end near x = 1
    a power s^(n-1), integrated on a logarithmic scale.  For n = 0, I = ln(2E/(3Y)) exactly.
    """
    from scipy import integrate  # imported when needed (start-up time)

    eps = 1.5 * Y / E
    if not 0 < eps < 1:
        raise ValueError("eq. (18) needs 3Y/(2E) < 1")
    s0 = -math.log1p(-eps)
    def f_log(v):  # s = e^v, ds = s dv
        return math.exp(v * (n + 1.0)) / math.expm1(math.exp(v))
    head = 0.0
    if s0 < 1.0:
        head = integrate.quad(f_log, math.log(s0), 0.0, epsabs=0.0, epsrel=1e-13, limit=200)[0]
    tail = integrate.quad(lambda s: s**n * math.exp(-s) / -math.expm1(-s), max(s0, 1.0), math.inf, epsabs=0.0, epsrel=1e-13, limit=200)[0]
    return head + tail


def hardening_resistance(Y: float, E: float, n: float) -> float:
    """Part I, eq. (18): R_t = (2/3) Y (1 + (2E/(3Y))^n I) [Pa] (incompressible, power-law hardening).

    As n -> 0 it tends to the incompressible elastic-plastic limit (2/3) Y (1 + ln(2E/(3Y))),
    which is eq. (16) at nu = 1/2.
    """
    return 2.0 / 3.0 * Y * (1.0 + (2.0 * E / (3.0 * Y)) ** n * hardening_integral(Y, E, n))


def limestone_resistance(radius: float, psi: float = 607e6, phi: float = 86e6, a0: float = 12.7e-3) -> float:
    """Part I, eq. (19) (Frew): R_t = Psi + phi (a_0 / a) [Pa], a the projectile radius [m].

    Psi = 607 MPa, phi = 86 MPa, 2 a_0 = 25.4 mm as printed.
    """
    return psi + phi * (a0 / radius)


def part4_resistance(Y: float, E: float) -> float:
    """Part IV, eq. (6): R = Y (2/3 + ln(2E / (3Y))) [Pa].

    Not Part I, eq. (16) at nu = 1/2: the log term's coefficient is 1, not 2/3 (errata item 6).
    """
    from semianalytic.ballistic_limit.theory import resistance_part4  # the one implementation (Part IV module)

    return float(resistance_part4(Y, E))


# --------------------------------------------------------------------------------------
# models (frozen dataclasses, SI)


@dataclass(frozen=True)
class ElasticPlastic:
    """Elastic-perfectly plastic target, Part I, eq. (16).  Y, E [Pa]; nu [-]."""

    yield_stress: float
    youngs_modulus: float
    poisson_ratio: float
    name = "elastic-plastic"
    equation = "Part I, eq. (16)"

    def pressure(self, diameter: float | None = None) -> float:
        return elastic_plastic_resistance(self.yield_stress, self.youngs_modulus, self.poisson_ratio)


@dataclass(frozen=True)
class Brittle:
    """Elastic-brittle target, Part I, eq. (17).  Y (compressive), sigma_f (tensile), E [Pa]; nu, alpha [-]."""

    compressive_strength: float
    tensile_strength: float
    youngs_modulus: float
    poisson_ratio: float
    alpha: float
    name = "brittle"
    equation = "Part I, eq. (17)"

    def pressure(self, diameter: float | None = None) -> float:
        return brittle_resistance(
            self.compressive_strength, self.tensile_strength, self.youngs_modulus, self.poisson_ratio, self.alpha
        )


@dataclass(frozen=True)
class Hardening:
    """Strain-hardening (power law, exponent n) incompressible target, Part I, eq. (18).  Y, E [Pa]."""

    yield_stress: float
    youngs_modulus: float
    hardening_exponent: float
    name = "hardening"
    equation = "Part I, eq. (18)"

    def pressure(self, diameter: float | None = None) -> float:
        return hardening_resistance(self.yield_stress, self.youngs_modulus, self.hardening_exponent)


@dataclass(frozen=True)
class Limestone:
    """Limestone (Frew), Part I, eq. (19): R_t = Psi + phi a_0 / a.  Psi, phi [Pa]; 2 a_0 [m]."""

    psi: float = 607e6
    phi: float = 86e6
    reference_diameter: float = 25.4e-3
    name = "limestone"
    equation = "Part I, eq. (19)"

    def pressure(self, diameter: float | None = None) -> float:
        if diameter is None or not diameter > 0:
            raise InputError("projectile.diameter", "the limestone resistance, eq. (19), needs the projectile diameter")
        return limestone_resistance(0.5 * diameter, self.psi, self.phi, 0.5 * self.reference_diameter)


@dataclass(frozen=True)
class Part4:
    """Elastic-plastic resistance of Part IV, eq. (6).  Y, E [Pa]."""

    yield_stress: float
    youngs_modulus: float
    name = "part4"
    equation = "Part IV, eq. (6)"

    def pressure(self, diameter: float | None = None) -> float:
        if np.ndim(self.yield_stress) or np.ndim(self.youngs_modulus):  # arrays (Monte Carlo)
            from semianalytic.ballistic_limit.theory import resistance_part4

            return resistance_part4(self.yield_stress, self.youngs_modulus)
        return part4_resistance(self.yield_stress, self.youngs_modulus)


@dataclass(frozen=True)
class Cavity:
    """The Part II brittle cavity-expansion pressure R_r of Part II, eq. (34), in Pa."""

    material: BrittleMaterial
    name = "cavity"
    equation = "Part II, eq. (34)"

    def pressure(self, diameter: float | None = None) -> float:
        from semianalytic.cavity import solve_cavity

        return float(solve_cavity(self.material).cavity_pressure)


@dataclass(frozen=True)
class Constant:
    """A given resistance R_t [Pa] (e.g. a value quoted in a paper)."""

    value: float
    name = "constant"
    equation = "given R_t"

    def pressure(self, diameter: float | None = None) -> float:
        return self.value


Resistance = ElasticPlastic | Brittle | Hardening | Limestone | Part4 | Cavity | Constant

MODELS: list[str] = []
"""The names of the registered ``[target.resistance]`` models, in order: kept by
:func:`semianalytic.sections.penetration.register_resistance` (the one list of models)."""


def resistance_from_case(case) -> Resistance:
    """The resistance model of a validated case's ``[target.resistance]`` (an error if it has none).

    The section holds the validated input (:mod:`semianalytic.sections.penetration`); its
    ``build()`` gives the model.
    """
    spec = case.require("target").resistance
    if spec is None:
        raise InputError(
            "target.resistance",
            "missing: add a [target.resistance] table with 'model' = one of " + ", ".join(MODELS),
        )
    return spec.build()
