"""Inputs of the Part II cavity model: a brittle material, SI units, validated up front.

Symbols (Part II, section 1): E, nu (elastic region, eqs. (3)-(5)); sigma_f, the strength in
uniaxial tension (eq. (4)); Y_s, the flow stress of the solid phase in uniaxial compression
(eq. (19)); K_s, the bulk modulus of the solid phase (eq. (32)); theta_0, the initial
porosity (eq. (16)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from semianalytic.errors import ModelError

__all__ = ["BrittleMaterial"]


@dataclass(frozen=True)
class BrittleMaterial:
    """A brittle target material for the three-zone cavity model (Part II).

    youngs_modulus      E [Pa] (> 0)
    poisson_ratio       nu [-] (-1 < nu < 0.5)
    tensile_strength    sigma_f [Pa] (> 0): hoop stress at the fracture front r = c, eq. (4)
    compressive_strength Y_s [Pa] (> 0): flow stress of the solid phase, eq. (19)
    bulk_modulus        K_s [Pa] (> 0) of the solid phase, eq. (32); ``None`` means
                        E / (3 (1 - 2 nu))
    initial_porosity    theta_0 [-] (0 <= theta_0 < 1), eq. (16)

    Invalid values raise :class:`~semianalytic.errors.ModelError` naming ``cavity.<field>``
    (the case layer maps it to the key the user wrote, e.g. ``material.<field>``; exit status 2).
    """

    youngs_modulus: float
    poisson_ratio: float
    tensile_strength: float
    compressive_strength: float
    bulk_modulus: float | None = None
    initial_porosity: float = 0.0

    def __post_init__(self):
        def finite(name, value):
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ModelError(f"must be a finite number; got {value!r}", f"cavity.{name}")

        for name in ("youngs_modulus", "tensile_strength", "compressive_strength"):
            value = getattr(self, name)
            finite(name, value)
            if not value > 0:
                raise ModelError(f"must be positive (Pa); got {value!r}", f"cavity.{name}")
        finite("poisson_ratio", self.poisson_ratio)
        if not -1.0 < self.poisson_ratio < 0.5:
            raise ModelError(f"must lie in (-1, 0.5); got {self.poisson_ratio!r}", "cavity.poisson_ratio")
        if self.bulk_modulus is not None:
            finite("bulk_modulus", self.bulk_modulus)
            if not self.bulk_modulus > 0:
                raise ModelError(f"must be positive (Pa); got {self.bulk_modulus!r}", "cavity.bulk_modulus")
        finite("initial_porosity", self.initial_porosity)
        if not 0.0 <= self.initial_porosity < 1.0:
            raise ModelError(f"must lie in [0, 1); got {self.initial_porosity!r}", "cavity.initial_porosity")

    @property
    def K_s(self) -> float:
        """Bulk modulus of the solid phase, K_s = E_s / (3 (1 - 2 nu_s)) unless given (Part II, eq. (32))."""
        if self.bulk_modulus is not None:
            return float(self.bulk_modulus)
        return self.youngs_modulus / (3.0 * (1.0 - 2.0 * self.poisson_ratio))

    @classmethod
    def from_section(cls, section) -> BrittleMaterial:
        """From a validated ``[material]`` case section (:class:`semianalytic.sections.cavity.MaterialSection`)."""
        return cls(
            youngs_modulus=section.youngs_modulus,
            poisson_ratio=section.poisson_ratio,
            tensile_strength=section.tensile_strength,
            compressive_strength=section.compressive_strength,
            bulk_modulus=section.bulk_modulus,
            initial_porosity=section.initial_porosity,
        )
