"""``[nanostrength]``: the case-file section of Part III (theoretical strength, size effect).

Example (see ``cases/part3_*.toml``)::

    [nanostrength]
    materials = ["C", "BN", "SiC", "AlN"]    # Tables 1-2 crystals and/or [[nanostrength.crystal]] names
    law = "cutoff"                 # bulk Phi(d): "cutoff" (exact to Table 2) or "uber" (for comparison)
    stress_measure = "current"     # eq. (14): 1/d with d the current ("current") or initial ("reference") spacing
    surface_energy = "eq15"        # gamma: "eq15" (integral) or "eq16" (printed ratio, Table 3)
    deformation_energy = "law"     # Delta Phi for eq16: "law" or "printed" (text after eq. 16)
    odd_surface_ratio = 5.0        # Phi_1/Phi_0 at the lone-plane surface of an odd plate (assumed)

    [[nanostrength.study]]
    name = "table4"
    materials = ["C", "BN", "SiC", "AlN"]
    basis = ["rectangle", "parallelogram"]   # or "none" (plate)
    l = [100]                      # atomic planes, or "inf" (bar unbounded along [111])
    mn = [25]                      # m = n, or "inf" with basis "none"
    i = [2]                        # mesolayers, "all", or entries "centre"
    compare = "table4"             # set the printed values beside (table4 | table5)
    plot = "i"                     # draw against i | mn | l

Custom crystals (SI quantities with units)::

    [[nanostrength.crystal]]
    name = "X"
    interlayer_energy = "2.0 J/m^2"   # |Phi_0|
    spacing = "1.59 angstrom"         # d_0 = c_0/4
    youngs_modulus = "1100 GPa"
    compressive_strength = "204 GPa"
    compressive_strain = 0.0975
    tensile_strength = "139 GPa"
    tensile_strain = 0.1456
"""

from __future__ import annotations

import math
import re
from typing import Literal

from pydantic import Field, field_validator, model_validator

from semianalytic.nanostrength import data, mesolayer
from semianalytic.nanostrength.analysis import Analysis, StudySpec
from semianalytic.nanostrength.crystal import Crystal, paper_crystal
from semianalytic.schema import Section
from semianalytic.units import Length, Pressure, SurfaceEnergy

Inf = Literal["inf"]


class CrystalSpec(Section):
    """``[[nanostrength.crystal]]``: a crystal given by the quantities of Tables 1-2."""

    name: str = Field(min_length=1, max_length=40)
    interlayer_energy: SurfaceEnergy
    spacing: Length
    youngs_modulus: Pressure
    compressive_strength: Pressure
    compressive_strain: float = Field(gt=0, lt=1)
    tensile_strength: Pressure
    tensile_strain: float = Field(gt=0, lt=1)
    deformation_energy_tension: SurfaceEnergy | None = None
    deformation_energy_compression: SurfaceEnergy | None = None

    @field_validator("name")
    @classmethod
    def _name(cls, v):
        if not re.fullmatch(r"[A-Za-z0-9_.+-]+", v):
            raise ValueError("use letters, digits and _.+- only")
        if v in data.MATERIALS:
            raise ValueError(f"{v!r} is a built-in crystal of Tables 1-2; choose another name")
        return v

    def crystal(self) -> Crystal:
        return Crystal(
            name=self.name, phi0=-self.interlayer_energy, d0=self.spacing, E=self.youngs_modulus,
            sigma_c=self.compressive_strength, e_c=self.compressive_strain,
            sigma_t=self.tensile_strength, e_t=self.tensile_strain,
            dphi_t=self.deformation_energy_tension, dphi_c=self.deformation_energy_compression,
        )


# Issue 27 (this project's own bounds): the largest bar and basis a study may name.  The
# report's largest are l = 1200 and m = n = 2500.
MAX_PLANES = 2040
MAX_MN = 10**9


class StudySection(Section):
    """``[[nanostrength.study]]``: a grid of nanoparticle geometries (Part III, eqs. (21)-(29))."""

    name: str = Field(min_length=1, max_length=40)
    title: str = ""
    materials: list[str] | None = None
    basis: list[Literal["parallelogram", "rectangle", "none"]] = Field(default=["parallelogram"], min_length=1)
    l: list[int | Inf] = Field(default=["inf"], min_length=1)
    mn: list[int | Inf] = Field(default=["inf"], min_length=1)
    i: Literal["all"] | list[int | Literal["centre"]] = "all"
    compare: Literal["table4", "table5"] | None = None
    plot: Literal["i", "mn", "l"] | None = None

    @field_validator("name")
    @classmethod
    def _name(cls, v):
        if not re.fullmatch(r"[A-Za-z0-9_-]+", v):
            raise ValueError("use letters, digits, _ and - only (it names the figure file)")
        return v

    @model_validator(mode="after")
    def _consistent(self):
        for l in self.l:
            if l != "inf" and (isinstance(l, bool) or l < 2):
                raise ValueError(f"'l' entries must be integers >= 2 (atomic planes) or \"inf\"; got {l!r}")
            if l != "inf" and l > MAX_PLANES:  # issue 27: 2^(j + 2) of eq. (20) overflows a double beyond j ~ 1020
                raise ValueError(f"'l' entries must be at most {MAX_PLANES} planes (the mesolayer sums overflow beyond; a bar "
                                 f"that long is bulk: use \"inf\"); got {l!r}")
        for mn in self.mn:
            if mn != "inf" and not isinstance(mn, bool) and mn > MAX_MN:
                raise ValueError(f"'mn' entries must be at most {MAX_MN} lattice vectors (a basis that wide is a plate: use "
                                 f"basis \"none\" with mn = [\"inf\"]); got {mn!r}")
            if mn != "inf" and (isinstance(mn, bool) or mn < 2):
                raise ValueError(f"'mn' entries must be integers >= 2 (m = n lattice vectors) or \"inf\"; got {mn!r}")
        for b in self.basis:
            for mn in self.mn:
                if b == "none" and mn != "inf":
                    raise ValueError("basis \"none\" (a plate unbounded in x, y) needs mn = [\"inf\"]")
                if b != "none" and mn == "inf":
                    raise ValueError(f"basis {b!r} needs finite 'mn' (use basis \"none\" for a plate)")
        if self.i != "all":
            if not self.i:
                raise ValueError("'i' must list at least one mesolayer (or be \"all\")")
            for k in self.i:
                if k != "centre" and (isinstance(k, bool) or k < 1):
                    raise ValueError(f"'i' entries must be integers >= 1 or \"centre\"; got {k!r}")
            for l in self.l:
                if l == "inf":
                    raise ValueError("'i' needs finite 'l' (an unbounded bar has no free surface along [111]); "
                                     "use i = \"all\" with l = [\"inf\"]")
                j = mesolayer.mesolayer_count(l)
                for k in self.i:
                    if k != "centre" and k > j:
                        raise ValueError(f"mesolayer i = {k} exceeds the j = {j} mesolayers of l = {l} planes")
        axis = {"i": None, "mn": self.mn, "l": self.l}
        if self.plot == "i" and (self.i != "all" or "inf" in self.l):
            raise ValueError("plot = \"i\" needs i = \"all\" and finite 'l'")
        if self.plot in ("mn", "l") and len(axis[self.plot]) < 2:
            raise ValueError(f"plot = {self.plot!r} needs at least two '{self.plot}' values")
        if self.plot in ("mn", "l") and "inf" in axis[self.plot]:
            raise ValueError(f"plot = {self.plot!r} needs finite '{self.plot}' values")
        return self

    def spec(self, default_materials: tuple[str, ...]) -> StudySpec:
        conv = lambda v: None if v == "inf" else int(v)  # noqa: E731
        return StudySpec(
            name=self.name, title=self.title or self.name,
            materials=tuple(self.materials) if self.materials is not None else default_materials,
            basis=tuple(self.basis), l=tuple(conv(v) for v in self.l), mn=tuple(conv(v) for v in self.mn),
            i=self.i if self.i == "all" else tuple(self.i), compare=self.compare, plot=self.plot,
        )


class NanostrengthSection(Section):
    """``[nanostrength]``: Part III analyses (see the module docstring for an example)."""

    materials: list[str] = Field(default_factory=lambda: list(data.MATERIALS), min_length=1)
    crystal: list[CrystalSpec] = Field(default_factory=list)
    law: Literal["cutoff", "uber"] = "cutoff"
    stress_measure: Literal["current", "reference"] = "current"
    surface_energy: Literal["eq15", "eq16"] = "eq15"
    deformation_energy: Literal["law", "printed"] = "law"
    odd_surface_ratio: float = Field(default=mesolayer.DEFAULT_ODD_SURFACE_RATIO, gt=0)
    study: list[StudySection] = Field(default_factory=list)

    @field_validator("odd_surface_ratio")
    @classmethod
    def _finite(cls, v):
        if not math.isfinite(v):
            raise ValueError("must be a finite positive number")
        return v

    @model_validator(mode="after")
    def _consistent(self):
        custom = [c.name for c in self.crystal]
        if len(set(custom)) != len(custom):
            raise ValueError("crystal names must be unique")
        known = set(data.MATERIALS) | set(custom)
        for name in self.materials:
            if name not in known:
                raise ValueError(f"unknown crystal {name!r}; known: {', '.join(sorted(known))}")
        if len(set(self.materials)) != len(self.materials):
            raise ValueError("'materials' lists a crystal twice")
        if self.surface_energy == "eq15" and self.deformation_energy == "printed":
            raise ValueError("deformation_energy = \"printed\" goes with surface_energy = \"eq16\"; "
                             "eq. (15) integrates the law's stress")
        if self.deformation_energy == "printed":
            for c in self.crystal:
                if c.name in self.materials and (c.deformation_energy_tension is None or c.deformation_energy_compression is None):
                    raise ValueError(f"crystal {c.name!r} needs deformation_energy_tension and _compression "
                                     "for deformation_energy = \"printed\"")
        names = [s.name for s in self.study]
        if len(set(names)) != len(names):
            raise ValueError("study names must be unique")
        for s in self.study:
            for name in s.materials or []:
                if name not in self.materials:
                    raise ValueError(f"study {s.name!r}: crystal {name!r} is not in 'materials'")
        return self

    def crystals(self) -> list[Crystal]:
        """The crystals to analyse, in the order of ``materials``."""
        custom = {c.name: c for c in self.crystal}
        return [custom[n].crystal() if n in custom else paper_crystal(n) for n in self.materials]

    def studies(self) -> list[StudySpec]:
        return [s.spec(tuple(self.materials)) for s in self.study]


def analyse_section(section) -> Analysis:
    """Run the analysis (:func:`semianalytic.nanostrength.analysis.analyse`) of a validated
    ``[nanostrength]`` section; a crystal the law cannot be calibrated to (the model's
    ``CalibrationError``) is an InputError naming the case key of that crystal."""
    from semianalytic.errors import InputError
    from semianalytic.nanostrength.analysis import analyse
    from semianalytic.nanostrength.interplanar import CalibrationError

    crystals = section.crystals()
    custom = [c.name for c in section.crystal]
    try:
        out = analyse(crystals, section.studies(), law=section.law, measure=section.stress_measure,
                      odd_surface_ratio=section.odd_surface_ratio)
    except CalibrationError as exc:
        field = f"nanostrength.crystal.{custom.index(exc.crystal)}" if exc.crystal in custom else "nanostrength.materials"
        raise InputError(field, str(exc)) from None
    out.options.update({"surface_energy": section.surface_energy, "deformation_energy": section.deformation_energy})
    return out
