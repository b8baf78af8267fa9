"""The optimisation problem from the command line, checked against the case (case layer).

``--vary KEY=LOW:HIGH`` (repeatable) names a nose-shape parameter and its bounds, with units
like case files (``projectile.half_angle=10 deg:40 deg``; ``crh`` is a bare number).  Allowed
keys per nose kind: ogive ``projectile.crh`` (>= 0.5); cone ``projectile.half_angle``; power
``projectile.exponent`` (in (0, 1]) and ``projectile.nose_length``; spline
``projectile.control_radii.K`` (the K-th control radius, 0-based, a fraction of d/2 in (0, 1])
and ``projectile.nose_length``; and
``projectile.meplat_diameter`` / ``projectile.tip_radius`` (blunted or truncated ogives and
cones) where the case schema has them.

Every bound corner and the bounds' centre must make a valid case that meets the constraints,
else exit 2 naming the flag (``--vary projectile.crh``, ``--constraint mass``); nothing is
written before these checks pass.
"""

from __future__ import annotations

import itertools
import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from semianalytic.case import Case, ProjectileSection, parse_case
from semianalytic.errors import InputError
from semianalytic.optimize.model import (
    CONSTRAINTS,
    DEPTH_MODELS,
    OBJECTIVES,
    PLATE_OBJECTIVES,
    SEARCH_KNOTS_PER_PIECE,
    Infeasible,
    shank_for_constraints,
)
from semianalytic.sweep.spec import apply_overrides

# key -> (nose kinds it applies to (None: any with the schema key), SI unit of its values, parse kind)
NOSE_KEYS: dict[str, tuple[tuple[str, ...] | None, str, str | None]] = {
    "projectile.crh": (("ogive",), "", None),
    "projectile.half_angle": (("cone",), "rad", "angle"),
    "projectile.meplat_diameter": (None, "m", "length"),
    "projectile.tip_radius": (None, "m", "length"),
    "projectile.exponent": (("power",), "", None),
    "projectile.nose_length": (("power", "spline"), "m", "length"),
}
# a spline nose's control radius K (0-based): --vary projectile.control_radii.K=LOW:HIGH (fractions of d/2)
CONTROL_RADIUS = "projectile.control_radii"


def control_index(key: str) -> int | None:
    """K of ``projectile.control_radii.K`` (None for any other key)."""
    head, _, k = key.rpartition(".")
    return int(k) if head == CONTROL_RADIUS and k.isdigit() else None


@dataclass(frozen=True)
class Variable:
    """A design variable: a case key between ``low`` and ``high`` (SI)."""

    key: str
    low: float
    high: float
    unit: str  # SI unit of the values ('' dimensionless)

    @property
    def flag(self) -> str:
        return f"--vary {self.key}"

    def raw(self, value: float) -> Any:
        """The value as a case file writes it."""
        return float(value) if not self.unit else f"{float(value)!r} {self.unit}"


@dataclass(frozen=True)
class Problem:
    """A validated optimisation problem (sent to the workers: plain data only)."""

    raw_json: str  # the base case (parsed TOML) as JSON
    case_path: str | None
    variables: tuple[Variable, ...]
    objective: str
    depth_model: str
    constraints: tuple[str, ...]
    fixed_mass: float | None  # m0 [kg] when --constraint mass
    fixed_length: float | None  # L0 [m] when --constraint length
    start_shank: float
    velocities: tuple[float, ...] = field(default=())
    # [coefficients] settings of every design's table (--table-depths, --table-nose-lengths): key -> value
    table_overrides: tuple[tuple[str, Any], ...] = field(default=())
    # depth objective: knots per smooth piece of its table over [0, P_max] (only the depths it reads,
    # optimize.model.depth_knots); 0: the case's own table to the deep limit (before issue 24)
    depth_knots: int = SEARCH_KNOTS_PER_PIECE

    @property
    def low(self) -> list[float]:
        return [v.low for v in self.variables]

    @property
    def high(self) -> list[float]:
        return [v.high for v in self.variables]

    def overrides(self, x) -> dict:
        return {v.key: v.raw(xi) for v, xi in zip(self.variables, x)}


def _parse_bound(text: str, kind: str | None, field_: str) -> tuple[float, str]:
    from semianalytic.units import parse_quantity

    text = text.strip()
    if kind is None:
        try:
            return float(text), ""
        except ValueError:
            raise InputError(field_, f"expected a number; got {text!r}") from None
    return parse_quantity(text, kind, field_), text


def parse_variable(text: str) -> Variable:
    """``KEY=LOW:HIGH`` -> Variable (syntax and units only; the case checks come later)."""
    if "=" not in text:
        raise InputError("--vary", f"expected KEY=LOW:HIGH, e.g. projectile.crh=1:6; got {text!r}")
    key, _, rest = (s.strip() for s in text.partition("="))
    if control_index(key) is not None:
        flag = f"--vary {key}"
        parts = rest.split(":")
        if len(parts) != 2:
            raise InputError(flag, f"bounds are LOW:HIGH; got {rest!r}")
        low, high = (_parse_bound(t, None, flag)[0] for t in parts)
        if not (0.0 < low < high <= 1.0):
            raise InputError(flag, f"a control radius is a fraction of d/2: need 0 < LOW < HIGH <= 1; got {rest!r}")
        return Variable(key, low, high, "")
    if key not in NOSE_KEYS:
        raise InputError("--vary", f"{key!r} is not a nose-shape parameter; one of {', '.join(NOSE_KEYS)}, "
                                   f"{CONTROL_RADIUS}.K (K = 0, 1, ..)")
    kinds, unit, kind = NOSE_KEYS[key]
    flag = f"--vary {key}"
    parts = rest.split(":")
    if len(parts) != 2:
        raise InputError(flag, f"bounds are LOW:HIGH; got {rest!r}")
    lo_t, hi_t = parts
    if kind is not None:  # a bare number borrows the other bound's unit ("0:2 mm")
        unit_of = lambda t: t.strip().lstrip("+-0123456789.eE ").strip()  # noqa: E731
        if not unit_of(lo_t) and unit_of(hi_t):
            lo_t = f"{lo_t.strip()} {unit_of(hi_t)}"
        if not unit_of(hi_t) and unit_of(lo_t):
            hi_t = f"{hi_t.strip()} {unit_of(lo_t)}"
    low, _ = _parse_bound(lo_t, kind, flag)
    high, _ = _parse_bound(hi_t, kind, flag)
    if not high > low:
        raise InputError(flag, f"HIGH must be above LOW; got {rest!r}")
    if key == "projectile.exponent" and not (low > 0.0 and high <= 1.0):
        raise InputError(flag, f"the power-law exponent must lie in (0, 1]; got {rest!r}")
    if key == "projectile.nose_length" and not low > 0.0:
        raise InputError(flag, f"the nose length must be positive; got LOW = {low:g} m")
    if key == "projectile.crh" and low < 0.5:
        raise InputError(flag, f"crh must be >= 0.5 for a tangent ogive (0.5 is the hemisphere); got LOW = {low:g}")
    return Variable(key, low, high, unit)


def _design_raw(problem: Problem, overrides: Mapping[str, Any]) -> dict:
    """The base case with the overrides; ``projectile.control_radii.K`` sets one radius of the list."""
    radii = {control_index(k): v for k, v in overrides.items() if control_index(k) is not None}
    raw = apply_overrides(json.loads(problem.raw_json), {k: v for k, v in overrides.items() if control_index(k) is None})
    if radii:
        p = raw.setdefault("projectile", {})
        values = list(p.get("control_radii") or [])
        for k, v in radii.items():
            if k >= len(values):
                raise InputError(f"{CONTROL_RADIUS}.{k}", f"the case's spline nose has {len(values)} control radii "
                                                          f"(K = 0..{len(values) - 1})")
            values[k] = v
        p["control_radii"] = values
    return raw


def design_case(problem: Problem, overrides: Mapping[str, Any]) -> Case:
    """The validated case of one design: the overrides applied, then the shank (and mass) that
    meet the constraints (:func:`~semianalytic.optimize.model.shank_for_constraints`).
    Raises InputError (invalid shape) or Infeasible (a constraint cannot be met)."""
    from semianalytic.geometry import nose_from_section

    path = Path(problem.case_path) if problem.case_path else None
    raw = _design_raw(problem, {**dict(problem.table_overrides), **overrides})
    case = parse_case(raw, path)
    psec = case.require("projectile")
    nose = nose_from_section(psec)
    choice = shank_for_constraints(
        nose.volume(), nose.length, psec.diameter, start_shank=problem.start_shank, density=psec.density,
        mass=problem.fixed_mass, length=problem.fixed_length,
    )
    p = dict(raw["projectile"])
    p.pop("length", None)
    p["shank_length"] = f"{float(choice.shank_length)!r} m"
    if choice.mass is not None:
        p["mass"] = f"{float(choice.mass)!r} kg"
    raw["projectile"] = p
    return parse_case(raw, path)


def build_problem(
    case: Case,
    vary: list[str],
    objective: str,
    constraints: list[str],
    depth_model: str = "rigid",
    table_depths: int | None = None,
    table_nose_lengths: float | None = None,
    striking_velocity: str | None = None,
    depth_knots: int | None = None,
) -> Problem:
    """Parse and check everything the user gave (exit 2 naming the flag on bad input).

    ``table_depths`` / ``table_nose_lengths`` set every design's ``[coefficients] depths`` and
    ``max_depth_nose_lengths`` (the design tables; None: the case's own); ``striking_velocity``
    (``--striking-velocity``, with units): the depth objective at that one velocity;
    ``depth_knots`` (``--depth-knots``): knots per piece of the depth objective's tables over the
    depths it reads (default 4; 0: the case's own tables; ignored with ``table_depths`` /
    ``table_nose_lengths``, which set the case's tables)."""
    from semianalytic.geometry import projectile_from_section

    if objective not in OBJECTIVES:
        raise InputError("--objective", f"must be one of {', '.join(OBJECTIVES)}; got {objective!r}")
    if depth_model not in DEPTH_MODELS:
        raise InputError("--depth-model", f"must be one of {', '.join(DEPTH_MODELS)}; got {depth_model!r}")
    if not vary:
        raise InputError("--vary", "give at least one nose parameter to optimise, e.g. --vary projectile.crh=1:6")
    psec = case.projectile
    if psec is None:
        raise InputError("--objective", "the case has no [projectile]: there is no nose to optimise")
    variables = tuple(parse_variable(v) for v in vary)
    keys = [v.key for v in variables]
    if len(set(keys)) != len(keys):
        raise InputError("--vary", "a key is varied twice")
    for v in variables:
        k = control_index(v.key)
        if k is not None:
            if psec.nose != "spline":
                raise InputError(v.flag, f"applies to a spline nose; the case's nose is {psec.nose!r}")
            if k >= len(psec.control_radii or []):
                raise InputError(v.flag, f"the case's spline nose has {len(psec.control_radii or [])} control radii "
                                         f"(K = 0..{len(psec.control_radii or []) - 1})")
            continue
        kinds = NOSE_KEYS[v.key][0]
        name = v.key.split(".", 1)[1]
        if kinds is not None and psec.nose not in kinds:
            raise InputError(v.flag, f"applies to a {' or '.join(kinds)} nose; the case's nose is {psec.nose!r}")
        if kinds is None and name not in ProjectileSection.model_fields:
            raise InputError(v.flag, f"this version's [projectile] has no {name!r} key")
        if name == "meplat_diameter" and not v.high < psec.diameter:
            raise InputError(v.flag, f"the meplat must be smaller than the diameter {psec.diameter * 1e3:g} mm; "
                                     f"got HIGH = {v.high * 1e3:g} mm")
        if name == "tip_radius" and not v.high < 0.5 * psec.diameter:
            raise InputError(v.flag, f"the tip radius must be below d/2 = {psec.diameter * 500:g} mm; "
                                     f"got HIGH = {v.high * 1e3:g} mm")
    for c in constraints:
        if c not in CONSTRAINTS:
            raise InputError("--constraint", f"must be one of {', '.join(CONSTRAINTS)}; got {c!r}")
    cons = tuple(dict.fromkeys(constraints))
    # objective defined for the case?
    velocities: tuple[float, ...] = ()
    if objective == "depth":
        if case.target is None or case.target.resistance is None:
            raise InputError("--objective", "depth needs a [target.resistance] in the case (the target's R_t)")
        if case.impact is None and striking_velocity is None:
            raise InputError("--objective", "depth needs [impact] striking_velocities in the case (or --striking-velocity)")
        velocities = tuple(case.impact.striking_velocities) if case.impact is not None else ()
        if depth_model == "exact-rod" and (psec.youngs_modulus is None or psec.density is None and psec.mass is None):
            raise InputError("--depth-model", "exact-rod needs projectile.youngs_modulus (e.g. '210 GPa')")
    elif objective in PLATE_OBJECTIVES:
        velocities = check_plate_objective(case, objective, striking_velocity)
    else:
        extra = [c for c in cons if c != "caliber"]
        if extra:
            raise InputError("--constraint", f"{extra[0]} is not defined for --objective deep_drag: the deep drag "
                                             "Bbar depends on the nose shape only, not on the mass or the length")
    if striking_velocity is not None:
        from semianalytic.units import parse_quantity

        if objective not in ("depth", "residual_velocity"):
            raise InputError("--striking-velocity", f"applies to --objective depth or residual_velocity, not {objective}")
        v = parse_quantity(striking_velocity, "velocity", "--striking-velocity")
        if not v > 0:
            raise InputError("--striking-velocity", f"must be positive (m/s); got {striking_velocity!r}")
        velocities = (float(v),)
    start = projectile_from_section(psec)
    fixed_mass = fixed_length = None
    if "mass" in cons:
        if psec.density is None and psec.mass is None:
            raise InputError("--constraint", "mass needs projectile.density (or projectile.mass) in the case")
        fixed_mass = start.mass
        if psec.density is None and "length" not in cons:  # a given mass with a free length: already fixed
            fixed_mass = None
    if "length" in cons:
        fixed_length = start.length
    tables: list[tuple[str, Any]] = []
    if table_depths is not None:
        if not 8 <= table_depths <= 2000:
            raise InputError("--table-depths", f"must lie in [8, 2000] (depths of each design's table); got {table_depths}")
        tables.append(("coefficients.depths", int(table_depths)))
    if table_nose_lengths is not None:
        if not table_nose_lengths > 1.0:
            raise InputError("--table-nose-lengths", f"must be above 1 (nose lengths); got {table_nose_lengths:g}")
        tables.append(("coefficients.max_depth_nose_lengths", float(table_nose_lengths)))
    if depth_knots is None:
        depth_knots = SEARCH_KNOTS_PER_PIECE
    if depth_knots != 0 and not 2 <= depth_knots <= 64:
        raise InputError("--depth-knots", f"must be 0 (the case's own tables) or lie in [2, 64] (knots per piece); "
                                          f"got {depth_knots}")
    problem = Problem(
        json.dumps(case.raw), str(case.path) if case.path else None, variables, objective, depth_model, cons,
        fixed_mass, fixed_length, start.shank_length, velocities, tuple(tables), int(depth_knots),
    )
    check_bounds(problem)
    return problem


def check_plate_objective(case: Case, objective: str, striking_velocity: str | None) -> tuple[float, ...]:
    """A plate objective needs a plate ([target] thickness or [[target.layers]]) and the perforation
    model (:mod:`semianalytic.perforation`); residual_velocity also striking velocities.  Returns them."""
    from semianalytic.sweep.perforation import has_plate

    if not has_plate(case):
        raise InputError("--objective", f"{objective} needs a plate case: [target] thickness = '20 mm' (or "
                                        "[[target.layers]]); this case is a half-space")
    velocities = tuple(case.impact.striking_velocities) if case.impact is not None else ()
    if objective == "residual_velocity" and not velocities and striking_velocity is None:
        raise InputError("--objective", "residual_velocity needs [impact] striking_velocities (or --striking-velocity)")
    return velocities


def check_bounds(problem: Problem) -> None:
    """Every corner of the bounds and their centre must be a valid design meeting the constraints."""
    corners = list(itertools.product(*[(v.low, v.high) for v in problem.variables]))
    corners.append(tuple(0.5 * (v.low + v.high) for v in problem.variables))
    if sum(control_index(v.key) is not None for v in problem.variables) > 1:
        # several control radii: corners of the box may be non-monotone or non-convex meridians (invalid designs,
        # marked so in the search); the box's centre must be a valid design
        corners = corners[-1:]
    for x in corners:
        try:
            from semianalytic.guards import check_case

            check_case(design_case(problem, problem.overrides(x)))  # and its BEM table fits the budget
        except Infeasible as exc:
            shown = ", ".join(f"{v.key.split('.', 1)[1]} = {xi:g} {v.unit}".rstrip() for v, xi in zip(problem.variables, x))
            raise InputError(f"--constraint {exc.constraint}", f"cannot be met at the bounds' corner {shown}: {exc}") from None
        except InputError as exc:
            var = next((v for v in problem.variables if v.key == exc.field or str(exc.field).endswith(v.key.split(".")[-1])),
                       problem.variables[0])
            lo, hi = (f"{b:g} {var.unit}".strip() for b in (var.low, var.high))
            raise InputError(var.flag, f"bounds {lo}:{hi} outside the nose's validity: {exc}") from None
