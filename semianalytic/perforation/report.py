"""Documents of the perforation results (computes nothing): the V_r against V_s figure (the
computed curve, the bisection's ballistic limit and Part IV's V_cr as vertical lines, measured
points as markers), its data as CSV, and ``validation_perforation.md``."""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np

__all__ = ["perforation_figure", "figure_csv", "write_report", "error_rows"]

_STYLES = ["C1--", "C2--", "C3--", "C4-.", "C5-.", "C6-."]


def perforation_figure(result: dict):
    """V_r against V_s of one ``perforate`` result."""
    from semianalytic.report.figures import Points, Series, line_figure

    c = result["curve"]
    x, y = np.asarray(c["striking_velocity_m_s"]), np.asarray(c["residual_velocity_m_s"])
    top = float(max(y.max(), 1.0)) * 1.05
    series = [Series(x, y, "eq. (11) through the plate", "k-")]
    if result.get("ballistic_limit_m_s") is not None:
        V = result["ballistic_limit_m_s"]
        series.append(Series(np.array([V, V]), np.array([0.0, top]), f"V_bl bisection {V:.0f} m/s", "k:"))
    for (name, V), st in zip(result.get("part4_v_cr_m_s", {}).items(), _STYLES):
        series.append(Series(np.array([V, V]), np.array([0.0, top]), f"Part IV {name} {V:.0f} m/s", st))
    points = []
    data = result.get("data")
    if data:
        points.append(Points(np.asarray(data["striking_velocity_m_s"]), np.asarray(data["measured_residual_velocity_m_s"]),
                             "measured", "o"))
    return line_figure(series, "striking velocity V_s [m/s]", "residual velocity V_r [m/s]",
                       f"Perforation: {result['thickness_m'] * 1e3:.4g} mm ({result['back_face']} back face)", points)


def figure_csv(result: dict) -> str:
    """The figure's data: rows kind, name, Vs_m_s, Vr_m_s (curve, limits, measured)."""
    buf = io.StringIO()
    buf.write("kind,name,Vs_m_s,Vr_m_s\n")
    c = result["curve"]
    for v, r in zip(c["striking_velocity_m_s"], c["residual_velocity_m_s"]):
        buf.write(f"computed,eq11,{v:.6g},{r:.6g}\n")
    if result.get("ballistic_limit_m_s") is not None:
        buf.write(f"limit,bisection,{result['ballistic_limit_m_s']:.6g},0\n")
    for name, V in result.get("part4_v_cr_m_s", {}).items():
        buf.write(f"limit,part4_{name},{V:.6g},0\n")
    data = result.get("data")
    if data:
        for v, r in zip(data["striking_velocity_m_s"], data["measured_residual_velocity_m_s"]):
            buf.write(f"measured,data,{v:.6g},{r:.6g}\n")
    return buf.getvalue()


def error_rows(result: dict) -> list[list[str]]:
    """Per data set: mean |error| of V_bl and V_r of this model, of Part IV's formulas and of the
    Lambert-Jonas fit of the data itself (V_bl of the data = the fit's V_bl)."""
    data = result.get("data")
    if not data:
        return []
    fit = data.get("lambert_jonas_data")
    V_meas = fit["V_bl_m_s"] if fit else float("nan")
    f = lambda v: "-" if v is None or not math.isfinite(v) else f"{v:.0f}"  # noqa: E731
    rows = [["eq. (11) through the plate (this model)", f(abs(result["ballistic_limit_m_s"] - V_meas) if result.get("ballistic_limit_m_s") else None),
             f(data["mean_abs_error_residual_m_s"])]]
    for name, V in result.get("part4_v_cr_m_s", {}).items():
        rows.append([f"Part IV {name}", f(abs(V - V_meas)), "-"])
    if fit:
        rows.append(["Lambert-Jonas fit of the data", "0 (defines V_bl)", f(data["mean_abs_error_residual_lambert_jonas_data_m_s"])])
    return rows


def write_report(results: list[dict], out_dir, argv: list[str]) -> Path:
    """``validation_perforation.md`` with one figure and CSV per case, written into ``out_dir``."""
    from semianalytic.io import atomic_write_bytes, atomic_write_text
    from semianalytic.report.figures import png_bytes
    from semianalytic.report.provenance import generated_by

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    lines = ["# Perforation: residual velocity and ballistic limit against data and Part IV", "",
             generated_by("python -m semianalytic " + " ".join(argv)), "",
             "Model: Part I, eq. (11) through the plate (tip depth 0 to the exit of the nose), the resistance "
             "falling near the back face (module `semianalytic.perforation.model`: finite-sphere cavity expansion, "
             "Hill 1950 / Macek & Duffey 2000; or constant R_t of eq. (16)); ballistic limit by bisection on the "
             "dynamics; Part IV's V_cr from `semianalytic.ballistic_limit` (eq. (5) with R(1)-R(3), eqs. (7)-(9)).", ""]
    for r in results:
        stem = "validation_perforation_" + Path(str(r["case"])).stem
        lines += [f"## {r['title']}", "", f"Case `{r['case']}`; target {r['thickness_m'] * 1e3:.4g} mm in "
                  f"{len(r['layers'])} layer(s); back face `{r['back_face']}`; failure `{r['failure']}`.", "",
                  f"Coefficients: {r['coefficients']}.", ""]
        if r.get("ballistic_limit_m_s") is not None:
            lines.append(f"Ballistic limit (bisection on eq. (11)): **{r['ballistic_limit_m_s']:.1f} m/s**, numerical "
                         f"error estimate {r['ballistic_limit_error_m_s']:.2f} m/s.")
        lj = r.get("lambert_jonas")
        if lj:
            lines.append(f"Lambert-Jonas fit of the computed curve: a = {lj['a']:.4f}, p = {lj['p']:.3f}, "
                         f"V_bl = {lj['V_bl_m_s']:.1f} m/s.")
        if r.get("part4_v_cr_m_s"):
            lines.append("Part IV V_cr: " + ", ".join(f"{k} = {v:.0f} m/s" for k, v in r["part4_v_cr_m_s"].items()) + ".")
        lines.append("")
        rows = error_rows(r)
        if rows:
            d = r["data"]
            lines += [f"Data: `{d['file']}` ({d.get('source') or 'source in the file header'}), {len(d['striking_velocity_m_s'])} shots.", "",
                      "| predictor | mean abs. error of V_bl [m/s] | mean abs. error of V_r [m/s] |", "|---|---|---|"]
            lines += ["| " + " | ".join(row) + " |" for row in rows]
            lines.append("")
        else:
            lines += ["No measured residual velocities for this case (no `[perforation] data`).", ""]
        st = r.get("shot_table")
        if st:
            f0 = lambda v: "-" if v is None else f"{v:.0f}"  # noqa: E731
            cols = ["model_V_m_s", "eq5_R1", "eq5_R2", "eq5_R3", "eq7", "eq8", "eq9"]
            cols = [c for c in cols if c in st["statistics"]]
            label = {"model_V_m_s": "eq. (11) through the plate"}
            lines += [f"### Measured ballistic limits of `{st['table']}` (V_bl only: no residual velocities)", "",
                      f"Nose ASSUMED ({st['nose']}, scaled to each core's diameter: the table gives none); resistance "
                      "R(1) = HM delta_H of Part IV, constant to the exit; half-space stand-in coefficients. Part IV's "
                      "constants C1-C3 were fitted on this table (in-sample); eq. (5) uses the same R(1); eqs. (7)-(9) take "
                      "P = m_p / (pi d_p^2 / 4) for every row (errata 26: the printed values follow three rules).", "",
                      "| shot | measured V_bl [m/s] | " + " | ".join(label.get(c, f"Part IV {c}") + " [m/s]" for c in cols) + " |",
                      "|---|---|" + "---|" * len(cols)]
            for row in st["rows"]:
                if "skipped" in row:
                    lines.append(f"| {row['name']} | skipped: {row['skipped']} |" + " |" * len(cols))
                else:
                    lines.append(f"| {row['name']} | {f0(row['measured_V_m_s'])} | " + " | ".join(f0(row.get(c)) for c in cols) + " |")
            lines += ["", "| predictor | shots | mean abs. error of V_bl [m/s] | mean abs. relative error |", "|---|---|---|---|"]
            for c in cols:
                v = st["statistics"][c]
                lines.append(f"| {label.get(c, 'Part IV ' + c)} | {v['n']} | {v['mean_abs_error_m_s']:.0f} | "
                             f"{v['mean_abs_relative_error']:.1%} |")
            lines.append("")
        atomic_write_bytes(out / f"{stem}.png", png_bytes(perforation_figure(r)))
        atomic_write_text(out / f"{stem}.csv", figure_csv(r))
        lines += [f"![V_r against V_s]({stem}.png)", "", f"The figure's data: `{stem}.csv`.", ""]
    if not any(r.get("data") for r in results):
        lines += ["## Data", "",
                  "Measured ballistic limits (V_bl only) are those of Part IV, Table 3 (section above). "
                  "No measured residual velocities are bundled yet: no public table of striking and residual "
                  "velocities (Piekutowski, Forrestal, Poormon & Warren 1996, Int. J. Impact Eng. 18:877, 6061-T651 "
                  "plates and ogive rods; Forrestal et al. 1987/1990/1992; Borvik et al. on AA5083-H116 and AA7075-T651 "
                  "plates) could be read from the sources reachable when this feature was built, and numbers read "
                  "from memory are not data. The secondary V50 of about 514 m/s (20 mm 6082-T651, 7.62 mm AP) is a "
                  "lead only and is not used. A case adds a data set with `[perforation] data = \"file.csv\"` "
                  "(columns Vs_m_s, Vr_m_s; '#' header lines with the full source and how each number was checked); "
                  "this report then gives, per data set, the mean absolute error of V_bl and of V_r of the model "
                  "beside Part IV's formulas and the Lambert-Jonas fit of the data itself.", ""]
    path = out / "validation_perforation.md"
    atomic_write_text(path, "\n".join(lines))
    from semianalytic.report.html import html_beside

    html_beside(path)  # the same report as one self-contained page (figures embedded)
    return path
