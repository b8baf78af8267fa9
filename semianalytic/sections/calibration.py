"""The ``[calibration]`` case section, prior strings with units, the shots and the posterior file.

Example (``cases/piekutowski1999_var4340.toml``)::

    [calibration]
    models = ["elastic_exact_rod", "quasi_rigid", "forrestal"]   # default: every depth model
    parameters = ["target.resistance.yield_stress"]  # default: the resistance model's strength
    discrepancy = "halfnormal(0.15)"  # prior of sigma, the sd of ln(measured/predicted depth)
    walkers = 32                      # emcee ensemble
    steps = 1000
    burn = 250
    seed = 1
    transfer = ["piekutowski1999_aermet100.toml"]   # cases predicted in --cross-validate
    [calibration.prior]
    "target.resistance.yield_stress" = "lognormal(300 MPa, 0.5)"

The eroding rod (``--model eroding``, Alekseevskii-Tate, issue 17) is calibrated on the shots whose
recorded response (``[data] response_column``) is an eroding one (eroded, broken_eroding), its
parameters ``target.resistance.eroding_resistance`` (R_t) and ``projectile.dynamic_yield_stress``
(Y_p), both by default, with priors as above (``cases/piekutowski1999_var4340_eroding.toml``).  The
other models use the shots recorded rigid (all selected shots when the data name no response).

Priors: ``lognormal(MEDIAN, SIGMA_LN)``, ``normal(MEAN, SD)``, ``uniform(LOW, HIGH)``,
``halfnormal(SCALE)``, quantities with the parameter's unit (dimensionless parameters and
SIGMA_LN plain numbers).  Default prior of a parameter: lognormal(the case's value, 0.5).
"""

from __future__ import annotations

import dataclasses
import json
import math
import re
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from pydantic import Field

from semianalytic.calibration.names import CALIBRATION_MODELS, ERODING, ERODING_KEYS
from semianalytic.calibration.priors import HalfNormal, LogNormal, Normal, Uniform
from semianalytic.errors import InputError
from semianalytic.schema import Section

if TYPE_CHECKING:
    from semianalytic.calibration.models import ShotSet

__all__ = ["CalibrationSection", "parse_prior", "parameter_kind", "default_parameter", "load_shot_set", "shots_in_regime",
           "read_posterior", "POSTERIOR_FORMAT"]

POSTERIOR_FORMAT = "semianalytic-posterior"
# version 2 adds the eroding model (per-model "parameters" and "eroding"); version 1 files are still read
POSTERIOR_VERSION = 2
POSTERIOR_VERSIONS_READ = (1, 2)
MIN_SHOTS = 3

# resistance field -> unit kind (pint) and display unit
_KINDS = {
    "yield_stress": ("pressure", "MPa", 1e6), "youngs_modulus": ("pressure", "GPa", 1e9),
    "compressive_strength": ("pressure", "MPa", 1e6), "tensile_strength": ("pressure", "MPa", 1e6),
    "psi": ("pressure", "MPa", 1e6), "phi": ("pressure", "MPa", 1e6), "value": ("pressure", "MPa", 1e6),
    "reference_diameter": ("length", "mm", 1e-3),
    "poisson_ratio": ("dimensionless", "", 1.0), "alpha": ("dimensionless", "", 1.0),
    "hardening_exponent": ("dimensionless", "", 1.0),
}


class CalibrationSection(Section):
    """``[calibration]`` (see the module docstring)."""

    models: list[str] | None = None
    parameters: list[str] | None = None
    discrepancy: str = "halfnormal(0.15)"
    walkers: int = Field(default=32, ge=4, le=1000)
    steps: int = Field(default=1000, ge=50, le=10**6)
    burn: int = Field(default=250, ge=0)
    seed: int = 1
    transfer: list[str] = Field(default_factory=list)
    prior: dict[str, str] = Field(default_factory=dict)


def parameter_kind(key: str, resistance, *, eroding: bool = False) -> tuple[str, str, float]:
    """(unit kind, display unit, its SI scale) of a calibrated case key, or InputError.  With
    ``eroding`` the keys of the eroding rod (:data:`ERODING_KEYS`), else the resistance's."""
    if eroding or key in ERODING_KEYS:
        if key not in ERODING_KEYS:
            raise InputError("--parameter", f"the eroding model calibrates {' and '.join(ERODING_KEYS)}; got {key!r}")
        if not eroding:
            raise InputError("--parameter", f"{key!r} is a parameter of the eroding rod: calibrate it with --model eroding")
        return ("pressure", "MPa", 1e6)
    prefix = "target.resistance."
    if not key.startswith(prefix):
        raise InputError("--parameter", f"only target.resistance.* keys can be calibrated (the target's "
                                        f"resistance, Part I eqs. (16)-(19)); got {key!r}")
    name = key[len(prefix):]
    fields = {f.name for f in dataclasses.fields(resistance)}
    if name not in fields or name not in _KINDS:
        ok = ", ".join(prefix + f for f in sorted(fields) if f in _KINDS)
        raise InputError("--parameter", f"{key!r} is not a number of the '{resistance.name}' resistance model; "
                                        f"one of: {ok or 'none'}")
    return _KINDS[name]


def default_parameter(resistance) -> str:
    from semianalytic.sections.penetration import MODELS, calibrated_parameter

    name = calibrated_parameter(resistance.name)
    if name is None:
        ok = [m for m in MODELS if calibrated_parameter(m) is not None]
        raise InputError("target.resistance.model", f"the '{resistance.name}' resistance cannot be calibrated; "
                                                    f"use {', '.join(ok[:-1])} or {ok[-1]}")
    return "target.resistance." + name


_PRIOR = re.compile(r"^\s*(lognormal|normal|uniform|halfnormal)\s*\((.*)\)\s*$", re.IGNORECASE)


def _value(text: str, kind: str, field: str) -> float:
    from semianalytic.units import parse_quantity

    text = text.strip()
    if kind == "dimensionless":
        try:
            return float(text)
        except ValueError:
            raise InputError(field, f"expected a plain number; got {text!r}") from None
    return parse_quantity(text, kind, field)


def parse_prior(text, kind: str, field: str):
    """A prior from its string, e.g. ``"lognormal(300 MPa, 0.5)"`` with a ``kind`` quantity."""
    m = _PRIOR.match(text) if isinstance(text, str) else None
    if m is None:
        raise InputError(field, f"expected lognormal(MEDIAN, SIGMA_LN), normal(MEAN, SD), uniform(LOW, HIGH) or "
                                f"halfnormal(SCALE); got {text!r}")
    name, args = m.group(1).lower(), [a for a in m.group(2).split(",")]
    need = 1 if name == "halfnormal" else 2
    if len(args) != need or any(not a.strip() for a in args):
        raise InputError(field, f"{name} takes {need} argument(s); got {text!r}")
    if name == "lognormal":
        median, sigma = _value(args[0], kind, field), _value(args[1], "dimensionless", field)
        if not (median > 0 and sigma > 0):
            raise InputError(field, f"lognormal needs a positive median and sigma; got {text!r}")
        return LogNormal(median, sigma)
    if name == "normal":
        mean, sd = _value(args[0], kind, field), _value(args[1], kind, field)
        if not sd > 0:
            raise InputError(field, f"normal needs a positive sd; got {text!r}")
        return Normal(mean, sd)
    if name == "uniform":
        lo, hi = _value(args[0], kind, field), _value(args[1], kind, field)
        if not hi > lo:
            raise InputError(field, f"uniform needs LOW < HIGH; got {text!r}")
        return Uniform(lo, hi)
    scale = _value(args[0], kind, field)
    if not scale > 0:
        raise InputError(field, f"halfnormal needs a positive scale; got {text!r}")
    return HalfNormal(scale)


def check_models(models) -> tuple[str, ...]:
    for m in models:
        if m not in CALIBRATION_MODELS:
            raise InputError("--model", f"unknown model {m!r}; one of {', '.join(CALIBRATION_MODELS)}")
    models = tuple(dict.fromkeys(models))
    if ERODING in models and len(models) > 1:
        raise InputError("--model", "the eroding model is calibrated on the eroded shots with its own parameters, the "
                                    "others on the rigid shots: calibrate it in a run of its own (--model eroding), "
                                    "then pass both posteriors to penetrate (--posterior A --posterior B)")
    return models


def shots_in_regime(case, shots, regime: str):
    """The shots whose recorded response (``[data] response_column``) maps to ``regime``
    (penetration.regime_setup.RESPONSE_REGIME: rigid -> rigid; eroded, broken_eroding -> eroding).
    Without a response column: every shot for ``rigid`` (the case's ``select`` says which are
    rigid, as before), InputError for ``eroding`` (the eroded shots must be recorded as such)."""
    from semianalytic.penetration.regime_setup import RESPONSE_REGIME

    col = case.require("data").response_column
    if not col:
        if regime == "rigid":
            return shots
        raise InputError("data.response_column", f"the {regime} model is calibrated on the shots recorded {regime}: "
                                                 "name the column of the recorded response (rigid, eroded, ...)")
    for s in shots:
        if s.row.get(col, "") not in RESPONSE_REGIME:
            raise InputError("data.response_column", f"shot {s.id}: response {s.row.get(col, '')!r} is not one of "
                                                     f"{', '.join(RESPONSE_REGIME)}")
    return [s for s in shots if RESPONSE_REGIME[s.row[col]] == regime]


def load_shot_set(case, projectile_mass: float, *, minimum: int = MIN_SHOTS, regime: str | None = None) -> ShotSet:
    """The case's ``[data]`` shots as a :class:`ShotSet` (SI), each with its own mass where the
    data give one, else the projectile's; with ``regime``, only the shots recorded in it
    (:func:`shots_in_regime`).  Bad input (file missing or empty, a column absent,
    a non-positive value, fewer than ``minimum`` shots): InputError naming the field."""
    from semianalytic.calibration.models import ShotSet  # the models load on use
    from semianalytic.penetration.validation import load_shots

    data = case.section("data")
    if data is None or data.file is None:
        raise InputError("data.file", "calibration needs a [data] section with a CSV 'file' of shots")
    shots = load_shots(case)
    if regime is not None:
        shots = shots_in_regime(case, shots, regime)
    if len(shots) < minimum:
        which = f"recorded {regime} " if regime is not None and data.response_column else ""
        raise InputError("data.file", f"at least {minimum} {which}shots with a depth are needed (after 'select'); "
                                      f"got {len(shots)}")
    mass = np.array([s.mass if s.mass is not None else projectile_mass for s in shots], float)
    if not np.all(mass > 0):
        raise InputError("projectile.mass", "the projectile mass must be positive")
    return ShotSet(np.array([s.velocity for s in shots]), mass, np.array([s.depth for s in shots]),
                   tuple(s.id for s in shots))


def _need(obj, key, typ, field):
    if not isinstance(obj, dict) or key not in obj:
        raise InputError(field, f"missing '{key}'")
    val = obj[key]
    if typ is float:
        if isinstance(val, bool) or not isinstance(val, (int, float)) or not math.isfinite(val):
            raise InputError(f"{field}.{key}", f"expected a finite number; got {val!r}")
        return float(val)
    if not isinstance(val, typ):
        raise InputError(f"{field}.{key}", f"expected {typ.__name__}; got {type(val).__name__}")
    return val


def _samples(obj, key, field, n=None) -> np.ndarray:
    arr = _need(obj, key, list, field)
    if len(arr) > MAX_POSTERIOR_DRAWS:
        raise InputError(f"{field}.{key}", f"{len(arr)} draws; a posterior written by calibrate holds at most "
                                           f"{MAX_POSTERIOR_DRAWS}")
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in arr):  # "1.5" is not a draw
        raise InputError(f"{field}.{key}", "expected a list of numbers (JSON numbers, not strings or booleans)")
    try:
        out = np.asarray(arr, float)
    except (TypeError, ValueError):
        raise InputError(f"{field}.{key}", "expected a list of numbers") from None
    if out.ndim != 1 or out.size == 0 or not np.all(np.isfinite(out)) or (n is not None and out.size != n):
        raise InputError(f"{field}.{key}", "expected a non-empty list of finite numbers, one per draw")
    return out


# A posterior.json of calibrate holds a few thousand draws (~0.5 MB); these bounds (this project's
# own, issue 27) stop a file that is no posterior of calibrate before it is parsed into memory.
MAX_POSTERIOR_BYTES = 20e6
MAX_POSTERIOR_DRAWS = 200_000


def read_posterior(path) -> dict:
    """Read and validate a posterior.json written by ``calibrate``; returns
    {"target": ..., "parameters": [keys], "models": {name: {"theta": (n, p), "sigma": (n,)}}, "raw": obj}.
    Every draw is checked: finite, one per draw in every list, and inside its prior's support
    (:func:`_check_support`); an InputError names the file and the parameter."""
    path = Path(path)
    try:
        return _read_posterior(path)
    except InputError as exc:
        if str(path) in exc.message:
            raise
        raise InputError(exc.field, f"{path}: {exc.message}") from None


PRIOR_TAIL = 1e-9
"""A draw of a posterior file must lie inside its prior's central 1 - 2e-9 (the ppf at 1e-9 and
1 - 1e-9: for a lognormal of sigma_ln 0.5 a factor 20 either side of the median).  ``calibrate``
truncates its posterior to the priors' central 1 - 2e-3 (calibration.evaluate._range), so a real
file never comes near; a draw beyond is no draw of that posterior (e.g. edited, or another
prior's)."""


def _check_support(values: np.ndarray, prior_text, kind: str, field: str) -> None:
    """Refuse draws outside the support of the prior written beside them (``prior_text``, as
    ``calibrate`` writes it), within :data:`PRIOR_TAIL`; a file without the text is checked for
    positivity where the parameter is a positive quantity."""
    if not isinstance(prior_text, str):
        return
    prior = parse_prior(prior_text, kind, field)
    lo, hi = (float(v) for v in prior.ppf([PRIOR_TAIL, 1.0 - PRIOR_TAIL]))
    if getattr(prior, "positive", False):
        lo = max(lo, 0.0)
    bad = ~((values >= lo * (1 - 1e-12)) & (values <= hi * (1 + 1e-12)))
    if bad.any():
        k = int(np.argmax(bad))
        raise InputError(field, f"draw {k} is {values[k]:.6g}, outside the support of its prior {prior_text} "
                                f"({lo:.4g} to {hi:.4g} SI, the central 1 - {2 * PRIOR_TAIL:g}): not a posterior of "
                                "that prior")


def _kind_of(key: str) -> str:
    if key in ERODING_KEYS:
        return "pressure"
    return _KINDS.get(key.rsplit(".", 1)[-1], ("dimensionless",))[0]


def _read_posterior(path: Path) -> dict:
    field = "--posterior"
    if not path.is_file():
        raise InputError(field, f"file {str(path)!r} does not exist")
    try:
        size = path.stat().st_size
    except OSError as exc:
        raise InputError(field, f"cannot read {str(path)!r}: {exc.strerror or exc}") from None
    if size > MAX_POSTERIOR_BYTES:
        raise InputError(field, f"{path.name} is {size / 1e6:.0f} MB; a posterior.json written by calibrate is at most "
                                f"{MAX_POSTERIOR_BYTES / 1e6:.0f} MB (this project's own bound)")
    try:
        obj = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(field, f"{path.name} is not a JSON file: {exc}") from None
    if not isinstance(obj, dict) or obj.get("format") != POSTERIOR_FORMAT:
        raise InputError(f"{field}.format", f"expected '{POSTERIOR_FORMAT}' (a posterior.json written by calibrate)")
    version = obj.get("version")
    if isinstance(version, bool) or version not in POSTERIOR_VERSIONS_READ:
        raise InputError(f"{field}.version", f"expected one of {', '.join(map(str, POSTERIOR_VERSIONS_READ))} (the posterior "
                                             f"formats this version reads); got {version!r}")
    target = _need(obj, "target", dict, field)
    _need(target, "density_kg_m3", float, "target")
    _need(target, "resistance_model", str, "target")
    fixed = _need(target, "resistance_fixed", dict, "target")
    for k, v in fixed.items():  # noqa: B007
        _need(fixed, k, float, "target.resistance_fixed")
    params = _need(obj, "parameters", list, field)
    keys = []
    for i, p in enumerate(params):
        keys.append(_need(p, "key", str, f"parameters[{i}]"))
    if not keys:
        raise InputError("parameters", "empty: the posterior holds no calibrated parameter")
    models_obj = _need(obj, "models", dict, field)
    if not models_obj:
        raise InputError("models", "empty: the posterior holds no model")
    models = {}
    for name, mobj in models_obj.items():
        if name not in CALIBRATION_MODELS or (name == ERODING and version < 2):
            raise InputError(f"models.{name}", f"unknown model; one of {', '.join(CALIBRATION_MODELS)}")
        samples = _need(mobj, "samples", dict, f"models.{name}")
        sigma = _samples(samples, "sigma", f"models.{name}.samples")
        if not np.all(np.isfinite(sigma) & (sigma > 0) & (sigma < 10.0)):
            # sigma is the log-normal scale of the depth error: beyond 10 (a factor e^10) it is no model
            raise InputError(f"models.{name}.samples.sigma", "must be finite, positive and below 10")
        mkeys = keys
        if "parameters" in mobj:  # version 2: the keys of this model (default: all of the file's)
            mkeys = [_need({"k": k}, "k", str, f"models.{name}.parameters") for k in _need(mobj, "parameters", list, f"models.{name}")]
            if not mkeys or any(k not in keys for k in mkeys):
                raise InputError(f"models.{name}.parameters", "expected a non-empty list of the file's parameter keys")
        theta = np.column_stack([_samples(samples, k, f"models.{name}.samples", len(sigma)) for k in mkeys])
        priors = {p.get("key"): p.get("prior") for p in params if isinstance(p, dict)}
        for j, k in enumerate(mkeys):
            _check_support(theta[:, j], priors.get(k), _kind_of(k), f"models.{name}.samples.{k}")
        disc = obj.get("discrepancy")
        _check_support(sigma, disc.get("prior") if isinstance(disc, dict) else None, "dimensionless",
                       f"models.{name}.samples.sigma")
        models[name] = {"theta": theta, "sigma": sigma, "parameters": list(mkeys)}
        if name == ERODING:
            models[name]["eroding"] = _eroding_entry(mobj, mkeys, theta, f"models.{name}")
    cav = obj.get("cavity_shape")
    if not (isinstance(cav, list) and len(cav) == 3
            and all(isinstance(c, (int, float)) and not isinstance(c, bool) and math.isfinite(c) and c >= 0 for c in cav)
            and cav[0] > 0):
        raise InputError("cavity_shape", "expected [A, B, C] of the cavity law (A > 0)")
    return {"target": target, "parameters": keys, "models": models, "cavity_shape": tuple(map(float, cav)), "raw": obj}


def _eroding_entry(mobj: dict, keys, theta, field: str) -> dict:
    """The eroding model's own record: the projectile density it was calibrated for and the
    value of each of its two parameters that was not calibrated (SI); every draw positive."""
    ero = _need(mobj, "eroding", dict, field)
    rho = _need(ero, "projectile_density_kg_m3", float, f"{field}.eroding")
    fixed = _need(ero, "fixed", dict, f"{field}.eroding")
    out = {"projectile_density_kg_m3": rho, "fixed": {}}
    for k in ERODING_KEYS:
        if k in keys:
            continue
        out["fixed"][k] = _need(fixed, k, float, f"{field}.eroding.fixed")
        if not out["fixed"][k] > 0:
            raise InputError(f"{field}.eroding.fixed.{k}", "must be positive")
    if not rho > 0 or not np.all(theta > 0) or any(k not in ERODING_KEYS for k in keys):
        raise InputError(f"{field}.samples", f"expected positive draws of {' and/or '.join(ERODING_KEYS)}")
    return out
