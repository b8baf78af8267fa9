"""Case-file keys of finite and layered targets and of the ``perforate`` command (issue 23).

```toml
[target]
density = "2710 kg/m^3"
thickness = "26.3 mm"          # absent: the half-space (every older case keeps its meaning)

# or a layered target (instead of 'thickness'):
[[target.layers]]
thickness = "10 mm"
[[target.layers]]
gap = "5 mm"                   # air before this layer (default 0)
thickness = "6 mm"
density = "7850 kg/m^3"        # default: [target] density
name = "steel back plate"      # optional label (the 'material')
[target.layers.resistance]     # default: [target.resistance]
model = "elastic-plastic"
yield_stress = "1.2 GPa"
youngs_modulus = "200 GPa"
poisson_ratio = 0.29

[perforation]                  # all optional
coefficients = "plate"         # the plate BEM table; "half-space": X(P) - X(P - H) of the half-space
                               # table (an approximation, no plate table to build)
back_face = "auto"             # the default chosen by transfer; "finite-sphere" (Macek & Duffey 2000),
                               # "constant" (R_t of eq. (16) to the exit), "cylindrical" (Forrestal et al.
                               # 1987: sigma_s of the cylindrical cavity to the exit), "sphere-to-cylinder"
                               # (finite sphere with the cylindrical sigma_s as its floor; ours)
failure = "auto"               # "hole-growth", "plug" (auto: plug for a flat nose)
shear_strength = "230 MPa"     # tau of the plug criterion (default Y/sqrt(3) of the resistance)
tolerance = "0.05 m/s"         # bracket of the ballistic-limit bisection
data = "my_perforation.csv"    # measured V_s, V_r (columns Vs_m_s, Vr_m_s; '#' comment lines)
# Part IV inputs (hardness and plasticity characteristic delta_H of the indentation test):
target_hardness = "1.07 GPa"   # HV of the target
target_delta_h = 0.88
projectile_hardness = "5.7 GPa"
projectile_delta_h = 0.74
```
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, field_validator

from semianalytic.errors import InputError
from semianalytic.schema import Section
from semianalytic.sections.penetration import ResistanceField
from semianalytic.units import (
    Density,
    Length,
    Pressure,
    Velocity,
    _quantity_validator,  # a signed length: a negative gap is reported as an overlap
)

__all__ = ["TargetLayerSection", "PerforationSection", "check_target_layers"]

SignedLength = Annotated[float, _quantity_validator("length")]


class TargetLayerSection(Section):
    """One ``[[target.layers]]`` entry: ``thickness``, optional ``gap`` before it, ``density``,
    ``resistance`` (default: the target's) and a ``name``."""

    thickness: SignedLength | None = None
    gap: SignedLength | None = None
    density: Density | None = None
    resistance: ResistanceField | None = None
    name: str | None = None


def check_target_layers(thickness: float | None, layers) -> None:
    """Cross-checks of ``[target]`` thickness and layers (raises InputError naming the key):
    thickness zero or negative, both thickness and layers, a layer without thickness (a gap
    with no layer after it), overlapping layers (a negative gap)."""
    if thickness is not None and not thickness > 0:
        raise InputError("target.thickness", f"must be positive (a plate thickness, e.g. '20 mm'); got {thickness:g} m")
    if layers is None:
        return
    if thickness is not None:
        raise InputError("target.thickness", "give either 'thickness' (one plate) or [[target.layers]], not both")
    if not layers:
        raise InputError("target.layers", "needs at least one layer with a 'thickness'")
    for k, ly in enumerate(layers):
        where = f"target.layers.{k}"
        if ly.thickness is None:
            if ly.gap is not None:
                raise InputError(f"{where}.gap", "a gap without a following layer: give this layer's 'thickness' "
                                 "(a gap is the space before its own layer), or remove the gap")
            raise InputError(f"{where}.thickness", "missing (required): the layer's thickness, e.g. '10 mm'")
        if not ly.thickness > 0:
            raise InputError(f"{where}.thickness", f"must be positive (e.g. '10 mm'); got {ly.thickness:g} m")
        if ly.gap is not None and ly.gap < 0:
            if k == 0:
                raise InputError(f"{where}.gap", f"must not be negative (the first layer starts at the impact face); got {ly.gap:g} m")
            raise InputError(f"{where}.gap", f"overlapping layers: a negative gap ({ly.gap * 1e3:g} mm) puts layer {k} "
                             f"inside layer {k - 1}; gaps are lengths >= 0 (length unit, e.g. '2 mm')")


class PerforationSection(Section):
    """``[perforation]``: options of the ``perforate`` command (module docstring)."""

    coefficients: Literal["plate", "half-space"] = "plate"  # "half-space": the stand-in approximation (fast)
    back_face: Literal["auto", "finite-sphere", "constant", "cylindrical", "sphere-to-cylinder"] = "auto"
    failure: Literal["auto", "hole-growth", "plug"] = "auto"
    shear_strength: Pressure | None = None
    tolerance: Velocity = Field(default=0.05, description="bracket of the ballistic-limit bisection [m/s]")
    data: str | None = Field(default=None, min_length=1)
    data_source: str | None = None
    target_hardness: Pressure | None = None
    target_delta_h: float | None = Field(default=None, gt=0.0, le=1.0)
    projectile_hardness: Pressure | None = None
    projectile_delta_h: float | None = Field(default=None, gt=0.0, le=1.0)
    yield_stress: Pressure | None = Field(default=None, description="Y of the target for R(3) of Part IV eq. (6)")
    youngs_modulus: Pressure | None = None

    @field_validator("tolerance")
    @classmethod
    def _tol(cls, v):
        if not v <= 0.5:
            raise ValueError(f"must be at most 0.5 m/s (the issue's reproducibility); got {v:g} m/s")
        return v


Thickness = Length  # re-exported for case.py's [target] thickness
