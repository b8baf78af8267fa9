"""The analyses of a ``run``, one step each: which sections a step needs, the input checks it
makes before anything is computed (``preflight``: bad input -> InputError, exit 2, nothing
written) and what it puts into the report and ``results.json``.

Steps call the models' public functions only; the physics lives in the model packages.
A step whose model package is not installed in this version is listed as skipped.
"""

from __future__ import annotations

import importlib
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from semianalytic.case import Case
from semianalytic.errors import InputError
from semianalytic.report.case import ANALYSES, RunSection
from semianalytic.report.context import Context
from semianalytic.report.document import fmt


@dataclass(frozen=True)
class Step:
    name: str
    title: str
    requires: tuple[str, ...]  # case sections
    modules: tuple[str, ...]  # model packages it calls
    applies: Callable[[Case], bool]
    preflight: Callable[[Case, RunSection], None]
    run: Callable[[Context], None]

    def available(self) -> str | None:
        """None if the model packages import, else why not."""
        for m in self.modules:
            try:
                importlib.import_module(m)
            except ImportError as exc:
                return f"not available in this version ({m}: {exc})"
        return None


# --------------------------------------------------------------------------------------
# shared helpers


def _projectile(case: Case):
    from semianalytic.geometry import projectile_from_section

    return projectile_from_section(case.require("projectile"))


def _field_velocity(case: Case, run: RunSection, memo: dict | None = None, depth: float | None = None) -> tuple[float, str]:
    """u for v = -u grad(phi): [run] field_velocity, else the rigid projectile's speed at this
    depth for the first striking velocity (when the penetration step ran), else U_s."""
    if run.field_velocity is not None:
        return run.field_velocity, "[run] field_velocity"
    if case.impact is None:
        return 1.0, "unit speed"
    U = float(case.impact.striking_velocities[0])
    motion = (memo or {}).get("rigid_motion", {}).get(U)
    if motion is not None and depth is not None and depth < motion.final_depth:
        return float(np.interp(depth, motion.P, motion.u)), f"rigid projectile at this depth, U_s = {U:g} m/s"
    return U, "striking velocity U_s"


def bem_options(case: Case) -> dict:
    """order (and refinement, when the case sets it) for the BEM solvers."""
    out = {"order": case.bem.order}
    if case.bem.refinement is not None:
        out["refinement"] = case.bem.refinement
    return out


def _mm(v) -> str:
    return fmt(None if v is None else v * 1e3)


def _coefficient_table(ctx: Context):
    """The case's coefficient table, built (or loaded from the cache) once per run."""
    if "table" not in ctx.memo:
        from semianalytic.sweep.kernels import coefficient_table_for

        ctx.memo["table"] = coefficient_table_for(ctx.case, ctx.cache_dir)
    return ctx.memo["table"]


def table_available() -> bool:
    try:
        importlib.import_module("semianalytic.coefficients.table")
    except ImportError:
        return False
    return True


# --------------------------------------------------------------------------------------
# introduction


def introduction(ctx: Context, case_path, steps: list[Step], skipped: dict[str, str]) -> None:
    case = ctx.case
    d = ctx.doc
    d.para(f"Case file: `{Path(case_path).as_posix()}`.")
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


# --------------------------------------------------------------------------------------
# added mass of a closed body (Part I section 1.4; exact: Lamb)


def _added_mass_preflight(case: Case, run: RunSection) -> None:
    from semianalytic.geometry import body_from_section

    body_from_section(case.require("body"))


def _added_mass_run(ctx: Context) -> None:
    from semianalytic import exact
    from semianalytic.bem import solve_body
    from semianalytic.geometry import body_from_section
    from semianalytic.report.figures import Series, line_figure

    b = ctx.case.body
    meridian = body_from_section(b)
    sol = solve_body(meridian, **bem_options(ctx.case))
    k = sol.added_mass_coefficient
    ref = None
    if b.shape == "sphere":
        ref = exact.sphere_added_mass_coefficient()
    elif b.shape == "spheroid":
        ref = exact.spheroid_added_mass_coefficient(b.length, b.diameter)
    d = ctx.doc
    d.heading("Added mass (BEM, unbounded fluid)")
    rows = [["added-mass coefficient A/V (BEM)", f"{k:.10f}"], ["unknowns", str(sol.unknowns)]]
    if ref is not None:
        rows += [["exact (Lamb)", f"{ref:.10f}"], ["relative error", f"{abs(k - ref) / ref:.2e}"]]
    d.table(["quantity", "value"], rows)
    nodes = sol.nodes
    series = [Series(nodes.x, nodes.phi, "BEM phi on the surface", "o")]
    if ref is not None:
        xs = np.linspace(nodes.x.min(), nodes.x.max(), 200)
        series.append(Series(xs, ref * xs, "exact phi = k1 x (Lamb)", "-"))
    fig = line_figure(series, "x [m]", "phi [m] (unit speed)", "Surface potential of the body")
    ctx.figure("added_mass_surface_phi", fig, "Surface potential phi(x) against the exact k1 x.")
    ctx.results["added_mass"] = {
        "added_mass_coefficient": k,
        "added_mass_coefficient_exact": ref,
        "relative_error": None if ref is None else abs(k - ref) / ref,
        "A_m3": sol.A,
        "volume_m3": meridian.volume(),
        "unknowns": sol.unknowns,
    }


# --------------------------------------------------------------------------------------
# velocity field (Part I eq. (23), Figs. 12-13)


def _field_depths(case: Case, run: RunSection) -> list[float]:
    if run.field_depths:
        return list(run.field_depths)
    pr = _projectile(case)
    return [0.5 * pr.length]


def _depth_tag(P: float) -> str:
    """File-name tag of a depth: 35.9 mm -> 'P35p9mm'."""
    return f"P{P * 1e3:.1f}mm".replace(".", "p")


def _velocity_field_preflight(case: Case, run: RunSection) -> None:
    case.require("target")
    pr = _projectile(case)
    for i, P in enumerate(_field_depths(case, run)):
        if not P > 0:
            raise InputError(f"run.field_depths.{i}", "must be positive")
        if P > 1000 * pr.length:
            raise InputError(f"run.field_depths.{i}", f"{P:g} m is beyond 1000 projectile lengths")


def _velocity_field_run(ctx: Context) -> None:
    from semianalytic.report import vtk
    from semianalytic.report.figures import velocity_field_figure

    case, run = ctx.case, ctx.run
    pr = _projectile(case)
    d = ctx.doc
    d.heading("Velocity field (Part I, eq. (23); Figs. 12-13)")
    d.para(
        "v = -u grad(phi) (eq. (8)) from the BEM potential of the half-space problem, on a "
        f"{run.field_grid[0]} x {run.field_grid[1]} grid of the meridian plane {run.field_extent:g} diameters around "
        f"the nose, revolved into {run.field_segments} azimuthal segments. Open the `.vtu` files in ParaView or "
        "pyvista (point data `velocity` [m/s], `speed` [m/s], `phi` [m] at unit speed, `Phi` = u phi [m^2/s])."
    )
    out = []
    for P in _field_depths(case, run):
        u, why = _field_velocity(case, run, ctx.memo, P)
        field, sol = vtk.projectile_field(
            pr.nose, pr.length, P, u, extent=run.field_extent, grid=tuple(run.field_grid),
            **bem_options(case),
        )
        tag = _depth_tag(P)
        rel2, p2 = ctx.vtk_path(f"velocity_meridian_{tag}.vtu")
        rel3, p3 = ctx.vtk_path(f"velocity_3d_{tag}.vtu")
        rels, ps = ctx.vtk_path(f"projectile_{tag}.vtu")
        vtk.write_vtu(vtk.meridian_mesh(field), p2)
        vtk.write_vtu(vtk.revolved_mesh(field, run.field_segments), p3)
        vtk.write_vtu(vtk.revolved_surface(vtk.projectile_outline(pr.nose, pr.length, P), 4 * run.field_segments), ps)
        outline = vtk.projectile_outline(pr.nose, pr.length, P)
        fig = velocity_field_figure(field.grid.x, field.grid.r, field.vx, field.vr, outline,
                                    f"|v| and direction at P = {P * 1e3:.1f} mm, u = {fmt(u)} m/s")
        ctx.figure(f"velocity_field_{tag}", fig,
                   f"Velocity field near the nose at P = {P * 1e3:.1f} mm (cf. Figs. 12-13); free surface dashed.")
        if ctx.render:
            rel_png = f"{run.figures_dir.rstrip('/')}/velocity_render_{tag}.png"
            try:
                vtk.render_png(p3, p2, ps, ctx.out.path(rel_png, "run.figures_dir"),
                               f"P = {P * 1e3:.1f} mm, u = {fmt(u)} m/s")
            except Exception as exc:  # no off-screen OpenGL here: the VTK files are still written
                ctx.doc.note(f"The pyvista render failed ({type(exc).__name__}: {exc}); open `{rel3}` in ParaView.",
                             "warning")
            else:
                ctx.doc.image(rel_png, f"pyvista render of `{rel3}` (half cut away) at P = {P * 1e3:.1f} mm.")
                ctx.figures.append(rel_png)
        speed = np.hypot(field.vx, field.vr)
        out.append({
            "depth_m": P,
            "speed_u_m_s": u,
            "speed_u_from": why,
            "phi_tip_m": sol.phi_tip,
            "max_speed_m_s": float(np.nanmax(speed)),
            "A_m3": sol.A,
            "C_m2": sol.C,
            "vtk": {"meridian": rel2, "revolved": rel3, "projectile": rels},
        })
    d.table(
        ["P [mm]", "u [m/s] (from)", "max |v| on grid [m/s]", "phi at tip [mm]", "Abar [mm]", "Cbar"],
        [[_mm(o["depth_m"]), f'{fmt(o["speed_u_m_s"])} ({o["speed_u_from"]})', fmt(o["max_speed_m_s"]), _mm(o["phi_tip_m"]),
          _mm(4 * o["A_m3"] / (math.pi * pr.diameter**2)), fmt(4 * o["C_m2"] / (math.pi * pr.diameter**2))]
         for o in out],
    )
    ctx.results["velocity_field"] = out


# --------------------------------------------------------------------------------------
# FEM potential field of fem_check (explicit only: [run] analyses or --only fem_field)


def _fem_field_run(ctx: Context) -> None:
    from fem_check.meshing import MeshOptions, build_mesh, halfspace_domain
    from fem_check.potential import solve_potential

    from semianalytic.bem import solve_halfspace
    from semianalytic.report import vtk

    case, run = ctx.case, ctx.run
    pr = _projectile(case)
    d = ctx.doc
    d.heading("FEM potential field (fem_check)")
    d.para(
        "The independent finite-element solution of the same potential problem (fem_check: gmsh mesh of the "
        "meridian half-plane, P2 elements with curved edges, monopole Robin far field, errata item 2f), written "
        "as `.vtu` with the BEM potential at the same vertices for comparison (`phi_bem`, `phi_difference`)."
    )
    rows, out = [], []
    opts = MeshOptions()
    for P in _field_depths(case, run):
        u, why = _field_velocity(case, run, ctx.memo, P)
        dm = build_mesh(halfspace_domain(pr.nose, P, opts), opts)
        sol = solve_potential(dm, "monopole")
        bem = solve_halfspace(pr.nose, P, **bem_options(case))
        mesh = vtk.fem_meridian_mesh(sol, u, bem)
        tag = _depth_tag(P)
        rel, path = ctx.vtk_path(f"fem_potential_{tag}.vtu")
        vtk.write_vtu(mesh, path)
        pts = mesh.points
        near = np.hypot(pts[:, 0] - P, pts[:, 1]) < 3 * pr.diameter
        diff, ref = mesh.point_data["phi_difference"], mesh.point_data["phi_bem"]
        ok = near & np.isfinite(diff)
        dmax = float(np.max(np.abs(diff[ok])) / np.max(np.abs(ref[ok]))) if ok.any() else float("nan")
        rows.append([_mm(P), str(sol.n_dofs), fmt(sol.A), fmt(bem.A), f"{abs(sol.A - bem.A) / abs(bem.A):.1e}",
                     f"{dmax:.1e}"])
        out.append({"depth_m": P, "dofs": sol.n_dofs, "A_fem_m3": sol.A, "A_bem_m3": bem.A, "C_fem_m2": sol.C,
                    "C_bem_m2": bem.C, "max_rel_phi_difference_near_nose": dmax, "vtk": rel, "speed_u_m_s": u})
    d.table(["P [mm]", "FEM dofs", "A FEM [m^3]", "A BEM [m^3]", "relative difference",
             "max |phi_FEM - phi_BEM| / max |phi| within 3 d of the tip"], rows)
    ctx.results["fem_field"] = out


# --------------------------------------------------------------------------------------
# Part II: brittle cavity expansion


def _cavity_solve(case: Case):
    import warnings

    from semianalytic.cavity import BrittleMaterial, solve_cavity
    from semianalytic.errors import ModelValidityWarning

    sec = case.require("material")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelValidityWarning)  # reported in the document
        return BrittleMaterial.from_section(sec), solve_cavity(BrittleMaterial.from_section(sec), sec.solver)


def _cavity_preflight(case: Case, run: RunSection) -> None:
    _cavity_solve(case)  # hard conditions of errata item 20 raise InputError here


def _cavity_run(ctx: Context) -> None:
    from semianalytic.cavity import zones
    from semianalytic.report.figures import Series, line_figure

    material, r = _cavity_solve(ctx.case)
    d = ctx.doc
    d.heading("Brittle cavity expansion (Part II)")
    for w in r.warnings:
        d.note(w, "warning")
    d.table(
        ["quantity", "value"],
        [
            ["sigma* (eq. 21) [GPa]", fmt(r.sigma_star / 1e9)],
            ["C (eq. 21)", fmt(r.C)],
            ["theta* (eq. 17)", fmt(r.theta_star)],
            ["theta_c (eq. 18)", fmt(r.theta_c)],
            ["v* (eq. 26)", fmt(r.v_star)],
            ["c/b (eq. 13)", fmt(r.c_over_b)],
            ["a/b (eqs. 28-29)", fmt(r.a_over_b)],
            ["e_k (eq. 30)", fmt(r.e_k)],
            ["e_ks (eq. 32)", fmt(r.e_ks)],
            ["theta_k (eq. 33)", fmt(r.theta_k)],
            ["R_r, cavity pressure (eq. 34) [GPa]", fmt(r.cavity_pressure / 1e9)],
            ["solver", f"{r.method}, {r.iterations} iterations"],
        ],
        caption="Three-zone solution (corrected forms of errata items 7-20).",
    )
    b = 1.0
    a, c = r.a_over_b * b, r.c_over_b * b
    ra = np.linspace(a, b, 60)
    rb = np.linspace(b, c, 60)
    rc = np.linspace(c, 3 * c, 80)
    s_a, _ = zones.comminuted_zone(ra, b, r.sigma_star, r.theta_k)
    _, s_b = zones.cracked_zone(rb, b, c, r.sigma_star, material)
    _, s_c, _ = zones.elastic_zone(rc, c, material)
    fig = line_figure(
        [Series(ra, -s_a / 1e9, "comminuted a < r < b (eq. 23)"),
         Series(rb, -s_b / 1e9, "cracked b < r < c (eq. 11)"),
         Series(rc, -s_c / 1e9, "elastic r > c (eq. 5)")],
        "r / b", "-sigma_r [GPa]", "Radial stress through the three zones",
    )
    ctx.figure("cavity_radial_stress", fig, "Compressive radial stress against r/b (Part II, Fig. 1 zones).")
    ctx.results["cavity"] = r.to_json()


# --------------------------------------------------------------------------------------
# registry


def _has(*sections: str) -> Callable[[Case], bool]:
    return lambda case: all(case.section(s) is not None for s in sections)


def _no_preflight(case: Case, run: RunSection) -> None:
    return None


STEPS: dict[str, Step] = {}

# sections each analysis needs (also for analyses whose model is not installed)
REQUIRES: dict[str, tuple[str, ...]] = {
    "added_mass": ("body",),
    "coefficients": ("projectile",),
    "penetration": ("projectile", "target", "impact"),
    "critical_velocity": ("projectile", "target"),
    "validation": ("projectile", "target", "data"),
    "velocity_field": ("projectile", "target"),
    "fem_field": ("projectile", "target"),
    "cavity": ("material",),
    "ballistic_limit": ("ballistic_limit",),
    "nanostrength": ("nanostrength",),
}


def register(step: Step) -> Step:
    STEPS[step.name] = step
    return step


register(Step("added_mass", "Added mass", ("body",), ("semianalytic.bem",), _has("body"),
              _added_mass_preflight, _added_mass_run))
register(Step("fem_field", "FEM field", ("projectile", "target"), ("fem_check.potential", "fem_check.meshing"),
              lambda case: False, _velocity_field_preflight, _fem_field_run))
register(Step("cavity", "Brittle cavity expansion", ("material",), ("semianalytic.cavity",), _has("material"),
              _cavity_preflight, _cavity_run))
register(Step("velocity_field", "Velocity field", ("projectile", "target"),
              ("semianalytic.bem", "meshio"), _has("projectile", "target"),
              _velocity_field_preflight, _velocity_field_run))


def select_steps(case: Case, run: RunSection, only=None) -> tuple[list[Step], dict[str, str]]:
    """Steps to run, in the fixed order of :data:`ANALYSES`, and the skipped ones with why.

    Explicitly requested analyses (``[run] analyses`` or ``--only``) must be possible with the
    case's sections (else InputError naming the section); the automatic choice takes every
    step whose sections are present.
    """
    requested = list(only) if only else (list(run.analyses) if run.analyses else None)
    field = "--only" if only else "run.analyses"
    chosen, skipped = [], {}
    for name in ANALYSES:
        step = STEPS.get(name)
        if requested is not None and name not in requested:
            continue
        if requested is not None:
            for sec in REQUIRES[name]:
                if case.section(sec) is None:
                    raise InputError(sec, f"the case has no [{sec}] section, which analysis {name!r} ({field}) needs")
        if step is None:
            if requested is not None:
                skipped[name] = "not available in this version"
            continue
        if requested is None and not step.applies(case):
            continue
        why = step.available()
        if why:
            skipped[name] = why
            continue
        chosen.append(step)
    if not chosen:
        raise InputError(field if requested else "case", "nothing to run: no analysis applies to this case")
    return chosen, skipped


# Part I steps register themselves on import
from semianalytic.report import steps_part1  # noqa: E402,F401
from semianalytic.report import steps_other  # noqa: E402,F401
