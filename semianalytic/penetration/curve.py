"""All projectile models of Part I for many striking velocities at once.

For each striking velocity U_s: the rigid projectile (eq. (11), u(0) = U_s), the quasi-rigid
one (eq. (11) from eq. (26)), the elastic projectile with the paper's W2 (eqs. (29), (30'))
and with the exact-rod vibration energy (errata item 5), and the critical impact velocity
U_sC (eqs. (33)/(36)) with the flag U_s >= U_sC (the projectile yields: outside the model).

Everything follows from ONE integration of eq. (11) with the depth P as the independent
variable (:func:`~semianalytic.penetration.motion.depth_profile`): u^2(P) for any start
velocity, the final depth G(P_f) = U_0^2, and the time t(P) = int dP/u, computed on the
mapped grid P = P_f s (2 - s), s in [0, 1], on which dt/ds = 2 P_f (1 - s)/u stays finite at
the stop (u ~ sqrt(P_f - P)).  The elastic stop s* (m ubar^2 = 2W) is found by bisection and
P = int_0^s* u dP/ds ds by Gauss quadrature on s = s* (1 - (1 - tau)^2) (u ~ sqrt(s* - s)).
:func:`semianalytic.penetration.elastic.solve_elastic` (time domain) is the independent check.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from semianalytic.errors import InputError
from semianalytic.penetration import critical as crit
from semianalytic.penetration.elastic import (
    W1_MODELS,
    lateral_energy,
    oscillation_energy,
    quasi_rigid_start,
    start_force_coefficients,
)
from semianalytic.penetration.motion import DepthProfile, deep_coefficients, depth_profile
from semianalytic.penetration.rod import Rod

__all__ = ["PenetrationSetup", "penetration_curve", "curve_profile", "sweep_support", "paper_coefficients"]


# The deep-penetration coefficients the paper quotes (section 2 and Appendix; errata item 2):
# (Abar [m], Bbar, Cbar).  Used only as the explicitly named option "paper".
PAPER_COEFFICIENTS = {
    "sphere": (1.5e-3, 0.58, 1.00),
    ("ogive", 3.0): (1.0e-3, 0.11, 1.00),
}


def paper_coefficients(projectile_section):
    """ConstantCoefficients from the paper's quoted Abar, Bbar, Cbar (sphere; ogive psi = 3)."""
    from semianalytic.coefficients import ConstantCoefficients

    p = projectile_section
    key = "sphere" if p.nose == "sphere" or (p.nose == "ogive" and p.crh == 0.5) else (p.nose, p.crh)
    if key not in PAPER_COEFFICIENTS:
        raise InputError(
            "projectile.nose",
            "the paper quotes coefficients only for the spherical nose and the psi = 3 ogive; use the BEM table",
        )
    return ConstantCoefficients.from_normalised(*PAPER_COEFFICIENTS[key], p.diameter)


@dataclass(frozen=True)
class PenetrationSetup:
    """Inputs of the Part I projectile models (SI).

    coefficients  DragCoefficients (BEM table or constants); mass m [kg];
    target_density rho [kg/m^3]; resistance_pa R_t [Pa];
    rod           the projectile as the cylinder of eq. (24) (L, d, E_p, rho_p), or None;
    poisson_ratio nu_p (for W1); yield_stress Y_p [Pa] (dynamic) or None; phi buckling factor.
    """

    coefficients: object
    mass: float
    target_density: float
    resistance_pa: float
    rod: Rod | None = None
    poisson_ratio: float | None = None
    yield_stress: float | None = None
    phi: float = 1.0
    contact: str = "full"  # "separated": eq. (11) over the wetted part of eq. (15) (BEM tables only)

    @classmethod
    def from_case(cls, case, coefficients, *, mass: float | None = None, require_material: bool = True):
        """From a case's [projectile] and [target] (+ [target.resistance]); ``mass`` overrides."""
        from semianalytic.geometry import projectile_from_section
        from semianalytic.penetration.resistance import resistance_from_case

        psec = case.require("projectile")
        tsec = case.require("target")
        projectile = projectile_from_section(psec)
        m = float(mass if mass is not None else projectile.mass)
        R = float(resistance_from_case(case).pressure(psec.diameter))
        if not R > 0:
            raise InputError("target.resistance", f"the resistance R_t must be positive; got {R:g} Pa")
        missing = [k for k in ("youngs_modulus", "yield_stress") if getattr(psec, k) is None]
        if missing and require_material:
            raise InputError(
                f"projectile.{missing[0]}",
                "missing: the elastic projectile and the critical velocity need youngs_modulus and yield_stress "
                "(e.g. '210 GPa', '1.5 GPa')",
            )
        rod = None
        phi = 1.0
        if psec.youngs_modulus is not None:
            rho_p = psec.density if psec.density is not None else m / projectile.volume()
            rod = Rod(projectile.length, psec.diameter, psec.youngs_modulus, rho_p)
            if psec.yield_stress is not None:
                lam = crit.slenderness(projectile.length, psec.diameter)
                phi = crit.buckling_factor(psec.buckling, lam, psec.youngs_modulus, psec.yield_stress, psec.buckling_table)
        return cls(coefficients, m, float(tsec.density), R, rod, psec.poisson_ratio, psec.yield_stress, float(phi),
                   contact=case.coefficients.contact)

    def critical_inputs(self) -> crit.CriticalInputs:
        A, B, C = deep_coefficients(self.coefficients)
        r = self.rod
        return crit.CriticalInputs(r.youngs_modulus, r.density, self.mass, r.diameter, A, B, C, self.target_density, self.resistance_pa)

    def critical_velocity(self) -> float:
        """U_sC of eqs. (33)/(36) with the deep-limit coefficients (NaN without Y_p or E_p)."""
        if self.rod is None or self.yield_stress is None:
            return math.nan
        return crit.critical_velocity(self.yield_stress, self.critical_inputs(), self.phi)


# --------------------------------------------------------------------------------------


def _rows_hermite(s: np.ndarray, t: np.ndarray, dt: np.ndarray, S: np.ndarray, rows=slice(None)) -> np.ndarray:
    """t at row-wise points S (n, K) by cubic Hermite interpolation of the rows ``rows`` of t
    (., J+1) with slopes dt on the uniform grid s (values and exact slopes: 4th order)."""
    J = s.size - 1
    x = np.clip(S, 0.0, 1.0) * J
    j = np.clip(np.floor(x).astype(np.intp), 0, J - 1)
    u = x - j
    rows = np.arange(t.shape[0])[rows][:, None]
    h = 1.0 / J
    u2 = u * u
    u3 = u2 * u
    h01 = 3.0 * u2 - 2.0 * u3
    return ((1.0 - h01) * t[rows, j] + h01 * t[rows, j + 1]
            + h * ((u3 - 2.0 * u2 + u) * dt[rows, j] + (u3 - u2) * dt[rows, j + 1]))


def _cumulative_simpson(f: np.ndarray, h: float) -> np.ndarray:
    """int_0^{s_j} f ds at every node of a uniform grid (rows): each pair of intervals by the
    quadratic through its three nodes, split at the middle node (Simpson's rule at the even
    nodes; as scipy's cumulative_simpson on a uniform grid); an odd last interval by the
    quadratic through it and its previous neighbour."""
    J = f.shape[1] - 1
    if J < 2:
        return np.concatenate([np.zeros((f.shape[0], 1)), np.cumsum(0.5 * h * (f[:, 1:] + f[:, :-1]), axis=1)], axis=1)
    piece = np.empty((f.shape[0], J))
    e = 2 * (J // 2)
    f0, f1, f2 = f[:, 0:e:2], f[:, 1:e:2], f[:, 2:e + 1:2]
    piece[:, 0:e:2] = h / 12.0 * (5.0 * f0 + 8.0 * f1 - f2)
    piece[:, 1:e:2] = h / 12.0 * (-f0 + 8.0 * f1 + 5.0 * f2)
    if e < J:
        piece[:, -1] = h / 12.0 * (-f[:, -3] + 8.0 * f[:, -2] + 5.0 * f[:, -1])
    return np.concatenate([np.zeros((f.shape[0], 1)), np.cumsum(piece, axis=1)], axis=1)


_GX, _GW = np.polynomial.legendre.leggauss(16)
_GX, _GW = 0.5 * (_GX + 1.0), 0.5 * _GW  # on [0, 1]
_KX, _KW = np.polynomial.legendre.leggauss(6)
_KX, _KW = 0.5 * (_KX + 1.0), 0.5 * _KW  # on [0, 1]
_KINKS = 3  # kinks of the exact-rod energy split off inside the window (16 cells hold at most 3 on grids >= 128)
_WINDOW = 16  # grid cells before the elastic stop integrated by the mapped Gauss rule (see _elastic)
_BLOCK = 256  # striking velocities per block (bounds the (velocities x grid) arrays)


@dataclass(frozen=True, eq=False)
class _Stops:
    """Per start velocity: final depth, time grid t(s) and its slope on the mapped grid s."""

    U0: np.ndarray
    P_f: np.ndarray
    s: np.ndarray
    t: np.ndarray  # (n, J+1)
    dt: np.ndarray  # (n, J+1) dt/ds
    u2: np.ndarray  # (n, J+1) rigid u^2 on the grid (the elastic models start from it)
    converged: np.ndarray  # the root of G(P_f) = U0^2

    @property
    def stop_time(self) -> np.ndarray:
        return self.t[:, -1]

    def time(self, S: np.ndarray, rows=slice(None)) -> np.ndarray:
        return _rows_hermite(self.s, self.t, self.dt, S, rows)


def _stops(prof: DepthProfile, U0: np.ndarray, n_grid: int) -> _Stops:
    U0 = np.asarray(U0, float)
    root = prof.stop(U0)
    P_f = np.atleast_1d(root.x)
    s = np.linspace(0.0, 1.0, n_grid + 1)
    P = P_f[:, None] * (s * (2.0 - s))[None, :]
    u2 = prof.speed2_to_stop(U0[:, None], P_f[:, None], P)
    u = np.sqrt(np.maximum(u2, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        dt = 2.0 * P_f[:, None] * (1.0 - s)[None, :] / u
        # at s = 1: u = sqrt(-dw/dP P_f) (1 - s)  =>  dt/ds = 2 sqrt(P_f / (-dw/dP))
        dt[:, -1] = 2.0 * np.sqrt(P_f / np.atleast_1d(root.rate))
    dt[P_f == 0] = 0.0
    t = _cumulative_simpson(dt, 1.0 / n_grid)
    return _Stops(U0, P_f, s, t, dt, u2, np.atleast_1d(root.converged))


def _elastic(prof: DepthProfile, st: _Stops, sigma0, setup: PenetrationSetup, w2: str, w1: str):
    """Depth, stop time and convergence flag of the elastic projectile (eq. (30)) for each row of ``st``."""
    m, rod = setup.mass, setup.rod
    nu = setup.poisson_ratio if setup.poisson_ratio is not None else 0.0
    sig = np.asarray(sigma0, float)[:, None]
    Pf = st.P_f[:, None]

    def g(S, T=None, ub2=None, r=slice(None)):  # (ubar^2 - 2W/m, ubar^2) at mapped coordinate S (rows r)
        P = Pf[r] * S * (2.0 - S)
        T = st.time(S, r) if T is None else T
        W = oscillation_energy(w2, rod, sig[r], T) + lateral_energy(
            w1, P, sigma0=sig[r], resistance_pa=setup.resistance_pa, rod=rod, poisson_ratio=nu
        )
        ub2 = prof.speed2(st.U0[r, None], P) if ub2 is None else ub2
        return ub2 - 2.0 * W / m, ub2

    vals, _ = g(np.broadcast_to(st.s, st.t.shape), st.t, st.u2)  # on the time grid: u^2 known already
    vals[:, -1] = np.minimum(vals[:, -1], 0.0)
    n = len(st.U0)
    j = np.argmax(vals[:, 1:] <= 0.0, axis=1) + 1
    # Illinois (modified regula falsi) on the bracketing grid cell, all rows at once
    rows = np.arange(n)
    a, b = st.s[j - 1].copy(), st.s[j].copy()
    fa, fb = vals[rows, j - 1].copy(), vals[rows, j].copy()
    done = fb == 0
    for _ in range(100):
        with np.errstate(invalid="ignore", divide="ignore"):
            x = b - fb * (b - a) / (fb - fa)
        inside = np.isfinite(x) & (x > np.minimum(a, b)) & (x < np.maximum(a, b))
        x = np.where(inside, x, 0.5 * (a + b))
        fx = g(x[:, None])[0][:, 0]
        flip = fx * fb < 0
        upd = ~done
        step = np.abs(x - b)
        a = np.where(upd & flip, b, a)
        fa = np.where(upd, np.where(flip, fb, 0.5 * fa), fa)
        b, fb = np.where(upd, x, b), np.where(upd, fx, fb)
        # converged: the bracket collapsed, an exact zero, or a step below 1e-15 (of s in [0, 1])
        done |= (np.abs(b - a) <= 4e-16) | (fb == 0) | (upd & (step <= 1e-15))
        if np.all(done):
            break
    s_star = b
    # P = int u dt = int_0^s* (u/ubar) dPbar/ds ds: Simpson on the time grid (u/ubar known there)
    # up to _WINDOW cells before the stop, the rest by Gauss on s = s* - (s* - a)(1 - tau)^2
    # (u ~ sqrt(s* - s) at the stop: smooth in tau)
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.where(vals > 0, np.sqrt(np.maximum(vals, 0.0) / st.u2), 0.0) * (2.0 * Pf * (1.0 - st.s)[None, :])
    i0 = np.maximum(j - 1 - _WINDOW, 0)
    i0 -= i0 % 2  # an even node: whole Simpson pairs
    bulk = _cumulative_simpson(f, st.s[1] - st.s[0])[rows, i0]
    if w2 == "exact-rod":  # the energy's kinks (multiples of L/c0, as elastic.solve_elastic's panels)
        bulk = bulk + _kink_correction(st, f, i0, rod.length / rod.c0, g)
    a0 = st.s[i0]
    # the window in tau, split at the kinks of the exact-rod energy inside it (up to _KINKS)
    cuts = np.ones((n, _KINKS))
    if w2 == "exact-rod":
        period = rod.length / rod.c0
        t0, t1 = st.t[rows, i0], st.time(s_star[:, None])[:, 0]
        tk = (np.floor(t0 / period) + 1.0)[:, None] * period + period * np.arange(_KINKS)[None, :]
        inside = (tk < t1[:, None]) & (t1 > t0)[:, None]
        if inside.any():
            x = _invert_time(st, np.where(inside, tk, 0.0))
            with np.errstate(divide="ignore", invalid="ignore"):
                tau = 1.0 - np.sqrt(np.maximum(s_star[:, None] - x, 0.0) / (s_star - a0)[:, None])
            cuts = np.where(inside, np.clip(np.nan_to_num(tau, nan=1.0), 0.0, 1.0), 1.0)
    ends = np.concatenate([np.zeros((n, 1)), np.sort(np.nan_to_num(cuts, nan=1.0), axis=1), np.ones((n, 1))], axis=1)
    width = np.diff(ends, axis=1)  # (n, _KINKS + 1) segments of [0, 1] in tau
    tau = (ends[:, :-1, None] + width[:, :, None] * _GX[None, None, :]).reshape(n, -1)
    wts = (width[:, :, None] * _GW[None, None, :]).reshape(n, -1)
    S = s_star[:, None] - (s_star - a0)[:, None] * (1.0 - tau) ** 2
    dS = 2.0 * (s_star - a0)[:, None] * (1.0 - tau) * wts
    gv, ub2 = g(S)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(gv > 0, np.sqrt(np.maximum(gv, 0.0) / ub2), 0.0)  # u / ubar, eq. (30)
    depth = bulk + np.sum(ratio * (2.0 * Pf * (1.0 - S)) * dS, axis=1)
    t_star = st.time(s_star[:, None])[:, 0]
    zero = st.P_f == 0
    depth[zero], t_star[zero] = 0.0, 0.0
    return depth, t_star, done


def _invert_time(st: _Stops, tk: np.ndarray, rows=slice(None)) -> np.ndarray:
    """s with t(s) = tk (rows x K, tk <= the row's stop time): the bracketing grid cell by one
    search on the row-offset grid, then Newton on the Hermite interpolant of t(s) (the slope
    dt/ds taken linear in the cell)."""
    t = st.t[rows]
    n, J1 = t.shape
    span = float(np.max(t[:, -1])) + 1.0
    offs = span * np.arange(n)[:, None]
    flat = (t + offs).ravel()
    idx = np.searchsorted(flat, (tk + offs).ravel()).reshape(tk.shape) - (J1 * np.arange(n))[:, None]
    idx = np.clip(idx, 1, J1 - 1)
    r = np.arange(n)[:, None]
    h = st.s[1] - st.s[0]
    lo, hi = st.s[idx - 1], st.s[idx]
    t0, t1 = t[r, idx - 1], t[r, idx]
    with np.errstate(divide="ignore", invalid="ignore"):
        x = np.clip(lo + np.nan_to_num((tk - t0) / (t1 - t0)) * h, lo, hi)
    d0, d1 = st.dt[rows][r, idx - 1], st.dt[rows][r, idx]
    for _ in range(5):
        T = _rows_hermite(st.s, t, st.dt[rows], x)
        slope = d0 + (d1 - d0) * (x - lo) / h
        with np.errstate(divide="ignore", invalid="ignore"):
            x = np.clip(np.where(slope > 0, x - (T - tk) / slope, x), lo, hi)
    return x


def _kink_correction(st: _Stops, f: np.ndarray, i0: np.ndarray, period: float, g) -> np.ndarray:
    """Per row: Gauss on the two sides of each kink of the integrand at t = k ``period`` minus the
    Simpson pair that holds it (a kink costs Simpson O(h^2); the split rule is exact to O(h^8) on
    the smooth sides), for the pairs below node ``i0``; ``g(S)`` -> (ubar^2 - 2W/m, ubar^2)."""
    n = st.t.shape[0]
    rows = np.arange(n)
    h = st.s[1] - st.s[0]
    t_end = st.t[rows, i0]
    K = int(np.max(t_end) / period) if np.max(t_end) > 0 else 0
    if K == 0:
        return np.zeros(n)
    tk = period * np.arange(1, K + 1)[None, :] * np.ones((n, 1))
    use = tk < t_end[:, None]
    x = _invert_time(st, np.where(use, tk, 0.0))
    cell = np.clip(np.floor(x / h).astype(np.intp), 0, st.s.size - 2)
    p = cell // 2 * 2  # the pair [s_p, s_p+2] holding the kink
    use &= p + 2 <= i0[:, None]
    p = np.where(use, p, 0)
    x0, x2 = st.s[p], st.s[p + 2]
    x = np.where(use, np.clip(x, x0, x2), x0)
    r = rows[:, None]
    simpson = h / 3.0 * (f[r, p] + 4.0 * f[r, p + 1] + f[r, p + 2])
    left = x0[:, :, None] + (x - x0)[:, :, None] * _KX
    right = x[:, :, None] + (x2 - x)[:, :, None] * _KX
    S = np.concatenate([left, right], axis=2).reshape(n, -1)
    w = np.concatenate([(x - x0)[:, :, None] * _KW, (x2 - x)[:, :, None] * _KW], axis=2).reshape(n, -1)
    gv, ub2 = g(S)
    with np.errstate(divide="ignore", invalid="ignore"):
        val = np.where(gv > 0, np.sqrt(np.maximum(gv, 0.0) / ub2), 0.0) * 2.0 * st.P_f[:, None] * (1.0 - S)
    split = np.sum((w * val).reshape(n, K, -1), axis=2)
    return np.sum(np.where(use, split - simpson, 0.0), axis=1)


def penetration_curve(
    setup: PenetrationSetup,
    striking_velocities,
    *,
    w1: str = "neglect",
    elastic: bool = True,
    n_grid: int = 512,
    rtol: float | None = None,
    panel_scale: float = 1.0,
    profile=None,
) -> dict[str, np.ndarray]:
    """Every Part I projectile model for each striking velocity (arrays, SI; keys carry units).

    Keys: striking_velocity_m_s, depth_rigid_m, time_rigid_s, start_velocity_m_s (eq. (26)),
    axial_stress_Pa (sigma_0), depth_quasi_rigid_m, time_quasi_rigid_s, depth_elastic_m and
    stop_time_elastic_s (paper's W2, eq. (29)), depth_elastic_exact_rod_m and
    stop_time_elastic_exact_rod_s (errata item 5), delta_P_elastic_m and
    delta_P_elastic_exact_rod_m (Delta P = P - Pbar of section 2, against the quasi-rigid
    depth), critical_velocity_m_s (eq. (33)), yields, and ``converged`` (every iterative solve
    of that velocity converged: the roots of the rigid and quasi-rigid stops, the elastic stops).
    Without a projectile material (setup.rod None) or with ``elastic=False`` only the rigid
    keys are filled (the rest NaN).  ``rtol`` is accepted for symmetry with
    :func:`~semianalytic.penetration.motion.solve_motion` and not needed: the integration in P
    is spectral on panels and converges to round-off (see the tests).  ``profile``: a prebuilt
    profile of ``setup`` covering the velocities (the error estimate's perturbed profiles).
    All on arrays, in blocks of velocities (memory bounded whatever their number).
    """
    if w1 not in W1_MODELS:
        raise InputError("w1", f"must be one of {', '.join(W1_MODELS)}; got {w1!r}")
    U = np.atleast_1d(np.asarray(striking_velocities, float))
    if U.size == 0 or np.any(~np.isfinite(U)) or np.any(U <= 0):
        raise InputError("impact.striking_velocities", "must be positive (m/s)")
    prof = profile if profile is not None else curve_profile(setup, float(U.max()), panel_scale=panel_scale)
    nan = np.full(U.shape, np.nan)
    out = {
        "striking_velocity_m_s": U,
        "depth_rigid_m": nan.copy(),
        "time_rigid_s": nan.copy(),
        "start_velocity_m_s": nan.copy(),
        "axial_stress_Pa": nan.copy(),
        "depth_quasi_rigid_m": nan.copy(),
        "time_quasi_rigid_s": nan.copy(),
        "depth_elastic_m": nan.copy(),
        "stop_time_elastic_s": nan.copy(),
        "depth_elastic_exact_rod_m": nan.copy(),
        "stop_time_elastic_exact_rod_s": nan.copy(),
        "delta_P_elastic_m": nan.copy(),
        "delta_P_elastic_exact_rod_m": nan.copy(),
    }
    converged = np.ones(U.shape, bool)
    full = setup.rod is not None and elastic
    if full:
        alpha, beta = start_force_coefficients(setup.coefficients, setup.mass, setup.target_density, setup.resistance_pa)
        U0, sigma0 = quasi_rigid_start(U, setup.rod.c0, setup.rod.youngs_modulus, alpha, beta)
        out.update(start_velocity_m_s=np.atleast_1d(U0).copy(), axial_stress_Pa=np.atleast_1d(sigma0).copy())
    for lo in range(0, U.size, _BLOCK):
        blk = slice(lo, lo + _BLOCK)
        rigid = _stops(prof, U[blk], n_grid)
        out["depth_rigid_m"][blk], out["time_rigid_s"][blk] = rigid.P_f, rigid.stop_time
        converged[blk] &= rigid.converged
        if not full:
            continue
        qr = _stops(prof, out["start_velocity_m_s"][blk], n_grid)
        out["depth_quasi_rigid_m"][blk], out["time_quasi_rigid_s"][blk] = qr.P_f, qr.stop_time
        converged[blk] &= qr.converged
        for w2, key in (("paper", "elastic"), ("exact-rod", "elastic_exact_rod")):
            depth, t_star, ok = _elastic(prof, qr, out["axial_stress_Pa"][blk], setup, w2, w1)
            out[f"depth_{key}_m"][blk] = depth
            out[f"stop_time_{key}_s"][blk] = t_star
            out[f"delta_P_{key}_m"][blk] = depth - qr.P_f  # Delta P = P - Pbar < 0 (section 2)
            converged[blk] &= ok
    U_sC = setup.critical_velocity()
    out["critical_velocity_m_s"] = np.full(U.shape, U_sC)
    out["yields"] = (U >= U_sC) if np.isfinite(U_sC) else np.zeros(U.shape, bool)
    out["converged"] = converged
    return out


def curve_profile(setup: PenetrationSetup, U_max: float, *, panel_scale: float = 1.0):
    """The profile of eq. (11) in P that :func:`penetration_curve` integrates for ``setup``: the
    full-contact :func:`~semianalytic.penetration.motion.depth_profile`, or with
    ``contact = "separated"`` the wetted-part profile (eq. (15))."""
    if setup.contact == "separated":
        from semianalytic.penetration.motion import separated_profile

        if not hasattr(setup.coefficients, "nodes"):
            raise InputError("coefficients.contact", "'separated' needs the BEM table's surface solution (not constant coefficients)")
        return separated_profile(setup.coefficients, setup.mass, setup.target_density, setup.resistance_pa,
                                 rtol=1e-10 * panel_scale)
    return depth_profile(setup.coefficients, setup.mass, setup.target_density, setup.resistance_pa, U_max,
                         panel_scale=panel_scale)


def sweep_support(case, coefficients, striking_velocities, full: bool = False) -> dict[str, np.ndarray]:
    """The sweep kernel's columns (semianalytic.sweep.kernels.PenetrationKernel): depth_rigid_m,
    critical_velocity_m_s, yields, and with ``full`` also depth_quasi_rigid_m, depth_elastic_m,
    depth_elastic_exact_rod_m.  Without projectile material constants: NaN / False."""
    setup = PenetrationSetup.from_case(case, coefficients, require_material=full)
    res = penetration_curve(setup, striking_velocities, elastic=full)
    keys = ["depth_rigid_m", "critical_velocity_m_s", "yields"]
    if full:
        keys += ["depth_quasi_rigid_m", "depth_elastic_m", "depth_elastic_exact_rod_m"]
    return {k: res[k] for k in keys}
