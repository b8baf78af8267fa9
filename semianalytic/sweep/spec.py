"""What a sweep varies: grid axes (``--vary``) and seeded random inputs (``--sample``).

``--vary KEY=START:STOP:STEP`` (STOP included), ``--vary KEY=V1,V2,...``;
``--sample KEY=normal(MEAN,SD)`` | ``uniform(LOW,HIGH)`` | ``lognormal(MEDIAN,SIGMA)``
(SIGMA of ln X, dimensionless) | ``triangular(LOW,MODE,HIGH)``, with ``--samples N --seed S``.

Values carry units like case files (``"500 m/s:1.5 km/s:10 m/s"``; bare numbers take the
unit of the one number that has it, e.g. ``500:1500:10 m/s``); dimensionless keys (``crh``,
``poisson_ratio``) take bare numbers.  KEY is a dotted case-file path
(``target.resistance.yield_stress``); ``impact.striking_velocity`` sets
``impact.striking_velocities = [value]``.

Cases are the Cartesian product of the axes (first axis slowest), times the N samples
(innermost) when there are samplers.  A case's id is its index in that order, so a sweep
that is re-run with the same spec enumerates the same cases (``--resume``).
"""

from __future__ import annotations

import copy
import hashlib
import json
import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from semianalytic.errors import InputError
from semianalytic.units import KINDS, registry

VELOCITY_KEY = "impact.striking_velocity"
MAX_CASES = 50_000_000
_DISTRIBUTIONS = {"normal": 2, "uniform": 2, "lognormal": 2, "triangular": 3}


# --------------------------------------------------------------------------------------
# quantities


def _si_unit(q) -> str:
    """The SI unit string (as written in case files) of a pint quantity's dimension."""
    ureg = registry()
    for dim, si, _ in KINDS.values():
        if dim and q.dimensionality == ureg.get_dimensionality(dim):
            return si
    raise ValueError(f"unsupported dimension {q.dimensionality}")


def _parse_numbers(texts: Sequence[str], field: str, dimensionless_ok: Sequence[bool] | None = None):
    """Parse ``texts`` into SI floats sharing one unit; bare numbers borrow it.

    Returns (values, unit) with unit '' for dimensionless numbers.
    """
    ureg = registry()
    parsed = []
    for t in texts:
        t = t.strip()
        if not t:
            raise InputError(field, "empty value")
        try:
            q = ureg.Quantity(t)
        except Exception:
            raise InputError(field, f"cannot read {t!r} as a number with an optional unit") from None
        parsed.append(q)
    with_unit = [q for q in parsed if isinstance(q, ureg.Quantity) and not q.dimensionless]
    unit = ""
    if with_unit:
        try:
            unit = _si_unit(with_unit[0])
        except ValueError as exc:
            raise InputError(field, str(exc)) from None
        dim = with_unit[0].dimensionality
        if any(q.dimensionality != dim for q in with_unit):
            raise InputError(field, "values have different dimensions")
        ref_unit = with_unit[0].units
    out = []
    for i, q in enumerate(parsed):
        if not isinstance(q, ureg.Quantity):
            mag = float(q)
            if with_unit and not (dimensionless_ok and dimensionless_ok[i]):
                mag = float(ureg.Quantity(mag, ref_unit).to(unit.replace("^", "**")).magnitude)
            out.append(mag)
        elif q.dimensionless:
            if with_unit and not (dimensionless_ok and dimensionless_ok[i]):
                mag = float(ureg.Quantity(q.to("dimensionless").magnitude, ref_unit).to(unit.replace("^", "**")).magnitude)
            else:
                mag = float(q.to("dimensionless").magnitude)
            out.append(mag)
        else:
            out.append(float(q.to(unit.replace("^", "**")).magnitude))
    if not all(math.isfinite(v) for v in out):
        raise InputError(field, "values must be finite")
    return out, unit


def column_name(key: str, unit: str) -> str:
    """Results-file column of a varied key: ``target.density_kg_m3``-style, SI unit appended."""
    if not unit:
        return key
    return key + "_" + unit.replace("/", "_").replace("^", "").replace("*", "")


def raw_value(value: float, unit: str, integer: bool = False) -> Any:
    """The value as it would be written in a case file (a unit string, or a bare number)."""
    if unit:
        return f"{float(value)!r} {unit}"
    if integer:
        return int(round(value))
    return float(value)


# --------------------------------------------------------------------------------------
# axes and samplers


@dataclass(frozen=True)
class Axis:
    """A grid axis: ``key`` takes each of ``values`` (SI)."""

    key: str
    values: tuple[float, ...]
    unit: str
    integer: bool = False

    @property
    def column(self) -> str:
        return column_name(self.key, self.unit)


@dataclass(frozen=True)
class Sampler:
    """A random input: ``key`` drawn from ``dist`` with SI parameters ``params``."""

    key: str
    dist: str
    params: tuple[float, ...]
    unit: str

    @property
    def column(self) -> str:
        return column_name(self.key, self.unit)

    def support(self) -> tuple[float, float]:
        """The range the draws cover: the ends of a uniform or triangular distribution; a normal's
        or lognormal's quantiles of 1e-4 and 1 - 1e-4 (a sweep of up to ~10^4 samples reaches
        them; the case must be valid there, issue 40)."""
        p = self.params
        if self.dist == "normal":
            return p[0] - SUPPORT_SIGMAS * p[1], p[0] + SUPPORT_SIGMAS * p[1]
        if self.dist == "lognormal":
            return p[0] * math.exp(-min(SUPPORT_SIGMAS * p[1], 700.0)), p[0] * math.exp(min(SUPPORT_SIGMAS * p[1], 700.0))
        return p[0], p[-1]

    def draw(self, rng: np.random.Generator, n: int) -> np.ndarray:
        p = self.params
        if self.dist == "normal":
            return rng.normal(p[0], p[1], n)
        if self.dist == "uniform":
            return rng.uniform(p[0], p[1], n)
        if self.dist == "lognormal":
            return p[0] * np.exp(rng.normal(0.0, p[1], n))
        if self.dist == "triangular":
            return rng.triangular(p[0], p[1], p[2], n)
        raise AssertionError(self.dist)


def _split_key(text: str, option: str) -> tuple[str, str]:
    if "=" not in text:
        raise InputError(option, f"expected KEY=VALUES, e.g. impact.striking_velocity=500:1500:100 m/s; got {text!r}")
    key, _, rest = text.partition("=")
    key = key.strip()
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)+", key):
        raise InputError(option, f"KEY must be a dotted case-file path like projectile.crh; got {key!r}")
    return key, rest.strip()


def parse_vary(text: str, option: str = "--vary") -> Axis:
    """``KEY=START:STOP:STEP`` (STOP included) or ``KEY=V1,V2,...``."""
    key, rest = _split_key(text, option)
    field = f"{option} {key}"
    if ":" in rest:
        parts = rest.split(":")
        if len(parts) != 3:
            raise InputError(field, f"a range is START:STOP:STEP; got {rest!r}")
        (start, stop, step), unit = _parse_numbers(parts, field)
        if not step > 0:
            raise InputError(field, f"STEP must be positive; got {parts[2]!r}")
        if stop < start:
            raise InputError(field, f"STOP must not be below START; got {rest!r}")
        n = int(math.floor((stop - start) / step * (1 + 1e-12) + 1e-9)) + 1
        if n > MAX_CASES:
            raise InputError(field, f"{n} values is too many")
        values = [start + i * step for i in range(n)]
    else:
        values, unit = _parse_numbers(rest.split(","), field)
    integer = not unit and all(float(v).is_integer() for v in values) and not any("." in p or "e" in p.lower() for p in re.split("[,:]", rest))  # noqa: E501
    return Axis(key, tuple(values), unit, integer)


def parse_sample(text: str, option: str = "--sample") -> Sampler:
    """``KEY=normal(MEAN,SD)`` and the other distributions of the module docstring."""
    key, rest = _split_key(text, option)
    field = f"{option} {key}"
    m = re.fullmatch(r"([a-z]+)\((.*)\)", rest)
    if not m or m.group(1) not in _DISTRIBUTIONS:
        names = ", ".join(f"{k}(...)" for k in _DISTRIBUTIONS)
        raise InputError(field, f"expected one of {names}; got {rest!r}")
    dist, args = m.group(1), [a for a in m.group(2).split(",")]
    if len(args) != _DISTRIBUTIONS[dist]:
        raise InputError(field, f"{dist} takes {_DISTRIBUTIONS[dist]} arguments; got {len(args)}")
    dimless = [False, True] if dist == "lognormal" else None
    params, unit = _parse_numbers(args, field, dimless)
    if dist == "normal" and not params[1] > 0:
        raise InputError(field, "the standard deviation must be positive")
    if dist == "uniform" and not params[1] > params[0]:
        raise InputError(field, "uniform(LOW,HIGH) needs HIGH > LOW")
    if dist == "lognormal" and not (params[0] > 0 and params[1] > 0):
        raise InputError(field, "lognormal(MEDIAN,SIGMA) needs MEDIAN > 0 and SIGMA > 0")
    if dist == "triangular" and not (params[0] <= params[1] <= params[2] and params[0] < params[2]):
        raise InputError(field, "triangular(LOW,MODE,HIGH) needs LOW <= MODE <= HIGH and LOW < HIGH")
    if unit:  # issue 27: a quantity with a unit (strength, density, velocity, length) is positive
        if dist == "normal" and params[0] < NORMAL_SIGMAS * params[1]:
            import math

            p_neg = 0.5 * math.erfc(params[0] / (params[1] * math.sqrt(2)))
            raise InputError(field, f"normal(MEAN,SD) draws values <= 0 with probability {p_neg:.2g}, and the quantity "
                                    f"is positive: give SD <= MEAN/{NORMAL_SIGMAS:g} or use lognormal(MEDIAN,SIGMA)")
        if dist in ("uniform", "triangular") and not params[0] > 0:
            raise InputError(field, f"{dist}(...) reaches values <= 0, and the quantity is positive: give LOW > 0")
    return Sampler(key, dist, tuple(params), unit)


# The standard-normal quantile of 1 - 1e-4: the support of a normal or lognormal sample checked up front.
SUPPORT_SIGMAS = 3.719


# A normal distribution of a positive quantity must keep its mean this many standard deviations
# above zero (P(x <= 0) < 3e-5; this project's own rule, issue 27).
NORMAL_SIGMAS = 4.0


# --------------------------------------------------------------------------------------
# the whole spec


@dataclass(frozen=True)
class SweepSpec:
    axes: tuple[Axis, ...] = ()
    samplers: tuple[Sampler, ...] = ()
    n_samples: int = 0
    seed: int = 0

    def __post_init__(self):
        keys = [a.key for a in self.axes] + [s.key for s in self.samplers]
        dup = {k for k in keys if keys.count(k) > 1}
        if dup:
            raise InputError("--vary", f"key {sorted(dup)[0]!r} is varied twice")
        if not keys:
            raise InputError("--vary", "nothing to sweep: give at least one --vary or --sample")
        if self.samplers and self.n_samples < 1:
            raise InputError("--samples", "must be at least 1 with --sample")
        if self.n_cases > MAX_CASES:
            raise InputError("--vary", f"{self.n_cases} cases is more than the limit {MAX_CASES}")

    @property
    def grid_shape(self) -> tuple[int, ...]:
        return tuple(len(a.values) for a in self.axes)

    @property
    def n_cases(self) -> int:
        n = int(np.prod(self.grid_shape, dtype=np.int64)) if self.axes else 1
        return n * (self.n_samples if self.samplers else 1)

    @property
    def keys(self) -> tuple[str, ...]:
        return tuple(a.key for a in self.axes) + tuple(s.key for s in self.samplers)

    @property
    def columns(self) -> dict[str, str]:
        """key -> results-file column."""
        return {**{a.key: a.column for a in self.axes}, **{s.key: s.column for s in self.samplers}}

    def units(self) -> dict[str, str]:
        return {**{a.key: a.unit for a in self.axes}, **{s.key: s.unit for s in self.samplers}}

    def sampled_keys(self) -> set[str]:
        return {s.key for s in self.samplers}

    def integer_keys(self) -> set[str]:
        return {a.key for a in self.axes if a.integer}

    def draws(self) -> dict[str, np.ndarray]:
        """All random draws, in a fixed order (reproducible from the seed)."""
        rng = np.random.default_rng(self.seed)
        return {s.key: s.draw(rng, self.n_samples) for s in self.samplers}

    def values(self, ids: np.ndarray, draws: Mapping[str, np.ndarray] | None = None) -> dict[str, np.ndarray]:
        """SI value of every varied key for the case ids (vectorised)."""
        ids = np.asarray(ids, dtype=np.int64)
        ns = self.n_samples if self.samplers else 1
        grid_id, sample_id = np.divmod(ids, ns)
        out: dict[str, np.ndarray] = {}
        if self.axes:
            idx = np.unravel_index(grid_id, self.grid_shape)
            for a, i in zip(self.axes, idx):
                out[a.key] = np.asarray(a.values, dtype=float)[i]
        if self.samplers:
            draws = draws if draws is not None else self.draws()
            for s in self.samplers:
                out[s.key] = draws[s.key][sample_id]
        return out

    def to_json(self) -> dict:
        return {
            "axes": [{"key": a.key, "unit": a.unit, "integer": a.integer, "values": list(a.values)} for a in self.axes],
            "samplers": [{"key": s.key, "dist": s.dist, "params": list(s.params), "unit": s.unit} for s in self.samplers],
            "n_samples": self.n_samples,
            "seed": self.seed,
        }

    def fingerprint(self) -> str:
        return hashlib.sha256(json.dumps(self.to_json(), sort_keys=True).encode()).hexdigest()[:16]


def build_spec(vary: Sequence[str] = (), sample: Sequence[str] = (), n_samples: int = 0, seed: int = 0) -> SweepSpec:
    axes = tuple(parse_vary(v) for v in vary)
    samplers = tuple(parse_sample(s) for s in sample)
    if samplers and n_samples < 1:
        raise InputError("--samples", "give the number of Monte-Carlo samples (>= 1) with --sample")
    if n_samples and not samplers:
        raise InputError("--samples", "--samples needs at least one --sample KEY=DIST(...)")
    return SweepSpec(axes, samplers, int(n_samples), int(seed))


# --------------------------------------------------------------------------------------
# applying values to a case


def apply_overrides(raw: Mapping[str, Any], overrides: Mapping[str, Any]) -> dict:
    """A deep copy of the parsed TOML ``raw`` with dotted keys set to case-file values.

    ``impact.striking_velocity`` sets ``impact.striking_velocities = [value]``.  A missing
    section or sub-table is created (validation then says whether it is allowed).
    """
    out = copy.deepcopy(dict(raw))
    for key, value in overrides.items():
        parts = key.split(".")
        if key == VELOCITY_KEY:
            parts, value = ["impact", "striking_velocities"], [value]
        node = out
        for p in parts[:-1]:
            nxt = node.get(p)
            if nxt is None:
                nxt = node[p] = {}
            elif not isinstance(nxt, dict):
                raise InputError(key, f"{p!r} is not a table in the case, so {key!r} cannot be set")
            node = nxt
        node[parts[-1]] = value
    return out
