"""Verification studies of Part IV behind ``reports/part4_ballistic_limit.md`` (numbers only; the
report module formats them): the closed forms of eqs. (2)-(4) against eq. (1) integrated
numerically, and the Young's moduli Table 1's printed delta_H would need."""

from __future__ import annotations

import numpy as np

from semianalytic.ballistic_limit.indentation import plasticity_from_vickers
from semianalytic.ballistic_limit.tables import load_table1
from semianalytic.ballistic_limit.theory import depth_at_time, eq1_deceleration, stop_time, velocity_at_time

__all__ = ["closed_forms_against_ode", "implied_moduli"]

GPa = 1e9


def closed_forms_against_ode(rho_t: float = 7800.0, rho_p: float = 7800.0, L: float = 0.0516,
                             R: float = 2.388 * GPa, us: float = 900.0) -> tuple[float, float]:
    """Largest relative error of u(t) (eq. (2), errata 22) and P(t) (errata 24) against eq. (1)
    integrated with DOP853 (rtol = atol = 1e-12) over 200 times to the stop, for a Steel-40-like shot."""
    from scipy.integrate import solve_ivp

    t_end = stop_time(us, R, rho_t, rho_p, L)
    t = np.linspace(0, t_end, 200)
    sol = solve_ivp(lambda _, y: [-eq1_deceleration(y[0], R, rho_t, rho_p, L), y[0]], (0, t_end), [us, 0.0],
                    t_eval=t, rtol=1e-12, atol=1e-12, method="DOP853")
    if not sol.success:
        raise RuntimeError(f"eq. (1) integration failed: {sol.message}")
    eu = np.max(np.abs(velocity_at_time(t, us, R, rho_t, rho_p, L) - sol.y[0])) / us
    eP = np.max(np.abs(depth_at_time(t, us, R, rho_t, rho_p, L) - sol.y[1])) / sol.y[1][-1]
    return float(eu), float(eP)


def implied_moduli(markings: tuple[str, ...] = ("Steel 600", "Ti-alloy", "SiC")) -> dict[str, float]:
    """The Young's modulus [GPa] at which eqs. (10)-(14) give Table 1's printed delta_H (the row's
    assumed nu), by brentq on [150, 5000] GPa, where delta_H rises with E."""
    from scipy.optimize import brentq

    need = {}
    for r in load_table1():
        if r.marking in markings:
            def gap(E, r=r):
                return float(plasticity_from_vickers(r.hardness, E, r.nu_assumed)) - r.delta_H

            need[r.marking] = brentq(gap, 150 * GPa, 5000 * GPa) / GPa
    return need
