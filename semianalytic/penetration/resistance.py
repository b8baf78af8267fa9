"""Target resistance R_t: the quasi-static spherical-cavity pressure of Part I, eqs. (16)-(19),
and Part IV, eq. (6).

Each model is a frozen dataclass with ``pressure(diameter)`` -> R_t [Pa] (only the limestone
model, eq. (19), depends on the projectile; the others ignore the argument).  The case-file
table ``[target.resistance]`` is a pydantic discriminated union on its ``model`` key:

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

This module does not import :mod:`semianalytic.case` (the case module imports it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING
from typing import Annotated, Any, Literal, Union

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, TypeAdapter, ValidationError, field_validator
from scipy import integrate

from semianalytic.errors import InputError
from semianalytic.units import Length, NonNegativePressure, Pressure

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
    "ResistanceSpec",
    "ResistanceField",
    "parse_resistance",
    "resistance_from_case",
    "MODELS",
]


# --------------------------------------------------------------------------------------
# closed forms (pure functions, SI)


def elastic_plastic_resistance(Y: float, E: float, nu: float) -> float:
    """Part I, eq. (16): R_t = (2/3) Y (1 + ln(E / (3 Y (1 - nu)))) [Pa] (elastic-perfectly plastic)."""
    return 2.0 / 3.0 * Y * (1.0 + math.log(E / (3.0 * Y * (1.0 - nu))))


def brittle_resistance(Y: float, sigma_f: float, E: float, nu: float, alpha: float) -> float:
    """Part I, eq. (17): R_t = Y [E / (3 Y (1 - (1 - nu) sqrt(sigma_f / (2 Y))))]^(2 alpha / 3) [Pa].

    Y: strength in uniaxial compression, sigma_f: tensile strength, alpha: characteristic of
    the fractured medium (ref. [23] of Part I).  Needs (1 - nu) sqrt(sigma_f / (2 Y)) < 1.
    """
    q = 1.0 - (1.0 - nu) * math.sqrt(sigma_f / (2.0 * Y))
    if not q > 0:
        raise ValueError("(1 - nu) sqrt(tensile_strength / (2 compressive_strength)) must be below 1 in eq. (17)")
    return Y * (E / (3.0 * Y * q)) ** (2.0 * alpha / 3.0)


def hardening_integral(Y: float, E: float, n: float) -> float:
    """I of Part I, eq. (18): I = int_0^{1 - 3Y/(2E)} (-ln x)^n / (1 - x) dx.

    Evaluated as int_{s0}^inf s^n / (e^s - 1) ds with x = e^(-s), s0 = -ln(1 - 3Y/(2E)): the
    logarithmic end x -> 0 becomes an exponentially decaying tail and the end near x = 1
    a power s^(n-1), integrated on a logarithmic scale.  For n = 0, I = ln(2E/(3Y)) exactly.
    """
    eps = 1.5 * Y / E
    if not 0 < eps < 1:
        raise ValueError("eq. (18) needs 3Y/(2E) < 1")
    s0 = -math.log1p(-eps)
    f_log = lambda v: math.exp(v * (n + 1.0)) / math.expm1(math.exp(v))  # s = e^v, ds = s dv
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
        return part4_resistance(self.yield_stress, self.youngs_modulus)


@dataclass(frozen=True)
class Cavity:
    """The Part II brittle cavity-expansion pressure R_r of Part II, eq. (34), in Pa."""

    material: "BrittleMaterial"
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

# --------------------------------------------------------------------------------------
# case-file input: a discriminated union on ``model``


class _Input(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


def _nu(v):
    if not (-1.0 < v < 0.5):
        raise ValueError(f"must lie in (-1, 0.5); got {v!r}")
    return v


class ElasticPlasticInput(_Input):
    model: Literal["elastic-plastic"]
    yield_stress: Pressure
    youngs_modulus: Pressure
    poisson_ratio: float
    _check_nu = field_validator("poisson_ratio")(_nu)

    def build(self) -> ElasticPlastic:
        if not self.youngs_modulus > 3 * self.yield_stress * (1 - self.poisson_ratio):
            raise InputError("target.resistance.youngs_modulus", "eq. (16) needs E > 3 Y (1 - nu) (a positive logarithm)")
        return ElasticPlastic(self.yield_stress, self.youngs_modulus, self.poisson_ratio)


class BrittleInput(_Input):
    model: Literal["brittle"]
    compressive_strength: Pressure
    tensile_strength: Pressure
    youngs_modulus: Pressure
    poisson_ratio: float
    alpha: float = Field(gt=0.0, description="characteristic of the fractured medium (dimensionless)")
    _check_nu = field_validator("poisson_ratio")(_nu)

    def build(self) -> Brittle:
        if not (1 - self.poisson_ratio) * math.sqrt(self.tensile_strength / (2 * self.compressive_strength)) < 1:
            raise InputError(
                "target.resistance.tensile_strength",
                "eq. (17) needs (1 - nu) sqrt(tensile_strength / (2 compressive_strength)) < 1",
            )
        return Brittle(self.compressive_strength, self.tensile_strength, self.youngs_modulus, self.poisson_ratio, self.alpha)


class HardeningInput(_Input):
    model: Literal["hardening"]
    yield_stress: Pressure
    youngs_modulus: Pressure
    hardening_exponent: float = Field(ge=0.0, lt=1.0, description="n of the power law, 0 <= n < 1")

    def build(self) -> Hardening:
        if not self.youngs_modulus > 1.5 * self.yield_stress:
            raise InputError("target.resistance.youngs_modulus", "eq. (18) needs E > 3Y/2")
        return Hardening(self.yield_stress, self.youngs_modulus, self.hardening_exponent)


class LimestoneInput(_Input):
    model: Literal["limestone"]
    psi: NonNegativePressure = 607e6
    phi: NonNegativePressure = 86e6
    reference_diameter: Length = 25.4e-3

    def build(self) -> Limestone:
        return Limestone(self.psi, self.phi, self.reference_diameter)


class Part4Input(_Input):
    model: Literal["part4"]
    yield_stress: Pressure
    youngs_modulus: Pressure

    def build(self) -> Part4:
        if not self.youngs_modulus > 1.5 * self.yield_stress:
            raise InputError("target.resistance.youngs_modulus", "Part IV, eq. (6) needs E > 3Y/2")
        return Part4(self.yield_stress, self.youngs_modulus)


class CavityInput(_Input):
    model: Literal["cavity"]
    youngs_modulus: Pressure
    poisson_ratio: float
    tensile_strength: Pressure
    compressive_strength: Pressure
    bulk_modulus: Pressure | None = None
    initial_porosity: float = Field(default=0.0, ge=0.0, lt=1.0)
    _check_nu = field_validator("poisson_ratio")(_nu)

    def build(self) -> Cavity:
        from semianalytic.cavity.material import BrittleMaterial

        return Cavity(BrittleMaterial(
            youngs_modulus=self.youngs_modulus,
            poisson_ratio=self.poisson_ratio,
            tensile_strength=self.tensile_strength,
            compressive_strength=self.compressive_strength,
            bulk_modulus=self.bulk_modulus,
            initial_porosity=self.initial_porosity,
        ))


class ConstantInput(_Input):
    model: Literal["constant"]
    value: Pressure

    def build(self) -> Constant:
        return Constant(self.value)


ResistanceSpec = Annotated[
    Union[
        ElasticPlasticInput, BrittleInput, HardeningInput, LimestoneInput, Part4Input, CavityInput, ConstantInput
    ],
    Field(discriminator="model"),
]
"""The ``[target.resistance]`` table (a pydantic discriminated union on ``model``)."""



def _builds(spec):
    """Case-load check: the inputs must give a model (e.g. eq. (16)'s logarithm positive)."""
    try:
        spec.build()
    except InputError as exc:
        raise ValueError(f"{exc.field.rsplit('.', 1)[-1]}: {exc.message}") from None
    return spec


ResistanceField = Annotated[ResistanceSpec, AfterValidator(_builds)]
"""The annotation of ``TargetSection.resistance`` in :mod:`semianalytic.case`."""

MODELS = ("elastic-plastic", "brittle", "hardening", "limestone", "part4", "cavity", "constant")
_ADAPTER = TypeAdapter(ResistanceSpec)


def _message(err: dict) -> str:
    if err.get("type") in ("union_tag_invalid", "union_tag_not_found"):
        inp = err.get("input")
        got = f"; got {inp.get('model')!r}" if isinstance(inp, dict) and "model" in inp else ""
        return f"'model' must be one of {', '.join(MODELS)}{got}"
    from semianalytic.case import _pydantic_message  # the case files' wording (imported late: no cycle)

    return _pydantic_message(err)


def parse_resistance(data: Any, field: str = "target.resistance") -> Resistance:
    """Validate a ``[target.resistance]`` table and build its model (SI).

    Raises :class:`InputError` naming the field (``target.resistance.yield_stress``) and what
    was expected.  An already-parsed input model is accepted too.
    """
    if isinstance(data, (ElasticPlasticInput, BrittleInput, HardeningInput, LimestoneInput, Part4Input, CavityInput, ConstantInput)):
        spec = data
    else:
        if not isinstance(data, dict):
            raise InputError(field, f"must be a table with a 'model' key ({', '.join(MODELS)})")
        try:
            spec = _ADAPTER.validate_python(data)
        except ValidationError as exc:
            err = exc.errors()[0]
            loc = [str(p) for p in err.get("loc", ())]
            if loc and loc[0] in MODELS:  # drop the union tag from the path
                loc = loc[1:]
            if err.get("type") in ("union_tag_invalid", "union_tag_not_found"):
                loc = ["model"]
            raise InputError(".".join([field, *loc]), _message(err)) from None
    try:
        return spec.build()
    except InputError as exc:
        raise InputError(exc.field.replace("target.resistance", field, 1), exc.message) from None


def resistance_from_case(case) -> Resistance:
    """The resistance model of a case's ``[target.resistance]`` (an error if it has none)."""
    target = case.require("target")
    spec = target.resistance
    if spec is None:
        raise InputError(
            "target.resistance",
            "missing: add a [target.resistance] table with 'model' = one of " + ", ".join(MODELS),
        )
    return parse_resistance(spec)
