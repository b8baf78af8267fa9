"""``[run]``: what ``python -m semianalytic run`` does with a case (all keys optional).

Example (Part I, Fig. 13: the velocity field around the ogival nose at P = 35.9 mm)::

    [run]
    analyses = ["coefficients", "velocity_field"]   # default: everything the case supports
    field_depths = ["35.9 mm"]                      # depths P of the velocity field (eq. (23))
    field_extent = 2.0                              # window: this many diameters around the nose
    field_grid = [49, 25]                           # body-fitted grid: 2 x 49 rays of 25 nodes
    field_segments = 24                             # azimuthal segments of the revolved 3D grid
    render = true                                   # off-screen pyvista render into the report
    coefficients = "bem"                            # or "paper": the paper's quoted Abar, Bbar, Cbar
    vtk_dir = "vtk"                                 # sub-folder of the output folder

Paths (``vtk_dir``, ``figures_dir``) are relative to the output folder and may not leave it
(absolute paths and ``..`` are rejected here; :func:`semianalytic.io.contained_path` checks
again when the files are written).
"""

from __future__ import annotations

from pathlib import PurePosixPath, PureWindowsPath
from typing import Literal

from pydantic import Field, field_validator

from semianalytic.schema import Section
from semianalytic.units import Length, Velocity

ANALYSES = (
    "added_mass",  # [body]: BEM added mass against the exact sphere/spheroid value
    "coefficients",  # [projectile]: A(P), B(P), C(P), phi at the tip (Part I Figs. 6-8)
    "penetration",  # [projectile]+[target]+[impact]: u(t), P(t), u(P), P(U_s) (Figs. 9-11, 14-16)
    "critical_velocity",  # U_sC of Part I eqs. (33)/(36)
    "validation",  # [data]: predicted against measured depth
    "velocity_field",  # eq. (23) on a grid -> .vtu + render (Figs. 12-13)
    "fem_field",  # fem_check potential field -> .vtu (when fem_check exposes it)
    "cavity",  # [material]: Part II
    "ballistic_limit",  # [ballistic_limit]: Part IV
    "perforation",  # [target] thickness or layers: V_r against V_s, ballistic limit (issue 23)
    "nanostrength",  # [nanostrength]: Part III
)
Analysis = Literal[
    "added_mass",
    "coefficients",
    "penetration",
    "critical_velocity",
    "validation",
    "velocity_field",
    "fem_field",
    "cavity",
    "ballistic_limit",
    "perforation",
    "nanostrength",
]


def _relative_subdir(value: str) -> str:
    """A sub-folder name that stays inside the output folder (no absolute path, no '..')."""
    if not isinstance(value, str) or not value.strip():
        raise ValueError("must be a non-empty relative folder name")
    for flavour in (PurePosixPath(value), PureWindowsPath(value)):
        if flavour.is_absolute() or flavour.anchor:
            raise ValueError(f"must be relative to the output folder; got the absolute path {value!r}")
        if ".." in flavour.parts:
            raise ValueError(f"may not contain '..' (it would leave the output folder); got {value!r}")
    return value


class RunSection(Section):
    """``[run]``: analyses to run and options of the report (see the module docstring)."""

    analyses: list[Analysis] | None = Field(default=None, min_length=1)
    field_depths: list[Length] | None = Field(default=None, min_length=1, max_length=8)
    field_extent: float = Field(default=2.0, gt=0.0, le=50.0, description="half-window, in diameters")
    field_grid: tuple[int, int] = (49, 25)
    field_segments: int = Field(default=24, ge=3, le=180)
    field_velocity: Velocity | None = None
    render: bool = True
    coefficients: Literal["bem", "paper"] = "bem"  # "paper": the paper's quoted Abar, Bbar, Cbar (errata 2, 2c)
    vtk_dir: str = "vtk"
    vtk_coordinates: Literal["m", "mm"] = Field(
        default="m", description="unit of the .vtu coordinates (mm: readable axis ticks at projectile scale; the "
                                 "arrays stay SI, named with their unit)")
    figures_dir: str = "figures"

    @field_validator("field_grid")
    @classmethod
    def _grid(cls, v):
        nx, nr = v
        if not (4 <= nx <= 801 and 4 <= nr <= 801):
            raise ValueError(f"both node counts must lie in [4, 801]; got {list(v)!r}")
        return v

    @field_validator("vtk_dir", "figures_dir")
    @classmethod
    def _subdir(cls, v):
        return _relative_subdir(v)

    @field_validator("analyses")
    @classmethod
    def _unique(cls, v):
        if v is not None and len(set(v)) != len(v):
            raise ValueError("lists an analysis twice")
        return v
