"""Error estimates of the predicted depths: the coefficients' error estimates carried through
Part I, eq. (11) and the models built on it, plus the integrator's error, without solving the
whole curve again per coefficient.

- Coefficients: each of A, B, C off by its estimated error (interpolation plus BEM,
  :meth:`semianalytic.coefficients.table.CoefficientTable.error`; the deep limit by its
  extrapolation error), one at a time; the estimate is the sum of the three changes (first
  order in the errors, no assumption on their signs).  The changes of F and G of the profile
  are carried by the same panels and quadrature as F and G (complex-step rows,
  :meth:`~semianalytic.penetration.motion.DepthProfile.sensitivities`), so for the rigid and
  quasi-rigid depths dP_f = (2 U_0 dU_0 - dG(P_f)) / G'(P_f) at every velocity (dU_0: the start
  velocity of eq. (26) with the shifted deep limit).  The elastic depths are solved again on
  the perturbed profiles (no coefficient evaluation, no integration) at up to ``N_SUBSET``
  velocities.
- Integrator: for the rigid and quasi-rigid depths the embedded spectral tails of the panels
  up to the stop (:meth:`~semianalytic.penetration.motion.DepthProfile.integration_error`),
  plus the root's tolerance; for the elastic depths (time grid and quadrature of eq. (30)) the
  change from the grid of 512 to 1024 cells with panels halved, extrapolated with the observed
  order of convergence (from 256, 512, 1024 cells; between 1 and 4), and at least the change
  from 256 to 512 cells (this project's own rule: the W2 kinks make the order erratic), at the
  same velocities.
- Velocities beyond the ``N_SUBSET`` solved again (this project's own rule): each gets twice
  the larger relative estimate of its two neighbours among them, times its own depth.

The paper's quoted constants (``--coefficients paper``) carry no numerical error of their
own (they are inputs); only the integrator's part remains.  With ``contact = "separated"`` (no
profile in P to perturb) every model is solved again on the subset with shifted coefficients.
"""

from __future__ import annotations

import dataclasses

import numpy as np

__all__ = ["MODEL_KEYS", "N_SUBSET", "ShiftedCoefficients", "coefficient_shift", "depth_error_estimate"]

MODEL_KEYS = {
    "rigid": "depth_rigid_m",
    "quasi_rigid": "depth_quasi_rigid_m",
    "elastic": "depth_elastic_m",
    "elastic_exact_rod": "depth_elastic_exact_rod_m",
}
ELASTIC = ("elastic", "elastic_exact_rod")
N_SUBSET = 32  # velocities at which the elastic depths are solved again
INTERPOLATED_FACTOR = 2.0  # safety factor of the estimates carried to the other velocities (this project's own)


class ShiftedCoefficients:
    """A coefficient table with one coefficient (``A``, ``B`` or ``C``) shifted by its
    estimated error; everything else passes through."""

    def __init__(self, table, which: str):
        self._table, self._which = table, which

    def __getattr__(self, name):
        return getattr(self._table, name)

    def _shift(self, name: str, P, value):
        return value + (self._table.error(name, P) if name[0] == self._which else 0.0)

    def A(self, P):
        return self._shift("A", P, self._table.A(P))

    def B(self, P, reading: str | None = None):
        reading = reading or self._table.reading
        return self._shift(f"B_{reading}", P, self._table.B(P, reading))

    def C(self, P):
        return self._shift("C", P, self._table.C(P))

    def deep_limit(self, reading: str | None = None):
        t = self._table
        reading = reading or t.reading
        A, B, C = t.deep_limit(reading)
        names = ("A", f"B_{reading}", "C")
        shifted = [v + ((t.limit_errors.get(n, 0.0) + t.bem_errors.get(n, 0.0)) if n[0] == self._which else 0.0)
                   for v, n in zip((A, B, C), names)]
        return tuple(shifted)


def coefficient_shift(table):
    """P -> (dA, dB, dC): the table's estimated errors of A, B (its reading) and C at P."""
    reading = table.reading

    def shift(P):
        return (np.asarray(table.error("A", P), float), np.asarray(table.error(f"B_{reading}", P), float),
                np.asarray(table.error("C", P), float))

    return shift


def _subset(U: np.ndarray) -> np.ndarray:
    """Indices of up to N_SUBSET velocities spread over the sorted set (its ends included)."""
    order = np.argsort(U, kind="stable")
    if U.size <= N_SUBSET:
        return order
    return np.unique(order[np.round(np.linspace(0, U.size - 1, N_SUBSET)).astype(int)])


def _spread(U, depth, U_sub, est_sub, depth_sub, exact: np.ndarray):
    """Carry estimates from the subset velocities to all (module docstring); ``exact``: where
    a velocity is itself in the subset (its own estimate is kept)."""
    order = np.argsort(U_sub)
    Us, es, ds = U_sub[order], est_sub[order], np.abs(depth_sub[order])
    rel = np.where(ds > 0, es / np.where(ds > 0, ds, 1.0), 0.0)
    flat = np.where(ds > 0, 0.0, es)  # zero depths (no penetration): absolute
    k = np.clip(np.searchsorted(Us, U), 1, max(Us.size - 1, 1))
    lo, hi = np.clip(k - 1, 0, Us.size - 1), np.clip(k, 0, Us.size - 1)
    out = INTERPOLATED_FACTOR * (np.maximum(rel[lo], rel[hi]) * np.abs(depth) + np.maximum(flat[lo], flat[hi]))
    return np.where(exact, 0.0, np.nan_to_num(out))


def _observed(U_sub, curve, setup, w1, base, profile) -> dict:
    """Integrator part of the elastic depths at the subset: Richardson on 256/512/1024 cells."""
    from semianalytic.penetration.curve import penetration_curve

    coarse = penetration_curve(setup, U_sub, w1=w1, n_grid=256, profile=profile)
    fine = curve(setup, U_sub, w1=w1, n_grid=1024, panel_scale=0.5)
    out = {}
    for k in ELASTIC:
        key = MODEL_KEYS[k]
        d1 = np.abs(np.asarray(base[key]) - np.asarray(fine[key]))
        d0 = np.abs(np.asarray(coarse[key]) - np.asarray(base[key]))
        with np.errstate(divide="ignore", invalid="ignore"):
            p = np.clip(np.nan_to_num(np.log2(d0 / d1), nan=1.0, posinf=4.0, neginf=1.0), 1.0, 4.0)
        out[k] = np.maximum(d1 * 2.0**p / (2.0**p - 1.0), d0)  # the coarser change bounds it for any order >= 1
    return out


def depth_error_estimate(setup, velocities, nominal: dict, *, w1: str = "neglect", curve=None, profile=None) -> dict:
    """{"rigid": [...], "quasi_rigid": [...], "elastic": [...], "elastic_exact_rod": [...]}:
    the estimated numerical error [m] of each depth of ``nominal`` (the output of
    :func:`semianalytic.penetration.curve.penetration_curve` for ``setup``), per striking velocity.
    ``profile``: the curve's profile, if at hand (else integrated again, as the curve does)."""
    from semianalytic.penetration.curve import curve_profile, penetration_curve
    from semianalytic.penetration.elastic import quasi_rigid_start, start_force_coefficients

    curve = curve or penetration_curve
    U = np.atleast_1d(np.asarray(velocities, float))
    total = {k: np.zeros(U.shape) for k in MODEL_KEYS}
    depth = {k: np.asarray(nominal[key], float) for k, key in MODEL_KEYS.items()}
    coef = setup.coefficients
    has_error = callable(getattr(coef, "error", None))
    sub = _subset(U)
    U_sub = U[sub]
    in_sub = np.isin(np.arange(U.size), sub)
    if setup.contact == "separated":  # no profile in P to perturb: solve the subset again
        base = curve(setup, U_sub, w1=w1)
        est = {k: np.zeros(U_sub.shape) for k in MODEL_KEYS}
        runs = [curve(dataclasses.replace(setup, coefficients=ShiftedCoefficients(coef, X)), U_sub, w1=w1)
                for X in "ABC" if has_error]
        runs.append(curve(setup, U_sub, w1=w1, n_grid=1024, panel_scale=0.5))
        for res in runs:
            for k, key in MODEL_KEYS.items():
                est[k] += np.abs(np.asarray(res[key], float) - np.asarray(base[key], float))
        for k, key in MODEL_KEYS.items():
            total[k][sub] = est[k]
            total[k] += _spread(U, depth[k], U_sub, est[k], np.asarray(base[key], float), in_sub)
        return {k: [float(x) for x in v] for k, v in total.items()}

    prof = profile if profile is not None else curve_profile(setup, float(U.max()))
    # rigid and quasi-rigid: embedded integration error and first-order sensitivities at the stops
    stops = {"rigid": (depth["rigid"], U, None)}
    qr_ok = np.isfinite(depth["quasi_rigid"])
    if qr_ok.any() and setup.rod is not None:
        stops["quasi_rigid"] = (depth["quasi_rigid"], np.asarray(nominal["start_velocity_m_s"], float), qr_ok)
    sens = prof.sensitivities(coefficient_shift(coef)) if has_error else None
    for k, (P, U0, ok) in stops.items():
        sel = np.isfinite(P) if ok is None else ok
        Pk = P[sel]
        dG = prof._eval(Pk, (prof._dG,))[0]
        eF, eG = prof.integration_error(Pk)
        with np.errstate(divide="ignore", invalid="ignore"):
            est = np.where(Pk > 0, eG / dG + 1e-13 * Pk, 0.0)
            if sens is not None:
                for i, X in enumerate("ABC"):
                    dGX = prof._eval(Pk, (sens[1][i],))[0]
                    if k == "quasi_rigid":
                        shifted = ShiftedCoefficients(coef, X)
                        alpha, beta = start_force_coefficients(shifted, setup.mass, setup.target_density, setup.resistance_pa)
                        U0s = np.atleast_1d(quasi_rigid_start(U[sel], setup.rod.c0, setup.rod.youngs_modulus, alpha, beta)[0])
                        dGX = dGX - 2.0 * U0[sel] * (U0s - U0[sel])
                    est = est + np.where(Pk > 0, np.abs(dGX / dG), 0.0)
        total[k][sel] = np.nan_to_num(est)
    # elastic: solved again at the subset, on the perturbed profiles and on finer grids
    if setup.rod is not None and np.isfinite(depth["elastic"]).any():
        base = curve(setup, U_sub, w1=w1, profile=prof)
        est = _observed(U_sub, curve, setup, w1, base, prof)
        if sens is not None:
            for i, X in enumerate("ABC"):
                pX = prof.shifted(sens[0][i], sens[1][i], sens[2][i], sens[3][i])
                res = curve(dataclasses.replace(setup, coefficients=ShiftedCoefficients(coef, X)), U_sub, w1=w1,
                            profile=pX)
                for k in ELASTIC:
                    est[k] = est[k] + np.abs(np.asarray(res[MODEL_KEYS[k]]) - np.asarray(base[MODEL_KEYS[k]]))
        for k in ELASTIC:
            total[k][sub] = est[k]
            total[k] += _spread(U, depth[k], U_sub, est[k], np.asarray(base[MODEL_KEYS[k]], float), in_sub)
    return {k: [float(x) for x in v] for k, v in total.items()}
