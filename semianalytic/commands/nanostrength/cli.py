"""``python -m semianalytic nanostrength CASE.toml [--json] [--report DIR] [--force]``

Theoretical strength of diamond-like crystals and nanoparticles (Part III): calibrates the bulk
interplanar law to Tables 1-2, computes Table 3's fracture quantities and runs the case's
studies (Tables 4-5, Figs. 5-7).  Prints a summary (or JSON with units in the keys); with
``--report DIR`` writes ``DIR/<case stem>.md`` and its PNG figures (never overwriting without
``--force``).  Bad input: exit status 2 with one line naming the field, nothing written.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from semianalytic.case import load_case
from semianalytic.io import check_report_target
from semianalytic.nanostrength import data
from semianalytic.nanostrength.analysis import Analysis
from semianalytic.sections.nanostrength import analyse_section


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from semianalytic.cli_types import output_dir

    parser.add_argument("case", help="TOML case file with a [nanostrength] section")
    from semianalytic.report.formats import add_format_arguments

    add_format_arguments(parser, json_help="print the results as JSON (units in the keys)")
    parser.add_argument("--report", metavar="DIR", type=output_dir, help="write DIR/<case stem>.md and its PNG figures")
    parser.add_argument("--force", action="store_true", help="overwrite an existing report")


def _summary(a: Analysis, title: str) -> str:
    o = a.options
    lines = [f"Part III theoretical strength: {title}",
             f"law = {o['law']}, stress measure = {o['stress_measure']}, odd-plate surface ratio = {o['odd_surface_ratio']:g}",
             "", "Bulk (eq. 14 on the calibrated law; Table 2 in brackets)",
             f"{'crystal':<8}{'sigma1 [GPa]':>22}{'-e*':>18}{'E [GPa]':>18}{'sigma2 [GPa]':>22}{'e**':>18}"]
    for name, r in a.crystals.items():
        c, b = r.crystal, r.bulk
        lines.append(f"{name:<8}{b.sigma_c / 1e9:>12.3f} ({c.sigma_c / 1e9:7.3f}){b.e_c:>9.4f} ({c.e_c:.4f})"
                     f"{r.law.youngs_modulus / 1e9:>9.1f} ({c.E / 1e9:6.1f}){b.sigma_t / 1e9:>12.3f} ({c.sigma_t / 1e9:7.3f})"
                     f"{b.e_t:>9.4f} ({c.e_t:.4f})")
    key = f"{o['surface_energy']}/{o['deformation_energy'] if o['surface_energy'] == 'eq16' else 'law'}"
    lines += ["", f"Fracture ({key}): Y_1c [N/m], K_1c [MPa m^1/2]; tension I, compression II",
              f"{'crystal':<8}{'Y_1c I':>10}{'Y_1c II':>10}{'K_1c I':>10}{'K_1c II':>10}   Table 3: Y I, Y II, K I, K II"]
    for name, r in a.crystals.items():
        ft, fc = r.fracture.get(f"{key}/tension"), r.fracture.get(f"{key}/compression")
        if ft is None or fc is None:
            lines.append(f"{name:<8}  (not available with this law)")
            continue
        t3 = data.TABLE3.get(name)
        printed = f"   {t3.Y_t:g}, {t3.Y_c:g}, {t3.K_t:g}, {t3.K_c:g}" if t3 else ""
        lines.append(f"{name:<8}{ft.Y1c:>10.4f}{fc.Y1c:>10.4f}{ft.K1c / 1e6:>10.4f}{fc.K1c / 1e6:>10.4f}{printed}")
    for s in a.studies:
        lines += ["", f"Study {s.spec.name}: {s.spec.title}",
                  f"{'crystal':<8}{'basis':<14}{'l':>6}{'m=n':>6}{'i':>5}{'Phi_i/Phi_0':>13}{'sigma1 [GPa]':>14}{'sigma2 [GPa]':>14}"
                  + ("   printed sigma1 / sigma2 [GPa] (diff %)" if s.spec.compare else "")]
        for r in s.rows:
            g = r.geometry
            line = (f"{r.material:<8}{g.basis:<14}{'inf' if g.l is None else g.l:>6}{'inf' if g.m is None else g.m:>6}"
                    f"{'-' if g.i is None else g.i:>5}{r.factor:>13.7f}{r.strength.sigma_c / 1e9:>14.4f}{r.strength.sigma_t / 1e9:>14.4f}")
            if r.printed is not None:
                d1, d2 = r.differences()
                line += f"   {r.printed[0]:g} ({100 * d1:+.3f}) / {r.printed[1]:g} ({100 * d2:+.3f})"
            lines.append(line)
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    from semianalytic.report.formats import Output, chosen_format, emit

    fmt = chosen_format(args)
    t0 = time.perf_counter()
    case = load_case(args.case)
    section = case.require("nanostrength")
    stem = Path(args.case).stem
    if args.report:
        check_report_target(Path(args.report) / f"{stem}.md", args.force)
    from semianalytic.progress import stages

    bar = stages(2 if args.report else 1, "nanostrength")
    bar.step("Part III analyses (crystals, studies)")
    analysis = analyse_section(section)
    if args.report:
        bar.step("report figures")
        from semianalytic.commands.nanostrength.report import build_report, write_report

        command = f"python -m semianalytic nanostrength {args.case} --report {args.report}" + (" --force" if args.force else "")
        text, figs = build_report(analysis, case_path=str(args.case), stem=stem,
                                  elapsed=time.perf_counter() - t0, command=command)
        written = write_report(args.report, stem, text, figs, args.force)
    bar.close()

    def text(stream) -> None:
        print(_summary(analysis, case.title), file=stream)
        if args.report:
            print(f"\nreport: {written[-2]} and {written[-1]} (+ {len(written) - 2} figures)", file=stream)

    emit(Output(data=analysis.to_json(), json_options={"indent": 2, "allow_nan": False}, text=text), fmt)
    return 0
