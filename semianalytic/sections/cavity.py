"""``[material]`` case section: a brittle target material for the Part II cavity model.

```toml
[material]
youngs_modulus = "373.14 GPa"
poisson_ratio = 0.232
tensile_strength = "0.262 GPa"      # sigma_f
compressive_strength = "2.62 GPa"   # Y_s
bulk_modulus = "231.8 GPa"          # optional; default E/(3(1-2 nu))
initial_porosity = 0.0              # optional theta_0
solver = "bracket"                  # optional: "bracket" or "fixed-point" (Part II eq. 22)
```
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field, field_validator, model_validator

from semianalytic.schema import Section, check_brittle_constants
from semianalytic.units import Pressure

__all__ = ["MaterialSection", "MODEL_FIELDS"]

# the cavity model's input names -> the keys of a case file (errors.model_field)
MODEL_FIELDS = {"cavity.method": "method", "cavity.": "material."}


class MaterialSection(Section):
    """``[material]``: E, nu, sigma_f, Y_s (and optionally K_s, theta_0) of Part II, with units."""

    youngs_modulus: Pressure
    poisson_ratio: float
    tensile_strength: Pressure
    compressive_strength: Pressure
    bulk_modulus: Pressure | None = None
    initial_porosity: float = Field(default=0.0, ge=0.0, lt=1.0)
    solver: Literal["bracket", "fixed-point"] = "bracket"

    @field_validator("poisson_ratio")
    @classmethod
    def _nu(cls, v):
        if not -1.0 < v < 0.5:
            raise ValueError(f"must lie in (-1, 0.5); got {v!r}")
        return v

    @model_validator(mode="after")
    def _consistent(self):
        check_brittle_constants("material", self.youngs_modulus, self.poisson_ratio, self.tensile_strength,
                                self.compressive_strength, self.bulk_modulus)
        return self
