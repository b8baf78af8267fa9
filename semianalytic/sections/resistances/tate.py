"""``model = "tate"``: Tate's target resistance R_t = Y_t (2/3 + ln(0.57 E_t / Y_t)).

Published: A. Tate, Int. J. Mech. Sci. 28 (1986) 599-612 (the equation lives in
:func:`semianalytic.penetration.regime.tate_resistance`, also the eroding rod's R_t option).
Valid for a ductile metal target with 0 < Y_t < E_t; it is the resistance of the eroding-rod
theory, used here as the quasi-static R_t of Part I, eq. (11) (compare with eq. (16) at the same
Y_t, E_t before choosing it).  Case file::

    [target.resistance]
    model = "tate"
    yield_stress = "400 MPa"
    youngs_modulus = "68.9 GPa"

This module is the worked example of docs/extending.md: the model (a frozen dataclass of SI
values with ``name``, ``equation``, ``pressure``) and its registered case-file input, one file.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from pydantic import Field

from semianalytic.errors import InputError
from semianalytic.sections.penetration import ResistanceInput, register_resistance
from semianalytic.units import Pressure

__all__ = ["Tate", "TateInput"]


@dataclass(frozen=True)
class Tate:
    """Tate's (1986) target resistance.  Y_t, E_t [Pa]."""

    yield_stress: float
    youngs_modulus: float
    name = "tate"
    equation = "Tate (1986), R_t = Y_t (2/3 + ln(0.57 E_t/Y_t))"

    def pressure(self, diameter: float | None = None) -> float:
        from semianalytic.penetration.regime import tate_resistance

        return tate_resistance(self.yield_stress, self.youngs_modulus)


@register_resistance(calibrate="yield_stress")
class TateInput(ResistanceInput):
    """``[target.resistance]`` of ``model = "tate"``."""

    model: Literal["tate"]
    yield_stress: Pressure = Field(description="target yield stress Y_t of Tate's R_t")
    youngs_modulus: Pressure = Field(description="target Young's modulus E_t of Tate's R_t")

    def build(self) -> Tate:
        if not self.youngs_modulus > self.yield_stress:
            raise InputError("target.resistance.youngs_modulus", "Tate's R_t needs E_t > Y_t")
        return Tate(self.yield_stress, self.youngs_modulus)
