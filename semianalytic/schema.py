"""The base of every case-file section (the case layer's foundation).

:class:`Section` is a frozen pydantic model that rejects unknown keys; :func:`validate_section`
turns the first pydantic error into one :class:`~semianalytic.errors.InputError` naming the
field.  :mod:`semianalytic.case` and each package's ``case`` module build on these; models
never import them.
"""

from __future__ import annotations

import math
import re
import types
import typing
from typing import Any

from pydantic import BaseModel, ConfigDict, ValidationError, ValidationInfo, field_validator

from semianalytic.errors import InputError

__all__ = ["Section", "pydantic_message", "validate_section", "read_toml_text", "check_tree", "MAX_CASE_BYTES", "MAX_DEPTH"]

MAX_CASE_BYTES = 4 * 1024 * 1024  # a case file is a few kB; the largest table nose is ~100 kB
MAX_DEPTH = 8  # tables and arrays nested in a case file: [section.sub] = 2, points = [[x, r]] = 2 more
MAX_ITEMS = 200_000  # values in one case (a table of 100 000 points is already absurd)


class Section(BaseModel):
    """Base of every case-file section: frozen, unknown keys rejected, and strict numbers.

    A plain number field (``crh``, ``poisson_ratio``, ``order``, the pairs of a ``points``
    table) takes a TOML number only: a string (``crh = "3"``) or a boolean is rejected
    instead of being coerced, and so is ``inf`` or ``nan``.  Quantity fields (unit strings)
    are checked by :mod:`semianalytic.units`.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    @field_validator("*", mode="before")
    @classmethod
    def _strict_numbers(cls, value: Any, info: ValidationInfo) -> Any:
        field = cls.model_fields.get(info.field_name) if info.field_name else None
        if field is not None and not any(type(m).__name__.endswith("Validator") for m in field.metadata):
            problem = number_problem(field.annotation, value)
            if problem:
                raise ValueError(problem)
        return value

    @field_validator("*", mode="after")
    @classmethod
    def _plausible(cls, value: Any, info: ValidationInfo) -> Any:
        """The field's plausible range (:data:`semianalytic.units.PLAUSIBLE_RANGES`, issue 27)."""
        from semianalytic.units import plausibility_problem

        problem = plausibility_problem(info.field_name or "", value)
        if problem:
            raise ValueError(problem)
        return value


_NUMBER_TYPES = (float, int)


def _is_plain_number_type(annotation: Any) -> bool:
    return annotation in _NUMBER_TYPES


def number_problem(annotation: Any, value: Any) -> str | None:
    """Why ``value`` is not acceptable where ``annotation`` wants plain numbers (or None).

    Walks ``float``, ``int``, ``X | None``, ``list[...]`` and ``tuple[...]``; anything else
    (quantities, strings, literals, nested sections) is left to pydantic.
    """
    origin = typing.get_origin(annotation)
    if origin in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(annotation) if a is not type(None)]
        if value is None:
            return None
        if len(args) == 1:
            return number_problem(args[0], value)
        return None
    if annotation is bool:
        if not isinstance(value, bool):
            return f"expected true or false (a TOML boolean); got {value!r}"
        return None
    if _is_plain_number_type(annotation):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            kind = "an integer" if annotation is int else "a number"
            return f"expected {kind} (a TOML number, not a string or boolean); got {value!r}"
        if isinstance(value, float) and not math.isfinite(value):
            return f"expected a finite number; got {value!r}"
        if isinstance(value, float) and annotation is float and value != 0 and not 1e-300 < abs(value) < 1e300:
            return f"{value!r} is not representable in the computations (|x| between 1e-300 and 1e300)"
        return None
    if origin in (list, tuple) and isinstance(value, (list, tuple)):
        args = typing.get_args(annotation)
        if origin is tuple and args and args[-1] is not Ellipsis:
            items = zip(args, value)
        else:
            items = ((args[0] if args else Any, v) for v in value)
        for k, (arg, item) in enumerate(items):
            problem = number_problem(arg, item)
            if problem:
                return f"item {k}: {problem}"
    return None


def pydantic_message(err: dict) -> str:
    """One pydantic error in the case files' wording."""
    msg = err.get("msg", "invalid")
    typ = err.get("type", "")
    if typ == "missing":
        return "missing (required)"
    if typ == "extra_forbidden":
        return "unknown key"
    for prefix in ("Value error, ", "Assertion failed, "):
        if msg.startswith(prefix):
            msg = msg[len(prefix):]
    if "input" in err and typ not in ("value_error",) and not isinstance(err["input"], dict):
        msg = f"{msg}; got {err['input']!r}"
    return msg


def validate_section(name: str, model: type[BaseModel], data: Any) -> Any:
    """Validate one section's table with ``model``; errors become ``InputError``."""
    if not isinstance(data, dict):
        raise InputError(name, f"must be a table [{name}]; got {type(data).__name__}")
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        errors = exc.errors()
        # an unknown (misspelt) key first: the "missing" error it causes is only its consequence
        err = next((e for e in errors if e.get("type") == "extra_forbidden"), errors[0])
        inner = (err.get("ctx") or {}).get("error")
        if isinstance(inner, InputError):  # a cross-field check that names its own field
            raise InputError(inner.field, inner.message) from None
        parts, node = [name], data
        for p in err.get("loc", ()):
            if isinstance(node, dict) and p not in node and node.get("model") == p:
                continue  # the tag of a discriminated union (e.g. [target.resistance] model), not a key
            parts.append(str(p))
            node = node.get(p) if isinstance(node, dict) else None
        if err.get("type") in ("union_tag_invalid", "union_tag_not_found"):  # name the tag's key itself
            parts.append(str((err.get("ctx") or {}).get("discriminator", "model")).strip("'"))
        raise InputError(".".join(parts), _project_words(err, model) or pydantic_message(err)) from None


def _models_in(annotation: Any) -> list[type[BaseModel]]:
    """The pydantic models an annotation can hold (through Optional, unions, Annotated, lists)."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    return [m for a in typing.get_args(annotation) for m in _models_in(a)]


def allowed_values(annotation: Any) -> list[Any]:
    """The values of a ``Literal`` annotation (through Optional and Annotated), else []."""
    if typing.get_origin(annotation) is typing.Literal:
        return list(typing.get_args(annotation))
    return [v for a in typing.get_args(annotation) for v in allowed_values(a)]


def _keys_at(model: type[BaseModel], loc: tuple) -> list[str]:
    """The valid keys of the table at ``loc`` (the last item of ``loc`` is the bad key)."""
    classes = [model]
    for p in loc[:-1]:
        if isinstance(p, int):
            continue
        fields = [c.model_fields[p] for c in classes if p in c.model_fields]
        if fields:
            classes = [m for f in fields for m in _models_in(f.annotation)]
        else:  # the tag of a discriminated union: the member whose `model` literal holds it
            tagged = [c for c in classes if p in allowed_values(getattr(c.model_fields.get("model"), "annotation", None))]
            classes = tagged or classes
    return sorted({k for c in classes for k in c.model_fields})


def did_you_mean(word: str, choices: list[str]) -> str:
    """`` (did you mean 'x'?)`` for the closest of ``choices`` (difflib), else ``""``."""
    import difflib

    close = difflib.get_close_matches(str(word), [str(c) for c in choices], n=1, cutoff=0.6)
    return f"; did you mean {close[0]!r}?" if close else ""


def _project_words(err: dict, model: type[BaseModel]) -> str | None:
    """An unknown key with its closest valid key, a wrong choice with the valid ones: the
    project's words for pydantic's ``extra_forbidden``, ``literal_error`` and
    ``union_tag_invalid`` errors (None for any other error)."""
    typ, loc, ctx = err.get("type"), tuple(err.get("loc", ())), err.get("ctx") or {}
    if typ == "extra_forbidden" and loc:
        keys = _keys_at(model, loc)
        return f"unknown key{did_you_mean(loc[-1], keys)} (valid keys: {', '.join(keys)})"
    if typ == "literal_error":
        choices = re.findall(r"'([^']*)'", str(ctx.get("expected", "")))
        got = err.get("input")
        return f"{got!r} is not one of {', '.join(choices)}{did_you_mean(got, choices)}"
    if typ == "union_tag_invalid":
        choices = re.findall(r"'([^']*)'", str(ctx.get("expected_tags", "")))
        got = ctx.get("tag", err.get("input"))
        return f"{got!r} is not one of {', '.join(choices)}{did_you_mean(got, choices)}"
    if typ == "union_tag_not_found":
        return f"missing {str(ctx.get('discriminator', 'model')).strip(chr(39))!r} (the kind of table this is)"
    return None


def read_toml_text(path: Any) -> dict:
    """Read a TOML case file safely: it must exist, be at most :data:`MAX_CASE_BYTES`, be UTF-8
    text (no NUL bytes), parse as TOML and nest at most :data:`MAX_DEPTH` levels.  Every
    failure is one ``InputError`` on the field ``case``."""
    import tomllib
    from pathlib import Path

    path = Path(path)
    try:
        if not path.is_file():
            what = "is a folder, not a case file" if path.is_dir() else "does not exist"
            raise InputError("case", f"file {str(path)!r} {what}")
        size = path.stat().st_size
        if size > MAX_CASE_BYTES:
            raise InputError("case", f"{path.name} is {size / 2**20:.1f} MiB; a case file is at most {MAX_CASE_BYTES // 2**20} MiB of TOML text")  # noqa: E501
        with path.open("rb") as fh:
            raw = fh.read(MAX_CASE_BYTES + 1)
    except OSError as exc:
        raise InputError("case", f"cannot read {str(path)!r}: {exc.strerror or exc}") from None
    if len(raw) > MAX_CASE_BYTES:
        raise InputError("case", f"{path.name} is larger than {MAX_CASE_BYTES // 2**20} MiB; a case file is TOML text")
    nul = raw.find(b"\x00")
    if nul >= 0:
        raise InputError("case", f"{path.name} is a binary file (NUL byte at offset {nul}); expected TOML text")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise InputError("case", f"{path.name} is not UTF-8 text (byte 0x{raw[exc.start]:02x} on line {line}); save it as UTF-8") from None
    depth = _bracket_depth(text)
    if depth > MAX_DEPTH:
        raise InputError("case", f"{path.name} nests arrays or tables {depth} deep; a case needs at most {MAX_DEPTH}")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError("case", f"{path.name} is not valid TOML: {exc}") from None
    except RecursionError:
        raise InputError("case", f"{path.name} nests arrays or tables too deeply") from None
    return data


def _bracket_depth(text: str) -> int:
    """An upper bound of the nesting of inline arrays and tables (brackets and braces outside
    comments; strings may inflate it, which only makes the check stricter on absurd files)."""
    depth = deepest = 0
    for line in text.splitlines():
        for ch in line.split("#", 1)[0] if '"' not in line and "'" not in line else line:
            if ch in "[{":
                depth += 1
                deepest = max(deepest, depth)
            elif ch in "]}":
                depth = max(depth - 1, 0)
        if deepest > MAX_DEPTH:
            break
    return deepest


def check_tree(data: Any, where: str = "case") -> None:
    """Refuse a parsed case nested deeper than :data:`MAX_DEPTH` or with more than
    :data:`MAX_ITEMS` values, without recursion (any tree, also one built in Python)."""
    stack = [(data, 0, where)]
    count = 0
    while stack:
        node, depth, loc = stack.pop()
        count += 1
        if count > MAX_ITEMS:
            raise InputError(where, f"more than {MAX_ITEMS} values; a case file is small")
        if isinstance(node, dict):
            if depth >= MAX_DEPTH:
                raise InputError(loc, f"nested more than {MAX_DEPTH} levels deep")
            for k, v in node.items():
                if not isinstance(k, str):
                    raise InputError(loc, f"keys must be strings; got {k!r}")
                stack.append((v, depth + 1, k if loc == "case" else f"{loc}.{k}"))
        elif isinstance(node, (list, tuple)):
            if depth >= MAX_DEPTH:
                raise InputError(loc, f"nested more than {MAX_DEPTH} levels deep")
            stack.extend((v, depth + 1, loc) for v in node)


# Measured elastic constants of one isotropic material agree to a few per cent (the bundled
# ceramics: AD995, SiC, B4C to 0.2 %).  A bulk modulus more than 10 % away from
# E / (3 (1 - 2 nu)) is warned about; a factor of 10 or more away (a wrong unit prefix) is
# refused.  Between the two the model still runs (K enters only the compressed zone), which
# keeps sensitivity studies of nu at a fixed measured K possible.
BULK_MODULUS_WARN = 0.10
BULK_MODULUS_FACTOR = 10.0


def check_brittle_constants(section: str, youngs_modulus: float, poisson_ratio: float, tensile_strength: float,
                            compressive_strength: float, bulk_modulus: float | None) -> None:
    """Cross-field checks of a brittle material (Part II): the tensile strength sigma_f below
    the compressive strength Y_s (the material fails in tension first: that is what makes the
    cracked zone of Part II, Fig. 1), and K_s consistent with E and nu (isotropic elasticity,
    K = E / (3 (1 - 2 nu))).  Raises ``InputError`` naming the field."""
    if not tensile_strength < compressive_strength:
        raise InputError(
            f"{section}.tensile_strength",
            f"sigma_f = {tensile_strength / 1e9:.4g} GPa must lie below compressive_strength (Y_s = {compressive_strength / 1e9:.4g} GPa) "
            "for a brittle material: otherwise no cracked zone forms (Part II, Fig. 1)",
        )
    if bulk_modulus is not None and poisson_ratio < 0.5:
        implied = youngs_modulus / (3 * (1 - 2 * poisson_ratio))
        apart = abs(bulk_modulus / implied - 1)
        ratio = bulk_modulus / implied
        if not 1 / BULK_MODULUS_FACTOR < ratio < BULK_MODULUS_FACTOR:
            raise InputError(
                f"{section}.bulk_modulus",
                f"{bulk_modulus / 1e9:.4g} GPa is inconsistent with youngs_modulus and poisson_ratio, which give "
                f"K = E / (3 (1 - 2 nu)) = {implied / 1e9:.4g} GPa (a factor {max(ratio, 1 / ratio):.3g} apart); "
                "leave bulk_modulus out to use that value",
            )
        if apart > BULK_MODULUS_WARN:
            import warnings

            from semianalytic.errors import ModelValidityWarning

            warnings.warn(
                f"{section}.bulk_modulus: {bulk_modulus / 1e9:.4g} GPa is {apart:.0%} away from E / (3 (1 - 2 nu)) = "
                f"{implied / 1e9:.4g} GPa; check the elastic constants", ModelValidityWarning, stacklevel=2)


# --------------------------------------------------------------------------------------
# one-line descriptions of the case-file keys (the case-file reference page is generated from
# them, tools/docs_hooks.py): ``"Model.key"`` first, then the key alone; a description set on a
# field (``Field(description=...)``) or a comment beside it in the source wins.  The SI unit of
# a quantity is appended by :func:`key_description`.

KEY_HELP: dict[str, str] = {
    # shared names
    "youngs_modulus": "Young's modulus E",
    "poisson_ratio": "Poisson's ratio nu (dimensionless)",
    "yield_stress": "yield stress Y (uniaxial)",
    "density": "mass density",
    "tensile_strength": "uniaxial tensile strength sigma_f",
    "compressive_strength": "uniaxial compressive strength Y_s",
    "bulk_modulus": "bulk modulus K (default E / (3 (1 - 2 nu)))",
    "initial_porosity": "initial porosity theta_0 (volume fraction of voids, dimensionless)",
    "eroding_resistance": "target resistance R_t of the eroding rod (Alekseevskii-Tate); default the model's R_t",
    "model": "which model of the section (the other keys depend on it)",
    "name": "identifier (letters, digits, _ - .), used in tables and file names",
    "points": "meridian points [[x, r], ...] from the tip (0, 0) back, in points_unit",
    "points_unit": "length unit of points",
    "thickness": "thickness of the plate or layer",
    "title": "title of the study in the report",
    "materials": "materials analysed (names of Tables 1-2 or of [[nanostrength.crystal]])",
    # [body]
    "BodySection.shape": "closed body: sphere, spheroid, cylinder, double cone or a table of points",
    "BodySection.length": "length of the body along its axis",
    "BodySection.diameter": "largest diameter of the body",
    # [projectile]
    "ProjectileSection.nose": "nose shape (each kind has its own keys, see the section text)",
    "ProjectileSection.diameter": "shank diameter d",
    "ProjectileSection.shank_length": "length of the cylindrical shank (total length = shank + nose)",
    "ProjectileSection.density": "density of the projectile material rho_p (for the mass when mass is absent)",
    "ProjectileSection.mass": "measured mass m (instead of density x volume)",
    "ProjectileSection.half_angle": "cone half-angle of the nose",
    "ProjectileSection.corner_radius": "radius of the rounded corner of a flat nose",
    "ProjectileSection.poisson_ratio": "Poisson's ratio of the projectile nu_p (dimensionless)",
    "ProjectileSection.yield_stress": "dynamic yield stress of the projectile Y_p (Part I, eqs. (33), (36))",
    "ProjectileSection.dynamic_factor": "dynamic over static yield stress, with hardness (dimensionless)",
    "ProjectileSection.buckling": "buckling reduction of the critical velocity: none, johnson-euler or table",
    "ProjectileSection.buckling_table": "buckling factor against L/d as [[L/d, factor], ...] (with buckling = table)",
    # [target] and its resistance
    "TargetSection.density": "density of the target rho_t",
    "TargetSection.resistance": "the target resistance table [target.resistance] (a model and its keys)",
    "ElasticPlasticInput.yield_stress": "target yield stress Y (R_t of Part I, eq. (16))",
    "HardeningInput.yield_stress": "target yield stress Y of the power-law hardening (Part I, eq. (18))",
    "Part4Input.yield_stress": "target yield stress Y (Part IV, eq. (6))",
    "LimestoneInput.psi": "constant Psi of the limestone resistance R_t = Psi + phi a_0 / a (Frew; Part I, eq. (19))",
    "LimestoneInput.phi": "size-effect constant phi of R_t = Psi + phi a_0 / a (Part I, eq. (19))",
    "LimestoneInput.reference_diameter": "reference diameter 2 a_0 of the size effect (Part I, eq. (19))",
    "ConstantInput.value": "the constant target resistance R_t",
    "CavityInput.compressive_strength": "compressive strength Y_s of the brittle target (Part II cavity)",
    "BrittleInput.compressive_strength": "compressive strength Y_s of the brittle target",
    # [[target.layers]]
    "TargetLayerSection.thickness": "thickness of the layer",
    "TargetLayerSection.gap": "air gap in front of the layer",
    "TargetLayerSection.density": "density of the layer",
    "TargetLayerSection.resistance": "the layer's resistance table (as [target.resistance])",
    "TargetLayerSection.name": "name of the layer in tables",
    # [impact], [coefficients]
    "ImpactSection.striking_velocities": "striking velocities U_s of the projectile",
    "CoefficientsSection.max_depth_nose_lengths": "deepest BEM solve of the table, in nose lengths L_h (dimensionless)",
    "CoefficientsSection.reading": "which B of Part I, eq. (12): body (default), literal or bernoulli",
    # [material] (cavity)
    "MaterialSection.solver": "root finder of the front stress: bracket (robust) or fixed-point (Part II, eq. (22))",
    # [ballistic_limit]
    "BallisticLimitSection.table": "CSV file of shots next to the case file (Part IV tables)",
    "BallisticLimitSection.shots": "shots given inline ([[ballistic_limit.shots]])",
    "BallisticLimitSection.hardness": "rule of the hardness resistance R(1) = H_M delta_H (Part IV, eq. (5))",
    "BallisticLimitSection.areal_mass": "rule of the projectile's areal mass P in eqs. (7)-(9)",
    "BallisticLimitSection.projectile_density": "projectile density rho_p for the areal mass",
    "BallisticLimitSection.C1": "empirical constant C1 of Part IV, eq. (7) [m^2/s^2]",
    "BallisticLimitSection.C2": "empirical constant C2 of Part IV, eq. (8) [(m/s)^2/GPa]",
    "BallisticLimitSection.C3": "empirical constant C3 of Part IV, eq. (9) [m^2/s^2]",
    "BallisticLimitSection.critical_velocities": "velocities of the critical areal density and thickness (Table 4)",
    "ShotSection.name": "shot identifier",
    "ShotSection.projectile_length": "projectile length L_p",
    "ShotSection.projectile_density": "projectile density rho_p",
    "ShotSection.projectile_diameter": "projectile diameter d",
    "ShotSection.projectile_mass": "projectile mass",
    "ShotSection.projectile_hardness": "projectile hardness H (Meyer)",
    "ShotSection.projectile_delta_h": "projectile hardness factor delta_H (dimensionless)",
    "ShotSection.target_density": "target density rho_t",
    "ShotSection.thickness": "target plate thickness h",
    "ShotSection.target_hardness": "target hardness H_M (Meyer)",
    "ShotSection.target_delta_h": "target hardness factor delta_H of R(1) = H_M delta_H (dimensionless)",
    "ShotSection.yield_stress": "target yield stress Y for R(3) of Part IV, eq. (6)",
    "ShotSection.youngs_modulus": "target Young's modulus E for R(3) of Part IV, eq. (6)",
    "ShotSection.measured": "measured ballistic limit",
    "ShotSection.layers": "layers of a layered target ([[...layers]])",
    "LayerSection.name": "layer name",
    "LayerSection.density": "layer density",
    "LayerSection.thickness": "layer thickness",
    "LayerSection.hardness": "layer hardness H_M (Meyer)",
    "LayerSection.delta_h": "layer hardness factor delta_H (dimensionless)",
    # [nanostrength]
    "NanostrengthSection.crystal": "crystals beyond the built-in ones ([[nanostrength.crystal]], Tables 1-2 quantities)",
    "NanostrengthSection.law": "interplanar law: cutoff (the paper's) or uber (universal binding energy)",
    "NanostrengthSection.stress_measure": "stress per current or reference area",
    "NanostrengthSection.surface_energy": "surface energy by Part III, eq. (15) or eq. (16)",
    "NanostrengthSection.deformation_energy": "deformation energy from the law or as printed (Table 3)",
    "NanostrengthSection.odd_surface_ratio": "surface-energy ratio of the odd surfaces (dimensionless)",
    "NanostrengthSection.study": "grids of nanoparticle geometries ([[nanostrength.study]])",
    "CrystalSpec.interlayer_energy": "interlayer (surface) energy Phi_0",
    "CrystalSpec.spacing": "interplanar spacing",
    "CrystalSpec.youngs_modulus": "Young's modulus normal to the planes",
    "CrystalSpec.compressive_strength": "theoretical compressive strength sigma_1 of the bulk crystal",
    "CrystalSpec.compressive_strain": "strain at the compressive strength (dimensionless)",
    "CrystalSpec.tensile_strength": "theoretical tensile strength sigma_2 of the bulk crystal",
    "CrystalSpec.tensile_strain": "strain at the tensile strength (dimensionless)",
    "CrystalSpec.deformation_energy_tension": "printed deformation energy in tension (Table 3)",
    "CrystalSpec.deformation_energy_compression": "printed deformation energy in compression (Table 3)",
    "StudySection.name": "study id (names its figure file)",
    "StudySection.basis": "particle basis: parallelogram, rectangle or none",
    "StudySection.l": "number of planes l (integers or \"inf\")",
    "StudySection.mn": "particle sizes m = n (integers or \"inf\")",
    "StudySection.i": "mesolayer index i: all, centre or a list",
    "StudySection.compare": "compare with the printed Table 4 or Table 5",
    "StudySection.plot": "variable on the figure's horizontal axis: i, mn or l",
    # [data]
    "DataSection.file": "CSV of shots, relative to the case file ('#' lines skipped)",
    "DataSection.source": "where the data come from (paper, table)",
    "DataSection.id_column": "column of the shot id",
    "DataSection.velocity_column": "column of the striking velocity",
    "DataSection.velocity_unit": "unit of the velocity column (e.g. m/s)",
    "DataSection.depth_column": "column of the measured depth of penetration",
    "DataSection.depth_unit": "unit of the depth column (e.g. mm)",
    "DataSection.mass_column": "column of each shot's measured projectile mass (optional)",
    "DataSection.mass_unit": "unit of the mass column (e.g. g)",
    "DataSection.select": "keep only rows with these values, {column = [values]}",
    "DataSection.cavity_yield_stress": "the data authors' Y of their cavity-expansion fit (Forrestal peer model)",
    "DataSection.cavity_A": "constant A of sigma_r/Y = A + B sqrt(rho/Y) V + C (rho/Y) V^2 (dimensionless)",
    "DataSection.cavity_B": "constant B of the cavity-expansion fit (dimensionless)",
    "DataSection.cavity_C": "constant C of the cavity-expansion fit (dimensionless)",
    "DataSection.critical_velocity": "measured critical impact velocity U_sC (the Appendix's inverse problem)",
    # [run]
    "RunSection.analyses": "analyses of run (default: what the sections allow)",
    "RunSection.field_depths": "tip depths of the velocity-field exports",
    "RunSection.field_grid": "body-fitted grid of the field [rays, nodes per ray]",
    "RunSection.field_segments": "azimuthal segments of the revolved 3D field",
    "RunSection.field_velocity": "projectile speed u of the field (default from the penetration at that depth)",
    "RunSection.render": "render the 3D field with pyvista (off-screen)",
    "RunSection.vtk_dir": "folder of the .vtu files inside --out",
    "RunSection.figures_dir": "folder of the figures inside --out",
    # [calibration]
    "CalibrationSection.models": "models calibrated (default all rigid-shot models)",
    "CalibrationSection.parameters": "case keys calibrated (default the resistance's strength)",
    "CalibrationSection.discrepancy": "prior of the relative model discrepancy, e.g. halfnormal(0.15)",
    "CalibrationSection.walkers": "emcee walkers",
    "CalibrationSection.steps": "emcee steps per walker",
    "CalibrationSection.burn": "steps discarded as burn-in",
    "CalibrationSection.seed": "seed of the sampler",
    "CalibrationSection.transfer": "case files predicted by the posterior (transfer, not fitted)",
    "CalibrationSection.prior": "priors per parameter, {key = \"normal(400 MPa, 50 MPa)\"}",
    # [perforation]
    "PerforationSection.back_face": "resistance near the back face: finite-sphere cavity expansion or constant",
    "PerforationSection.failure": "plate failure: auto, hole-growth or plug",
    "PerforationSection.shear_strength": "shear strength of the plug's cylinder (failure = plug)",
    "PerforationSection.data": "CSV of perforation shots (striking and residual velocities), relative to the case",
    "PerforationSection.data_source": "where the perforation data come from",
    "PerforationSection.target_hardness": "target hardness H_M for Part IV's V_cr",
    "PerforationSection.target_delta_h": "target hardness factor delta_H (dimensionless)",
    "PerforationSection.projectile_hardness": "projectile hardness for Part IV's V_cr",
    "PerforationSection.projectile_delta_h": "projectile hardness factor delta_H (dimensionless)",
    "PerforationSection.youngs_modulus": "target E for R(3) of Part IV, eq. (6)",
}


def key_description(model, key: str, si: str = "", comment: str = "") -> str:
    """The one-line description of ``key`` in the section ``model`` (a pydantic model class):
    the field's own description, else its source ``comment``, else :data:`KEY_HELP`
    (``"Model.key"``, then ``key``), with the SI unit ``si`` of a quantity appended as
    ``[unit]`` unless the text names it already."""
    field = model.model_fields.get(key)
    text = (field.description if field is not None else None) or comment or KEY_HELP.get(f"{model.__name__}.{key}") \
        or KEY_HELP.get(key, "")
    if text and si and f"[{si}]" not in text:
        text = f"{text} [{si}]"
    return text
