"""The penetration case sections: ``[target.resistance]`` and ``[data]``.

``[target.resistance]`` is a pydantic discriminated union on its ``model`` key over the
registered inputs (:func:`register_resistance`: one decorator beside each input class is the
only list of models; docs/extending.md adds one); each input validates units and ranges and
``build()`` gives the frozen SI model of :mod:`semianalytic.penetration.resistance` (see its
table of models and keys).

``[data]``: experimental data a penetration case is compared with.

Either a CSV file of shots (striking velocity, depth of penetration, optionally the measured
projectile mass), or a measured critical impact velocity (the Appendix's inverse problem), or
both.  Example (the Piekutowski et al. 1999 shots bundled in ``cases/``)::

    [data]
    name = "piekutowski1999"              # id of the data set: reports/validation_<name>.md
    file = "piekutowski1999_ogive_6061T6511.csv"   # relative to the case file; '#' lines skipped
    source = "Piekutowski et al., Int. J. Impact Eng. 23 (1999) 723-734, Tables 1-2"
    velocity_column = "Vs_m_s"            # with velocity_unit = "m/s"
    depth_column = "P_mm"                 # with depth_unit = "mm"
    mass_column = "mass_g"                # optional, with mass_unit = "g": each shot's own mass
    select = { regime = ["rigid"], material = ["VAR4340"] }   # keep rows with these values
    # the data authors' cavity-expansion constants (Forrestal peer model), optional:
    # sigma_r/Y = A + B sqrt(rho/Y) V + C (rho/Y) V^2 (with C absent: A + B (rho/Y) V^2)
    cavity_yield_stress = "276 MPa"
    cavity_A = 5.04
    cavity_B = 0.983
    cavity_C = 0.940
    critical_velocity = "1000 m/s"        # optional: a measured U_sC -> dynamic yield stress
    response_column = "regime"            # optional: recorded response per shot (regime confusion table)
"""

from __future__ import annotations

import math
import typing
from typing import Annotated, Any, Literal, Union

from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Field,
    TypeAdapter,
    ValidationError,
    field_validator,
    model_validator,
)

from semianalytic.errors import InputError, ModelError, case_key
from semianalytic.penetration.resistance import (
    MODELS,
    Brittle,
    Cavity,
    Constant,
    ElasticPlastic,
    Hardening,
    Limestone,
    Part4,
    Resistance,
)
from semianalytic.schema import Section, allowed_values, pydantic_message
from semianalytic.sections.cavity import MODEL_FIELDS as CAVITY_FIELDS
from semianalytic.units import Length, NonNegativePressure, Pressure, Velocity

__all__ = [
    "MODELS",
    "DataSection",
    "ResistanceField",
    "ResistanceInput",
    "ResistanceSpec",
    "calibrated_parameter",
    "parse_resistance",
    "register_resistance",
    "resistance_inputs",
    "unregister_resistance",
]

_NAME = r"^[A-Za-z0-9_.-]+$"


class DataSection(Section):
    """``[data]``: experiment CSV and/or a measured critical velocity (see the module docstring)."""

    name: str = Field(default="data", pattern=_NAME, description="data-set id, used in report names")
    file: str | None = Field(default=None, min_length=1)
    source: str | None = None
    id_column: str | None = "shot"
    velocity_column: str = "Vs_m_s"
    velocity_unit: str = "m/s"
    depth_column: str = "P_mm"
    depth_unit: str = "mm"
    mass_column: str | None = None
    mass_unit: str = "g"
    select: dict[str, list[str]] = Field(default_factory=dict)
    cavity_yield_stress: Pressure | None = None
    cavity_A: float | None = Field(default=None, gt=0)
    cavity_B: float | None = Field(default=None, ge=0)
    cavity_C: float | None = Field(default=None, ge=0)
    critical_velocity: Velocity | None = None
    response_column: str | None = Field(default=None, description="column of the recorded response (rigid, curved, eroded, ...)")
    hardness_column: str | None = Field(default=None, description="column of each projectile's Rockwell C hardness "
                                        "(used with [projectile] hardness: per-shot strength)")

    @model_validator(mode="after")
    def _complete(self):
        if self.file is None and self.critical_velocity is None:
            raise ValueError("give 'file' (a CSV of shots) and/or 'critical_velocity' (a measured U_sC)")
        cav = (self.cavity_yield_stress, self.cavity_A, self.cavity_B)
        if any(v is not None for v in (*cav, self.cavity_C)) and any(v is None for v in cav):
            raise ValueError("the cavity-expansion constants need cavity_yield_stress, cavity_A and cavity_B together")
        from semianalytic.units import parse_quantity

        for key, kind in (("velocity_unit", "velocity"), ("depth_unit", "length"), ("mass_unit", "mass")):
            parse_quantity(f"1 {getattr(self, key)}", kind, f"data.{key}")
        return self


# --------------------------------------------------------------------------------------
# case-file input: a discriminated union on ``model``


class _Input(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    # R_t of the eroding rod (Alekseevskii-Tate, penetration.regime); default: the model's R_t at the projectile's diameter
    eroding_resistance: Pressure | None = None
    # strict numbers as in every Section (a "*" validator would touch the discriminator 'model')
    _strict = field_validator("poisson_ratio", "alpha", "hardening_exponent", "initial_porosity",
                              mode="before", check_fields=False)(Section._strict_numbers.__func__)
    _plausible = field_validator("*", mode="after")(Section._plausible.__func__)  # ranges of issue 27


ResistanceInput = _Input
"""Base class of a ``[target.resistance]`` input: a ``model: Literal[name]`` field, its keys, ``build()``."""

_REGISTRY: dict[str, type[_Input]] = {}
_CALIBRATED: dict[str, str] = {}
_BUILT = False  # True once the union below exists: a later registration rebuilds it


def register_resistance(cls: type[_Input] | None = None, *, calibrate: str | None = None):
    """Class decorator: register a ``[target.resistance]`` input under the name of its ``model`` literal.

    The case schema (``[target.resistance]`` and ``[[target.layers]]`` resistance), the list of
    models in error messages (:data:`MODELS`) and ``calibrate``'s default parameter (``calibrate``:
    the key calibrated when the case names none; None: the model has no default) all read this
    registration.  Registering after import rebuilds the schemas that hold the union.
    """
    def decorate(cls: type[_Input]) -> type[_Input]:
        names = allowed_values(cls.model_fields["model"].annotation)
        if len(names) != 1:
            raise TypeError(f"{cls.__name__}.model must be one Literal name; got {names}")
        _REGISTRY[names[0]] = cls
        _CALIBRATED.pop(names[0], None)
        if calibrate is not None:
            _CALIBRATED[names[0]] = calibrate
        MODELS[:] = list(_REGISTRY)
        if _BUILT:
            _refresh()
        return cls

    return decorate if cls is None else decorate(cls)


def unregister_resistance(name: str) -> None:
    """Remove a registered model (a test's clean-up); the schemas are rebuilt without it."""
    del _REGISTRY[name]
    _CALIBRATED.pop(name, None)
    MODELS[:] = list(_REGISTRY)
    _refresh()


def resistance_inputs() -> dict[str, type[_Input]]:
    """The registered inputs by model name, in registration order."""
    return dict(_REGISTRY)


def calibrated_parameter(model: str) -> str | None:
    """The ``[target.resistance]`` key ``calibrate`` fits by default for ``model`` (None: none)."""
    return _CALIBRATED.get(model)


def _nu(v):
    if not (-1.0 < v < 0.5):
        raise ValueError(f"must lie in (-1, 0.5); got {v!r}")
    return v


@register_resistance(calibrate='yield_stress')
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


@register_resistance(calibrate='compressive_strength')
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


@register_resistance(calibrate='yield_stress')
class HardeningInput(_Input):
    model: Literal["hardening"]
    yield_stress: Pressure
    youngs_modulus: Pressure
    hardening_exponent: float = Field(ge=0.0, lt=1.0, description="n of the power law, 0 <= n < 1")

    def build(self) -> Hardening:
        if not self.youngs_modulus > 1.5 * self.yield_stress:
            raise InputError("target.resistance.youngs_modulus", "eq. (18) needs E > 3Y/2")
        return Hardening(self.yield_stress, self.youngs_modulus, self.hardening_exponent)


@register_resistance(calibrate='psi')
class LimestoneInput(_Input):
    model: Literal["limestone"]
    psi: NonNegativePressure = 607e6
    phi: NonNegativePressure = 86e6
    reference_diameter: Length = 25.4e-3

    def build(self) -> Limestone:
        return Limestone(self.psi, self.phi, self.reference_diameter)


@register_resistance(calibrate='yield_stress')
class Part4Input(_Input):
    model: Literal["part4"]
    yield_stress: Pressure
    youngs_modulus: Pressure

    def build(self) -> Part4:
        if not self.youngs_modulus > 1.5 * self.yield_stress:
            raise InputError("target.resistance.youngs_modulus", "Part IV, eq. (6) needs E > 3Y/2")
        return Part4(self.yield_stress, self.youngs_modulus)


@register_resistance
class CavityInput(_Input):
    model: Literal["cavity"]
    youngs_modulus: Pressure
    poisson_ratio: float
    tensile_strength: Pressure
    compressive_strength: Pressure
    bulk_modulus: Pressure | None = None
    initial_porosity: float = Field(default=0.0, ge=0.0, lt=1.0)
    _check_nu = field_validator("poisson_ratio")(_nu)

    @model_validator(mode="after")
    def _consistent(self):
        from semianalytic.schema import check_brittle_constants

        check_brittle_constants("target.resistance", self.youngs_modulus, self.poisson_ratio, self.tensile_strength,
                                self.compressive_strength, self.bulk_modulus)
        return self

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


@register_resistance(calibrate='value')
class ConstantInput(_Input):
    model: Literal["constant"]
    value: Pressure

    def build(self) -> Constant:
        return Constant(self.value)


def _union():
    members = tuple(_REGISTRY.values())
    return Annotated[Union[members] if len(members) > 1 else members[0], Field(discriminator="model")]  # noqa: UP007 (a tuple)


def _builds(spec):
    """Case-load check: the inputs must give a model (e.g. eq. (16)'s logarithm positive)."""
    try:
        spec.build()
    except (InputError, ModelError) as exc:  # the model's input name: its last part is the key
        raise ValueError(f"{exc.field.rsplit('.', 1)[-1]}: {exc.message}") from None
    return spec


def _refresh() -> None:
    """The union over the registered inputs, and every section model holding it rebuilt on it."""
    global ResistanceSpec, ResistanceField, _ADAPTER
    old = ResistanceField
    ResistanceSpec = _union()
    ResistanceField = Annotated[ResistanceSpec, AfterValidator(_builds)]
    _ADAPTER = TypeAdapter(ResistanceSpec)
    _rebuild_holders(old, ResistanceField)


def _rebuild_holders(old, new) -> None:
    """Point every project model field annotated with ``old`` (optionally ``| None``) at ``new``,
    then rebuild those models and every project model that holds one of them."""
    from pydantic.fields import FieldInfo

    from semianalytic.schema import _models_in

    def subclasses(c):
        for s in c.__subclasses__():
            yield s
            yield from subclasses(s)

    models = [c for c in subclasses(BaseModel) if c.__module__.startswith("semianalytic")]
    changed = []
    for c in models:
        for name, f in list(c.__pydantic_fields__.items()):
            args = typing.get_args(f.annotation)
            if f.annotation is old or old in args:
                ann = new if f.annotation is old else new | None
                info = FieldInfo.from_annotated_attribute(ann, f.default)
                info.description = f.description
                c.__pydantic_fields__[name] = info
                changed.append(c)
    done: list = []
    while changed:
        c = changed.pop(0)
        if c in done:
            continue
        c.model_rebuild(force=True)
        done.append(c)
        changed += [h for h in models if h not in done and any(
            m in done for f in h.__pydantic_fields__.values() for m in _models_in(f.annotation))]


ResistanceSpec = _union()
"""The ``[target.resistance]`` table (a pydantic discriminated union on ``model`` over the registered inputs)."""
ResistanceField = Annotated[ResistanceSpec, AfterValidator(_builds)]
"""The annotation of ``TargetSection.resistance`` in :mod:`semianalytic.case`."""

_ADAPTER = TypeAdapter(ResistanceSpec)
_BUILT = True


def _message(err: dict) -> str:
    if err.get("type") in ("union_tag_invalid", "union_tag_not_found"):
        inp = err.get("input")
        got = f"; got {inp.get('model')!r}" if isinstance(inp, dict) and "model" in inp else ""
        return f"'model' must be one of {', '.join(MODELS)}{got}"
    return pydantic_message(err)


def parse_resistance(data: Any, field: str = "target.resistance") -> Resistance:
    """Validate a ``[target.resistance]`` table and build its model (SI).

    Raises :class:`InputError` naming the field (``target.resistance.yield_stress``) and what
    was expected.  An already-parsed input model is accepted too.
    """
    if isinstance(data, tuple(_REGISTRY.values())):
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
    except ModelError as exc:  # the cavity model's input names -> the keys of the case (InputError, as documented)
        raise InputError(case_key(exc.field, CAVITY_FIELDS), exc.message) from None
    except InputError as exc:
        raise InputError(exc.field.replace("target.resistance", field, 1), exc.message) from None

