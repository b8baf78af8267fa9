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

__all__ = ["BallisticLimitSection", "ShotSection", "LayerSection", "SHOT_RANGES", "check_shot", "check_limits"]

# Plausible ranges of the Part IV inputs (this project's own limits, with their reasons; far wider
# than Part IV's Tables 2-3, which hold L_p 12-52 mm, m_p 2.3-7.9 g, delta_H 0.35-0.93 and
# ballistic limits of 280-916 m/s).  Outside: exit status 2 naming the field and the range.
SHOT_RANGES: dict[str, tuple[float, float, str, str]] = {
    "projectile_length": (1e-4, 3.0, "m", "0.1 mm (a fragment) to 3 m (three times the longest kinetic-energy "
                                          "penetrator)"),
    "projectile_diameter": (1e-4, 0.5, "m", "0.1 mm (a fragment) to 0.5 m (a naval shell)"),
    "projectile_mass": (1e-6, 1e3, "kg", "1 mg (a fragment) to 1000 kg (a bunker-buster's penetrator)"),
    "delta_h": (0.1, 1.0, "", "0.1 to 1 (Milman's plasticity characteristic: Part IV, Table 1 spans 0.35 for "
                              "ceramics to 0.93 for metals; no solid is known below 0.1)"),
    "measured": (1.0, 12e3, "m/s", "1 m/s (slower than a dropped projectile: not a ballistic test) to 12 km/s "
                                   "(beyond every model, as for striking velocities)"),
}
# alpha = rho_t h_t / (rho_p L_p) of eq. (5): V_cr grows like exp(alpha/2).  Part IV's plates have
# alpha <= 0.8; at alpha = 10 a rigid rod would need V_cr ~ 150 a (several km/s for any metal), beyond the
# rigid-projectile model of eq. (2) (the rod erodes above ~1.5 km/s): refused above, with the reason.
MAX_ALPHA = 10.0
MAX_BALLISTIC_LIMIT = 12e3  # m/s: a computed V_cr above the striking velocities' bound is refused


def _range_problem(key: str, value) -> str | None:
    bounds = SHOT_RANGES.get("delta_h" if key.endswith("delta_h") or key.endswith("delta_H") else key)
    if value is None or bounds is None:
        return None
    low, high, unit, why = bounds
    if low <= value <= high:
        return None
    return f"{value:.4g}{' ' + unit if unit else ''} lies outside the plausible range {why}"


def _check_range(key: str):
    def validate(v):
        problem = _range_problem(key, v)
        if problem:
            raise ValueError(problem)
        return v

    return validate


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

    @field_validator("delta_h")
    @classmethod
    def _delta_h(cls, v):
        return _check_range("delta_h")(v)

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

    @field_validator("projectile_length", "projectile_diameter", "projectile_mass", "projectile_delta_h",
                     "target_delta_h", "measured")
    @classmethod
    def _plausible_shot(cls, v, info):
        return _check_range(info.field_name)(v)

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


_SHOT_FIELDS = {"projectile_length": "projectile_length", "projectile_diameter": "projectile_diameter",
                "projectile_mass": "projectile_mass", "projectile_delta_H": "projectile_delta_h",
                "target_delta_H": "target_delta_h", "measured": "measured"}


def check_shot(shot: Shot, field: str, row: str = "") -> None:
    """Refuse a shot (of a table file: ``field`` is ``ballistic_limit.table``, ``row`` names the
    shot) whose inputs leave :data:`SHOT_RANGES` or whose plate is beyond eq. (5)'s reach
    (:data:`MAX_ALPHA`); an inline shot's fields are checked by :class:`ShotSection`."""
    from semianalytic.errors import InputError

    where = f"{row}: " if row else ""
    for attr, key in _SHOT_FIELDS.items():
        problem = _range_problem(key, getattr(shot, attr))
        if problem:
            raise InputError(field if row else f"{field}.{key}", f"{where}{key} {problem}")
    for k, layer in enumerate(shot.layers):
        problem = _range_problem("delta_h", layer.delta_H)
        if problem:
            raise InputError(field if row else f"{field}.layers.{k}.delta_h", f"{where}delta_h {problem}")
    plates = [(layer.density, layer.thickness, f"layers.{k}.thickness") for k, layer in enumerate(shot.layers)] or [
        (shot.target_density, shot.thickness, "thickness")]
    rho_p, L_p = shot.projectile_density, shot.projectile_length
    alpha = sum(rho * h for rho, h, _ in plates if rho and h) / (rho_p * L_p) if rho_p and L_p else 0.0
    if alpha > MAX_ALPHA:
        key = plates[-1][2] if len(plates) == 1 else "layers"
        raise InputError(field if row else f"{field}.{key}",
                         f"{where}the plate's areal mass is alpha = rho_t h_t/(rho_p L_p) = {alpha:.3g} times the "
                         f"projectile's, above {MAX_ALPHA:g}: eq. (5) grows like exp(alpha/2) (Part IV's plates have "
                         "alpha <= 0.8), so no rigid projectile perforates this plate; give a thinner plate or a "
                         "longer projectile")


def check_limits(row: dict, field: str) -> None:
    """Refuse a shot whose computed ballistic limit (any law) exceeds :data:`MAX_BALLISTIC_LIMIT`:
    the inputs are beyond every model (the field named is the plate's thickness)."""
    import math

    from semianalytic.errors import InputError

    for key, value in row.items():
        if key.startswith("V_") and isinstance(value, float) and math.isfinite(value) and value > MAX_BALLISTIC_LIMIT:
            raise InputError(field, f"{row['name']}: the ballistic limit {key} = {value:.3g} m/s exceeds "
                                    f"{MAX_BALLISTIC_LIMIT / 1e3:g} km/s, beyond every model (the projectile would "
                                    "melt): the plate is too thick or too hard for this projectile")
