"""Case files: TOML in, validated frozen sections out.

A case describes either a body of revolution in unbounded fluid (``[body]``) or a
projectile penetrating a half-space target (``[projectile]``, ``[target]``, ``[impact]``),
plus whatever the other analyses need (cavity material, ballistic-limit tables, ...).
Quantities are unit strings (see :mod:`semianalytic.units`).  Every section rejects unknown
keys; any error becomes one :class:`~semianalytic.errors.InputError` naming the field
(``projectile.diameter``), the value and what was expected.

Sections owned by other analyses register themselves in :data:`SECTIONS` as
``"module:Model"``; they are imported only when a case uses them.
"""

from __future__ import annotations

import importlib
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, Field, field_validator, model_validator

from semianalytic.errors import InputError
from semianalytic.geometry import NOSE_KINDS
from semianalytic.schema import Section, validate_section
from semianalytic.schema import pydantic_message as _pydantic_message  # noqa: F401 (old name)
from semianalytic.sections.penetration import ResistanceField
from semianalytic.sections.perforation import TargetLayerSection, check_target_layers
from semianalytic.sections.resistances import load_all as _load_added_resistances
from semianalytic.units import Angle, Density, Length, Mass, NonNegativeLength, Pressure, Velocity

__all__ = [
    "Section",
    "BodySection",
    "ProjectileSection",
    "TargetSection",
    "ImpactSection",
    "BemSection",
    "CoefficientsSection",
    "Case",
    "load_case",
    "parse_case",
    "validate_section",
    "SECTIONS",
]


LengthUnit = Literal["m", "cm", "mm", "um"]
_UNIT_SCALE = {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "um": 1e-6}
MAX_DYNAMIC_FACTOR = 5.0  # projectile.dynamic_factor: above it no metal's rate sensitivity (issue 40)


class BodySection(Section):
    """``[body]``: a closed body of revolution in unbounded fluid.

    sphere: ``diameter``; spheroid (prolate or oblate), cylinder (flat-ended) and double_cone
    (two cones base to base): ``length`` along the axis and ``diameter``; table: ``points = [[x, r], ...]`` in ``points_unit``, a meridian from one
    axis point (r = 0) to the other.
    """  # noqa: E501

    shape: Literal["sphere", "spheroid", "table", "cylinder", "double_cone"]
    length: Length | None = None
    diameter: Length | None = None
    points: list[tuple[float, float]] | None = None
    points_unit: LengthUnit | None = None
    exponent: float | None = Field(default=None, description="power nose: r = (d/2) (x/L_h)^n, n in (0, 1]")
    nose_length: Length | None = Field(default=None, description="power nose: nose length L_h")
    control_radii: list[float] | None = Field(
        default=None, description="spline nose: control radii at m equally spaced stations k L_h/(m+1), fractions of d/2 in (0, 1]")

    @model_validator(mode="after")
    def _complete(self):
        if self.shape == "sphere":
            if self.diameter is None:
                raise ValueError("a sphere needs 'diameter' (e.g. '1 m')")
            if self.length is not None and not math.isclose(self.length, self.diameter, rel_tol=1e-12):
                raise ValueError("a sphere's 'length' must equal its 'diameter' (or be left out)")
        elif self.shape in ("spheroid", "cylinder", "double_cone"):
            if self.diameter is None or self.length is None:
                raise ValueError(f"a {self.shape.replace('_', ' ')} needs 'length' (along the axis) and 'diameter'")
        else:
            if not self.points or self.points_unit is None:
                raise ValueError("a table body needs 'points' = [[x, r], ...] and 'points_unit'")
        return self

    def points_si(self) -> list[tuple[float, float]]:
        s = _UNIT_SCALE[self.points_unit or "m"]
        return [(x * s, r * s) for x, r in (self.points or [])]


class ProjectileSection(Section):
    """``[projectile]``: nose shape, shank and material of a penetrator.

    ``nose``: ogive (needs ``crh``, psi = s/d), sphere (hemispherical), cone (needs
    ``half_angle``), flat (optional ``corner_radius``) or table (``points = [[x, r], ...]``
    in ``points_unit``, x measured back from the tip, from (0, 0) to the shoulder at r = d/2).
    Ogive and cone take an optional ``meplat_diameter`` (flat tip: truncated nose) or
    ``tip_radius`` (spherically blunted tip); a key a nose kind has no use for is an error.
    power: r = (d/2) (x/L_h)^n from the tip, ``exponent`` n in (0, 1] and ``nose_length`` L_h.
    spline: ``control_radii`` = [c_1, .., c_m] (fractions of d/2, dimensionless, in (0, 1]) of the
    control points at m equally spaced stations k L_h / (m + 1) along ``nose_length`` L_h, between
    the tip and the shoulder: a Bezier curve, increasing, with non-increasing increments
    (monotone and convex; geometry.spline_nose).
    ``shank_length`` is the cylindrical part: total length = shank + nose.
    """

    nose: Literal[tuple(NOSE_KINDS)]  # the registered kinds (semianalytic.geometry.register_nose)
    diameter: Length
    shank_length: NonNegativeLength | None = None
    length: Length | None = Field(default=None, description="total length L = shank + nose (instead of shank_length)")
    density: Density | None = None
    mass: Mass | None = None
    crh: float | None = Field(default=None, description="ogive caliber radius head psi = s/d")
    half_angle: Angle | None = None
    corner_radius: NonNegativeLength | None = None
    meplat_diameter: NonNegativeLength | None = Field(default=None, description="ogive/cone: flat tip of this diameter (truncated nose)")
    tip_radius: NonNegativeLength | None = Field(default=None, description="ogive/cone: spherically blunted tip of this radius")
    points: list[tuple[float, float]] | None = None
    points_unit: LengthUnit | None = None
    exponent: float | None = Field(default=None, description="power nose: r = (d/2) (x/L_h)^n, n in (0, 1]")
    nose_length: Length | None = Field(default=None, description="power nose: nose length L_h")
    control_radii: list[float] | None = Field(
        default=None, description="spline nose: control radii at m equally spaced stations k L_h/(m+1), fractions of d/2 in (0, 1]")
    # material (Part I, section 2: elastic projectile and critical velocity)
    youngs_modulus: Pressure | None = None
    poisson_ratio: float | None = None
    yield_stress: Pressure | None = None
    dynamic_yield_stress: Pressure | None = None  # Y_p of the eroding rod (Alekseevskii-Tate); default: yield_stress
    # instead of yield_stress: Rockwell C hardness ("39.5 HRC") times dynamic_factor (penetration/hardness.py)
    hardness: str | None = None
    dynamic_factor: float | None = None
    buckling: Literal["none", "johnson-euler", "table"] = "none"
    buckling_table: list[tuple[float, float]] | None = None

    @model_validator(mode="before")
    @classmethod
    def _hardness(cls, data):
        """``hardness`` -> ``yield_stress`` = dynamic_factor x the static yield stress of that
        hardness (semianalytic.penetration.hardness: ASTM E140 + Pavlina & Van Tyne 2008)."""
        if isinstance(data, dict) and ("hardness" in data or "dynamic_factor" in data):
            from semianalytic.penetration.hardness import DEFAULT_DYNAMIC_FACTOR, dynamic_yield_stress, parse_hardness

            if "hardness" not in data:
                raise InputError("projectile.dynamic_factor", "only with projectile.hardness (it multiplies the static "
                                                              "yield stress of the hardness); remove it or give hardness")
            if "yield_stress" in data:
                raise InputError("projectile.hardness", "give hardness or yield_stress, not both")
            f = data.get("dynamic_factor", DEFAULT_DYNAMIC_FACTOR)
            if isinstance(f, bool) or not isinstance(f, (int, float)):
                raise InputError("projectile.dynamic_factor", f"must be a number >= 1 (dimensionless); got {f!r}")
            if not 1.0 <= float(f) <= MAX_DYNAMIC_FACTOR:  # the key the user wrote, not the yield_stress it makes
                raise InputError("projectile.dynamic_factor", f"must lie in [1, {MAX_DYNAMIC_FACTOR:g}] (dynamic / static "
                                 "yield stress: the regimes calibration finds 1.40-1.53 with a prior of 1-3, "
                                 f"reports/validation_regimes.md; above 5 is no metal's rate sensitivity); got {f!r}")
            data = dict(data, yield_stress=f"{float(dynamic_yield_stress(parse_hardness(data['hardness']), float(f))):.9g} Pa")
        return data

    @field_validator("exponent")
    @classmethod
    def _exponent(cls, v):
        if v is not None and not (math.isfinite(v) and 0.0 < v <= 1.0):
            raise ValueError(f"must lie in (0, 1] (r = (d/2) (x/L_h)^n); got {v!r}")
        return v

    @field_validator("poisson_ratio")
    @classmethod
    def _nu(cls, v):
        if v is not None and not (-1.0 < v < 0.5):
            raise ValueError(f"must lie in (-1, 0.5); got {v!r}")
        return v

    @model_validator(mode="after")
    def _complete(self):
        if self.nose == "ogive":
            if self.crh is None:
                raise ValueError("an ogive nose needs 'crh' (caliber radius head psi = s/d, >= 0.5)")
            if not self.crh >= 0.5:
                raise ValueError(f"'crh' must be >= 0.5 for a tangent ogive; got {self.crh!r}")
        if self.nose == "cone":
            if self.half_angle is None:
                raise ValueError("a conical nose needs 'half_angle' (e.g. '30 deg')")
            if not self.half_angle < math.pi / 2:
                raise ValueError("'half_angle' must be below 90 deg")
        if self.nose == "flat" and self.corner_radius is not None:
            if not self.corner_radius <= self.diameter / 2:
                raise ValueError("'corner_radius' must not exceed half the diameter")
        if self.nose == "table" and (not self.points or self.points_unit is None):
            raise ValueError("a table nose needs 'points' = [[x, r], ...] and 'points_unit'")
        if self.shank_length is None and self.length is None:
            raise ValueError("give 'shank_length' (the cylindrical part) or 'length' (the total length)")
        return self

    def check_geometry(self) -> None:
        """Build the nose (rejecting impossible shapes with the field at fault) and check
        the lengths against it.  Raises ``InputError``."""
        from semianalytic.geometry import nose_from_section

        keys = dict.fromkeys(k for kind in NOSE_KINDS.values() for k in kind.keys)
        uses = {key: tuple(n for n, kind in NOSE_KINDS.items() if key in kind.keys) for key in keys}
        for key, kinds in uses.items():
            if getattr(self, key) is not None and self.nose not in kinds:
                raise InputError(f"projectile.{key}", f"has no use for the '{self.nose}' nose (only for: {', '.join(kinds)}); remove it")
        if self.nose == "power":
            for key, example in (("exponent", "0.6"), ("nose_length", "'11.8 mm'")):
                if getattr(self, key) is None:
                    raise InputError(f"projectile.{key}", f"a power nose r = (d/2) (x/L_h)^n needs it, e.g. {key} = {example}")
        if self.nose == "spline":
            for key, example in (("control_radii", "[0.45, 0.75, 0.92] (fractions of d/2)"), ("nose_length", "'11.8 mm'")):
                if getattr(self, key) is None:
                    raise InputError(f"projectile.{key}", f"a spline nose needs it, e.g. {key} = {example}")
        nose = nose_from_section(self)
        if self.length is not None:
            shank = self.length - nose.length
            if shank < -1e-12 * self.length:
                raise InputError(
                    "projectile.length",
                    f"the nose (L_h = {nose.length * 1e3:.4g} mm) is longer than the body (length = {self.length * 1e3:.4g} mm)",
                )
            if self.shank_length is not None and abs(self.shank_length - shank) > 1e-6 * self.length:
                raise InputError(
                    "projectile.length",
                    f"{self.length * 1e3:.4g} mm differs from shank_length + nose length "
                    f"({(self.shank_length + nose.length) * 1e3:.4g} mm); give one of them",
                )

    @property
    def shank(self) -> float:
        """The cylindrical length L_c [m] (from 'shank_length' or 'length' minus the nose)."""
        if self.shank_length is not None:
            return self.shank_length
        from semianalytic.geometry import nose_from_section

        return max(self.length - nose_from_section(self).length, 0.0)

    def points_si(self) -> list[tuple[float, float]]:
        s = _UNIT_SCALE[self.points_unit or "m"]
        return [(x * s, r * s) for x, r in (self.points or [])]


class TargetSection(Section):
    """``[target]``: the half-space target, or a plate (``thickness``) or layered target
    (``[[target.layers]]``, :mod:`semianalytic.sections.perforation`).  ``resistance``: the schema of
    :mod:`semianalytic.sections.penetration` (a discriminated union on ``model``)."""

    density: Density
    resistance: ResistanceField | None = None
    thickness: Length | None = None  # a plate (issue 23); absent: the half-space
    layers: list[TargetLayerSection] | None = None  # a layered target (issue 23)

    @model_validator(mode="after")
    def _plate(self):
        check_target_layers(self.thickness, self.layers)
        return self


from semianalytic.limits import MAX_STRIKING_VELOCITY, MIN_STRIKING_VELOCITY, SOLID_STRIKING_VELOCITY  # noqa: E402,F401


class ImpactSection(Section):
    """``[impact]``: striking velocities U_s (each > 0)."""

    striking_velocities: list[Velocity] = Field(min_length=1)

    @field_validator("striking_velocities")
    @classmethod
    def _physical(cls, v):
        for k, u in enumerate(v):
            if u > MAX_STRIKING_VELOCITY:
                raise ValueError(
                    f"item {k}: {u / 1e3:.4g} km/s is above {MAX_STRIKING_VELOCITY / 1e3:.0f} km/s, faster than any "
                    "launcher (two-stage light-gas guns reach ~10 km/s) and far past every model here (intact projectile)"
                )
            if u < MIN_STRIKING_VELOCITY:
                raise ValueError(
                    f"item {k}: {u:.3g} m/s is below {MIN_STRIKING_VELOCITY * 1e3:g} mm/s: a quasi-static indentation, "
                    "not an impact (the penetration models are dynamic)"
                )
        fast = [u for u in v if u > SOLID_STRIKING_VELOCITY]
        if fast:
            import warnings

            from semianalytic.errors import ModelValidityWarning

            warnings.warn(
                f"impact.striking_velocities: {max(fast) / 1e3:.4g} km/s is above {SOLID_STRIKING_VELOCITY / 1e3:g} km/s, "
                "beyond the reach of every model here: they assume a solid projectile, which melts or vaporises "
                "at these shock pressures (> ~100 GPa)", ModelValidityWarning, stacklevel=2)
        return v


class BemSection(Section):
    """``[bem]``: numerical options of the boundary-element solver (all optional)."""

    order: int = Field(default=8, ge=2, le=16, description="Gauss points (unknowns) per panel")
    refinement: float | None = Field(
        default=None, gt=0.0, le=8.0, description="panel-count multiplier (default: 1 for bodies, 0.3 for tables)"
    )


class CoefficientsSection(Section):
    """``[coefficients]``: the A(P), B(P), C(P) table (all optional)."""

    depths: int | None = Field(default=None, ge=8, le=2000)  # a fixed grid instead of the adaptive knots
    max_depth_nose_lengths: float = Field(default=300.0, gt=1.0)
    reading: Literal["body", "literal", "bernoulli"] = "body"
    tolerance: float = Field(default=1e-5, gt=0.0, lt=0.1, description="relative interpolation error of the table")
    contact: Literal["full", "separated"] = Field(default="full", description="contact region of eq. (15) in eq. (11)")


# Other analyses' sections: name -> "module:Model" (imported only when used).
SECTIONS: dict[str, str] = {
    "material": "semianalytic.sections.cavity:MaterialSection",
    "ballistic_limit": "semianalytic.sections.ballistic_limit:BallisticLimitSection",
    "nanostrength": "semianalytic.sections.nanostrength:NanostrengthSection",
    "data": "semianalytic.sections.penetration:DataSection",
    "run": "semianalytic.run.case:RunSection",
    "calibration": "semianalytic.sections.calibration:CalibrationSection",
    "perforation": "semianalytic.sections.perforation:PerforationSection",
    "regimes": "semianalytic.sections.regimes:RegimesSection",
}

_CORE = {
    "body": BodySection,
    "projectile": ProjectileSection,
    "target": TargetSection,
    "impact": ImpactSection,
    "bem": BemSection,
    "coefficients": CoefficientsSection,
}
_META_KEYS = {"title", "description", "reproduces", "source"}


@dataclass(frozen=True)
class Case:
    """A validated case file.  Absent sections are ``None`` (``bem`` and ``coefficients``
    always hold their defaults)."""

    path: Path | None
    title: str
    reproduces: str
    body: BodySection | None = None
    projectile: ProjectileSection | None = None
    target: TargetSection | None = None
    impact: ImpactSection | None = None
    bem: BemSection = field(default_factory=BemSection)
    coefficients: CoefficientsSection = field(default_factory=CoefficientsSection)
    sections: Mapping[str, Section] = field(default_factory=dict)
    raw: Mapping[str, Any] = field(default_factory=dict, repr=False)

    @property
    def geometry(self):
        """The projectile's derived geometry (:class:`semianalytic.geometry.ProjectileGeometry`:
        ``nose_length_m``, ``length_m``, ``length_over_diameter``, ``volume_m3``, ``mass_kg``)."""
        from semianalytic.geometry import derived_geometry

        return derived_geometry(self.require("projectile"))

    def with_raw(self, raw: Mapping[str, Any]) -> Case:
        """Another case parsed (and validated) from ``raw``, a changed copy of :attr:`raw`; it has
        no path (relative file references are not resolved)."""
        return parse_case(raw, None)

    def section(self, name: str) -> Any:
        """Any section by name (core or registered); ``None`` if the case has none."""
        if name in _CORE:
            return getattr(self, name)
        return self.sections.get(name)

    def require(self, name: str) -> Any:
        """The section ``name``, or an ``InputError`` saying the case lacks it."""
        out = self.section(name)
        if out is None:
            raise InputError(name, f"the case has no [{name}] section, which this analysis needs")
        return out


def _section_model(name: str) -> type[BaseModel]:
    if name in _CORE:
        return _CORE[name]
    module, _, attr = SECTIONS[name].partition(":")
    model: type[BaseModel] = getattr(importlib.import_module(module), attr)  # a broken import is a bug: exit 1
    return model


def parse_case(data: Mapping[str, Any], path: Path | None = None) -> Case:
    """Validate a case given as a dict (the parsed TOML)."""
    from semianalytic.schema import check_tree

    check_tree(data)
    unknown = [k for k in data if k not in _CORE and k not in SECTIONS and k not in _META_KEYS]
    if unknown:
        known = ", ".join(sorted([*_CORE, *SECTIONS]))
        from semianalytic.schema import did_you_mean

        hint = did_you_mean(unknown[0], [*_CORE, *SECTIONS, *_META_KEYS])
        raise InputError(unknown[0], f"unknown section or key{hint} (known sections: {known})")
    for key in _META_KEYS:
        if key in data and not isinstance(data[key], str):
            raise InputError(key, "must be a string")
    core = {name: validate_section(name, model, data[name]) for name, model in _CORE.items() if name in data}
    extra = {name: validate_section(name, _section_model(name), data[name]) for name in SECTIONS if name in data}
    if "body" in core and "projectile" in core:
        raise InputError("body", "a case is either a [body] in unbounded fluid or a [projectile] in a target, not both")
    if "projectile" in core and "target" not in core:
        raise InputError("target", "a [projectile] case needs a [target] section with 'density'")
    if "projectile" in core:
        core["projectile"].check_geometry()
    if "body" in core:
        from semianalytic.geometry import body_from_section

        body_from_section(core["body"])  # rejects impossible tables with the field at fault
    return Case(
        path=path,
        title=str(data.get("title", path.stem if path else "case")),
        reproduces=str(data.get("reproduces", "")),
        sections=extra,
        raw=dict(data),
        **core,
    )


def load_case(path: str | Path) -> Case:
    """Read and validate a TOML case file.  Raises ``InputError`` (exit status 2)."""
    from semianalytic.bundled import resolve_path
    from semianalytic.schema import read_toml_text

    path = Path(resolve_path(path))  # `cases/X.toml` outside a checkout: the bundled case (one note)
    return parse_case(read_toml_text(path), path)


# the resistance models added one file each (semianalytic/sections/resistances/): registered once the
# schemas that hold [target.resistance] exist, so that their union is rebuilt with every model
_load_added_resistances()
