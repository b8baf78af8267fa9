"""The Python face of the project: what a notebook or a script needs, in a few functions.

Every function here is a thin wrapper over the code the commands run (the same case layer,
the same cached coefficient tables, the same evaluation), so a script gets exactly the numbers
``python -m semianalytic penetrate`` prints.  Quantities in a case are unit strings
(``"7.11 mm"``); a quantity passed to a function is an SI float or a unit string
(``"800 m/s"``); everything returned is in SI units, named in the keys (``depth_m``).

Every command returns a frozen :class:`Result`: ``result["depth_m"]`` (NumPy arrays),
``result.to_frame()`` (a pandas DataFrame, one row per velocity or case, units in the column
names) and ``result.to_dict()`` (the JSON the command prints).  Model-validity notices are
Python warnings of class :class:`semianalytic.errors.ValidityWarning` (filter them with
``warnings.simplefilter``); bad input raises :class:`semianalytic.errors.InputError`.

Example (more in ``docs/examples/``, the gallery of the docs site):

    from semianalytic import api

    case = api.load_case("cases/piekutowski1999_var4340.toml")
    print(api.depth(case, 800.0))          # m, the regime-aware depth at 800 m/s
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "case_from_dict",
    "case_from_keywords",
    "load_case",
    "geometry",
    "coefficients",
    "coefficients_at",
    "penetrate",
    "depth",
    "predict_with_posterior",
    "perforate",
    "ballistic_limit",
    "cavity",
    "nanostrength",
    "optimize",
    "sweep",
]

# The depths of `depth()`: the regime-aware depth and each Part I or peer model of `penetrate`.
DEPTH_MODELS = {
    "regime_aware": "depth_m",
    "rigid": "depth_rigid_m",
    "quasi_rigid": "depth_quasi_rigid_m",
    "elastic": "depth_elastic_m",
    "elastic_exact_rod": "depth_elastic_exact_rod_m",
    "forrestal": "depth_forrestal_m",
    "chen_li": "depth_chen_li_m",
    "eroding": "depth_eroding_m",
}


# --- results ------------------------------------------------------------------------------


def _array(value):
    """A list of numbers (None for "no value") as a float array, of booleans as a bool array;
    anything else as it is (strings, nested dicts)."""
    if isinstance(value, (list, tuple)) and value and all(
            v is None or (isinstance(v, (int, float, np.number)) and not isinstance(v, bool)) for v in value) \
            and any(v is not None for v in value):
        return np.array([np.nan if v is None else v for v in value], float)
    if isinstance(value, (list, tuple)) and value and all(isinstance(v, (bool, np.bool_)) for v in value):
        return np.array(value, bool)
    return value


class Quantiles(dict):
    """Quantile level -> values: float keys (``q[0.05]``); the strings of the JSON
    (``q["0.05"]``) are accepted too."""

    def __getitem__(self, key):
        return super().__getitem__(float(key) if isinstance(key, str) else key)

    def __contains__(self, key):
        try:
            return super().__contains__(float(key) if isinstance(key, str) else key)
        except ValueError:
            return False

    def get(self, key, default=None):
        return self[key] if key in self else default


@dataclass(frozen=True)
class Result(Mapping):
    """What a command computes, in SI units: the JSON it prints, as a read-only mapping.

    ``result[key]`` gives NumPy arrays for per-velocity (or per-case) lists of numbers (NaN
    where the command prints null); :meth:`to_frame` gives a pandas DataFrame with one row per
    velocity or case, the units in the column names and the scalars in ``frame.attrs``;
    :meth:`to_dict` gives the JSON the command prints.
    """

    data: Mapping[str, Any]
    command: str = ""
    rows_key: str | None = "striking_velocity_m_s"

    def __post_init__(self):
        import types

        object.__setattr__(self, "data", types.MappingProxyType(dict(self.data)))  # read-only at the top

    def __getitem__(self, key: str):
        value = self.data[key]
        if key == "depth_quantiles_m" and isinstance(value, Mapping):
            return {m: Quantiles({float(q): _array(v) for q, v in qs.items()}) for m, qs in value.items()}
        return _array(value)

    def __iter__(self):
        return iter(self.data)

    def __len__(self) -> int:
        return len(self.data)

    def __repr__(self) -> str:
        return f"<{type(self).__name__} of {self.command or 'semianalytic'}: {', '.join(list(self.data)[:8])}, ...>"

    def _repr_html_(self) -> str:
        """A notebook shows the frame."""
        try:
            return self.to_frame()._repr_html_()
        except Exception:  # a result without a table
            return f"<pre>{self!r}</pre>"

    @property
    def warnings(self) -> list[str]:
        """The notices the command prints on stderr (also issued as Python warnings)."""
        return list(self.data.get("warnings", []))

    def to_dict(self) -> dict:
        """The JSON the command prints (strict JSON: a non-finite number is null)."""
        import copy

        from semianalytic.report.output import json_safe

        return json_safe(copy.deepcopy(dict(self.data)))

    def _rows(self) -> int | None:
        if self.rows_key is None or self.rows_key not in self.data:
            return None
        return len(self.data[self.rows_key])

    def to_frame(self):
        """A pandas DataFrame: one row per striking velocity (or case), a column per quantity
        (units in the names: ``depth_m``); per-model lists become ``<key>.<model>`` columns,
        quantiles ``depth_quantiles_m.<model>.<level>``; the scalars go into ``frame.attrs``."""
        import pandas as pd

        n = self._rows()
        if n is None:
            return pd.DataFrame([self.to_dict()])
        cols, attrs = {}, {}

        def walk(prefix, value):
            if isinstance(value, (list, tuple)) and len(value) == n and all(not isinstance(v, (dict, list)) for v in value):
                cols[prefix] = _array(list(value)) if value else value
            elif isinstance(value, Mapping):
                for k, v in value.items():
                    walk(f"{prefix}.{k}", v)
            elif not isinstance(value, (list, tuple)):
                attrs[prefix] = value

        for key, value in self.data.items():
            if key != "warnings":
                walk(key, value)
        frame = pd.DataFrame(cols)
        frame.attrs.update(attrs)
        return frame


@dataclass(frozen=True)
class TableResult(Result):
    """A result whose rows are a list of records (``rows`` of ``ballistic-limit``, one per
    shot; the cases of a sweep): :meth:`to_frame` has one row per record."""

    rows_key: str | None = "rows"

    def to_frame(self):
        import pandas as pd

        def flat(rec, prefix=""):
            out = {}
            for k, v in rec.items():
                if isinstance(v, Mapping):
                    out.update(flat(v, f"{prefix}{k}."))
                elif not isinstance(v, list):
                    out[f"{prefix}{k}"] = v
            return out

        frame = pd.DataFrame([flat(r) for r in self.data.get(self.rows_key, [])])
        frame.attrs.update({k: v for k, v in self.data.items() if k != self.rows_key and not isinstance(v, (list, dict))})
        return frame


def _issue(lines, command: str) -> None:
    """The ``warning: ...`` lines of a result as :class:`~semianalytic.errors.ValidityWarning`,
    attributed to the caller's line (the first frame outside the package)."""
    import sys

    from semianalytic.errors import ValidityWarning

    level, frame = 1, sys._getframe(0)
    package = str(Path(__file__).resolve().parent)
    while frame is not None and str(Path(frame.f_code.co_filename).resolve()).startswith(package):
        level, frame = level + 1, frame.f_back
    for line in lines or []:
        text = str(line)
        if text.startswith("warning: "):
            warnings.warn(f"{command}: {text[len('warning: '):]}", ValidityWarning, stacklevel=level)


class _Reissue:
    """Collect the validity warnings the models issue inside an API call and issue them again
    from the caller's line (a model's own ``stacklevel`` points inside the package)."""

    def __init__(self, command: str):
        self.command = command

    def __enter__(self):
        self._cm = warnings.catch_warnings(record=True)
        self._seen = self._cm.__enter__()
        warnings.simplefilter("always")
        return self

    def __exit__(self, *exc):
        self._cm.__exit__(*exc)
        from semianalytic.errors import ValidityWarning

        for w in self._seen:
            if issubclass(w.category, ValidityWarning):
                _issue([f"warning: {w.message}"], self.command)
            else:
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        return False


def _quantities(value, kind: str, field: str) -> np.ndarray:
    """SI floats from floats or unit strings (one or a sequence), with the case layer's errors."""
    from semianalytic.errors import InputError
    from semianalytic.units import parse_quantity

    items = [value] if isinstance(value, (str, int, float, np.number)) else list(np.ravel(np.asarray(value, dtype=object)))
    out = []
    for i, v in enumerate(items):
        name = field if len(items) == 1 else f"{field}[{i}]"
        if isinstance(v, str):
            out.append(parse_quantity(v, kind, name))
        elif isinstance(v, (int, float, np.number)) and not isinstance(v, bool) and np.isfinite(v):
            out.append(float(v))
        else:
            raise InputError(name, f"expected a {kind} as a number in SI units or a unit string, e.g. '800 m/s'; got {v!r}")
    return np.asarray(out, float)


def _velocities(velocities):
    return None if velocities is None else _quantities(velocities, "velocity", "velocities")


# --- building a case ---------------------------------------------------------------------


def case_from_dict(data: Mapping[str, Any]):
    """Validate a case given as a dict, exactly as a TOML case file would be read.

    Parameters
    ----------
    data : Mapping[str, Any]
        The case's sections as nested dicts (``{"projectile": {...}, "target": {...}}``),
        quantities as unit strings (``"7.11 mm"``); the keys are those of the case-file
        reference.

    Returns
    -------
    semianalytic.case.Case
        The validated, frozen case (SI floats inside its sections).

    Raises
    ------
    semianalytic.errors.InputError
        On any bad value, naming the field (``projectile.diameter``) and what was expected.
    """
    from semianalytic.case import parse_case

    return parse_case(dict(data))


def case_from_keywords(**sections: Any):
    """Build a case from keyword arguments, one per section.

    Parameters
    ----------
    **sections : dict
        Each section as a dict, e.g. ``projectile={...}, target={...}, impact={...}``;
        ``title="..."`` is accepted as well.

    Returns
    -------
    semianalytic.case.Case
        The validated case, as ``case_from_dict`` would return it.
    """
    return case_from_dict(sections)


def load_case(path: str | os.PathLike):
    """Read and validate a TOML case file.

    Parameters
    ----------
    path : str or os.PathLike
        The case file (``cases/fig5_ogive.toml``); a ``[data]`` file it names is relative to it.

    Returns
    -------
    semianalytic.case.Case
        The validated case.
    """
    from semianalytic.case import load_case as _load

    return _load(Path(path))


# --- drag coefficients (Part I, eqs. (12)-(15)) ------------------------------------------------


def coefficients(case, source: str = "bem", cache_dir: str | os.PathLike | None = None):
    """The coefficients A(P), B(P), C(P) of the case's nose (Part I, eqs. (12)-(14)).

    Parameters
    ----------
    case : semianalytic.case.Case
        A case with a ``[projectile]`` section.
    source : {"bem", "paper"}
        ``"bem"``: the certified BEM table of the nose, cached per user (built once, in
        seconds); ``"paper"``: the paper's quoted deep-penetration constants.
    cache_dir : str or os.PathLike, optional
        Folder of the table cache (default ``$SEMIANALYTIC_CACHE_DIR``, else the per-user cache).

    Returns
    -------
    semianalytic.coefficients.table.CoefficientTable or constant coefficients
        Callable as ``.A(P)`` [m^3], ``.B(P)`` [m^2], ``.C(P)`` [m^2] for depths ``P`` [m]
        (floats or arrays), in the B reading of ``[coefficients] reading``.
    """
    from semianalytic.cache import coefficients_for_case

    # a new table takes seconds: progress by the commands' rule (semianalytic.progress)
    table, _desc, _fallback = coefficients_for_case(case, source, cache_dir, progress=True)
    return table


def coefficients_at(case, depths: Sequence[float] | np.ndarray, cache_dir: str | os.PathLike | None = None) -> Result:
    """A, B, C and their bars (divided by the cross-section pi d^2/4) at chosen depths.

    Parameters
    ----------
    case : semianalytic.case.Case
        A case with a ``[projectile]`` section.
    depths : sequence of float or str
        Depths of the tip below the free surface, P [m] (or unit strings, ``"5 mm"``).
    cache_dir : str or os.PathLike, optional
        Folder of the table cache.

    Returns
    -------
    Result
        One row per depth: ``depth_m``, ``A_m3``, ``B_m2``, ``C_m2`` (arrays over ``depths``, from the certified
        table) and ``A_bar_m``, ``B_bar``, ``C_bar`` (Part I, Fig. 8: Abar = 4A/(pi d^2) is a
        length, Bbar and Cbar are numbers).
    """
    P = _quantities(depths, "length", "depths")
    table = coefficients(case, "bem", cache_dir)
    area = np.pi * case.projectile.diameter**2 / 4
    A, B, C = (np.asarray(f(P), float) for f in (table.A, table.B, table.C))
    return Result({"depth_m": P.tolist(), "A_m3": A.tolist(), "B_m2": B.tolist(), "C_m2": C.tolist(),
                   "A_bar_m": (A / area).tolist(), "B_bar": (B / area).tolist(), "C_bar": (C / area).tolist()},
                  "coefficients", rows_key="depth_m")


# --- penetration (Part I, eq. (11); regimes) -------------------------------------------------


def penetrate(case, velocities: Sequence[float] | None = None, *, source: str = "bem", w1: str = "neglect",
              part1_model: str | None = None, cache_dir: str | os.PathLike | None = None) -> Result:
    """Everything ``python -m semianalytic penetrate CASE --json`` prints for one case.

    Parameters
    ----------
    case : semianalytic.case.Case
        A case with ``[projectile]``, ``[target]`` (with ``[target.resistance]``) and ``[impact]``.
    velocities : float, str or sequence of them, optional
        Striking velocities [m/s] (or unit strings, ``"0.8 km/s"``); default: the case's
        ``[impact] striking_velocities``.
    source : {"bem", "paper"}
        Coefficients from the BEM table (default) or the paper's constants.
    w1 : str
        Lateral-compression energy W1 of Part I, eq. (28) (default ``"neglect"``, as the paper).
    part1_model : str, optional
        Part I model of the regime-aware ``depth_m`` below the erosion onset (default
        ``"elastic_exact_rod"``).
    cache_dir : str or os.PathLike, optional
        Folder of the table cache.

    Returns
    -------
    Result
        Arrays over the striking velocities in SI units: ``striking_velocity_m_s``,
        ``depth_rigid_m``, ``depth_quasi_rigid_m``, ``depth_elastic_m``,
        ``depth_elastic_exact_rod_m``, ``depth_forrestal_m``, ``depth_chen_li_m``,
        ``regime``, ``depth_m``, ``critical_velocity_m_s``, ``yields``, ``valid``, ... and,
        when the case has ``[data]`` shots, ``validation`` (predicted against measured);
        ``.to_frame()`` has one row per velocity.

    Warns
    -----
    semianalytic.errors.ValidityWarning
        For every velocity outside a model's validity (the lines ``penetrate`` prints on stderr).
    """
    out = _penetrate(case, velocities, source=source, w1=w1, part1_model=part1_model, cache_dir=cache_dir)
    _issue(out.get("warnings"), "penetrate")
    return Result(out, "penetrate")


def _penetrate(case, velocities, *, source="bem", w1="neglect", part1_model=None, cache_dir=None) -> dict:
    from semianalytic.cache import coefficients_for_case
    from semianalytic.commands.penetrate.evaluate import evaluate_case

    U = _velocities(velocities)
    table, desc, _fallback = coefficients_for_case(case, source, cache_dir, progress=True)
    return dict(evaluate_case(case, table, w1=w1, velocities=U, part1_model=part1_model), coefficients=desc)


def depth(case, velocity: float | Sequence[float], model: str = "regime_aware", **options: Any):
    """Final depth of penetration at one or several striking velocities.

    Parameters
    ----------
    case : semianalytic.case.Case
        A penetration case (see ``penetrate``).
    velocity : float, str or sequence of them
        Striking velocity U_s [m/s] (or unit strings, ``"800 m/s"``).
    model : str
        ``"regime_aware"`` (default: rigid, deforming or eroding by the predicted regime),
        ``"rigid"``, ``"quasi_rigid"``, ``"elastic"``, ``"elastic_exact_rod"``,
        ``"forrestal"``, ``"chen_li"`` or ``"eroding"``.
    **options : dict
        Passed to ``penetrate`` (``source``, ``w1``, ``part1_model``, ``cache_dir``).

    Returns
    -------
    float or numpy.ndarray
        Depth [m]: a float for one velocity, an array for several.

    Warns
    -----
    semianalytic.errors.ValidityWarning
        Where the model asked for is outside its validity.
    """
    from semianalytic.errors import InputError

    if model not in DEPTH_MODELS:
        from semianalytic.schema import did_you_mean

        raise InputError("model", f"{model!r} is not one of {', '.join(DEPTH_MODELS)}{did_you_mean(model, list(DEPTH_MODELS))}")
    from semianalytic.penetration.regime_setup import _LABEL

    U = _quantities(velocity, "velocity", "velocity")
    result = _penetrate(case, U, **options)
    # the notices of the model asked for (the regime-aware depth: those naming it, and U_sC)
    label = _LABEL.get(model, "regime-aware")
    _issue([w for w in result.get("warnings", []) if label in w or (model == "regime_aware" and "U_sC" in w)], "depth")
    out = np.asarray(result[DEPTH_MODELS[model]], float)
    return float(out[0]) if isinstance(velocity, str) or np.ndim(velocity) == 0 else out


# --- posterior prediction (calibrate) ------------------------------------------------------


def predict_with_posterior(case, posterior: str | os.PathLike | Sequence[str | os.PathLike],
                           velocities: Sequence[float] | None = None, *, part1_model: str | None = None,
                           cache_dir: str | os.PathLike | None = None) -> Result:
    """Predictive depth quantiles from a posterior written by ``python -m semianalytic calibrate``.

    Parameters
    ----------
    case : semianalytic.case.Case
        The penetration case (its projectile; the target's calibrated parameters come from the
        posterior).
    posterior : path or sequence of paths
        ``posterior.json`` of a calibration run; several files to combine the rigid-shot
        models with the eroding rod's (``calibrate --model eroding``).
    velocities : sequence of float or str, optional
        Striking velocities [m/s] (or unit strings); default: the case's.
    part1_model : str, optional
        Part I model of the regime-aware quantiles.
    cache_dir : str or os.PathLike, optional
        Folder of the table cache.

    Returns
    -------
    Result
        ``depth_quantiles_m``: per model, ``{0.05: array, 0.5: array, 0.95: array, ...}``
        over the velocities [m] (float quantile levels; 0.05 and 0.95 bound the 90 %
        interval); ``.to_frame()`` has one row per velocity, a column per model and level.

    Warns
    -----
    semianalytic.errors.ValidityWarning
        The notices a command would print on stderr.
    """
    from semianalytic.commands.calibrate.evaluate import predict_with_posterior as _predict

    paths = [str(posterior)] if isinstance(posterior, (str, os.PathLike)) else [str(p) for p in posterior]
    U = _velocities(velocities)
    table = coefficients(case, "bem", cache_dir)
    out = _predict(case, table, paths, U, part1_model=part1_model)
    if "striking_velocity_m_s" not in out:
        U = np.asarray(case.require("impact").striking_velocities if U is None else U, float)
        out = {"striking_velocity_m_s": U.tolist(), **out}
    _issue(out.get("warnings"), "predict_with_posterior")
    return Result(out, "penetrate --posterior")


# --- derived geometry ------------------------------------------------------------------------


def geometry(case):
    """Derived geometry of the case's projectile: nose length, total length, L/D, volume, mass.

    Parameters
    ----------
    case : semianalytic.case.Case
        A case with a ``[projectile]`` section.

    Returns
    -------
    semianalytic.geometry.ProjectileGeometry
        ``diameter_m``, ``nose_length_m`` (L_h), ``shank_length_m``, ``length_m`` (L = shank +
        nose), ``length_over_diameter``, ``volume_m3`` and ``mass_kg`` (the case's measured mass,
        else density times volume; None without either).  Also ``case.geometry``.
    """
    from semianalytic.geometry import derived_geometry

    return derived_geometry(case.require("projectile"))


# --- the other commands --------------------------------------------------------------------------


def perforate(case, velocities: Sequence[float] | None = None, *, ballistic: bool = True,
              cache_dir: str | os.PathLike | None = None, quiet: bool = False) -> Result:
    """Perforation of the case's plate or layered target: ``python -m semianalytic perforate CASE --json``.

    Parameters
    ----------
    case : semianalytic.case.Case
        A case with ``[projectile]``, ``[target]`` with ``thickness`` (or ``[[target.layers]]``)
        and ``[impact]``.
    velocities : float, str or sequence of them, optional
        Striking velocities [m/s] (or unit strings); default: the case's.
    ballistic : bool
        Bisect for the ballistic limit (``ballistic_limit_m_s`` with its error estimate);
        False is ``--no-ballistic-limit``.
    cache_dir : str or os.PathLike, optional
        Folder of the plate-table cache.
    quiet : bool
        No progress on stderr.

    Returns
    -------
    Result
        Per striking velocity ``perforated``, ``residual_velocity_m_s`` (0 where it stops),
        ``depth_m`` (NaN where it perforates), ``exit_time_s``; scalars ``ballistic_limit_m_s``,
        ``ballistic_limit_error_m_s``, ``thickness_m``, ``mass_kg``; ``lambert_jonas`` and
        ``part4_v_cr_m_s``.  ``.to_frame()``: one row per velocity.

    Warns
    -----
    semianalytic.errors.ValidityWarning
        Where the model is used outside its validity (e.g. the plate-table reach).
    """
    from semianalytic.commands.perforate.evaluate import evaluate_case
    from semianalytic.progress import stages

    for sec in ("projectile", "target", "impact"):
        case.require(sec)
    U = _velocities(velocities)
    bar = stages(1, "perforate", quiet=quiet)
    bar.step(f"plate tables and eq. (11) for {case.title}")
    try:
        with _Reissue("perforate"):
            out = evaluate_case(case, cache_dir=cache_dir, velocities=U, ballistic=ballistic)
    finally:
        bar.close()
    return Result(out, "perforate")


def ballistic_limit(case) -> Result:
    """Part IV ballistic limits of the case's shots: ``python -m semianalytic ballistic-limit CASE --json``.

    Parameters
    ----------
    case : semianalytic.case.Case
        A case with a ``[ballistic_limit]`` section (shots inline or a ``table`` file).

    Returns
    -------
    Result
        ``rows``: per shot the theoretical V_cr of eq. (5) with R(1), R(2), R(3), the empirical
        V_cr of eqs. (7)-(9) and the measured value [m/s]; ``constants``, ``hardness_rule``,
        ``areal_mass_rule``.  ``.to_frame()``: one row per shot.
    """
    from semianalytic.commands.ballistic_limit.evaluate import evaluate_case

    return TableResult(evaluate_case(case), "ballistic-limit")


def cavity(case, method: str | None = None) -> Result:
    """Part II's three-zone cavity in a brittle material: ``python -m semianalytic cavity CASE --json``.

    Parameters
    ----------
    case : semianalytic.case.Case
        A case with a ``[material]`` section.
    method : {"bracket", "fixed-point"}, optional
        Root finder of the front stress (default the section's ``solver``).

    Returns
    -------
    Result
        ``sigma_star_Pa`` (front stress), ``cavity_pressure_Pa`` (R_r, Part II eq. (34)), the
        zone strains and radii ratios; ``.to_frame()``: one row.

    Warns
    -----
    semianalytic.errors.ValidityWarning
        Soft validity conditions of errata item 20 (theta_k > theta*, Y_s/E > 0.025, ...).
    """
    from semianalytic.cavity import BrittleMaterial, solve_cavity

    section = case.require("material")
    result = solve_cavity(BrittleMaterial.from_section(section), method or section.solver, warn=False)
    _issue([f"warning: {w}" for w in result.warnings], "cavity")
    return Result({"case": case.title, **result.to_json()}, "cavity", rows_key=None)


def nanostrength(case) -> Result:
    """Part III theoretical strength of nanocrystals: ``python -m semianalytic nanostrength CASE --json``.

    Parameters
    ----------
    case : semianalytic.case.Case
        A case with a ``[nanostrength]`` section.

    Returns
    -------
    Result
        The analysis JSON (``crystals``, ``studies`` with the printed values compared);
        ``.to_frame()``: one row per study row (material and geometry).
    """
    from semianalytic.sections.nanostrength import analyse_section

    return NanostrengthResult(analyse_section(case.require("nanostrength")).to_json(), "nanostrength", rows_key=None)


@dataclass(frozen=True)
class NanostrengthResult(Result):
    """The ``nanostrength`` analysis; :meth:`to_frame` has one row per (study, material,
    geometry) with the strengths in GPa (``sigma1_compression_GPa``, ...)."""

    def to_frame(self):
        import pandas as pd

        rows = [{"study": st.get("name"), **{k: v for k, v in r.items() if not isinstance(v, (dict, list))}}
                for st in self.data.get("studies", []) for r in st.get("rows", [])]
        if not rows:  # crystals only
            rows = [{"material": m, **{k: v for k, v in c.items() if not isinstance(v, (dict, list))}}
                    for m, c in self.data.get("crystals", {}).items()]
        return pd.DataFrame(rows)


def optimize(case, vary: Sequence[str], objective: str = "depth", *, constraint: Sequence[str] = (),
             method: str = "grid-pattern", depth_model: str = "rigid", workers: int = 1,
             out: str | os.PathLike | None = None, cache_dir: str | os.PathLike | None = None,
             quiet: bool = False, **options: Any) -> Result:
    """Optimise the projectile's nose: ``python -m semianalytic optimize CASE --vary ... --json``.

    Parameters
    ----------
    case : semianalytic.case.Case or str or os.PathLike
        The starting case (a loaded case or its file).
    vary : sequence of str
        Design variables ``"KEY=LOW:HIGH"`` (``"projectile.crh=1:4"``), as ``--vary``.
    objective : str
        ``"depth"`` (mean final depth, maximised), ``"deep_drag"`` (Bbar, minimised) or a
        plate objective, as ``--objective``.
    constraint : sequence of str
        ``"mass"``, ``"length"`` or ``"caliber"`` (held at the starting case's value).
    method : {"grid-pattern", "grid-nm", "de"}
        The optimiser.
    depth_model : str
        ``"rigid"`` or ``"exact-rod"``.
    workers : int
        1: in this process (default); more: a local dask cluster.
    out : str or os.PathLike, optional
        Also write the command's output folder (optimum.json, history, figure, report).
    cache_dir : str or os.PathLike, optional
        Folder of the table cache.
    quiet : bool
        No progress bar.
    **options : dict
        The other flags by their Python names (``coarse``, ``maxfev``, ``popsize``, ``maxiter``,
        ``tol``, ``seed``, ``resolution``, ``confirm``, ``striking_velocity``, ``table_depths``, ...).

    Returns
    -------
    Result
        The optimum as ``optimize --json`` prints it; ``.to_frame()``: one row.
    """
    from semianalytic.optimize.pipeline import optimize_case

    path = None
    if not hasattr(case, "projectile"):
        path, case = str(case), load_case(case)
    elif case.path is not None:
        path = str(case.path)
    with _Reissue("optimize"):
        result = optimize_case(path, list(vary), objective, case=case, constraint=list(constraint), method=method,
                               depth_model=depth_model, workers=workers, scheduler="inline" if workers == 1 else None,
                               out=None if out is None else str(out),
                               cache_dir=None if cache_dir is None else str(cache_dir),
                               progress=not quiet, command="semianalytic.api.optimize", **options)
    return Result(result, "optimize", rows_key=None)


def sweep(case: str | os.PathLike, out: str | os.PathLike, vary: Sequence[str] = (), sample: Sequence[str] = (), *,
          samples: int = 0, seed: int = 0, analysis: str | None = None, scheduler: str = "inline", workers: int = 2,
          force: bool = False, cache_dir: str | os.PathLike | None = None, quiet: bool = False) -> Result:
    """A grid or Monte-Carlo sweep: ``python -m semianalytic sweep CASE --out DIR --vary ...``.

    Parameters
    ----------
    case : str or os.PathLike
        The case file (the sweep's manifest names it).
    out : str or os.PathLike
        Output folder (``results.csv``, ``statistics.json``, ``sweep.json``).
    vary : sequence of str
        Grid axes ``"KEY=START:STOP:STEP UNIT"`` or ``"KEY=V1,V2"`` (Cartesian product).
    sample : sequence of str
        Random inputs ``"KEY=normal(MEAN, SD)"``, ``uniform``, ``lognormal``, ``triangular``.
    samples : int
        Number of Monte-Carlo samples (with ``sample``).
    seed : int
        Seed of the draws.
    analysis : {"penetration", "cavity", "perforation"}, optional
        What to compute per case (default: from the case's sections).
    scheduler : str
        ``"inline"`` (default: this process), ``"local"`` or a dask scheduler address.
    workers : int
        Workers of a local cluster.
    force : bool
        Discard earlier results in ``out``.
    cache_dir : str or os.PathLike, optional
        Folder of the table cache.
    quiet : bool
        No progress bar.

    Returns
    -------
    Result
        The summary ``sweep --json`` prints (``n_ok``, ``results``, ``statistics``, ...);
        ``.to_frame()``: the results table, one row per swept case.
    """
    from semianalytic.sweep.cli import sweep_case

    with _Reissue("sweep"):
        summary, stats = sweep_case(str(case), str(out), list(vary), list(sample), samples=samples, seed=seed,
                                    analysis=analysis, scheduler=scheduler, workers=workers, force=force,
                                    cache_dir=None if cache_dir is None else str(cache_dir), progress=not quiet)
    return SweepResult({**summary.to_json(), "statistics": stats}, "sweep", rows_key=None)


@dataclass(frozen=True)
class SweepResult(Result):
    """The summary of a sweep; :meth:`to_frame` reads its results table (one row per case)."""

    def to_frame(self):
        import pandas as pd

        path = Path(self.data["results"])
        return pd.read_parquet(path) if path.suffix == ".parquet" or path.is_dir() else pd.read_csv(path)
