"""The pipeline of ``python -m semianalytic run CASE.toml --out DIR``: every analysis the case
asks for, into one folder: ``results.json`` (SI values, units in the keys), ``report.md`` and
``report.html`` with PNG figures, and ``vtk/*.vtu`` fields.

The case is validated and every analysis checks its inputs before anything is computed:
bad input exits with status 2, one line naming the field, and nothing written.  The folder
is built aside and swapped in at the end (:class:`~semianalytic.report.output.StagedDir`);
an existing ``DIR`` is replaced only with ``--force``.

Importing this module registers every step (:mod:`.bodies`, :mod:`.fields`, :mod:`.part1`,
:mod:`.part2`, :mod:`.parts34`) in :mod:`.registry`.
"""

from __future__ import annotations

import time
from pathlib import Path

from semianalytic.errors import InputError
from semianalytic.report.document import fmt
from semianalytic.report.provenance import generated_by, version
from semianalytic.run import (  # noqa: F401 (steps register on import)
    bodies,
    fields,
    part1,
    part2,
    parts34,
    perforation,  # noqa: F401 (issue 23: registers the perforation step)
)
from semianalytic.run.context import Context
from semianalytic.run.registry import Step, _mm, _projectile, select_steps

__all__ = ["run_case", "introduction"]


def run_case(case_path, out, *, force: bool = False, only=None, render: bool = True, cache_dir=None,
             contact=None, tolerance=None, quiet: bool = True, command: str | None = None) -> dict:
    """Run a case into ``out``; returns the results dict (also written to ``out/results.json``).
    ``contact`` / ``tolerance`` override ``[coefficients]`` (flags ``--contact``, ``--tolerance``)."""
    from semianalytic.case import load_case
    from semianalytic.report.document import Document, to_markdown
    from semianalytic.report.html import to_html
    from semianalytic.report.output import StagedDir, check_output_dir
    from semianalytic.report.provenance import case_identity
    from semianalytic.run.case import RunSection

    t0 = time.perf_counter()
    case = load_case(case_path)
    identity = case_identity(case_path)
    if command is None:  # the command line that reproduces this folder, every flag that shaped it included
        flags = [f"--only {a}" for a in (only or [])] + (["--no-render"] if not render else [])
        flags += [f"--contact {contact}"] if contact is not None else []
        flags += [f"--tolerance {tolerance}"] if tolerance is not None else []
        command = " ".join([_command(identity, out, case_path), *flags, *(["--force"] if force else [])])
    if contact is not None or tolerance is not None:
        from semianalytic.cache import override_coefficients

        case = override_coefficients(case, contact=contact, tolerance=tolerance)
    run_section = case.section("run") or RunSection()
    steps, skipped = select_steps(case, run_section, only)
    check_output_dir(out, force, protect=(case_path,))
    for step in steps:  # every input check before any output
        step.preflight(case, run_section)
    with StagedDir(out, force, protect=(case_path,)) as staged:
        title = case.title or Path(case_path).stem
        ctx = Context(case, staged, run_section, Document(f"Report: {title}"), render=render, cache_dir=cache_dir)
        introduction(ctx, identity, steps, skipped, command)
        from semianalytic.progress import stages

        bar = stages(len(steps), "run", quiet=quiet)  # stderr only, and only on a terminal
        for step in steps:
            bar.step(step.name)
            t = time.perf_counter()
            step.run(ctx)
            ctx.timings[step.name] = time.perf_counter() - t
        bar.close()
        ctx.timings["total"] = time.perf_counter() - t0
        ctx.doc.heading("Run")
        ctx.doc.table(
            ["step", "time [s]"],
            [[k, f"{v:.2f}"] for k, v in ctx.timings.items()],
            caption="Wall-clock time of each analysis (this machine).",
        )
        results = {
            # the case by file name and content hash: no output carries a machine path
            "case": {"path": identity["file"], "file": identity["file"], "sha256": identity["sha256"],
                     "title": case.title, "reproduces": case.reproduces},
            "generated_by": {"command": command, "version": version()},
            "analyses": ctx.results,
            "skipped": skipped,
            "timings_s": ctx.timings,
            "figures": ctx.figures,
        }
        staged.write_json("results.json", results)
        staged.write_text("report.md", to_markdown(ctx.doc))
        # the figures embedded as data: URIs (the page can be mailed alone); the files stay beside it
        staged.write_text("report.html", to_html(ctx.doc, images=lambda rel: _staged_bytes(staged, rel)))
        results["files"] = sorted(staged.files)
    return results


def _staged_bytes(staged, rel: str) -> bytes | None:
    p = staged.root / rel
    return p.read_bytes() if p.is_file() else None


def _shown(path, name: str) -> str:
    """A path as a report may show it: relative as given (e.g. ``cases/x.toml``), else ``name``
    only (an absolute path, or one climbing with '..', would name the machine's folders)."""
    p = Path(path)
    return p.as_posix() if not p.is_absolute() and ".." not in p.parts else name


def _command(identity: dict, out, case_path) -> str:
    """The command that made the report, without the machine's folders."""
    return f"python -m semianalytic run {_shown(case_path, identity['file'])} --out {_shown(out, Path(out).name)}"


# --------------------------------------------------------------------------------------
# introduction


def introduction(ctx: Context, identity: dict, steps: list[Step], skipped: dict[str, str],
                 command: str | None = None) -> None:
    case = ctx.case
    d = ctx.doc
    if command is not None:
        d.para(generated_by(command))
    d.para(f"Case file: `{identity['file']}` (sha256 `{identity['sha256'][:12]}`).")
    if case.reproduces:
        d.para(f"Reproduces: {case.reproduces}.")
    d.para("Analyses run: " + ", ".join(f"`{s.name}`" for s in steps) + ".")
    for name, why in skipped.items():
        d.note(f"`{name}` skipped: {why}.", "warning" if "not available" in why else "note")
    rows = []
    if case.projectile is not None:
        p = case.projectile
        pr = _projectile(case)
        rows += [
            ["projectile nose", p.nose + (f" (psi = {p.crh:g})" if p.crh is not None else "")],
            ["diameter d [mm]", _mm(pr.diameter)],
            ["nose length L_h [mm]", _mm(pr.nose_length)],
            ["shank length L_c [mm]", _mm(pr.shank_length)],
            ["length L = L_c + L_h [mm]", _mm(pr.length)],
        ]
        try:
            rows.append(["mass m [g]", fmt(pr.mass * 1e3)])
        except InputError:
            pass
        for key, label, scale in (
            ("density", "projectile density [kg/m^3]", 1.0),
            ("youngs_modulus", "E_p [GPa]", 1e-9),
            ("poisson_ratio", "nu_p", 1.0),
            ("yield_stress", "Y_p [MPa]", 1e-6),
        ):
            v = getattr(p, key)
            if v is not None:
                rows.append([label, fmt(v * scale)])
    if case.target is not None:
        rows.append(["target density rho [kg/m^3]", fmt(case.target.density)])
        raw = case.raw.get("target", {}).get("resistance")
        if isinstance(raw, dict):
            rows.append(["target resistance", ", ".join(f"{k} = {v}" for k, v in raw.items())])
    if case.impact is not None:
        rows.append(["striking velocities U_s [m/s]", ", ".join(fmt(v) for v in case.impact.striking_velocities)])
    if case.body is not None:
        b = case.body
        rows.append(["body", b.shape])
        if b.diameter is not None:
            rows.append(["diameter [m]", fmt(b.diameter)])
        if b.length is not None:
            rows.append(["length [m]", fmt(b.length)])
    if rows:
        d.heading("Inputs")
        d.table(["quantity", "value"], rows, caption="Inputs as read from the case file (SI unless stated).")
