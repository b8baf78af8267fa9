"""Data tables of Part IV (``cases/part4_table*.csv``) and the generic shot-table reader.

Every file starts with ``#`` lines giving its source and the meaning and unit of each column
(units are part of the column names: ``h_t_mm``, ``HV_t_GPa``, ``rho_t_g_cm3`` ...).  The
readers convert to SI.  A malformed value is an ``InputError`` naming the file, line and column.

Generic shot columns (all optional except ``L_p_mm``; extra columns are ignored):
``id`` or ``material`` (name), ``rho_t_g_cm3``, ``h_t_mm``, ``HV_t_GPa``, ``delta_Ht``,
``sigma02_GPa`` (Y), ``E_GPa``, ``R3_GPa`` or ``R_column_GPa`` (+ ``column_holds`` R3|R2),
``d_p_mm``, ``L_p_mm``, ``m_p_g``, ``rho_p_g_cm3`` (default 7.8), ``HV_p_GPa``, ``delta_Hp``,
``V_actual_m_s`` (+ ``V_actual_qualifier`` "<" or ">"), ``layers``
(``"name:rho_g_cm3:h_mm:HV_GPa:delta_H | ..."`` for a composite target).
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass
from pathlib import Path

from semianalytic.ballistic_limit.shots import PAPER_PROJECTILE_DENSITY, Layer, Shot
from semianalytic.bundled import cases_dir
from semianalytic.errors import InputError

__all__ = [
    "CASES",
    "read_rows",
    "load_rows",
    "load_shots",
    "shot_from_row",
    "Table1Row",
    "Table2Row",
    "Table3Row",
    "Table4Cell",
    "load_table1",
    "load_table2",
    "load_table3",
    "load_table4",
    "load_table5",
]

CASES = cases_dir() or Path("cases")  # the bundled cases (semianalytic.bundled)
GPa, mm, g, g_cm3 = 1e9, 1e-3, 1e-3, 1e3  # unit scales to SI


def read_rows(path: str | Path) -> list[tuple[int, dict[str, str]]]:
    """Rows of a ``#``-commented CSV as ``(line number, {column: text})``."""
    path = Path(path)
    if not path.is_file():
        raise InputError("table", f"file {str(path)!r} does not exist")
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError("table", f"cannot read {path.name}: {exc}") from None
    lines = text.splitlines()
    body = [(i + 1, line) for i, line in enumerate(lines) if line.strip() and not line.lstrip().startswith("#")]
    if not body:
        raise InputError("table", f"{path.name} has no header line")
    reader = csv.reader(io.StringIO("\n".join(line for _, line in body)))
    rows = list(reader)
    header = [h.strip() for h in rows[0]]
    out = []
    for (lineno, _), values in zip(body[1:], rows[1:]):
        if len(values) != len(header):
            raise InputError(f"{path.name}:{lineno}", f"has {len(values)} fields, the header has {len(header)}")
        out.append((lineno, {h: v.strip() for h, v in zip(header, values)}))
    return out


class _Cells:
    """Typed access to one CSV row, with errors naming file, line and column."""

    def __init__(self, path: Path, lineno: int, row: dict[str, str]):
        self.path, self.lineno, self.row = path, lineno, row

    def where(self, column: str) -> str:
        return f"{self.path.name}:{self.lineno}:{column}"

    def text(self, column: str, default: str = "") -> str:
        return self.row.get(column, default) or default

    def number(self, column: str, scale: float = 1.0, *, required: bool = False, positive: bool = True):
        text = self.row.get(column, "")
        if text == "":
            if required:
                raise InputError(self.where(column), "missing value (required)")
            return None
        try:
            value = float(text)
        except ValueError:
            raise InputError(self.where(column), f"expected a number; got {text!r}") from None
        if positive and not value > 0:
            raise InputError(self.where(column), f"must be positive; got {text!r}")
        return value * scale

    def fraction(self, column: str, *, required: bool = False):
        value = self.number(column, required=required)
        if value is not None and not 0 < value <= 1:
            raise InputError(self.where(column), f"must lie in (0, 1]; got {value!r}")
        return value


def _layers(cells: _Cells) -> tuple[Layer, ...]:
    spec = cells.text("layers")
    if not spec:
        return ()
    layers = []
    for part in spec.split("|"):
        fields = [f.strip() for f in part.split(":")]
        if len(fields) != 5:
            raise InputError(cells.where("layers"), f"each layer is name:rho_g_cm3:h_mm:HV_GPa:delta_H; got {part.strip()!r}")
        try:
            rho, h, hv, dl = (float(f) for f in fields[1:])
        except ValueError:
            raise InputError(cells.where("layers"), f"non-numeric layer value in {part.strip()!r}") from None
        if min(rho, h, hv, dl) <= 0 or dl > 1:
            raise InputError(cells.where("layers"), f"layer values must be positive (delta_H <= 1); got {part.strip()!r}")
        layers.append(Layer(fields[0], rho * g_cm3, h * mm, hv * GPa, dl))
    return tuple(layers)


def shot_from_row(cells: _Cells) -> Shot:
    """A :class:`Shot` from one row of a shot table (see the module docstring)."""
    layers = _layers(cells)
    R3 = cells.number("R3_GPa", GPa)
    column = cells.number("R_column_GPa", GPa)
    delta_t = cells.fraction("delta_Ht")
    if R3 is None and column is not None:
        holds = cells.text("column_holds", "R3")
        if holds not in ("R3", "R2"):
            raise InputError(cells.where("column_holds"), f"must be R3 or R2; got {holds!r}")
        if holds == "R2" and delta_t is None:
            raise InputError(cells.where("delta_Ht"), "needed to read an R(2) column as R(3) = R(2)/delta_H")
        R3 = column if holds == "R3" else column / delta_t
    qualifier = cells.text("V_actual_qualifier")
    if qualifier not in ("", "<", ">"):
        raise InputError(cells.where("V_actual_qualifier"), f"must be empty, '<' or '>'; got {qualifier!r}")
    return Shot(
        name=cells.text("id") or cells.text("material") or f"line {cells.lineno}",
        projectile_length=cells.number("L_p_mm", mm, required=True),
        projectile_density=cells.number("rho_p_g_cm3", g_cm3) or PAPER_PROJECTILE_DENSITY,
        target_density=None if layers else cells.number("rho_t_g_cm3", g_cm3),
        thickness=None if layers else cells.number("h_t_mm", mm),
        target_hardness=None if layers else cells.number("HV_t_GPa", GPa),
        target_delta_H=None if layers else delta_t,
        yield_stress=cells.number("sigma02_GPa", GPa),
        youngs_modulus=cells.number("E_GPa", GPa),
        resistance_R3=R3,
        projectile_diameter=cells.number("d_p_mm", mm),
        projectile_mass=cells.number("m_p_g", g),
        projectile_hardness=cells.number("HV_p_GPa", GPa),
        projectile_delta_H=cells.fraction("delta_Hp"),
        measured=cells.number("V_actual_m_s"),
        measured_qualifier=qualifier,
        layers=layers,
    )


def load_rows(path: str | Path, make, require: str | None = None, what: str = "") -> list:
    """``make(cells, row)`` for every row of a ``#``-commented CSV (the one table loader of the
    package: every reader below is a row builder passed to it); ``require``: a column the file
    must have (else one ``InputError`` naming the file and ``what`` it is not)."""
    path = Path(path)
    rows = read_rows(path)
    if require is not None and rows and require not in rows[0][1]:
        raise InputError(f"{path.name}", f"is not {what}: it has no {require!r} column")
    return [make(_Cells(path, n, row), row) for n, row in rows]


def load_shots(path: str | Path) -> list[Shot]:
    """All rows of a shot table (Table 2 or 3 format, or any table with the generic columns)."""
    return load_rows(path, lambda c, row: shot_from_row(c), require="L_p_mm", what="a shot table")


# ------------------------------------------------------------------------------- paper tables


@dataclass(frozen=True)
class Table1Row:
    group: str
    marking: str
    hardness: float  # HV [Pa]
    delta_H: float
    E_assumed: float  # [Pa], not in the paper
    nu_assumed: float
    hardness_text: str
    delta_text: str


@dataclass(frozen=True)
class Table2Row:
    """One row of Table 2: the shot (R(3) read per ``column_holds``), the printed column, the
    printed V(1), V(2), V(3) [m/s], the errata-25 reading and the assumed E (not in the paper)."""

    material: str
    shot: Shot
    R_column: float
    printed: tuple[float, float, float]
    column_holds: str
    hardness_in_R1: str
    E_assumed: float
    note: str


@dataclass(frozen=True)
class Table3Row:
    """One row of Table 3: shot, printed V by eqs. (7), (8), (9) [m/s], the paper's areal-mass
    rule (errata 26-27) and a note on known deviations."""

    id: str
    material_class: str
    shot: Shot
    printed: tuple[float, float, float]
    paper_rule: str
    note: str


@dataclass(frozen=True)
class Table4Cell:
    """One (block, target, velocity) cell group of Table 4, SI units; ``*_text`` as printed."""

    block: str
    projectile: str
    HVdelta_p: float
    rho_p: float
    L_p: float
    target: str
    HV_t: float
    delta_t: float
    rho_t: float
    V: float
    rhoh: float
    h: float
    rhoh_composite: float | None
    rhoh_text: str
    h_text: str
    composite_text: str
    rho_t_text: str
    note: str


def load_table1(path: str | Path = CASES / "part4_table1.csv") -> list[Table1Row]:
    return load_rows(path, lambda c, row: Table1Row(
        c.text("group"), c.text("marking"), c.number("HV_GPa", GPa, required=True), c.fraction("delta_H", required=True),
        c.number("E_GPa_assumed", GPa, required=True), c.number("nu_assumed", required=True), row["HV_GPa"], row["delta_H"]))


def load_table2(path: str | Path = CASES / "part4_table2.csv") -> list[Table2Row]:
    return load_rows(path, lambda c, row: Table2Row(
        material=c.text("material"),
        shot=shot_from_row(c),
        R_column=c.number("R_column_GPa", GPa, required=True),
        printed=tuple(c.number(f"printed_V_{k}_m_s", required=True) for k in ("R1", "R2", "R3")),
        column_holds=c.text("column_holds"),
        hardness_in_R1=c.text("hardness_in_R1"),
        E_assumed=c.number("E_GPa_assumed", GPa, required=True),
        note=c.text("note"),
    ))


def load_table3(path: str | Path = CASES / "part4_table3.csv") -> list[Table3Row]:
    return load_rows(path, lambda c, row: Table3Row(
        id=c.text("id"),
        material_class=c.text("material_class"),
        shot=shot_from_row(c),
        printed=tuple(c.number(f"printed_V_eq{k}_m_s", required=True) for k in (7, 8, 9)),
        paper_rule=c.text("paper_rule"),
        note=c.text("note"),
    ))


def load_table4(path: str | Path = CASES / "part4_table4.csv") -> list[Table4Cell]:
    return load_rows(path, lambda c, row: Table4Cell(
        block=c.text("block"),
        projectile=c.text("projectile"),
        HVdelta_p=c.number("HVdelta_p_GPa", GPa, required=True),
        rho_p=c.number("rho_p_g_cm3", g_cm3, required=True),
        L_p=c.number("L_p_mm", mm, required=True),
        target=c.text("target"),
        HV_t=c.number("HV_t_GPa", GPa, required=True),
        delta_t=c.fraction("delta_Ht", required=True),
        rho_t=c.number("rho_t_g_cm3", g_cm3, required=True),
        V=c.number("V_p_m_s", required=True),
        rhoh=c.number("rhoh_cr_g_cm2", 10.0, required=True),  # g/cm^2 -> kg/m^2
        h=c.number("h_cr_mm", mm, required=True),
        rhoh_composite=c.number("rhoh_cr_composite_g_cm2", 10.0),
        rhoh_text=row["rhoh_cr_g_cm2"],
        h_text=row["h_cr_mm"],
        composite_text=row.get("rhoh_cr_composite_g_cm2", ""),
        rho_t_text=row["rho_t_g_cm3"],
        note=c.text("note"),
    ))


def load_table5(path: str | Path = CASES / "part4_table5.csv") -> tuple[dict, list[dict]]:
    """Table 5 (``{"material", "V", "w_k", "w_p", "ratio_percent"}``, SI) and the Fig. 2 legend
    regions (``{"region", "HV_min", "HV_max", "eps_min", "eps_max", "eps_qualifier", ...}``)."""
    path = Path(path)
    table5, regions = None, []
    for c, row in load_rows(path, lambda c, row: (c, row)):
        if row["kind"] == "table5":
            table5 = {"material": row["name"], "V": c.number("V_m_s", required=True),
                      "w_k": c.number("w_k_J", required=True), "w_p": c.number("w_p_J", required=True),
                      "ratio_percent": c.number("ratio_percent", required=True)}
        elif row["kind"] == "fig2":
            regions.append({
                "region": row["name"],
                "HV_min": c.number("HV_min_GPa", GPa, required=True), "HV_max": c.number("HV_max_GPa", GPa, required=True),
                "eps_min": c.number("eps_p_min_percent", 0.01, positive=False), "eps_max": c.number("eps_p_max_percent", 0.01),
                "eps_qualifier": row["eps_p_qualifier"],
                "delta_a": c.fraction("delta_H_a", required=True), "delta_b": c.fraction("delta_H_b", required=True),
            })
        else:
            raise InputError(c.where("kind"), f"must be table5 or fig2; got {row['kind']!r}")
    if table5 is None:
        raise InputError(path.name, "has no table5 line")
    return table5, regions
