"""``[data]``: experimental data a penetration case is compared with.

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
"""

from __future__ import annotations

from pydantic import Field, model_validator

from semianalytic.case import Section
from semianalytic.units import Pressure, Velocity

__all__ = ["DataSection"]

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
