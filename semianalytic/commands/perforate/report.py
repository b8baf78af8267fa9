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
    rows = [["eq. (11) through the plate (this model)", f(abs(result["ballistic_limit_m_s"] - V_meas) if result.get("ballistic_limit_m_s") else None),  # noqa: E501
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
             "near the back face by the case's `back_face` (module `semianalytic.perforation.model`; `auto` = "
             "`sphere-to-cylinder`, chosen by transfer below: Part I's spherical R_t with the finite-sphere weakening "
             "of Hill 1950 / Macek & Duffey 2000, never below the cylindrical cavity stress of Forrestal, Rosenberg, "
             "Luk & Bless 1987); a plate thinner than the spherical plastic zone c = (2E/3Y)^(1/3) d/2 takes the "
             "cylindrical cavity expansion throughout (thin-plate model); the failure mode by nose and thickness "
             "(`semianalytic.perforation.thin_plate`: shear plugging, Recht & Ipson 1963 / Chen & Li 2003, for blunt "
             "noses; ductile hole enlargement; petalling, Thomson 1955, below d/2); V_r never above the energy bound "
             "sqrt(V_s^2 - 2W/m); the ballistic limit found by the command itself (closed form without a plug, "
             "bracket and bisection with one; a lower bound above the rigid-projectile limit); Part IV's V_cr from "
             "`semianalytic.ballistic_limit` (eq. (5) with R(1)-R(3), eqs. (7)-(9)).", ""]
    for r in results:
        stem = "validation_perforation_" + Path(str(r["case"])).stem
        lines += [f"## {r['title']}", "", f"Case `{r['case']}`; target {r['thickness_m'] * 1e3:.4g} mm in "
                  f"{len(r['layers'])} layer(s); back face `{r['back_face']}`; failure mode `{r.get('failure_mode')}`.", "",
                  f"Coefficients: {r['coefficients']}.", ""]
        for note in r.get("model_notes", []):
            lines.append(f"Model note: {note}.")
        if r.get("ballistic_limit_m_s") is not None:
            if r.get("ballistic_limit_bound") == "lower":
                lines.append(f"Ballistic limit: above **{r['ballistic_limit_m_s']:.1f} m/s** (lower bound: "
                             f"{r.get('ballistic_limit_reason', '')}).")
            else:
                lines.append(f"Ballistic limit (the command's own search on eq. (11)): **{r['ballistic_limit_m_s']:.1f} m/s**, "
                             f"numerical error estimate {r['ballistic_limit_error_m_s']:.2g} m/s.")
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
            lines += [f"Data: `{d['file']}` ({d.get('source') or 'source in the file header'}), {len(d['striking_velocity_m_s'])} shots.", "",  # noqa: E501
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
            for key, what in (("statistics", "all"), ("statistics_case_nose", "the case's nose")):
                for c in cols:
                    v = st.get(key, {}).get(c)
                    if v is None:
                        continue
                    lines.append(f"| {label.get(c, 'Part IV ' + c)} ({what}) | {v['n']} | {v['mean_abs_error_m_s']:.0f} | "
                                 f"{v['mean_abs_relative_error']:.1%} |")
            lines += ["", "(`all`: every single plate with a measured V_bl, the three short cores with a shortened ASSUMED "
                      "ogive; `the case's nose`: the 9 plates whose core takes the case's ogive.)", ""]
        bs = r.get("back_face_study")
        if bs:
            faces = list(bs["statistics"])
            f0 = lambda v: "-" if v is None else f"{v:.0f}"  # noqa: E731
            lines += ["### Back face by transfer (Part IV Table 3, nothing fitted on it)", "",
                      "Each back face predicts the measured V_bl of the single plates of Table 3 with Y = HV/3 (Tabor 1951), "
                      "E and nu of Part IV Table 1's class, R_t of Part I eq. (16) from them (`constant-R1`: Part IV's R(1) = "
                      "HM delta_H, the resistance of eq. (5)), the nose ASSUMED (" + str(bs["nose"]) + ") and the half-space "
                      "stand-in coefficients. Most of these plates are thinner than the spherical plastic zone, so "
                      "`cylindrical` and `sphere-to-cylinder` coincide there; they differ on Steel 40 (40.5 mm). Beside them "
                      "the closed forms of `semianalytic.perforation.thin_plate` with the same Y and E: `recht-ipson` "
                      "(shear plugging, Recht & Ipson 1963, tau = Y/sqrt 3) and `hole (quasi-static)` (sqrt(2 pi a^2 H "
                      "sigma_s / m), Forrestal et al. 1987).", "",
                      "| shot | class | measured [m/s] | " + " | ".join(faces) + " |", "|---|---|---|" + "---|" * len(faces)]
            for row in bs["rows"]:
                if all(row.get(f) is None for f in faces):
                    lines.append(f"| {row['name']} | {row['class']} | {f0(row['measured_V_m_s'])} | skipped: {row.get('skipped', '')} |"
                                 + " |" * (len(faces) - 1))
                else:
                    lines.append(f"| {row['name']} | {row['class']} | {f0(row['measured_V_m_s'])} | "
                                 + " | ".join(f0(row.get(f)) for f in faces) + " |")
            classes = sorted({c for v in bs["statistics"].values() for c in v["class_mean_relative_error"]})
            lines += ["", "| back face | shots | mean abs. relative error | " + " | ".join(f"mean error {c}" for c in classes) + " |",
                      "|---|---|---|" + "---|" * len(classes)]
            for label, st in (("all", bs["statistics"]), ("case's nose", bs.get("statistics_case_nose", {}))):
                for f, v in st.items():
                    lines.append(f"| {f} ({label}) | {v['n']} | {v['mean_abs_relative_error']:.1%} | " + " | ".join(
                        f"{v['class_mean_relative_error'].get(c, float('nan')):+.1%}" for c in classes) + " |")
            lines += ["", "(`all`: every single plate with a measured V_bl; `case's nose`: without the three 12-12.5 mm "
                      "cores, whose ASSUMED ogive is shortened to fit them, psi = 1/4 + (0.9 L/d)^2. P2 (3 mm, HV 3.22 GPa, "
                      "328 m/s) is below P1 (HV 1.81 GPa, 470 m/s) with the same core, which no model here can follow.)", "",
                      "Finding: shear plugging (Recht & Ipson) predicts the high-strength aluminium alloys 8112 and 8312 "
                      "(435, 447 m/s against 438, 456) and the titanium alloy (562 against 490) better than hole enlargement "
                      "(606-671 m/s), while hole enlargement predicts the soft alloys (6112, AMG 5) and the steels; the "
                      "failure mode therefore depends on the material (adiabatic shear of high-strength Al and Ti), which "
                      "the nose-and-thickness criterion here does not see. The minimum-work rule (the cheaper of the two, "
                      "Woodward 1978) would choose plugging for every plate but Steel 40 and miss the soft alloys by "
                      "-42 to -63 %: not adopted."]
            lines += ["", f"Lowest mean |error|: `{bs['best']}` (Part IV's own resistance R(1)); of the back faces that take "
                      "Y and E, `cylindrical` = `sphere-to-cylinder` lowest, the default `auto` (`sphere-to-cylinder` keeps "
                      "Part I's spherical resistance where its plastic zone fits, so a thick plate tends to the half-space); "
                      "`finite-sphere` is kept as an option. Target of issue 37 (mean |error| <= 15 %, no class biased by "
                      "more than 10 %): NOT met by any back face here.", ""]
        sw = r.get("thickness_sweep")
        if sw:
            lines += ["### Thickness sweep (this case's projectile, half-space stand-in coefficients)", "",
                      "| thickness [mm] | failure mode | V_bl [m/s] | bound | max V_r - V_s [m/s] |", "|---|---|---|---|---|"]
            for row in sw:
                lines.append(f"| {row['thickness_mm']:.4g} | {row['failure_mode']} | {row['V_bl']:.1f} | {row['bound']} | "
                             f"{row['max_excess']:.3g} |")
            lines += ["", "max V_r - V_s < 0 at every thickness (50 velocities from 20 m/s to 3 km/s): no energy from nowhere. "
                      "Finding: V_bl jumps where the failure mode changes at H = d/2 (petalling below, Thomson's work "
                      "(pi/2) a^2 H Y; hole enlargement above, pi a^2 H sigma_s, sigma_s = 3.2 Y for 6061-T651), a factor "
                      "sqrt(2 sigma_s / Y) = 2.5: the threshold is this project's own (no published number was found) and "
                      "no data here test it. Above the rigid-projectile limit (Tate with Tabor's constraint, 1832 m/s for "
                      "this rod) V_bl is a lower bound.", ""]
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
                  "lead only and is not used. Searched again for issue 37 (the stored documentation, web-page, "
                  "issue and source-code corpora available to this project, for Piekutowski et al. 1996, Forrestal, "
                  "Luk & Brar 1990 on 5083-H131, Forrestal, Rosenberg, Luk & Bless 1987, Borvik et al. 2002 on 12 mm "
                  "Weldox 460 E with blunt, hemispherical and conical noses, Gupta et al. on aluminium plates): only the "
                  "openings of pages were reachable (e.g. Bendarma et al. 2017, J. Theor. Appl. Mech. 55:1219, AW5005 "
                  "sheets and conical noses: a lead), no table of striking and residual velocities; nothing was "
                  "transcribed. A case adds a data set with `[perforation] data = \"file.csv\"` "
                  "(columns Vs_m_s, Vr_m_s; '#' header lines with the full source and how each number was checked); "
                  "this report then gives, per data set, the mean absolute error of V_bl and of V_r of the model "
                  "beside Part IV's formulas and the Lambert-Jonas fit of the data itself.", ""]
    path = out / "validation_perforation.md"
    atomic_write_text(path, "\n".join(lines))
    from semianalytic.report.report_formats import write_beside

    write_beside(path)  # the registered formats beside it (the self-contained HTML page, figures embedded)
    return path
