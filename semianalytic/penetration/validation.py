"""Validation of the Part I projectile models against measured depths of penetration.

For each shot of a case's ``[data]`` CSV (rows kept by ``select``), with the shot's own
mass when the data give it: the depth predicted by the rigid, quasi-rigid, elastic (paper's
W2) and elastic (exact-rod W2) projectiles of Part I, by Forrestal's cavity-expansion
formula and by the Chen & Li formula (:mod:`.peers`); then the relative error
(predicted - measured)/measured of each model, and per model its mean, mean absolute,
maximum absolute and root-mean-square value.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from semianalytic.errors import InputError
from semianalytic.penetration import peers

if TYPE_CHECKING:
    from semianalytic.penetration.curve import PenetrationSetup

__all__ = ["MODEL_LABELS", "Shot", "read_csv_rows", "load_shots", "rigid_regime_shots", "peer_inputs", "predict_shots", "error_statistics"]

# column key -> label (the Part I models first, then the peers)
MODEL_LABELS = {
    "rigid": "rigid, eq. (11)",
    "quasi_rigid": "quasi-rigid, eqs. (11)+(26)",
    "elastic": "elastic, paper's W2 (29), (30')",
    "elastic_exact_rod": "elastic, exact-rod W2 (errata 5)",
    "forrestal": "Forrestal (cavity expansion)",
    "chen_li": "Chen & Li (2002)",
}


@dataclass(frozen=True)
class Shot:
    """One experiment: id, striking velocity [m/s], measured depth [m], mass [kg] or None."""

    id: str
    velocity: float
    depth: float
    mass: float | None
    row: dict



RESPONSE_REGIME = {  # the recorded responses of a [data] file and the regime each belongs to
    "rigid": "rigid",
    "curved": "deforming",
    "exited": "deforming",
    "turned_around": "deforming",
    "broken": "deforming",
    "eroded": "eroding",
    "broken_eroding": "eroding",
}


def _unit_scale(unit: str, kind: str, field: str) -> float:
    from semianalytic.units import parse_quantity

    return parse_quantity(f"1 {unit}", kind, field)


def _strip_comment(line: str) -> str:
    """The line up to a ``#`` outside double quotes (the rest is a comment)."""
    quoted = False
    for k, ch in enumerate(line):
        if ch == '"':
            quoted = not quoted
        elif ch == "#" and not quoted:
            return line[:k]
    return line


def read_csv_rows(path: Path, field: str = "data.file") -> tuple[list[str], list[dict]]:
    """(columns, rows as {column: text}) of a small CSV file, read as ``pandas.read_csv(path,
    comment="#", dtype=str, keep_default_na=False)`` reads it: ``#`` starts a comment, blank
    lines are skipped, the first line left is the header, every value stays text (missing ones
    ""), a repeated column name gets ".1", ".2", ...  The csv module, not pandas: the shot
    tables are small and pandas costs a command about 0.4 s to import.  Bad input raises
    ``InputError`` naming ``field``."""
    import csv

    def bad(why: str) -> InputError:
        return InputError(field, f"cannot read {path.name} as CSV: {why}")

    try:
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        raise bad(str(exc)) from None
    lines = [ln for ln in (_strip_comment(ln) for ln in text.splitlines(keepends=True)) if ln.strip()]
    try:
        records = list(csv.reader(lines, strict=True))
    except csv.Error as exc:
        raise bad(str(exc)) from None
    if not records:
        raise bad("no columns to parse from file")
    columns, seen = [], {}
    for name in records[0]:
        n = seen.get(name, 0)
        seen[name] = n + 1
        columns.append(name if n == 0 else f"{name}.{n}")
    rows = []
    for k, rec in enumerate(records[1:]):
        if len(rec) > len(columns):
            raise bad(f"expected {len(columns)} fields in line {k + 2}, saw {len(rec)}")
        rows.append(dict(zip(columns, rec + [""] * (len(columns) - len(rec)))))
    return columns, rows


def load_shots(case, *, require_depth: bool = True) -> list[Shot]:
    """The shots of the case's ``[data]`` CSV in SI units (rows with a depth, kept by ``select``;
    with ``require_depth=False`` also the rows without one, depth NaN)."""
    data = case.require("data")
    if data.file is None:
        return []
    from semianalytic.io import case_input_path
    from semianalytic.limits import MAX_STRIKING_VELOCITY, MIN_STRIKING_VELOCITY

    path = case_input_path(case.path, data.file, "data.file")
    if not path.is_file():
        raise InputError("data.file", f"{str(path)!r} does not exist")
    names, table = read_csv_rows(path)
    columns = {k: getattr(data, k, None) for k in ("velocity_column", "depth_column", "mass_column", "id_column",
                                                   "response_column", "hardness_column")}
    columns.update({f"select.{c}": c for c in data.select})
    for key, col in columns.items():
        if col is not None and col not in names:
            raise InputError(f"data.{key}", f"column {col!r} is not in {path.name} (columns: {', '.join(names)})")
    v_scale = _unit_scale(data.velocity_unit, "velocity", "data.velocity_unit")
    d_scale = _unit_scale(data.depth_unit, "length", "data.depth_unit")
    m_scale = _unit_scale(data.mass_unit, "mass", "data.mass_unit")
    shots = []
    for i, row in enumerate(table):
        if any(row[col] not in allowed for col, allowed in data.select.items()):
            continue
        no_depth = row[data.depth_column].strip() == ""
        if no_depth and require_depth:
            continue  # no depth printed (e.g. only a channel length)
        try:
            V = float(row[data.velocity_column]) * v_scale
            P = math.nan if no_depth else float(row[data.depth_column]) * d_scale
            m = float(row[data.mass_column]) * m_scale if data.mass_column else None
        except ValueError:
            raise InputError("data.file", f"row {i + 1} of {path.name} has a non-numeric value") from None
        if not all(math.isfinite(x) for x in (V, *(() if no_depth else (P,)), *(() if m is None else (m,)))):
            raise InputError("data.file", f"row {i + 1} of {path.name} has a value that is not a finite number (NaN or inf)")
        if not (V > 0 and (P > 0 or no_depth) and (m is None or m > 0)):
            raise InputError("data.file", f"row {i + 1} of {path.name}: velocity, depth and mass must be positive")
        if not MIN_STRIKING_VELOCITY <= V <= MAX_STRIKING_VELOCITY:  # the bound of a case's striking velocity
            raise InputError("data.velocity_column", f"row {i + 1} of {path.name}: {V:g} m/s is outside "
                                                     f"{MIN_STRIKING_VELOCITY:g}-{MAX_STRIKING_VELOCITY:g} m/s, the range "
                                                     "of a striking velocity any model here reads (a solid projectile)")
        shot_id = str(row[data.id_column]) if data.id_column else str(i + 1)
        _check_row_labels(data, row, i, shot_id, path.name)
        shots.append(Shot(shot_id, V, P, m, row))
    return shots


def _check_row_labels(data, row: dict, i: int, shot_id: str, name: str) -> None:
    """A selected row's recorded response (one of the known labels, or blank: not recorded) and
    its hardness (a number where ``hardness_column`` is given: a blank would silently take the
    nominal ``[projectile] hardness``)."""
    if data.response_column:
        label = row[data.response_column].strip()
        if label and label not in RESPONSE_REGIME:
            raise InputError("data.response_column", f"row {i + 1} of {name} (shot {shot_id}): response {label!r} is "
                                                     f"not a known label; one of {', '.join(RESPONSE_REGIME)} (or blank: "
                                                     "no recorded response)")
    col = getattr(data, "hardness_column", None)
    if col:
        h = row[col].strip()
        from semianalytic.penetration.hardness import HRC_RANGE

        try:
            value = float(h)
            ok = math.isfinite(value)
        except ValueError:
            ok = False
        if ok and not HRC_RANGE[0] <= value <= HRC_RANGE[1]:
            raise InputError("data.hardness_column", f"row {i + 1} of {name} (shot {shot_id}): {value:g} HRC is outside "
                                                     f"{HRC_RANGE[0]:g}-{HRC_RANGE[1]:g} HRC, the range of the hardness "
                                                     "conversion (ASTM E140, Table 1)")
        if not ok:
            raise InputError("data.hardness_column", f"row {i + 1} of {name} (shot {shot_id}): hardness {h!r} is not a "
                                                     "number (Rockwell C); give every selected shot its hardness, or drop "
                                                     "hardness_column to use [projectile] hardness for all")


def rigid_regime_shots(case, shots: list[Shot]) -> list[Shot]:
    """The shots whose recorded response (``[data] response_column``) is ``rigid``; all shots
    when the data name no response column (the case's ``select`` then says which are rigid)."""
    data = case.section("data")
    col = data.response_column if data is not None else None
    return shots if not col else [s for s in shots if s.row.get(col) == "rigid"]


def peer_inputs(case, setup: PenetrationSetup):
    """(Forrestal CavityLaw, Chen-Li (static resistance, B)) for a case.

    Forrestal: the data authors' constants from ``[data]`` if given, else the same static
    resistance as Part I (A Y = R_t) with the incompressible dynamic term B = 3/2.
    Chen & Li: always on the Part I inputs, A Y = R_t and B = 3/2 (two-term law).
    """
    data = case.section("data")
    if data is not None and data.cavity_A is not None:
        if data.cavity_C is None:
            law = peers.CavityLaw.two_term(data.cavity_yield_stress, data.cavity_A, data.cavity_B)
        else:
            law = peers.CavityLaw(data.cavity_yield_stress, data.cavity_A, data.cavity_B, data.cavity_C)
    else:
        law = peers.CavityLaw.two_term(setup.resistance_pa, 1.0, 1.5)
    return law, (setup.resistance_pa, 1.5)


def peer_depths(case, setup: PenetrationSetup, U, mass=None) -> dict[str, np.ndarray]:
    """Forrestal and Chen-Li depths [m] for striking velocities U (same projectile as ``setup``)."""
    from semianalytic.geometry import nose_from_section

    nose = nose_from_section(case.require("projectile"))
    N1, N2 = peers.nose_factors(nose)
    m = setup.mass if mass is None else mass
    law, (static, B) = peer_inputs(case, setup)
    d = nose.diameter
    return {
        "forrestal": np.atleast_1d(peers.forrestal_depth(m, d, setup.target_density, law, U, N1, N2)),
        "chen_li": np.atleast_1d(peers.chen_li_depth(m, d, setup.target_density, static, B, N2, U)),
    }


def predict_shots(case, coefficients, shots: list[Shot], *, w1: str = "neglect") -> list[dict]:
    """Per shot: measured and predicted depths [m] of every model in :data:`MODEL_LABELS`,
    plus U_sC [m/s] and the yield flag (U_s >= U_sC: outside the model's validity)."""
    rows = []
    from semianalytic.penetration.curve import PenetrationSetup, penetration_curve  # the models: not for load_shots

    base = PenetrationSetup.from_case(case, coefficients)
    for shot in shots:
        setup = base if shot.mass is None else PenetrationSetup.from_case(case, coefficients, mass=shot.mass)
        res = penetration_curve(setup, [shot.velocity], w1=w1)
        pe = peer_depths(case, setup, [shot.velocity])
        row = {
            "shot": shot.id,
            "velocity_m_s": shot.velocity,
            "mass_kg": setup.mass,
            "measured_m": shot.depth,
            "rigid": float(res["depth_rigid_m"][0]),
            "quasi_rigid": float(res["depth_quasi_rigid_m"][0]),
            "elastic": float(res["depth_elastic_m"][0]),
            "elastic_exact_rod": float(res["depth_elastic_exact_rod_m"][0]),
            "forrestal": float(pe["forrestal"][0]),
            "chen_li": float(pe["chen_li"][0]),
            "critical_velocity_m_s": float(res["critical_velocity_m_s"][0]),
            "yields": bool(res["yields"][0]),
            "case": case.title,
        }
        rows.append(row)
    return rows


def error_statistics(rows: list[dict], models=tuple(MODEL_LABELS)) -> dict[str, dict[str, float]]:
    """Per model: n, mean (signed), mean |.|, max |.| and rms of (predicted - measured)/measured."""
    out = {}
    for key in models:
        e = np.array([(r[key] - r["measured_m"]) / r["measured_m"] for r in rows], float)
        if e.size == 0:
            continue
        out[key] = {
            "n": int(e.size),
            "mean": float(np.mean(e)),
            "mean_abs": float(np.mean(np.abs(e))),
            "max_abs": float(np.max(np.abs(e))),
            "rms": float(math.sqrt(np.mean(e * e))),
        }
    return out
