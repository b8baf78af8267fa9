"""``[ballistic_limit]`` case section (Part IV): shots from a table file and/or listed inline.

```toml
[ballistic_limit]
table = "part4_table3.csv"          # optional: a shot table, relative to the case file
hardness = "meyer"                  # R(1) = HM delta_H with HM = HV/sin 68 deg ("vickers": HM = HV)
areal_mass = "mass-per-area"        # P of eqs. (7)-(9): m/(pi d^2/4) (errata 26) or "cylinder" (rho_p L_p)
projectile_density = "7.8 g/cm^3"   # default for shots that do not give one
C1 = "1.52e6 m^2/s^2"               # optional; default: the paper's constants
C2 = "0.79e6 m^2/s^2/GPa"           # (m/s)^2 per GPa of (HV delta_H)_t (errata 26)
C3 = "1.69e6 m^2/s^2"
critical_velocities = ["700 m/s"]   # optional: Table 4 style critical areal density/thickness

[[ballistic_limit.shots]]
name = "6112, 8 mm"
target_density = "2.7 g/cm^3"
thickness = "8 mm"
target_hardness = "0.84 GPa"        # HV_t
target_delta_h = 0.92
yield_stress = "0.26 GPa"           # optional, with youngs_modulus: R(3) of eq. (6)
youngs_modulus = "71 GPa"
projectile_length = "26 mm"
projectile_diameter = "7.62 mm"
projectile_mass = "7.9 g"
projectile_hardness = "1.6 GPa"     # HV_p
projectile_delta_h = 0.93
measured = "323 m/s"                # optional
```
A composite target lists ``[[ballistic_limit.shots.layers]]`` (name, density, thickness,
hardness, delta_h) instead of the target fields.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BeforeValidator, Field, field_validator, model_validator

from semianalytic.ballistic_limit.empirical import PAPER_CONSTANTS, EmpiricalConstants
from semianalytic.ballistic_limit.shots import PAPER_PROJECTILE_DENSITY, Layer, Shot
from semianalytic.schema import Section
from semianalytic.units import Density, Length, Mass, Pressure, Velocity, registry

__all__ = ["BallisticLimitSection", "ShotSection", "LayerSection"]


def _constant(unit: str, example: str):
    """Pydantic type for an empirical constant given with a unit, converted to ``unit`` (SI)."""

    def validate(value: Any) -> float:
        if not isinstance(value, str):
            raise ValueError(f"expected a quantity with a unit, e.g. '{example}'; got {value!r}")
        ureg = registry()
        try:
            q = ureg.Quantity(value.strip())
            out = float(q.to(unit).magnitude)
        except Exception:
            raise ValueError(f"expected a quantity convertible to {unit}, e.g. '{example}'; got {value!r}") from None
        if not out > 0:
            raise ValueError(f"must be positive; got {value!r}")
        return out

    return Annotated[float, BeforeValidator(validate)]


C13 = _constant("m**2/s**2", "1.52e6 m^2/s^2")
C2Type = _constant("m**3/kg", "0.79e6 m^2/s^2/GPa")
Fraction = Annotated[float, Field(gt=0.0, le=1.0)]


class LayerSection(Section):
    """One plate of a composite target."""

    name: str
    density: Density
    thickness: Length
    hardness: Pressure
    delta_h: Fraction

    def to_layer(self) -> Layer:
        return Layer(self.name, self.density, self.thickness, self.hardness, self.delta_h)


class ShotSection(Section):
    """One shot: a plate target (or ``layers``) and a projectile, with units."""

    name: str
    projectile_length: Length
    projectile_density: Density | None = None
    projectile_diameter: Length | None = None
    projectile_mass: Mass | None = None
    projectile_hardness: Pressure | None = None
    projectile_delta_h: Fraction | None = None
    target_density: Density | None = None
    thickness: Length | None = None
    target_hardness: Pressure | None = None
    target_delta_h: Fraction | None = None
    yield_stress: Pressure | None = None
    youngs_modulus: Pressure | None = None
    resistance: Pressure | None = Field(default=None, description="R(3) given directly instead of Y and E")
    measured: Velocity | None = None
    layers: list[LayerSection] | None = None

    @model_validator(mode="after")
    def _target(self):
        plate = (self.target_density, self.thickness)
        if self.layers:
            if any(v is not None for v in (*plate, self.target_hardness, self.target_delta_h)):
                raise ValueError("give either 'layers' or the single-plate target fields, not both")
        elif None in plate:
            raise ValueError("a shot needs 'target_density' and 'thickness' (or 'layers')")
        if (self.yield_stress is None) != (self.youngs_modulus is None):
            raise ValueError("'yield_stress' and 'youngs_modulus' go together (R(3) of Part IV eq. 6)")
        return self

    def to_shot(self, default_density: float) -> Shot:
        return Shot(
            name=self.name,
            projectile_length=self.projectile_length,
            projectile_density=self.projectile_density or default_density,
            target_density=self.target_density,
            thickness=self.thickness,
            target_hardness=self.target_hardness,
            target_delta_H=self.target_delta_h,
            yield_stress=self.yield_stress,
            youngs_modulus=self.youngs_modulus,
            resistance_R3=self.resistance,
            projectile_diameter=self.projectile_diameter,
            projectile_mass=self.projectile_mass,
            projectile_hardness=self.projectile_hardness,
            projectile_delta_H=self.projectile_delta_h,
            measured=self.measured,
            layers=tuple(l.to_layer() for l in self.layers or ()),
        )


class BallisticLimitSection(Section):
    """``[ballistic_limit]``: options and shots for ``python -m semianalytic ballistic-limit``."""

    table: str | None = None
    shots: list[ShotSection] = Field(default_factory=list)
    hardness: Literal["meyer", "vickers"] = "meyer"
    areal_mass: Literal["mass-per-area", "cylinder"] = "mass-per-area"
    projectile_density: Density = PAPER_PROJECTILE_DENSITY
    C1: C13 = PAPER_CONSTANTS.C1
    C2: C2Type = PAPER_CONSTANTS.C2
    C3: C13 = PAPER_CONSTANTS.C3
    critical_velocities: list[Velocity] = Field(default_factory=list)

    @field_validator("table")
    @classmethod
    def _table(cls, v):
        if v is not None and not v.strip():
            raise ValueError("must name a CSV file")
        return v

    @model_validator(mode="after")
    def _some_shots(self):
        if self.table is None and not self.shots:
            raise ValueError("give a 'table' file or at least one [[ballistic_limit.shots]]")
        return self

    @property
    def constants(self) -> EmpiricalConstants:
        return EmpiricalConstants(self.C1, self.C2, self.C3)
