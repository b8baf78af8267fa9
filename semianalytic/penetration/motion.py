"""Equation of motion of a rigid projectile, Part I, eq. (11):

    (m + rho A(P)) du/dt = -B(P) rho u^2 / 2 - C(P) R_t,   dP/dt = u,   P(0) = 0, u(0) = U_0,

with A [m^3], B, C [m^2] from any :class:`~semianalytic.coefficients.DragCoefficients`
(the BEM table of the projectile's nose, or the constant stand-in), m [kg], the target
density rho [kg/m^3] and resistance R_t [Pa].  The braking force is
N = -m du/dt = m (B rho u^2/2 + C R_t) / (m + rho A) (> 0), as after Part I, eq. (31).

Three evaluations, each a check on the others:

* :func:`solve_motion`: time histories with an adaptive Runge-Kutta integrator (DOP853) and
  a terminal event at u = 0 (the paper used Euler's method; section 3).
* :func:`final_depth` / :func:`depth_profile`: P as the independent variable.  With
  w = u^2, eq. (11) is linear, (m + rho A) dw/dP = -(rho B w + 2 C R_t), so
  w(P) = exp(-F(P)) [U_0^2 - G(P)] with F = int rho B/(m + rho A) dP and
  G = int 2 C R_t exp(F)/(m + rho A) dP, both by spectral quadrature on panels aligned with
  the coefficient table's knots.  One integration serves every U_0; the final depth solves
  G(P_f) = U_0^2 (vectorised).
* :class:`ConstantCoefficientSolution`: the closed form for constant A, B, C, Part IV,
  eqs. (2)-(3), with the corrections of errata items 22-24.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from semianalytic.ballistic_limit import theory as rigid
from semianalytic.errors import ConvergenceError, ModelError

__all__ = [
    "eq11_acceleration",
    "RootResult",
    "reduced_profiles",
    "MotionResult",
    "solve_motion",
    "braking_force",
    "DepthProfile",
    "depth_profile",
    "final_depth",
    "ConstantCoefficientSolution",
    "deep_coefficients",
]


def _check_inputs(mass, target_density, resistance_pa):
    for name, value in (("mass", mass), ("target_density", target_density), ("resistance_pa", resistance_pa)):
        if not (np.isfinite(value) and value > 0):
            raise ModelError(f"{name} must be positive and finite; got {value!r}")


def eq11_acceleration(A, B, C, mass, target_density, resistance_pa, u2):
    """du/dt [m/s^2] of Part I, eq. (11): -(B rho u^2/2 + C R_t) / (m + rho A), with u2 = u^2;
    vectorised (complex values pass through: the sensitivities' complex step).

    The one home of eq. (11)'s right-hand side: the time histories, the braking force, the
    w = u^2 form in P (:func:`_w_rates`), the wetted coefficients of eq. (15) and the
    separation check all call it (``tests/test_one_home.py`` greps for copies)."""
    return -(0.5 * target_density * B * u2 + C * resistance_pa) / (mass + target_density * A)


def deep_coefficients(coefficients) -> tuple[float, float, float]:
    """(A, B, C) in the deep-penetration limit: ``coefficients.deep_limit()`` when the object
    has one (the BEM table), else the values at a depth of 10^4 diameters."""
    deep = getattr(coefficients, "deep_limit", None)
    if callable(deep):
        A, B, C = deep()
        return float(A), float(B), float(C)
    P = 1e4 * float(coefficients.diameter)
    return float(coefficients.A(P)), float(coefficients.B(P)), float(coefficients.C(P))


def braking_force(coefficients, mass, target_density, resistance_pa, P, u):
    """N = m (B rho u^2/2 + C R_t) / (m + rho A) [N], the force compressing the projectile
    (Part I, text after eq. (31)); vectorised in P and u."""
    P = np.asarray(P, float)
    u = np.asarray(u, float)
    A, B, C = coefficients.A(P), coefficients.B(P), coefficients.C(P)
    return -mass * eq11_acceleration(A, B, C, mass, target_density, resistance_pa, u * u)


# --------------------------------------------------------------------------------------
# closed form (constant coefficients)


@dataclass(frozen=True)
class ConstantCoefficientSolution:
    """Closed-form solution of Part I, eq. (11) for constant A, B, C (Part IV, eqs. (2)-(3)).

    With M = m + rho A, k = rho B / (2 M) and a^2 = 2 C R_t / (rho B), eq. (11) reads
    du/dt = -k (u^2 + a^2) (Part IV, eq. (1) with rho_p L_p -> M / B, rho_t -> rho), hence
      u(t) = a (U_0 - a tan g) / (a + U_0 tan g),  g = a k t        (IV-(2), errata item 22)
      P(u) = ln((a^2 + U_0^2) / (a^2 + u^2)) / (2k)                 (IV-(3), errata item 23)
      P(t) = ln(cos g + (U_0/a) sin g) / k                          (errata item 24)
      T = arctan(U_0/a) / (a k),  P_f = ln(1 + U_0^2/a^2) / (2k).
    B = 0 is the limit of uniform deceleration C R_t / M.
    """

    A: float
    B: float
    C: float
    mass: float
    target_density: float
    resistance_pa: float
    U0: float

    @property
    def M(self) -> float:
        return self.mass + self.target_density * self.A

    @property
    def k(self) -> float:
        return self.target_density * self.B / (2.0 * self.M)

    @property
    def a(self) -> float:
        return math.sqrt(2.0 * self.C * self.resistance_pa / (self.target_density * self.B)) if self.B > 0 else math.inf

    @property
    def deceleration0(self) -> float:
        return self.C * self.resistance_pa / self.M

    # B > 0: du/dt = -k (u^2 + a^2), the closed forms of Part IV, eqs. (2)-(4) (their one home,
    # semianalytic.ballistic_limit.theory); B = 0: constant deceleration.
    @property
    def penetration_time(self) -> float:
        if self.B == 0:
            return self.U0 / self.deceleration0
        return float(rigid.quadratic_drag_stop_time(self.U0, self.a, self.k))

    @property
    def final_depth(self) -> float:
        if self.B == 0:
            return self.U0**2 / (2.0 * self.deceleration0)
        return float(rigid.quadratic_drag_depth_at_velocity(0.0, self.U0, self.a, self.k))

    def velocity(self, t):
        t = np.minimum(np.asarray(t, float), self.penetration_time)
        if self.B == 0:
            return self.U0 - self.deceleration0 * t
        return rigid.quadratic_drag_velocity(t, self.U0, self.a, self.k)

    def depth(self, t):
        t = np.minimum(np.asarray(t, float), self.penetration_time)
        if self.B == 0:
            return self.U0 * t - 0.5 * self.deceleration0 * t * t
        return rigid.quadratic_drag_depth_at_time(t, self.U0, self.a, self.k)

    def depth_at_velocity(self, u):
        u = np.asarray(u, float)
        if self.B == 0:
            return (self.U0**2 - u * u) / (2.0 * self.deceleration0)
        return rigid.quadratic_drag_depth_at_velocity(u, self.U0, self.a, self.k)


# --------------------------------------------------------------------------------------
# time histories (solve_ivp with an event at u = 0)


@dataclass(frozen=True, eq=False)
class MotionResult:
    """Solution of Part I, eq. (11) in time, at the integrator's steps (SI units).

    t [s], P [m], u [m/s], du_dt [m/s^2] (< 0 while braking), force N = -m du/dt [N]
    (> 0 braking); final_depth [m] and penetration_time [s] at the event u = 0.
    ``at(t)`` evaluates (P, u) anywhere in [0, penetration_time] (dense output).
    """

    t: np.ndarray
    P: np.ndarray
    u: np.ndarray
    du_dt: np.ndarray
    force: np.ndarray
    final_depth: float
    penetration_time: float
    mass: float
    U0: float
    _dense: object = field(default=None, repr=False)

    @property
    def deceleration(self) -> np.ndarray:
        """-du/dt [m/s^2]."""
        return -self.du_dt

    def at(self, t):
        """(P(t), u(t)) from the integrator's dense output; t is clipped to [0, penetration_time]."""
        t = np.clip(np.asarray(t, float), 0.0, self.penetration_time)
        if self._dense is None:  # U0 = 0: nothing moves
            return np.zeros_like(t), np.zeros_like(t)
        y = self._dense(t)
        return y[0], y[1]

    def sample(self, n: int = 200) -> dict[str, np.ndarray]:
        """Uniformly spaced samples t, P, u (n points from 0 to the stop)."""
        t = np.linspace(0.0, self.penetration_time, n)
        P, u = self.at(t)
        return {"t": t, "P": P, "u": u}


def solve_motion(
    coefficients,
    mass: float,
    target_density: float,
    resistance_pa: float,
    U0: float,
    *,
    rtol: float = 1e-10,
    atol=None,
    t_max: float | None = None,
    method: str = "DOP853",
) -> MotionResult:
    """Integrate Part I, eq. (11) from u(0) = U0 until u = 0 (adaptive, event-terminated).

    ``atol`` defaults to ``rtol`` times (diameter, U0) for (P, u).  ``t_max`` defaults to ten
    times the stopping time of the deep-limit closed form plus 100 diameters / U0.
    """
    _check_inputs(mass, target_density, resistance_pa)
    if not (np.isfinite(U0) and U0 >= 0):
        raise ModelError(f"U0 must be finite and non-negative; got {U0!r}")
    rho, R, m = float(target_density), float(resistance_pa), float(mass)
    d = float(coefficients.diameter)
    if U0 == 0:
        z = np.zeros(1)
        dec = -eq11_acceleration(float(coefficients.A(0.0)), 0.0, float(coefficients.C(0.0)), m, rho, R, 0.0)
        return MotionResult(z, z, z, -dec * np.ones(1), m * dec * np.ones(1), 0.0, 0.0, m, 0.0)

    cA, cB, cC = coefficients.A, coefficients.B, coefficients.C

    def rhs(t, y):
        P, u = max(y[0], 0.0), y[1]  # RK stages may step a hair below the surface at t = 0
        return (u, eq11_acceleration(float(cA(P)), float(cB(P)), float(cC(P)), m, rho, R, u * u))

    def stop(t, y):
        return y[1]

    stop.terminal = True
    stop.direction = -1

    if t_max is None:
        A8, B8, C8 = deep_coefficients(coefficients)
        t_max = 10.0 * ConstantCoefficientSolution(A8, B8, C8, m, rho, R, U0).penetration_time + 100.0 * d / U0
    if atol is None:
        atol = rtol * np.array([d, U0])
    from scipy.integrate import solve_ivp  # time histories only (start-up time)

    sol = solve_ivp(rhs, (0.0, t_max), [0.0, U0], method=method, rtol=rtol, atol=atol, events=stop, dense_output=True)
    if sol.status != 1 or not len(sol.t_events[0]):
        raise ConvergenceError(f"eq. (11) did not reach u = 0 before t = {t_max:g} s ({sol.message})")
    t_end = float(sol.t_events[0][0])
    t = sol.t.copy()
    P, u = sol.y[0].copy(), sol.y[1].copy()
    t[-1], P[-1], u[-1] = t_end, float(sol.y_events[0][0][0]), 0.0
    du_dt = eq11_acceleration(cA(P), cB(P), cC(P), m, rho, R, u * u)
    return MotionResult(
        t=t, P=P, u=u, du_dt=du_dt, force=-m * du_dt, final_depth=float(P[-1]), penetration_time=t_end,
        mass=m, U0=float(U0), _dense=sol.sol,
    )


# --------------------------------------------------------------------------------------
# P as the independent variable: all striking velocities at once


def _chebyshev_panel_rule(n: int):
    """Chebyshev-Lobatto nodes x (n, on [-1, 1], ascending), barycentric weights, the
    spectral integration matrix Q with (Q f)_i = int_{-1}^{x_i} p_f (p_f the interpolant of f),
    and the matrix of values -> Chebyshev coefficients."""
    from numpy.polynomial import chebyshev as ch

    x = -np.cos(np.pi * np.arange(n) / (n - 1))
    V = ch.chebvander(x, n - 1)  # V[i, j] = T_j(x_i)
    coef_of_values = np.linalg.inv(V)
    integ = np.column_stack([ch.chebint(np.eye(n)[j]) for j in range(n)])  # (n+1, n) antiderivative coefficients
    W = ch.chebvander(x, n) @ integ - ch.chebvander(np.array([-1.0]), n) @ integ
    bw = (-1.0) ** np.arange(n)
    bw[0] *= 0.5
    bw[-1] *= 0.5
    return x, bw, W @ coef_of_values, coef_of_values


_NODES = 16
_X, _BW, _Q, _COEF = _chebyshev_panel_rule(_NODES)
_CHUNK = 1 << 15  # points per block of an interpolation (bounds the (points x nodes) temporaries)
_STEP = 1e-20  # complex step of the sensitivities (relative to the coefficients' errors)


def _w_rates(A, B, C, r):
    """(F', G_1' e^-F) of the w = u^2 form of Part I, eq. (11) in reduced units (r = m/rho,
    rho = 1, R_t = 1): F' = B/(r + A) and 2 C/(r + A), both from :func:`eq11_acceleration`
    (its velocity term alone at u^2 = 1, its strength term alone at u^2 = 0)."""
    return -2.0 * eq11_acceleration(A, B, 0.0, r, 1.0, 1.0, 1.0), -2.0 * eq11_acceleration(A, 0.0, C, r, 1.0, 1.0, 0.0)


def _integrate_panels(coefficients, a, b, r, F0, G0, shift=None):
    """F, G_1 = int 2 C e^F/(r + A) dP and their derivatives at the Chebyshev nodes of the
    panels [a_k, b_k] (arrays (rows, panels, nodes)), one row per ratio r (rows,), continuing
    from F0, G0 (rows,) at a_0.  With ``shift`` (P -> (dA, dB, dC)), three complex rows: A, B
    and C shifted in turn by i _STEP dX (their imaginary parts / _STEP are the first-order
    changes of F and G_1 when that coefficient is off by dX; complex step, exact to round-off).
    Also the spectral tail of each panel's integrands (the embedded error estimate)."""
    h = 0.5 * (b - a)
    nodes = a[:, None] + h[:, None] * (_X + 1.0)[None, :]  # (panels, nodes)
    A = np.asarray(coefficients.A(nodes), float)
    B = np.asarray(coefficients.B(nodes), float)
    C = np.asarray(coefficients.C(nodes), float)
    if shift is not None:
        dA, dB, dC = (np.broadcast_to(np.asarray(v, float), nodes.shape) for v in shift(nodes))
        z = 1j * _STEP
        A = np.stack([A + z * dA, A + 0j, A + 0j])
        B = np.stack([B + 0j, B + z * dB, B + 0j])
        C = np.stack([C + 0j, C + 0j, C + z * dC])
        r = np.broadcast_to(np.asarray(r, float), (3,))
    r = np.asarray(r)[:, None, None]
    n = r.shape[0]
    dF, g = _w_rates(A, B, C, r)
    dF = np.broadcast_to(dF, (n,) + nodes.shape)
    Floc = h[None, :, None] * (dF @ _Q.T)
    F = F0[:, None, None] + np.concatenate([np.zeros((n, 1)), np.cumsum(Floc[:, :, -1], axis=1)[:, :-1]], axis=1)[:, :, None] + Floc
    dG = g * np.exp(F)
    Gloc = h[None, :, None] * (dG @ _Q.T)
    G = G0[:, None, None] + np.concatenate([np.zeros((n, 1)), np.cumsum(Gloc[:, :, -1], axis=1)[:, :-1]], axis=1)[:, :, None] + Gloc
    # embedded error: the last two Chebyshev coefficients of each integrand, times the panel length
    tail = lambda f: 2.0 * h * np.abs(np.real(f) @ _COEF[-2:].T).sum(axis=-1)  # noqa: E731
    return nodes, F, G, dF, dG, tail(dF), tail(dG)


@dataclass(frozen=True)
class RootResult:
    """Status of an iterative solve (as scipy's ``OptimizeResult``): the solution ``x``, per
    element whether it ``converged``, the ``iterations`` used, and ``rate`` = -dw/dP at the stop
    (w = u^2; for the time at the stop)."""

    x: np.ndarray
    converged: np.ndarray
    iterations: int
    rate: np.ndarray

    @property
    def success(self) -> bool:
        return bool(np.all(self.converged))


@dataclass(frozen=True, eq=False)
class DepthProfile:
    """F(P), G(P) of the linear form of eq. (11) in w = u^2 (see the module docstring) on
    [0, ``P_end``], where G(P_end) > U_max^2.  SI units.

    F and G are computed by spectral (Chebyshev) integration on panels whose ends include
    the breakpoints of piecewise-smooth coefficients (a ``depth`` attribute, as the BEM
    table's interpolation knots), so that every panel sees a smooth integrand; between the
    nodes they are evaluated by barycentric interpolation (``F``, ``G``, the root) or, on
    large arrays (``speed2``), by cubic Hermite interpolation between neighbouring nodes with
    the exact derivatives F', G' there (this project's own; 1e-11 relative, see the tests).

    ``speed2(U0, P)`` = u^2 at depth P for start velocity U0 (broadcasting);
    ``final_depth(U0)`` solves G(P_f) = U0^2 (``stop(U0)``: with its convergence status);
    ``dG(P)`` = G'(P) exactly from the coefficients.
    """

    coefficients: object
    mass: float
    target_density: float
    resistance_pa: float
    U_max: float
    P_end: float
    _edges: np.ndarray = field(repr=False)  # panel ends (n_panels + 1)
    _F: np.ndarray = field(repr=False)  # (n_panels, nodes) values at the Chebyshev nodes
    _G: np.ndarray = field(repr=False)
    _dF: np.ndarray | None = field(default=None, repr=False)  # F', G' at the nodes
    _dG: np.ndarray | None = field(default=None, repr=False)
    _tail: np.ndarray | None = field(default=None, repr=False)  # (2, n_panels + 1): embedded error of F, G at the edges

    def M(self, P):
        return self.mass + self.target_density * np.asarray(self.coefficients.A(P), float)

    def _locate(self, flat):
        e = self._edges
        k = np.clip(np.searchsorted(e, flat, side="right") - 1, 0, len(e) - 2)
        return k, 2.0 * (flat - e[k]) / (e[k + 1] - e[k]) - 1.0

    def _eval(self, P, arrays=None):
        """Barycentric interpolation of the node ``arrays`` (default F, G) at P (any shape)."""
        arrays = (self._F, self._G) if arrays is None else arrays
        P = np.asarray(P, float)
        flat = P.ravel()
        out = [np.empty(flat.shape, np.result_type(a, float)) for a in arrays]
        for lo in range(0, flat.size, _CHUNK):
            k, x = self._locate(flat[lo:lo + _CHUNK])
            d = x[:, None] - _X[None, :]
            d[d == 0.0] = 1e-300  # on a node: its weight dominates (exact to round-off)
            c = _BW[None, :] / d
            c /= c.sum(axis=1, keepdims=True)
            for o, a in zip(out, arrays):
                o[lo:lo + _CHUNK] = np.einsum("ij,ij->i", c, a[k])
        return tuple(o.reshape(P.shape) for o in out)

    def _hermite(self, P):
        """(F, G) at P by cubic Hermite interpolation between the neighbouring Chebyshev nodes
        (values and exact slopes F', G' there); cheap on large arrays."""
        P = np.asarray(P, float)
        flat = P.ravel()
        Fo, Go = np.empty(flat.shape), np.empty(flat.shape)
        n = _NODES
        e = self._edges
        for lo in range(0, flat.size, 1 << 16):
            p = flat[lo:lo + (1 << 16)]
            k, x = self._locate(p)
            j = np.clip(np.floor((n - 1) / np.pi * np.arccos(np.clip(-x, -1.0, 1.0))).astype(np.intp), 0, n - 2)
            half = 0.5 * (e[k + 1] - e[k])
            p0 = e[k] + half * (_X[j] + 1.0)
            hc = half * (_X[j + 1] - _X[j])
            s = (p - p0) / hc
            s2 = s * s
            s3 = s2 * s
            h01 = 3.0 * s2 - 2.0 * s3
            h00 = 1.0 - h01
            h10 = (s3 - 2.0 * s2 + s) * hc
            h11 = (s3 - s2) * hc
            i0 = k * n + j
            for out, v, dv in ((Fo, self._F, self._dF), (Go, self._G, self._dG)):
                v, dv = v.ravel(), dv.ravel()
                out[lo:lo + (1 << 16)] = h00 * v[i0] + h01 * v[i0 + 1] + h10 * dv[i0] + h11 * dv[i0 + 1]
        return Fo.reshape(P.shape), Go.reshape(P.shape)

    def F(self, P):
        return self._eval(P)[0]

    def G(self, P):
        return self._eval(P)[1]

    def dG(self, P):
        """G'(P) = 2 C R_t exp(F) / (m + rho A)."""
        P = np.asarray(P, float)
        A, C = np.asarray(self.coefficients.A(P), float), np.asarray(self.coefficients.C(P), float)
        r = self.mass / self.target_density
        return self.resistance_pa / self.target_density * _w_rates(A, 0.0, C, r)[1] * np.exp(self.F(P))

    def speed2(self, U0, P):
        """u^2 = exp(-F(P)) (U0^2 - G(P)) (>= 0 before the stop); broadcasting."""
        U0, P = np.broadcast_arrays(np.asarray(U0, float), np.asarray(P, float))
        F, G = self._hermite(P)
        return np.exp(-F) * (U0**2 - G)

    def speed2_to_stop(self, U0, P_f, P):
        """u^2 = exp(-F(P)) (G(P_f) - G(P)) at P <= P_f (the stop of U0): :meth:`speed2` with U0^2
        replaced by G(P_f) of the same interpolant, so that u^2 -> 0 at the stop without the
        cancellation of U0^2 - G(P) (the Hermite interpolant's 1e-13 offset)."""
        P_f, P = np.broadcast_arrays(np.asarray(P_f, float), np.asarray(P, float))
        F, G = self._hermite(P)
        return np.exp(-F) * (self._hermite(P_f[..., -1:])[1] - G)

    def stop(self, U0) -> RootResult:
        """P_f with G(P_f) = U0^2 for every U0 (vectorised), with its status: a cubic Hermite
        start inside the bracketing pair of nodes (values and exact slopes), then Newton on the
        spectral interpolant safeguarded by bisection of the bracket, at most 50 passes.  The
        one root finder of eq. (11) in P (the array path of the sweeps uses it too)."""
        U0 = np.asarray(U0, float)
        if np.any(U0 > self.U_max * (1 + 1e-12)) or np.any(U0 < 0):
            raise ModelError(f"U0 must lie in [0, U_max = {self.U_max:g}] of the profile")
        g = U0.ravel() ** 2
        Pn = (self._edges[:-1, None] + 0.5 * np.diff(self._edges)[:, None] * (_X + 1.0)[None, :]).ravel()
        Gn = np.maximum.accumulate(self._G.ravel())
        dGn = self._dG.ravel()
        k = np.clip(np.searchsorted(Gn, g, side="left"), 1, len(Gn) - 1)
        lo, hi = Pn[k - 1].copy(), Pn[k].copy()
        h = hi - lo
        y0, y1, d0, d1 = Gn[k - 1], Gn[k], dGn[k - 1] * h, dGn[k] * h
        with np.errstate(invalid="ignore", divide="ignore"):
            s = np.clip(np.where(y1 > y0, (g - y0) / (y1 - y0), 0.5), 0.0, 1.0)
        for _ in range(6):  # Newton on the Hermite cubic (a start within ~1e-10 relative)
            s2, s3 = s * s, s * s * s
            y = y0 * (2 * s3 - 3 * s2 + 1) + d0 * (s3 - 2 * s2 + s) + y1 * (3 * s2 - 2 * s3) + d1 * (s3 - s2)
            dy = 6 * (y0 - y1) * (s2 - s) + d0 * (3 * s2 - 4 * s + 1) + d1 * (3 * s2 - 2 * s)
            with np.errstate(invalid="ignore", divide="ignore"):
                s = np.clip(s - np.where(dy > 0, (y - g) / dy, 0.0), 0.0, 1.0)
        P = lo + s * h
        done = g == 0
        it = 0
        rate = np.zeros_like(P)
        for it in range(1, 51):  # noqa: B007 (the count is returned)
            F, G, dG = self._eval(P, (self._F, self._G, self._dG))
            r = G - g
            lo = np.where(r < 0, P, lo)
            hi = np.where(r >= 0, P, hi)
            rate = np.exp(-F) * dG
            with np.errstate(invalid="ignore", divide="ignore"):
                Pn_ = P - r / dG
            bad = ~np.isfinite(Pn_) | (Pn_ < lo) | (Pn_ > hi)
            Pn_ = np.where(bad, 0.5 * (lo + hi), Pn_)
            # converged: the step or the bracket at round-off, or the residual G - U0^2 itself at the
            # round-off of G (where G is flat, past a plate's back face, the step cannot settle)
            done = done | (((np.abs(Pn_ - P) <= 1e-13 * np.abs(P)) | (hi - lo <= 1e-15 * hi)
                            | (np.abs(r) <= 8.0 * np.finfo(float).eps * g)) & np.isfinite(r))
            P = np.where(g == 0, P, Pn_)
            if np.all(done):
                break
        P = np.where(g == 0, 0.0, P)
        shape = U0.shape
        return RootResult(P.reshape(shape)[()], done.reshape(shape)[()], it, rate.reshape(shape)[()])

    def final_depth(self, U0):
        """P_f with G(P_f) = U0^2, vectorised (see :meth:`stop`); raises :class:`ConvergenceError`
        if the root finder did not converge (never a silent result)."""
        res = self.stop(U0)
        if not res.success:
            raise ConvergenceError(f"eq. (11) in P: the final depth did not converge in {res.iterations} Newton passes "
                                   f"for {int(np.size(res.converged) - np.count_nonzero(res.converged))} velocities")
        return res.x

    def integration_error(self, P):
        """Embedded error estimate of (F, G) at P: the spectral tails of the integrands of the
        panels up to P (accumulated), G's including the effect of F's through e^F."""
        if self._tail is None:
            return np.zeros_like(np.asarray(P, float)), np.zeros_like(np.asarray(P, float))
        P = np.asarray(P, float)
        k = np.clip(np.searchsorted(self._edges, P, side="right"), 1, len(self._edges) - 1)
        eF, eG = self._tail[0][k], self._tail[1][k]  # through the end of P's panel (an upper bound)
        return eF, eG + np.abs(self.G(P)) * eF

    def shifted(self, dF, dG, ddF, ddG) -> DepthProfile:
        """The profile with F, G and their slopes changed by the given node arrays (first-order
        perturbed profiles of the error estimate: no coefficient evaluation, no integration)."""
        import dataclasses

        return dataclasses.replace(self, _F=self._F + dF, _G=self._G + dG, _dF=self._dF + ddF, _dG=self._dG + ddG)

    def sensitivities(self, shift):
        """First-order changes (dF, dG, dF', dG') at the nodes (each (3, panels, nodes), rows: A,
        B, C) when the coefficients are off by ``shift(P) -> (dA, dB, dC)``: the same panels and
        quadrature, complex-step rows (see :func:`_integrate_panels`)."""
        e = self._edges
        r = self.mass / self.target_density
        _, F, G, dF, dG, _, _ = _integrate_panels(self.coefficients, e[:-1], e[1:], r, np.zeros(3), np.zeros(3), shift)
        s = self.resistance_pa / self.target_density
        im = lambda z, f=1.0: f * np.imag(z) / _STEP  # noqa: E731
        return im(F), im(G, s), im(dF), im(dG, s)


def _panels(breaks: np.ndarray, P_to: float, max_len: float, start: float = 0.0) -> np.ndarray:
    """Panel ends on [start, P_to]: the breakpoints inside, each gap cut into pieces <= max_len."""
    pts = np.unique(np.concatenate([[start, P_to], breaks[(breaks > start) & (breaks < P_to)]]))
    out = [pts[:1]]
    for a, b in zip(pts[:-1], pts[1:]):
        n = int(np.ceil((b - a) / max_len))
        out.append(np.linspace(a, b, n + 1)[1:])
    return np.concatenate(out)


def reduced_profiles(coefficients, ratios, g_max: float, *, panel_scale: float = 1.0) -> list[DepthProfile]:
    """The :class:`DepthProfile` of eq. (11) in reduced units (mass r = m/rho, rho = 1, R_t = 1)
    for each ratio r in ``ratios``, on one set of panels and nodes (the coefficients evaluated
    once), integrated until every G_1 > ``g_max`` (G = (R_t/rho) G_1, F unchanged).

    Panels: the coefficients' breakpoints (``coefficients.depth`` if present) plus pieces no
    longer than a fortieth of the deep-limit stopping depth of the largest ratio (times
    ``panel_scale``), 16 Chebyshev nodes each."""
    r = np.atleast_1d(np.asarray(ratios, float))
    d = float(coefficients.diameter)
    breaks = np.asarray(getattr(coefficients, "depth", np.empty(0)), float).ravel()
    A8, B8, C8 = deep_coefficients(coefficients)
    P_scale = ConstantCoefficientSolution(A8, B8, C8, float(r.max()), 1.0, 1.0, math.sqrt(g_max)).final_depth + 2.0 * d
    max_len = panel_scale * P_scale / 40.0
    edges = np.array([0.0])
    parts = []
    F0, G0 = np.zeros(r.size), np.zeros(r.size)
    P_to = 1.5 * P_scale
    for _ in range(60):
        new = _panels(breaks, P_to, max_len, start=edges[-1])
        _, F, G, dF, dG, tF, tG = _integrate_panels(coefficients, new[:-1], new[1:], r, F0, G0)
        parts.append((F, G, dF, dG, tF, tG))
        edges = np.concatenate([edges, new[1:]])
        F0, G0 = F[:, -1, -1], G[:, -1, -1]
        if np.all(G0 > g_max * (1.0 + 1e-9)):
            break
        P_to = edges[-1] * 2.0
        if P_to > 1e3 * P_scale:  # a thousand deep-limit stopping depths: it does not stop
            raise ConvergenceError(f"eq. (11) in P: G did not reach U_max^2 by P = {edges[-1]:.3g} m "
                                   "(does the projectile stop?)")
    else:
        raise ConvergenceError("eq. (11) in P: G did not reach U_max^2 (does the projectile stop?)")
    F, G, dF, dG = (np.concatenate([p[i] for p in parts], axis=1) for i in range(4))
    tails = [np.cumsum(np.concatenate([np.zeros((r.size, 1))] + [p[i] for p in parts], axis=1), axis=1) for i in (4, 5)]
    out = []
    for j, rj in enumerate(r):
        tail = np.stack([tails[0][j], tails[1][j]])  # accumulated to each panel end
        out.append(DepthProfile(coefficients, float(rj), 1.0, 1.0, math.sqrt(g_max), float(edges[-1]), edges, F[j], G[j],
                                np.ascontiguousarray(np.broadcast_to(dF[j], F[j].shape)), dG[j], tail))
    return out


def depth_profile(
    coefficients, mass: float, target_density: float, resistance_pa: float, U_max: float, *, panel_scale: float = 1.0
) -> DepthProfile:
    """F and G of the w = u^2 form of Part I, eq. (11), integrated in P until G > U_max^2
    (the one integration of :func:`reduced_profiles` with r = m/rho; G = (R_t/rho) G_1)."""
    _check_inputs(mass, target_density, resistance_pa)
    if not (np.isfinite(U_max) and U_max > 0):
        raise ModelError(f"U_max must be positive; got {U_max!r}")
    rho, R, m = float(target_density), float(resistance_pa), float(mass)
    s = R / rho
    (p,) = reduced_profiles(coefficients, [m / rho], U_max**2 / s, panel_scale=panel_scale)
    import dataclasses

    return dataclasses.replace(p, mass=m, target_density=rho, resistance_pa=R, U_max=float(U_max), _G=p._G * s,
                               _dG=p._dG * s, _tail=p._tail * np.array([[1.0], [s]]))


def final_depth(coefficients, mass: float, target_density: float, resistance_pa: float, U0):
    """Final depth [m] of Part I, eq. (11) for every U0 [m/s] (array in, array out), from one
    integration in P (see the module docstring).  U0 = 0 gives 0."""
    U0 = np.asarray(U0, float)
    if np.any(~np.isfinite(U0)) or np.any(U0 < 0):
        raise ModelError("U0 must be finite and non-negative")
    if U0.size == 0 or np.max(U0) == 0:
        return np.zeros_like(U0)[()]
    prof = depth_profile(coefficients, mass, target_density, resistance_pa, float(np.max(U0)))
    return prof.final_depth(U0)


# --------------------------------------------------------------------------------------
# the contact region of eq. (15) in eq. (11): coefficients of the wetted part


class WettedCorrection:
    """A(P, u), B(P, u), C(P, u) of the wetted part of the nose (Part I, eqs. (11), (15)).

    At each table knot the surface solution stored with it gives, for a speed u, the
    deceleration of eq. (11) with the pressure integrated over the wetted part only
    (:func:`semianalytic.coefficients.contact.separated_acceleration`, a fixed point in
    du/dt); the change of A, B, C from full contact is interpolated linearly in P between
    knots and added to the table's (full-contact) values.  No BEM solve per step.
    """

    def __init__(self, table, mass: float, target_density: float, resistance_pa: float, reading: str | None = None):
        self.table = table
        self.mass, self.rho, self.R = float(mass), float(target_density), float(resistance_pa)
        self.reading = reading or getattr(table, "reading", "body")
        self.depth = np.asarray(table.depth, float)
        from semianalytic.coefficients.contact import wetted_coefficients

        self._full = [wetted_coefficients(nodes, self.reading) for nodes in table.nodes]

    def _delta(self, k: int, u: float) -> np.ndarray:
        _, wet = separated_acceleration(self.table.nodes[k], self.reading, self.mass, self.rho, u, self.R)
        return np.subtract(wet, self._full[k])

    def coefficients(self, P: float, u: float) -> tuple[float, float, float]:
        """(A_w, B_w, C_w) at depth P and speed u [m^3, m^2, m^2]."""
        t = self.table
        full = np.array([float(t.A(P)), float(t.B(P, self.reading)), float(t.C(P))])
        d = self.depth
        k = int(np.searchsorted(d, P))
        if k == 0:
            delta = self._delta(0, u) * (P / d[0] if d[0] > 0 else 1.0)
        elif k >= len(d):
            delta = self._delta(len(d) - 1, u)
        else:
            w = (P - d[k - 1]) / (d[k] - d[k - 1])
            delta = (1 - w) * self._delta(k - 1, u) + w * self._delta(k, u)
        A, B, C = full + delta
        return float(A), float(B), float(C)

    def acceleration(self, P: float, u: float) -> float:
        """du/dt of Part I, eq. (11) with the wetted coefficients."""
        A, B, C = self.coefficients(P, u)
        return eq11_acceleration(A, B, C, self.mass, self.rho, self.R, u * u)


def separated_acceleration(nodes: dict, reading: str, mass: float, rho: float, u: float, R_t: float, iterations: int = 20):
    """du/dt of Part I, eq. (11) with the coefficients of the wetted part (eq. (15)), and
    (A_w, B_w, C_w): fixed point from full contact (the wetted set usually settles in 2-3
    steps).  Raises :class:`ConvergenceError` if the wetted set still changes after
    ``iterations`` passes."""
    from semianalytic.coefficients.contact import contact_pressure, pressure_terms, wetted_coefficients

    phi, q = pressure_terms(nodes, reading)
    wet = np.ones(len(phi), bool)
    for _ in range(iterations):
        coef = wetted_coefficients(nodes, reading, wet)
        a = eq11_acceleration(*coef, mass, rho, R_t, u * u)
        new = contact_pressure(phi, q, rho, a, u * u, R_t) > 0
        if np.array_equal(new, wet):
            return a, coef
        wet = new
    raise ConvergenceError(f"the wetted part of eq. (15) did not settle in {iterations} fixed-point passes (u = {u:g} m/s)")


@functools.lru_cache(maxsize=1024)
def _separated_run(wetted: WettedCorrection, rtol: float, U0: float):
    """(P_f, dense output of w(P), -dw/dP at the stop) of one start velocity with the contact
    region of eq. (15) (DOP853 in P with an event at w = 0).  Cached here, outside the frozen
    :class:`SeparatedProfile`, keyed by the (identity of the) wetted correction, rtol and U0."""
    if U0 == 0.0:
        return 0.0, None, 0.0
    wc = wetted
    d = float(wc.table.diameter)

    def rhs(P, y):
        return [2.0 * wc.acceleration(max(P, 0.0), math.sqrt(max(y[0], 0.0)))]

    def stop(P, y):
        return y[0]

    stop.terminal, stop.direction = True, -1
    A8, B8, C8 = deep_coefficients(wc.table)
    P_end = 10.0 * ConstantCoefficientSolution(A8, B8, C8, wc.mass, wc.rho, wc.R, U0).final_depth + 100.0 * d
    from scipy.integrate import solve_ivp  # separated contact only (start-up time)

    sol = solve_ivp(rhs, (0.0, P_end), [U0 * U0], method="DOP853", rtol=rtol, atol=rtol * U0 * U0, events=stop,
                    dense_output=True)
    if sol.status != 1 or not len(sol.t_events[0]):
        raise ConvergenceError(f"eq. (11) with separation did not stop before P = {P_end:g} m ({sol.message})")
    P_f = float(sol.t_events[0][0])
    return P_f, sol.sol, -2.0 * wc.acceleration(P_f, 0.0)  # -dw/dP at the stop


@dataclass(frozen=True, eq=False)
class SeparatedProfile:
    """u^2(P) of Part I, eq. (11) with the contact region of eq. (15) for each start velocity
    (one integration in P per velocity, w = u^2, dw/dP = 2 du/dt; DOP853 with an event at
    w = 0).  Offers the methods of :class:`DepthProfile` that the models use.  Frozen: the runs
    are cached by :func:`_separated_run`, not in the instance."""

    wetted: WettedCorrection
    rtol: float = 1e-10

    def _run(self, U0: float):
        return _separated_run(self.wetted, float(self.rtol), float(U0))

    def stop(self, U0) -> RootResult:
        """P_f for each U0 with its status (an integrator that does not stop raises
        :class:`ConvergenceError`); ``rate`` = -dw/dP at the stop."""
        U0 = np.asarray(U0, float)
        runs = [self._run(u) for u in U0.ravel()]
        x = np.array([r[0] for r in runs]).reshape(U0.shape)[()]
        rate = np.array([r[2] for r in runs]).reshape(U0.shape)[()]
        return RootResult(x, np.ones(U0.shape, bool)[()], 1, rate)

    def final_depth(self, U0):
        return self.stop(U0).x

    def speed2(self, U0, P):
        U0 = np.asarray(U0, float)
        P = np.asarray(P, float)
        U0b, Pb = np.broadcast_arrays(U0, P)
        out = np.empty(Pb.shape)
        for idx in np.ndindex(Pb.shape[:-1] if Pb.ndim > 1 else ()):
            u = float(U0b[idx].ravel()[0]) if Pb.ndim > 1 else float(U0b.ravel()[0])
            P_f, dense, _ = self._run(u)
            row = Pb[idx]
            if dense is None:
                out[idx] = 0.0
            else:
                out[idx] = np.where(row <= P_f, dense(np.minimum(row, P_f))[0], 0.0)
        return out

    def F(self, P):
        return np.zeros_like(np.asarray(P, float))

    def speed2_to_stop(self, U0, P_f, P):
        return self.speed2(U0, P)


def separated_profile(table, mass: float, target_density: float, resistance_pa: float, rtol: float = 1e-10):
    """The :class:`SeparatedProfile` of a BEM table (Part I, eqs. (11), (15))."""
    return SeparatedProfile(WettedCorrection(table, mass, target_density, resistance_pa), rtol)


def separation_onset(table, mass: float, target_density: float, resistance_pa: float, profile, U0) -> list:
    """Per start velocity: the first knot depth [m] at which the full-contact pressure of
    eq. (9) would turn negative somewhere on the nose (eq. (15)), or None.

    All knots and velocities at once: the nodes' pressure terms do not depend on the velocity,
    and p_c (eq. (9) with du/dt of eq. (11)) is linear in u^2 at each node, so each knot
    separates for u^2 in a union of two intervals found once; the velocities are compared with
    those bounds on a (velocities x knots) array."""
    from semianalytic.coefficients.contact import contact_pressure, pressure_terms

    reading = getattr(table, "reading", "body")
    rho, R, m = float(target_density), float(resistance_pa), float(mass)
    P_k = np.asarray(table.depth, float)
    U = np.atleast_1d(np.asarray(U0, float))
    P_f = np.asarray(profile.final_depth(U), float).reshape(U.shape)
    inside = np.nonzero(P_k < P_f.max())[0] if U.size else np.empty(0, int)
    if inside.size == 0:
        return [None] * U.size
    phis, qs, owner = [], [], []
    for j, k in enumerate(inside):  # the nodes where separation counts (n_x > 0), knot by knot
        nodes = table.nodes[k]
        phi, q = pressure_terms(nodes, reading)
        keep = nodes["nx"] > 1e-12
        phis.append(phi[keep])
        qs.append(q[keep])
        owner.append(np.full(int(keep.sum()), j))
    phi, q, owner = np.concatenate(phis), np.concatenate(qs), np.concatenate(owner)
    starts = np.searchsorted(owner, np.arange(len(inside)))
    A = np.asarray(table.A(P_k[inside]), float)[owner]
    B = np.asarray(table.B(P_k[inside]), float)[owner]
    C = np.asarray(table.C(P_k[inside]), float)[owner]
    # p_c of eq. (9) with du/dt of eq. (11) is linear in w = u^2 at each node: p_c = slope w + icpt
    a_w = eq11_acceleration(A, B, 0.0, m, rho, R, 1.0)  # du/dt per unit u^2 (the velocity term)
    a_0 = eq11_acceleration(A, 0.0, C, m, rho, R, 0.0)  # du/dt at u = 0 (the strength term)
    slope = contact_pressure(phi, q, rho, a_w, 1.0, 0.0)
    icpt = contact_pressure(phi, q, rho, a_0, 0.0, R)
    # the w >= 0 where p_c <= 0: [0, x] (slope >= 0, icpt <= 0) or [y, inf) (slope < 0); per knot the union
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = -icpt / slope
    x = np.where((slope > 0) & (icpt <= 0), ratio, np.where((slope == 0) & (icpt <= 0), np.inf, -np.inf))
    y = np.where(slope < 0, np.maximum(ratio, 0.0), np.inf)
    X, Y = np.full(len(inside), -np.inf), np.full(len(inside), np.inf)
    has = np.diff(np.append(starts, len(owner))) > 0  # a knot without such nodes never separates
    X[has] = np.maximum.reduceat(x, starts[has])
    Y[has] = np.minimum.reduceat(y, starts[has])
    out = []
    for lo in range(0, U.size, 256):  # blocks of velocities bound the (velocities x knots) arrays
        u2 = np.maximum(profile.speed2(U[lo:lo + 256, None], P_k[None, inside]), 0.0)
        sep = ((u2 <= X[None, :]) | (u2 >= Y[None, :])) & (P_k[None, inside] < P_f[lo:lo + 256, None])
        first = np.argmax(sep, axis=1)
        out.extend(float(P_k[inside[f]]) if sep[i, f] else None for i, f in enumerate(first))
    return out
