"""The independent check of the Alekseevskii-Tate quadrature (semianalytic/penetration/regime.py, the
one home of the equations): the same rod equations integrated in time with scipy's DOP853
(rho_p L dv/dt = -Y_p, dL/dt = -(v - u), dP/dt = u, the interface balance solved for u here
again, not imported), then the rigid phase of the residual rod (Part IV, eqs. (2)-(3)).  Test code
only: another method, not another home."""

from __future__ import annotations

import math

from semianalytic.penetration.peers import TateResult


def _u(v, rho_p, Y_p, rho_t, R_t):
    if math.isclose(rho_p, rho_t, rel_tol=1e-12):
        u = 0.5 * v + (Y_p - R_t) / (rho_p * v)
    else:
        disc = rho_p * rho_t * v * v + 2.0 * (rho_p - rho_t) * (R_t - Y_p)
        u = (rho_p * v - math.sqrt(max(disc, 0.0))) / (rho_p - rho_t)
    return min(max(u, 0.0), v)


def tate_penetration_ode(length, rod_density, rod_strength, target_density, target_resistance, V, *, rtol=1e-10):
    """Alekseevskii-Tate penetration by time integration (module docstring)."""
    from scipy.integrate import solve_ivp

    rho_p, Y_p, rho_t, R_t = rod_density, rod_strength, target_density, target_resistance
    v_rigid = math.sqrt(2.0 * (Y_p - R_t) / rho_t) if Y_p > R_t else 0.0
    if V <= v_rigid:
        P = rho_p * length / rho_t * math.log1p(rho_t * V**2 / (2.0 * R_t))
        a = math.sqrt(2.0 * R_t / rho_t)
        return TateResult(P, length, 2.0 * rho_p * length / (rho_t * a) * math.atan(V / a), False, math.nan)
    v_stall = math.sqrt(2.0 * (R_t - Y_p) / rho_p) if R_t > Y_p else 0.0
    if V <= v_stall:
        return TateResult(0.0, length * math.exp(-rho_p * V**2 / (2.0 * Y_p)), length * rho_p * V / Y_p, True, 0.0)

    def rhs(t, y):
        v, L, _ = y
        u = _u(v, rho_p, Y_p, rho_t, R_t)
        return (-Y_p / (rho_p * L), -(v - u), u)

    def erosion_ends(t, y):
        return y[0] - max(v_rigid, v_stall) * (1.0 + 1e-12)

    def consumed(t, y):
        return y[1] - 1e-9 * length

    for ev in (erosion_ends, consumed):
        ev.terminal, ev.direction = True, -1
    sol = solve_ivp(rhs, (0.0, 1e4 * length / V), [V, length, 0.0], method="DOP853", rtol=rtol,
                    atol=[rtol * V, rtol * length, rtol * length], events=(erosion_ends, consumed))
    v, L, P = sol.y[:, -1]
    t = sol.t[-1]
    if len(sol.t_events[1]):
        return TateResult(P, 0.0, t, True, 0.0)
    if Y_p > R_t:
        a = math.sqrt(2.0 * R_t / rho_t)
        P += rho_p * L / rho_t * math.log1p(rho_t * v**2 / (2.0 * R_t))
        t += 2.0 * rho_p * L / (rho_t * a) * math.atan(v / a)
        return TateResult(P, L, t, True, v)
    return TateResult(P, L, t, True, 0.0)
