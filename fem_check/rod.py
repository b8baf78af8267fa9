"""FEM of the free-free elastic rod loaded at one end (Part I, section 2, eqs. (24)-(29)).

rho_p A w_tt = E_p A w_xx on 0 < x < L, free end x = 0 (E_p w_x = 0), loaded end x = L with
E_p A w_x(L, t) = -N(t) (compression; N = sigma_0 pi d^2 / 4 applied suddenly at t = 0 for
eq. (24)).  Displacements along +x, so the rod is pushed towards -x (the paper's sign).

Space: P1 or P2 Lagrange elements (scikit-fem, consistent mass).  Time: the trapezoidal rule
(Newmark average acceleration), which conserves the discrete energy
E = 1/2 v^T M v + 1/2 u^T K u exactly up to the work of the load,
E_{n+1} - E_n = 1/2 (f_n + f_{n+1})^T (u_{n+1} - u_n), so every energy below is the rod's own
discrete energy, not a post-processed formula.

The vibrational energy is the total mechanical energy minus the rigid-body kinetic energy
p^2 / (2 m), p = 1^T M v the momentum; the paper's W2 (eq. (29)) is reported beside it
(errata item 5).
"""

from __future__ import annotations

import argparse
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.sparse.linalg as spla
from skfem import Basis, BilinearForm, ElementLineP1, ElementLineP2, MeshLine1

from semianalytic.errors import InputError
from semianalytic.penetration import rod as series  # the series solution (24)-(29) compared with
from semianalytic.penetration.rod import Rod  # length L, diameter d, E_p, rho_p; c0, area, mass, period 2L/c0


@BilinearForm
def _mass(u, v, w):
    return u * v


@BilinearForm
def _stiff(u, v, w):
    return u.grad[0] * v.grad[0]


@dataclass
class RodHistory:
    """Time histories of the FEM rod (SI).  ``x_nodes``/``strain_snapshots`` hold the strain at
    element midpoints at the times ``snapshot_times``."""

    t: np.ndarray
    force: np.ndarray  # N(t) >= 0, compressive
    u_end: np.ndarray  # w(L, t)
    v_end: np.ndarray  # dw/dt (L, t)
    u_free: np.ndarray  # w(0, t)
    energy: np.ndarray  # total mechanical energy
    rigid_kinetic: np.ndarray  # p^2 / (2 m)
    work: np.ndarray  # work of the end force (trapezoidal, the discrete energy balance)
    x_mid: np.ndarray
    snapshot_times: np.ndarray
    strain_snapshots: np.ndarray
    n_dofs: int
    seconds: float

    @property
    def vibrational(self) -> np.ndarray:
        """Total mechanical energy minus the rigid-body kinetic energy [J]."""
        return self.energy - self.rigid_kinetic


def simulate_rod(rod: Rod, force: Callable[[np.ndarray], np.ndarray], t_end: float, n_elements: int = 400,
                 degree: int = 1, courant: float = 2**-0.5, snapshot_times=()) -> RodHistory:
    """Integrate the rod of Part I, eq. (24) under the end force N(t) >= 0 (compressive) from rest
    at t = 0 to ``t_end`` (the paper's problem is N = sigma_0 pi d^2/4 constant).

    ``courant`` = c_0 dt / h_node (h_node the node spacing).  The trapezoidal rule is
    unconditionally stable; for P1 with consistent mass the default 1/sqrt(2) cancels the
    second-order phase errors of space (omega_h ~ omega (1 + (kh)^2/24)) and time
    (omega_dt ~ omega_h (1 - (omega_h dt)^2/12)), which keeps the step-load wave fronts sharp.
    """
    if n_elements < 2:
        raise InputError("rod.elements", f"need at least 2 elements; got {n_elements!r}")
    if degree not in (1, 2):
        raise InputError("rod.degree", f"must be 1 or 2; got {degree!r}")
    t0 = time.perf_counter()
    L, A, E, rho = rod.length, rod.area, rod.youngs_modulus, rod.density
    mesh = MeshLine1.init_tensor(np.linspace(0.0, L, n_elements + 1))
    basis = Basis(mesh, ElementLineP1() if degree == 1 else ElementLineP2(), intorder=2 * degree + 1)
    M = (rho * A) * _mass.assemble(basis).tocsc()
    K = (E * A) * _stiff.assemble(basis).tocsc()
    N = basis.N
    iL = int(basis.nodal_dofs[0, -1])
    i0 = int(basis.nodal_dofs[0, 0])
    h_node = L / (n_elements * degree)
    dt_target = courant * h_node / rod.c0
    n_steps = max(1, int(math.ceil(t_end / dt_target)))
    dt = t_end / n_steps
    t = np.linspace(0.0, t_end, n_steps + 1)
    Nt = np.asarray(force(t), float) * np.ones_like(t)
    e_L = np.zeros(N)
    e_L[iL] = 1.0
    ones = np.ones(N)
    Mones = M @ ones  # momentum p = 1^T M v
    m = float(ones @ Mones)
    lu_M = spla.splu(M)
    lu = spla.splu((M + (dt * dt / 4.0) * K).tocsc())
    u = np.zeros(N)
    v = np.zeros(N)
    a = lu_M.solve(-Nt[0] * e_L)  # load present from t = 0+
    out = {k: np.zeros(n_steps + 1) for k in ("uL", "vL", "u0", "E", "T", "W")}
    snaps = sorted(float(s) for s in snapshot_times)
    snap_idx = [int(round(s / dt)) for s in snaps]
    elements = basis.element_dofs
    x_mid = 0.5 * (mesh.p[0, mesh.t[0]] + mesh.p[0, mesh.t[1]])
    strain_snaps = []

    def element_strain(uvec):
        # du/dx at the element midpoint: the chord slope for P1 and, for a quadratic, too
        x0, x1 = mesh.p[0, mesh.t[0]], mesh.p[0, mesh.t[1]]
        return (uvec[elements[1]] - uvec[elements[0]]) / (x1 - x0)

    work = 0.0
    f_prev = -Nt[0] * e_L
    for n in range(n_steps + 1):
        if n > 0:
            f_new = -Nt[n] * e_L
            pred = u + dt * v + (dt * dt / 4.0) * a
            a_new = lu.solve(f_new - K @ pred)
            u_new = pred + (dt * dt / 4.0) * a_new
            v = v + 0.5 * dt * (a + a_new)
            work += 0.5 * float((f_prev + f_new) @ (u_new - u))
            u, a, f_prev = u_new, a_new, f_new
        out["uL"][n], out["vL"][n], out["u0"][n] = u[iL], v[iL], u[i0]
        p = float(Mones @ v)
        out["E"][n] = 0.5 * float(v @ (M @ v)) + 0.5 * float(u @ (K @ u))
        out["T"][n] = p * p / (2 * m)
        out["W"][n] = work
        if n in snap_idx:
            strain_snaps.append(element_strain(u))
    return RodHistory(t, Nt, out["uL"], out["vL"], out["u0"], out["E"], out["T"], out["W"], x_mid,
                      np.array(snaps), np.array(strain_snaps), int(N), time.perf_counter() - t0)


# ------------------------------------------------------------------------------------
# comparisons with the series solution (Part I, eqs. (24)-(29)) and the command `rod`

DEFAULT_ROD = Rod(71.1e-3, 7.11e-3, 210e9, 7830.0)  # Fig. 5 ogival projectile (errata 2d)
DEFAULT_SIGMA0 = 1.0e9


def step_load_study(rod: Rod, sigma0: float, round_trips: float = 10.5, n_elements: int = 400,
                    courant: float = 2**-0.5) -> dict:
    """FEM against the series (24) for a suddenly applied end stress sigma0 (Part I, eqs. (24)-(29)).

    Errors: w(L, t) relative to max |w(L, t)| (rigid-body motion included, the brief's measure)
    and relative to the elastic amplitude sigma0 L / (2 E_p); the end velocity (25) in RMS over
    time relative to sigma0 c0 / E_p; the strain (27) in RMS over x at t = L/c0 (2i - 1), where
    (27) gives -sigma0/E_p everywhere; the vibrational energy against the exact solution's.
    """

    T = round_trips * rod.period
    t_snap = [(2 * i - 1) * rod.length / rod.c0 for i in range(1, int(round_trips) + 1)]
    hist = simulate_rod(rod, lambda t: sigma0 * rod.area * np.ones_like(t), T, n_elements, courant=courant,
                        snapshot_times=t_snap)
    w = series.end_displacement(rod, sigma0, hist.t)
    v = series.end_velocity(rod, sigma0, hist.t)
    E = rod.youngs_modulus
    amp = sigma0 * rod.length / (2 * E)
    err_w = np.abs(hist.u_end - w)
    snaps = []
    for ts, eps in zip(hist.snapshot_times, hist.strain_snapshots):
        ex = series.strain(rod, sigma0, hist.x_mid, ts)
        snaps.append({"t_s": float(ts), "rms_rel": float(np.sqrt(np.mean((eps - ex) ** 2)) / (sigma0 / E)),
                      "paper_value": -sigma0 / E, "fem_mean": float(np.mean(eps))})
    vib_exact = series.vibrational_energy(rod, sigma0, hist.t)
    W2 = series.paper_W2(rod, sigma0, hist.t)
    vmax = series.max_vibrational_energy(rod, sigma0)
    return {
        "rod": {"length_m": rod.length, "diameter_m": rod.diameter, "youngs_modulus_Pa": E, "density_kg_m3": rod.density,
                "c0_m_s": rod.c0, "round_trip_s": rod.period},
        "sigma0_Pa": sigma0, "round_trips": round_trips, "t_end_s": float(T), "n_elements": n_elements,
        "n_dofs": hist.n_dofs, "n_steps": len(hist.t) - 1, "courant": courant, "seconds": hist.seconds,
        "max_rel_error": float(err_w.max() / np.abs(w).max()),
        "end_displacement_error_over_elastic_amplitude": float(err_w.max() / amp),
        "end_velocity_rms_rel_error": float(np.sqrt(np.mean((hist.v_end - v) ** 2)) / (sigma0 * rod.c0 / E)),
        "strain_snapshots": snaps,
        "vibrational_energy_J": float(hist.vibrational[-1]),
        "vibrational_energy_series_J": float(vib_exact[-1]),
        "paper_W2_J": float(W2[-1]),
        "max_vibrational_energy_J": float(hist.vibrational.max()),
        "max_vibrational_energy_exact_J": float(vmax),
        "vibrational_energy_max_abs_error_over_max": float(np.abs(hist.vibrational - vib_exact).max() / vmax),
        "energy_balance_max_abs_J": float(np.abs(hist.energy - hist.work).max()),
        "momentum_max_rel_error": float(np.abs(np.sqrt(2 * rod.mass * hist.rigid_kinetic) - sigma0 * rod.area * hist.t).max()
                                        / (sigma0 * rod.area * T)),
        "_history": hist, "_w": w, "_v": v, "_vib_exact": vib_exact, "_W2": W2,
    }


def driven_study(case, rod: Rod, n_elements: int = 400, courant: float = 2**-0.5) -> dict:
    """The rod driven by the braking force N(t) of the Part I dynamics (eq. (11)) of ``case``.

    N(t) = -m du/dt from :func:`semianalytic.penetration.motion.solve_motion` with the case's
    nose (BEM coefficient table when available, else the paper's constant coefficients),
    target density and resistance, at the first striking velocity.  Returns the vibrational
    energy the rod takes up, beside the paper's W2 (eq. (29)) with sigma0 = 4 N / (pi d^2).
    """
    from semianalytic.geometry import projectile_from_section
    from semianalytic.penetration.motion import solve_motion
    from semianalytic.penetration.resistance import resistance_from_case

    proj = projectile_from_section(case.require("projectile"))
    target = case.require("target")
    U0 = float(case.require("impact").striking_velocities[0])
    Rt = resistance_from_case(case).pressure(proj.diameter)
    coeffs, source = _coefficients_for(proj.nose)
    motion = solve_motion(coeffs, proj.mass, target.density, Rt, U0)
    t_m, N_m = motion.t, motion.force
    T = motion.penetration_time
    hist = simulate_rod(rod, lambda t: np.interp(t, t_m, N_m), T, n_elements, courant=courant)

    sigma0 = 4 * hist.force / (math.pi * rod.diameter**2)
    W2 = math.pi * rod.diameter**2 * sigma0**2 * rod.c0 * hist.t / (8 * rod.youngs_modulus)
    return {
        "striking_velocity_m_s": U0, "resistance_Pa": Rt, "coefficients": source, "projectile_mass_kg": proj.mass,
        "penetration_time_s": T, "final_depth_m": motion.final_depth, "N0_N": float(N_m[0]), "N_end_N": float(N_m[-1]),
        "vibrational_energy_J": float(hist.vibrational[-1]), "max_vibrational_energy_J": float(hist.vibrational.max()),
        "mean_vibrational_energy_J": float(np.mean(hist.vibrational)),
        "paper_W2_J": float(W2[-1]), "initial_kinetic_energy_J": 0.5 * proj.mass * U0**2,
        "bound_pi_d2_sigma0max2_L_over_8E_J": float(series.max_vibrational_energy(rod, float(sigma0.max()))),
        "energy_balance_max_abs_J": float(np.abs(hist.energy - hist.work).max()),
        "_history": hist, "_W2": W2,
    }


def _coefficients_for(nose):
    """Drag coefficients for the nose: its BEM coefficient table (body reading, cached per user)."""
    from semianalytic.cache import cached_coefficient_table

    return cached_coefficient_table(nose), "BEM table (body reading)"


def rod_from_case(case) -> tuple[Rod, float | None]:
    """The cylinder of Part I, section 2 for a case's projectile (length L, diameter d, E_p, rho_p)
    and its yield stress (or None)."""
    from semianalytic.geometry import projectile_from_section

    sec = case.require("projectile")
    proj = projectile_from_section(sec)
    if sec.youngs_modulus is None:
        raise InputError("projectile.youngs_modulus", "the rod problem needs E_p (e.g. '210 GPa')")
    if sec.density is None:
        raise InputError("projectile.density", "the rod problem needs rho_p (e.g. '7830 kg/m^3')")
    return Rod(proj.length, proj.diameter, sec.youngs_modulus, sec.density), sec.yield_stress


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from fem_check.report import add_output_arguments

    parser.add_argument("case", nargs="?", help="case TOML with a [projectile] (default: the Fig. 5 ogival rod, 71.1 mm)")
    from semianalytic.cli_types import checked, integer, number, quantity

    parser.add_argument("--sigma0", default=None, type=checked(quantity("pressure")), help="end stress of the step load, e.g. '1 GPa' (default 1 GPa)")  # noqa: E501
    parser.add_argument("--round-trips", type=number(10.0, 1000.0), default=10.5, help="duration in round trips 2L/c0 (>= 10; default 10.5)")  # noqa: E501
    parser.add_argument("--elements", type=integer(10, 20000), default=400, help="number of P1 elements (default 400)")
    add_output_arguments(parser, "fem_rod")


def run(args) -> int:
    from fem_check.report import Report, emit_json
    from semianalytic.case import load_case
    from semianalytic.units import parse_quantity

    if not args.round_trips >= 10:
        raise InputError("--round-trips", f"must be at least 10 round trips 2L/c0; got {args.round_trips!r}")
    if not 10 <= args.elements <= 20000:
        raise InputError("--elements", f"must lie in [10, 20000]; got {args.elements!r}")
    sigma0 = parse_quantity(args.sigma0, "pressure", "--sigma0") if args.sigma0 else DEFAULT_SIGMA0
    if not sigma0 > 0:
        raise InputError("--sigma0", "must be positive (a compressive end stress, e.g. '1 GPa')")
    case = load_case(args.case) if args.case else None
    if case is not None and case.projectile is not None:  # the driven study builds the nose's BEM table
        from semianalytic.guards import check_case

        check_case(case)
    rod = rod_from_case(case)[0] if case else DEFAULT_ROD
    report = None if args.no_report else Report(Path(args.out), args.name, args.force)
    if report:
        report.check()
    step = step_load_study(rod, sigma0, args.round_trips, args.elements)
    driven = None
    if case is not None and case.section("impact") is not None and case.require("target").resistance is not None:
        driven = driven_study(case, rod, args.elements)
    payload = {k: v for k, v in step.items() if not k.startswith("_")}
    if driven is not None:
        payload["driven"] = {k: v for k, v in driven.items() if not k.startswith("_")}
    if report:
        _write_report(report, case, step, driven)
        payload["report"] = str(report.path)
    if args.json:
        emit_json(payload)
    else:
        print(f"rod: max relative error of w(L, t) {payload['max_rel_error']:.2e} "
              f"({payload['end_displacement_error_over_elastic_amplitude']:.2e} of the elastic amplitude); "
              f"vibrational energy at t_end {payload['vibrational_energy_J']:.4g} J, paper W2 {payload['paper_W2_J']:.4g} J")
        if report:
            print(f"report: {report.path}")
    return 0


def _write_report(report, case, step: dict, driven: dict | None) -> None:
    from fem_check.report import fmt, md_table, new_figure

    hist = step["_history"]
    rod = step["rod"]
    r = report
    L, c0, E = rod["length_m"], rod["c0_m_s"], rod["youngs_modulus_Pa"]
    s0 = step["sigma0_Pa"]
    r.add("# FEM check of the suddenly loaded free-free rod (Part I, section 2, eqs. (24)-(29))", "",
          "Generated by `python -m fem_check rod" + (f" {case.path}" if case and case.path else "") + " --out reports --force`.", "",
          f"Rod: L = {fmt(L * 1e3)} mm, d = {fmt(rod['diameter_m'] * 1e3)} mm, E_p = {fmt(E / 1e9)} GPa, "
          f"rho_p = {fmt(rod['density_kg_m3'])} kg/m^3, c_0 = {fmt(c0)} m/s, round trip 2L/c_0 = {fmt(rod['round_trip_s'] * 1e6)} us. "
          f"Step load sigma_0 = {fmt(s0 / 1e9)} GPa at x = L from t = 0, {fmt(step['round_trips'])} round trips.", "",
          "Method: P1 elements (consistent mass, scikit-fem), trapezoidal rule (Newmark average acceleration, "
          "energy-conserving: the discrete energy equals the discrete work of the load to round-off, "
          f"max abs(E - W) = {fmt(step['energy_balance_max_abs_J'])} J). Courant number c_0 dt/h = 1/sqrt(2): the "
          "spatial (consistent-mass) and temporal (trapezoidal) phase errors then cancel to second order. "
          f"{step['n_elements']} elements, {step['n_steps']} steps, {fmt(step['seconds'])} s.", "",
          "## Errors against the series solution (24)-(27)", "",
          md_table(["quantity", "FEM error", "measure"], [
              ["w(L, t), eq. (24)", step["max_rel_error"], "max over t of abs(error) / max abs(w(L, t)) (rigid motion included)"],
              ["w(L, t), eq. (24)", step["end_displacement_error_over_elastic_amplitude"], "max abs(error) / (sigma_0 L / 2E_p), the elastic amplitude"],  # noqa: E501
              ["dw/dt (L, t), eq. (25)", step["end_velocity_rms_rel_error"], "RMS over t / (sigma_0 c_0 / E_p) (Gibbs at the jumps)"],
              ["dw/dx at t = L/c_0 (2i-1), eq. (27)", max(s["rms_rel"] for s in step["strain_snapshots"]), "max over i of RMS over x / (sigma_0/E_p)"],  # noqa: E501
              ["vibrational energy", step["vibrational_energy_max_abs_error_over_max"], "max over t of abs(error) / (pi d^2 sigma_0^2 L / 8E_p)"],  # noqa: E501
              ["momentum", step["momentum_max_rel_error"], "abs(p - N t) / (N t_end)"],
          ]), "",
          "The loaded end moves like the series says: -sigma_0 c_0 t / E_p holds only during the first round trip "
          "(eq. (25)); afterwards the elastic part of w(L, t) is periodic (errata item 5).", "")
    t_us = hist.t * 1e6
    rigid = s0 * hist.t**2 / (2 * rod["density_kg_m3"] * L)
    fig = new_figure(8.0, 3.6)
    ax = fig.add_subplot(121)
    ax.plot(t_us, -(hist.u_end + rigid) * 1e6, label="FEM")
    ax.plot(t_us, -(step["_w"] + rigid) * 1e6, "--", label="series (24)")
    ax.set_xlabel("t [us]")
    ax.set_title("elastic part: abs(w(L,t)) - sigma_0 t^2/(2 rho_p L) [um]", fontsize=8)
    ax.legend(fontsize=8)
    ax = fig.add_subplot(122)
    first = t_us <= 3 * 2 * L / c0 * 1e6
    ax.plot(t_us[first], -hist.u_end[first] * 1e6, label="FEM abs(w(L,t))")
    ax.plot(t_us[first], -step["_w"][first] * 1e6, "--", label="series (24)")
    ax.plot(t_us[first], s0 * c0 * hist.t[first] / E * 1e6, ":", label="eq. (25): sigma_0 c_0 t / E_p")
    ax.axvline(2 * L / c0 * 1e6, color="k", lw=0.5)
    ax.set_xlabel("t [us]")
    ax.set_title("loaded-end displacement, first 3 round trips [um]", fontsize=8)
    ax.legend(fontsize=8)
    r.figure("end_displacement", fig, "loaded-end displacement: FEM, series (24) and eq. (25)")
    r.add("## Energy: which one does the FEM support?", "",
          md_table(["t_end [us]", "FEM vibrational energy [J]", "series (exact rod) [J]", "paper W2, eq. (29) [J]",
                    "max FEM vibrational energy [J]", "pi d^2 sigma_0^2 L / 8E_p [J]"],
                   [[step["t_end_s"] * 1e6, step["vibrational_energy_J"], step["vibrational_energy_series_J"], step["paper_W2_J"],
                     step["max_vibrational_energy_J"], step["max_vibrational_energy_exact_J"]]]), "",
          "The rod's vibrational energy (total mechanical energy minus the rigid-body kinetic energy p^2/2m, both "
          "computed from the FEM fields) stays bounded and periodic, between 0 and pi d^2 sigma_0^2 L / (8 E_p); it "
          "does not grow like the paper's W2 = pi d^2 sigma_0^2 c_0 t / (8 E_p) of eq. (29). **The FEM supports the "
          "bounded energy of the exact rod solution (errata item 5), not eq. (29)**: at t_end W2 overstates the "
          f"vibrational energy by a factor {fmt(step['paper_W2_J'] / max(step['vibrational_energy_J'], 1e-300))}, "
          "about c_0 t / L.", "")
    fig = new_figure()
    ax = fig.add_subplot(111)
    ax.plot(t_us, hist.vibrational, label="FEM vibrational energy")
    ax.plot(t_us, step["_vib_exact"], "--", label="exact rod solution")
    ax.plot(t_us, step["_W2"], ":", label="paper W2, eq. (29)")
    ax.set_xlabel("t [us]")
    ax.set_ylabel("energy [J]")
    ax.legend(fontsize=8)
    r.figure("energy", fig, "vibrational energy of the rod: FEM, exact solution, paper's W2")
    if driven is not None:
        r.add("## Rod driven by the braking force N(t) of the Part I dynamics", "")
        if "skipped" in driven:
            r.add(f"Skipped: {driven['skipped']}.", "")
        else:
            dh = driven["_history"]
            r.add(md_table(["quantity", "value"], [
                ["striking velocity [m/s]", driven["striking_velocity_m_s"]],
                ["coefficients", driven["coefficients"]],
                ["R_t [MPa]", driven["resistance_Pa"] / 1e6],
                ["N(0), N(t_stop) [kN]", f"{fmt(driven['N0_N'] / 1e3)}, {fmt(driven['N_end_N'] / 1e3)}"],
                ["penetration time [us]", driven["penetration_time_s"] * 1e6],
                ["final depth [mm]", driven["final_depth_m"] * 1e3],
                ["initial kinetic energy [J]", driven["initial_kinetic_energy_J"]],
                ["FEM vibrational energy at the stop [J]", driven["vibrational_energy_J"]],
                ["FEM vibrational energy, max / time mean [J]", f"{fmt(driven['max_vibrational_energy_J'])} / {fmt(driven['mean_vibrational_energy_J'])}"],  # noqa: E501
                ["paper W2 at the stop, sigma_0 = 4N/(pi d^2) [J]", driven["paper_W2_J"]],
                ["bound pi d^2 sigma_0,max^2 L / 8E_p [J]", driven["bound_pi_d2_sigma0max2_L_over_8E_J"]],
            ]), "",
                "Driven by the slowly varying N(t), the rod absorbs at most about the step-load bound; eq. (29) would "
                "take a much larger share of the kinetic energy.", "")
            fig = new_figure()
            ax = fig.add_subplot(111)
            ax.plot(dh.t * 1e6, dh.vibrational, label="FEM vibrational energy")
            ax.plot(dh.t * 1e6, driven["_W2"], ":", label="paper W2 with sigma_0 = 4N(t)/(pi d^2)")
            ax.set_xlabel("t [us]")
            ax.set_ylabel("energy [J]")
            ax.legend(fontsize=8)
            r.figure("driven_energy", fig, "energy absorbed by the rod under the braking force of the dynamics")
    r.write()
