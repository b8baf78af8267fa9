"""The field steps of a ``run``: the BEM velocity field around the projectile (Part I,
eq. (23); Figs. 12-13) on a meridian grid, and the independent FEM potential field of
fem_check at the same depths, both exported as ``.vtu``.

This is the one module of :mod:`semianalytic` that imports :mod:`fem_check`, and only its
public API (:mod:`fem_check.api`), for the ``fem_field`` export (import contract in
pyproject.toml).
"""

from __future__ import annotations

import math

import numpy as np

from semianalytic.case import Case
from semianalytic.errors import InputError
from semianalytic.report.document import fmt
from semianalytic.run.case import RunSection
from semianalytic.run.context import Context
from semianalytic.run.registry import Step, _field_velocity, _has, _mm, _projectile, bem_options, register

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
    from semianalytic.bem.field import projectile_field, projectile_outline
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
        field, sol = projectile_field(
            pr.nose, pr.length, P, u, extent=run.field_extent, grid=tuple(run.field_grid),
            **bem_options(case),
        )
        tag = _depth_tag(P)
        rel2, p2 = ctx.vtk_path(f"velocity_meridian_{tag}.vtu")
        rel3, p3 = ctx.vtk_path(f"velocity_3d_{tag}.vtu")
        rels, ps = ctx.vtk_path(f"projectile_{tag}.vtu")
        vtk.write_vtu(vtk.meridian_mesh(field), p2)
        vtk.write_vtu(vtk.revolved_mesh(field, run.field_segments), p3)
        outline = projectile_outline(pr.nose, pr.length, P)
        vtk.write_vtu(vtk.revolved_surface(outline, 4 * run.field_segments), ps)
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


def bem_at_vertices(field, bem) -> np.ndarray:
    """The BEM potential ``bem.potential`` at the FEM field's vertices off the body and the wall
    (NaN on them: the BEM field is singular there), for ``phi_bem`` / ``phi_difference``."""
    ref = np.full(len(field.phi), np.nan)
    off = ~np.asarray(field.on_surface, bool)
    ref[off] = bem.potential(np.asarray(field.points)[off])
    return ref


def _fem_field_run(ctx: Context) -> None:
    from fem_check.api import halfspace_potential_field

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
    for P in _field_depths(case, run):
        u, why = _field_velocity(case, run, ctx.memo, P)
        sol = halfspace_potential_field(pr.nose, P)
        bem = solve_halfspace(pr.nose, P, **bem_options(case))
        mesh = vtk.fem_meridian_mesh(sol, u, bem_at_vertices(sol, bem))
        tag = _depth_tag(P)
        rel, path = ctx.vtk_path(f"fem_potential_{tag}.vtu")
        vtk.write_vtu(mesh, path)
        pts = mesh.points
        near = np.hypot(pts[:, 0] - P, pts[:, 1]) < 3 * pr.diameter
        diff, ref = mesh.point_data["phi_difference"], mesh.point_data["phi_bem"]
        ok = near & np.isfinite(diff)
        dmax = float(np.max(np.abs(diff[ok])) / np.max(np.abs(ref[ok]))) if ok.any() else float("nan")
        rows.append([_mm(P), str(sol.dofs), fmt(sol.A), fmt(bem.A), f"{abs(sol.A - bem.A) / abs(bem.A):.1e}",
                     f"{dmax:.1e}"])
        out.append({"depth_m": P, "dofs": sol.dofs, "A_fem_m3": sol.A, "A_bem_m3": bem.A, "C_fem_m2": sol.C,
                    "C_bem_m2": bem.C, "max_rel_phi_difference_near_nose": dmax, "vtk": rel, "speed_u_m_s": u})
    d.table(["P [mm]", "FEM dofs", "A FEM [m^3]", "A BEM [m^3]", "relative difference",
             "max |phi_FEM - phi_BEM| / max |phi| within 3 d of the tip"], rows)
    ctx.results["fem_field"] = out



register(Step("fem_field", "FEM field", ("projectile", "target"), ("fem_check.api",),
              lambda case: False, _velocity_field_preflight, _fem_field_run))
register(Step("velocity_field", "Velocity field", ("projectile", "target"),
              ("semianalytic.bem", "meshio"), _has("projectile", "target"),
              _velocity_field_preflight, _velocity_field_run))
