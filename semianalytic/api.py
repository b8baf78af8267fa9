"""The Python face of the project: what a notebook or a script needs, in a few functions.

Every function here is a thin wrapper over the code the commands run (the same case layer,
the same cached coefficient tables, the same evaluation), so a script gets exactly the numbers
``python -m semianalytic penetrate`` prints.  Quantities in a case are unit strings
(``"7.11 mm"``); everything returned is in SI units, named in the keys (``depth_m``).

Example (more in ``docs/examples/``, the gallery of the docs site):

    from semianalytic import api

    case = api.load_case("cases/piekutowski1999_var4340.toml")
    print(api.depth(case, 800.0))          # m, the regime-aware depth at 800 m/s
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

__all__ = [
    "case_from_dict",
    "case_from_keywords",
    "load_case",
    "coefficients",
    "coefficients_at",
    "penetrate",
    "depth",
    "predict_with_posterior",
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

    table, _desc, _fallback = coefficients_for_case(case, source, cache_dir)
    return table


def coefficients_at(case, depths: Sequence[float] | np.ndarray, cache_dir: str | os.PathLike | None = None) -> dict:
    """A, B, C and their bars (divided by the cross-section pi d^2/4) at chosen depths.

    Parameters
    ----------
    case : semianalytic.case.Case
        A case with a ``[projectile]`` section.
    depths : sequence of float
        Depths of the tip below the free surface, P [m].
    cache_dir : str or os.PathLike, optional
        Folder of the table cache.

    Returns
    -------
    dict
        ``depth_m``, ``A_m3``, ``B_m2``, ``C_m2`` (arrays over ``depths``, from the certified
        table) and ``A_bar_m``, ``B_bar``, ``C_bar`` (Part I, Fig. 8: Abar = 4A/(pi d^2) is a
        length, Bbar and Cbar are numbers).
    """
    table = coefficients(case, "bem", cache_dir)
    P = np.asarray(depths, float)
    area = np.pi * case.projectile.diameter**2 / 4
    A, B, C = (np.asarray(f(P), float) for f in (table.A, table.B, table.C))
    return {"depth_m": P, "A_m3": A, "B_m2": B, "C_m2": C, "A_bar_m": A / area, "B_bar": B / area, "C_bar": C / area}


# --- penetration (Part I, eq. (11); regimes) -------------------------------------------------


def penetrate(case, velocities: Sequence[float] | None = None, *, source: str = "bem", w1: str = "neglect",
              part1_model: str | None = None, cache_dir: str | os.PathLike | None = None) -> dict:
    """Everything ``python -m semianalytic penetrate CASE --json`` prints for one case.

    Parameters
    ----------
    case : semianalytic.case.Case
        A case with ``[projectile]``, ``[target]`` (with ``[target.resistance]``) and ``[impact]``.
    velocities : sequence of float, optional
        Striking velocities [m/s]; default: the case's ``[impact] striking_velocities``.
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
    dict
        Lists over the striking velocities in SI units: ``striking_velocity_m_s``,
        ``depth_rigid_m``, ``depth_quasi_rigid_m``, ``depth_elastic_m``,
        ``depth_elastic_exact_rod_m``, ``depth_forrestal_m``, ``depth_chen_li_m``,
        ``regime``, ``depth_m``, ``critical_velocity_m_s``, ``yields``, ``valid``, ... and,
        when the case has ``[data]`` shots, ``validation`` (predicted against measured).
    """
    from semianalytic.penetration.evaluate import evaluate_case

    table = coefficients(case, source, cache_dir)
    return evaluate_case(case, table, w1=w1, velocities=velocities, part1_model=part1_model)


def depth(case, velocity: float | Sequence[float], model: str = "regime_aware", **options: Any):
    """Final depth of penetration at one or several striking velocities.

    Parameters
    ----------
    case : semianalytic.case.Case
        A penetration case (see ``penetrate``).
    velocity : float or sequence of float
        Striking velocity U_s [m/s].
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
    """
    from semianalytic.errors import InputError

    if model not in DEPTH_MODELS:
        from semianalytic.schema import did_you_mean

        raise InputError("model", f"{model!r} is not one of {', '.join(DEPTH_MODELS)}{did_you_mean(model, list(DEPTH_MODELS))}")
    U = np.atleast_1d(np.asarray(velocity, float))
    out = np.asarray(penetrate(case, U, **options)[DEPTH_MODELS[model]], float)
    return float(out[0]) if np.ndim(velocity) == 0 else out


# --- posterior prediction (calibrate) ------------------------------------------------------


def predict_with_posterior(case, posterior: str | os.PathLike | Sequence[str | os.PathLike],
                           velocities: Sequence[float] | None = None, *, part1_model: str | None = None,
                           cache_dir: str | os.PathLike | None = None) -> dict:
    """Predictive depth quantiles from a posterior written by ``python -m semianalytic calibrate``.

    Parameters
    ----------
    case : semianalytic.case.Case
        The penetration case (its projectile; the target's calibrated parameters come from the
        posterior).
    posterior : path or sequence of paths
        ``posterior.json`` of a calibration run; several files to combine the rigid-shot
        models with the eroding rod's (``calibrate --model eroding``).
    velocities : sequence of float, optional
        Striking velocities [m/s]; default: the case's.
    part1_model : str, optional
        Part I model of the regime-aware quantiles.
    cache_dir : str or os.PathLike, optional
        Folder of the table cache.

    Returns
    -------
    dict
        ``depth_quantiles_m``: per model, ``{"0.05": [...], "0.5": [...], "0.95": [...], ...}``
        lists over the velocities [m] (``"0.05"`` and ``"0.95"`` bound the 90 % interval);
        ``warnings``: lines a command would print on stderr.
    """
    from semianalytic.calibration.evaluate import predict_with_posterior as _predict

    paths = [str(posterior)] if isinstance(posterior, (str, os.PathLike)) else [str(p) for p in posterior]
    table = coefficients(case, "bem", cache_dir)
    return _predict(case, table, paths, velocities, part1_model=part1_model)


# --- perforation -------------------------------------------------------------------------------
# Perforation of plates of finite thickness comes from another branch: its function
# (`perforate(case, ...)`, NumPy-style docstring with Parameters and Returns) goes here and
# into __all__, and its page docs/perforation.md is picked up by the docs site.
