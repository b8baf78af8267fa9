"""The field steps of a ``run``: the BEM velocity field around the projectile (Part I,
eq. (23); Figs. 12-13) on a meridian grid, and the independent FEM potential field of
fem_check at the same depths, both exported as ``.vtu``.

This is the one module of :mod:`semianalytic` that imports :mod:`fem_check`, and only its
public API (:mod:`fem_check.api`), for the ``fem_field`` export (import contract in
pyproject.toml).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from semianalytic.case import Case
from semianalytic.errors import InputError
from semianalytic.report.document import fmt
from semianalytic.run.case import RunSection
from semianalytic.run.context import Context
from semianalytic.run.registry import Step, _field_velocity, _has, _mm, _projectile, bem_options, register

# --------------------------------------------------------------------------------------
# velocity field (Part I eq. (23), Figs. 12-13) on body-fitted points


@dataclass(frozen=True)
class BodyFittedField:
    """Eq. (23) velocity at the nodes of a body-fitted polar grid of the meridian half-plane.

    Node (i, j) = ``points[i * n_rho + j]`` lies on the ray i from a centre on the axis inside
    the nose (i = 0: the axis ahead of the tip), at the j-th graded distance from the body
    surface (j = 0, just outside it) to the window (x = 0 free surface, r = r_max, x = x_max).
    ``quads`` (counter-clockwise in (x, r)) cover the fluid only: no cell overlaps the body.
    """

    points: np.ndarray  # (n, 2) of (x, r) [m], target frame (free surface x = 0, tip at x = P)
    quads: np.ndarray  # (m, 4) node indices, counter-clockwise in (x, r)
    vx: np.ndarray  # (n,) [m/s]
    vr: np.ndarray  # (n,) [m/s]
    phi: np.ndarray  # (n,) unit-speed potential [m]
    speed_u: float  # u [m/s]
    depth: float  # P [m]
    shape: tuple[int, int]  # (n_theta, n_rho)
    window: tuple[float, float, float]  # (x_min = 0, x_max, r_max) [m]
    surface_radius: float  # body radius at the free surface x = 0 [m]


def _ray_exit(inside, xc: float, theta: np.ndarray, rho_max: np.ndarray, iterations: int = 60) -> np.ndarray:
    """Distance from (xc, 0) along each ray to the body surface (bisection; the body is convex
    and contains the centre, so each ray leaves it once)."""
    lo, hi = np.zeros_like(theta), rho_max.copy()
    c, s = np.cos(theta), np.sin(theta)
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        ins = np.asarray(inside(xc + mid * c, mid * s), bool)
        lo, hi = np.where(ins, mid, lo), np.where(ins, hi, mid)
    return hi


def _window_exit(xc: float, x1: float, r1: float, theta: np.ndarray) -> np.ndarray:
    """Distance from (xc, 0) along each ray to the window [0, x1] x [0, r1]."""
    c, s = np.cos(theta), np.sin(theta)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.stack([np.where(c > 1e-15, (x1 - xc) / c, np.inf),
                      np.where(c < -1e-15, -xc / c, np.inf),
                      np.where(s > 1e-15, r1 / s, np.inf)])
    return t.min(axis=0)


def body_fitted_points(nose, length: float, depth: float, extent: float, n_theta: int, n_rho: int):
    """A polar grid of the fluid around the nose, conforming to the body and the free surface.

    Rays from a centre on the axis inside the nose (x_c = P - min(L_h, P)/2) run from the body
    surface to the window x in [0, P + extent d], r in [0, max(extent d, 0.75 d)]: the body
    (convex, containing the centre) is crossed once by each ray, so the inner grid line is the
    wetted surface and the outer one contains the free surface x = 0.  Rays are spaced by a
    blend of angle, body arc length and window arc length; nodes along a ray are graded
    towards the body, where the field varies fastest.  Returns ``(points (n_theta*n_rho, 2),
    quads, window, surface_radius)``.
    """
    from semianalytic.bem.field import projectile_inside

    d = nose.diameter
    inside = projectile_inside(nose, length, depth)
    x1, r1 = depth + extent * d, max(extent * d, 0.75 * d)
    xc = depth - 0.5 * min(max(nose.length, 0.5 * d), depth)
    # body radius at the free surface: the last ray ends just above it (a zero-length ray would
    # give degenerate cells)
    r_surf = float(_ray_exit(lambda x, r: inside(np.zeros_like(r), r), 0.0, np.array([0.5 * np.pi]),
                             np.array([r1]))[0])
    theta_max = math.atan2(r_surf + 1e-5 * d, -xc)
    fine = np.linspace(0.0, theta_max, 4001)
    rho_w = _window_exit(xc, x1, r1, fine)
    rho_b = _ray_exit(inside, xc, fine, rho_w)
    arc = []
    for rho in (rho_b, rho_w):
        pts = np.column_stack([xc + rho * np.cos(fine), rho * np.sin(fine)])
        s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))])
        arc.append(s / s[-1])
    blend = (fine / theta_max + arc[0] + arc[1]) / 3.0
    theta = np.interp(np.linspace(0.0, 1.0, n_theta), blend, fine)
    # a ray through each corner of the window and each junction of the nose's meridian (the
    # shoulder, a flat face's edge), so that the grid lines follow them instead of cutting them
    junctions = [(float(seg.point(seg.t1)[0]) + depth, float(seg.point(seg.t1)[1])) for seg in nose.segments]
    corners = [math.atan2(r1, x1 - xc), math.atan2(r1, -xc)]
    corners += [math.atan2(r, x - xc) for x, r in junctions if x > 0.0 and r > 0.0]
    for corner in corners:
        if 0.0 < corner < theta_max:
            k = 1 + int(np.argmin(np.abs(theta[1:-1] - corner)))
            theta[k] = corner
    theta = np.unique(theta)
    n_theta = len(theta)
    rho_w = _window_exit(xc, x1, r1, theta)
    rho_b = _ray_exit(inside, xc, theta, rho_w)
    # grading towards the body: fraction (e^(beta t) - 1)/(e^beta - 1)
    t = np.linspace(0.0, 1.0, n_rho)
    frac = np.expm1(2.5 * t) / np.expm1(2.5)
    gap = 1e-3 * d  # first node off the surface (the boundary integrals are singular on it)
    for _ in range(30):
        off = np.minimum(gap, 0.25 * (rho_w - rho_b))  # short rays near the free surface's corner
        rho = (rho_b + off)[:, None] + (rho_w - rho_b - off)[:, None] * frac[None, :]
        X = xc + rho * np.cos(theta)[:, None]
        Rr = rho * np.sin(theta)[:, None]
        Rr[0, :] = 0.0  # the axis ray exactly on the axis
        # inner cell edges are chords of the convex body: keep their midpoints out of it
        mx, mr = 0.5 * (X[1:, 0] + X[:-1, 0]), 0.5 * (Rr[1:, 0] + Rr[:-1, 0])
        if not np.any(inside(mx, mr)):
            break
        gap *= 1.5
    points = np.column_stack([X.ravel(), Rr.ravel()])
    i, j = np.meshgrid(np.arange(n_theta - 1), np.arange(n_rho - 1), indexing="ij")
    i, j = i.ravel(), j.ravel()
    node = lambda a, b: a * n_rho + b  # noqa: E731
    quads = np.column_stack([node(i, j), node(i, j + 1), node(i + 1, j + 1), node(i + 1, j)])
    # counter-clockwise in (x, r)
    p = points[quads]
    area = 0.5 * np.sum(p[:, :, 0] * np.roll(p[:, :, 1], -1, axis=1) - np.roll(p[:, :, 0], -1, axis=1) * p[:, :, 1],
                        axis=1)
    quads[area < 0] = quads[area < 0][:, ::-1]
    # a table nose that is not star-shaped from the centre: drop the cells that would reach into it
    bad = np.asarray(inside(points[:, 0], points[:, 1]), bool)
    if bad.any():
        quads = quads[~bad[quads].any(axis=1)]
    return points, quads, (0.0, x1, r1), r_surf


def body_fitted_field(nose, length: float, depth: float, u: float, *, extent: float, grid: tuple[int, int],
                      order: int = 8, refinement: float | None = None, solution=None):
    """The BEM velocity field v = -u grad(phi) (Part I, eqs. (8), (23)) on
    :func:`body_fitted_points`; ``grid = (nx, nr)`` of ``[run] field_grid`` gives 2 nx rays of
    nr nodes.  Returns ``(BodyFittedField, solution)``."""
    from semianalytic.bem import solve_halfspace

    opts = {"order": order} if refinement is None else {"order": order, "refinement": refinement}
    sol = solution if solution is not None else solve_halfspace(nose, depth, **opts)
    n_theta, n_rho = 2 * int(grid[0]), int(grid[1])
    pts, quads, window, r_surf = body_fitted_points(nose, length, depth, extent, n_theta, n_rho)
    g = np.vstack([sol.gradient(pts[k:k + 2000]) for k in range(0, len(pts), 2000)])
    phi = np.concatenate([sol.potential(pts[k:k + 2000]) for k in range(0, len(pts), 2000)])
    field = BodyFittedField(pts, quads, -u * g[:, 0], -u * g[:, 1], phi, u, depth, (len(pts) // n_rho, n_rho), window,
                           r_surf)
    return field, sol


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
    from semianalytic.bem.field import projectile_outline
    from semianalytic.report import vtk
    from semianalytic.report.figures import velocity_field_figure

    case, run = ctx.case, ctx.run
    pr = _projectile(case)
    d = ctx.doc
    n_theta, n_rho = 2 * run.field_grid[0], run.field_grid[1]
    d.heading("Velocity field (Part I, eq. (23); Figs. 12-13)")
    d.para(
        "v = -u grad(phi) (eq. (8)) from the BEM potential of the half-space problem, on a body-fitted polar grid "
        f"of the meridian plane ({n_theta} rays x {n_rho} nodes from the projectile surface to a window reaching "
        f"{run.field_extent:g} diameters beyond the tip and the free surface x = 0), revolved into "
        f"{run.field_segments} azimuthal segments: the grid conforms to the body and to the free surface, so no "
        f"cell overlaps the projectile. Open the `.vtu` files in ParaView, pyvista or meshio (coordinates in {run.vtk_coordinates}; point "
        "data named with their unit: `velocity_m_s`, `speed_m_s`, `phi_m` at unit speed, `Phi_m2_s` = u phi; field "
        "data `speed_u_m_s`, `depth_m`); each file's `.units.json` beside it names every array's unit and meaning."
    )
    out = []
    for P in _field_depths(case, run):
        u, why = _field_velocity(case, run, ctx.memo, P)
        field, sol = body_fitted_field(pr.nose, pr.length, P, u, extent=run.field_extent,
                                       grid=tuple(run.field_grid), **bem_options(case))
        tag = _depth_tag(P)
        rel2, p2 = ctx.vtk_path(f"velocity_meridian_{tag}.vtu")
        rel3, p3 = ctx.vtk_path(f"velocity_3d_{tag}.vtu")
        rels, ps = ctx.vtk_path(f"projectile_{tag}.vtu")
        vtk.write_vtu(vtk.meridian_mesh(field), p2, run.vtk_coordinates)
        vtk.write_vtu(vtk.revolved_mesh(field, run.field_segments), p3, run.vtk_coordinates)
        outline = projectile_outline(pr.nose, pr.length, P)
        vtk.write_vtu(vtk.revolved_surface(outline, 4 * run.field_segments), ps, run.vtk_coordinates)
        drawn = np.unique(field.quads)
        speed = np.hypot(field.vx, field.vr)[drawn]
        fig, scale = velocity_field_figure(
            field.points, field.quads, field.vx, field.vr, outline, field.window, field.surface_radius,
            f"Target velocity |v| (Part I, eq. (23)) at depth P = {P * 1e3:.1f} mm, projectile speed u = {fmt(u)} m/s",
        )
        x1, r1 = field.window[1] * 1e3, field.window[2] * 1e3
        ctx.figure(
            f"velocity_field_{tag}", fig,
            f"Speed |v| of the target material around the {case.projectile.nose} nose at P = {P * 1e3:.1f} mm "
            f"(cf. Part I, Figs. 12-13) on the body-fitted grid ({n_theta} x {n_rho} nodes), window x = 0 to "
            f"{x1:.1f} mm, |r| <= {r1:.1f} mm, mirrored about the axis. The free surface x = 0 is inside the window "
            "(blue line; dphi/dn = 0 there in the mirror method of eqs. (20)-(22), so v is tangential to it); the wetted surface (the submerged projectile, x >= 0, where eq. (7) holds) is orange; "  # noqa: E501
            f"white lines are streamlines of v. Colour: {scale}.",
        )
        if ctx.render:
            rel_png = f"{run.figures_dir.rstrip('/')}/velocity_render_{tag}.png"
            try:
                vtk.render_png(p3, p2, ps, ctx.out.path(rel_png, "run.figures_dir"),
                               f"speed of the target at P = {P * 1e3:.1f} mm, u = {fmt(u)} m/s")
            except Exception as exc:  # no off-screen OpenGL here: the VTK files are still written
                ctx.doc.note(f"The pyvista render failed ({type(exc).__name__}: {exc}); open `{rel3}` in ParaView.",
                             "warning")
            else:
                ctx.doc.image(rel_png, f"pyvista render of `{rel3}` (the half z > 0 cut away) at P = {P * 1e3:.1f} "
                              f"mm: the revolved body-fitted field, clipped at the projectile surface; colour: {scale}.")
                ctx.figures.append(rel_png)
        out.append({
            "depth_m": P,
            "speed_u_m_s": u,
            "speed_u_from": why,
            "phi_tip_m": sol.phi_tip,
            "max_speed_m_s": float(np.max(speed)),
            "min_speed_m_s": float(np.min(speed)),
            "grid": {"kind": "body-fitted polar", "rays": n_theta, "nodes_per_ray": n_rho,
                     "window_m": list(field.window)},
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
        "as `.vtu` with the BEM potential at the same vertices for comparison (`phi_bem_m`, `phi_difference_m`)."
    )
    rows, out = [], []
    for P in _field_depths(case, run):
        u, why = _field_velocity(case, run, ctx.memo, P)
        sol = halfspace_potential_field(pr.nose, P)
        bem = solve_halfspace(pr.nose, P, **bem_options(case))
        mesh = vtk.fem_meridian_mesh(sol, u, bem_at_vertices(sol, bem))
        tag = _depth_tag(P)
        rel, path = ctx.vtk_path(f"fem_potential_{tag}.vtu")
        vtk.write_vtu(mesh, path, run.vtk_coordinates)
        pts = mesh.points
        near = np.hypot(pts[:, 0] - P, pts[:, 1]) < 3 * pr.diameter
        diff, ref = mesh.point_data["phi_difference_m"], mesh.point_data["phi_bem_m"]
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
