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

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = [
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
            raise ValueError(f"{name} must be positive and finite; got {value!r}")


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
    rho = target_density
    return mass * (0.5 * rho * B * u * u + C * resistance_pa) / (mass + rho * A)


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

    @property
    def penetration_time(self) -> float:
        if self.B == 0:
            return self.U0 / self.deceleration0
        return math.atan(self.U0 / self.a) / (self.a * self.k)

    @property
    def final_depth(self) -> float:
        if self.B == 0:
            return self.U0**2 / (2.0 * self.deceleration0)
        return math.log1p((self.U0 / self.a) ** 2) / (2.0 * self.k)

    def velocity(self, t):
        t = np.minimum(np.asarray(t, float), self.penetration_time)
        if self.B == 0:
            return self.U0 - self.deceleration0 * t
        a, U = self.a, self.U0
        tg = np.tan(a * self.k * t)
        return a * (U - a * tg) / (a + U * tg)

    def depth(self, t):
        t = np.minimum(np.asarray(t, float), self.penetration_time)
        if self.B == 0:
            return self.U0 * t - 0.5 * self.deceleration0 * t * t
        g = self.a * self.k * t
        return np.log(np.cos(g) + self.U0 / self.a * np.sin(g)) / self.k

    def depth_at_velocity(self, u):
        u = np.asarray(u, float)
        if self.B == 0:
            return (self.U0**2 - u * u) / (2.0 * self.deceleration0)
        a2 = self.a**2
        return np.log((a2 + self.U0**2) / (a2 + u * u)) / (2.0 * self.k)


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
        raise ValueError(f"U0 must be finite and non-negative; got {U0!r}")
    rho, R, m = float(target_density), float(resistance_pa), float(mass)
    d = float(coefficients.diameter)
    if U0 == 0:
        z = np.zeros(1)
        C0 = float(coefficients.C(0.0))
        A0 = float(coefficients.A(0.0))
        dec = C0 * R / (m + rho * A0)
        return MotionResult(z, z, z, -dec * np.ones(1), m * dec * np.ones(1), 0.0, 0.0, m, 0.0)

    cA, cB, cC = coefficients.A, coefficients.B, coefficients.C

    def rhs(t, y):
        P, u = max(y[0], 0.0), y[1]  # RK stages may step a hair below the surface at t = 0
        A, B, C = float(cA(P)), float(cB(P)), float(cC(P))
        return (u, -(0.5 * rho * B * u * u + C * R) / (m + rho * A))

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
        raise RuntimeError(f"eq. (11) did not reach u = 0 before t = {t_max:g} s ({sol.message})")
    t_end = float(sol.t_events[0][0])
    t = sol.t.copy()
    P, u = sol.y[0].copy(), sol.y[1].copy()
    t[-1], P[-1], u[-1] = t_end, float(sol.y_events[0][0][0]), 0.0
    A, B, C = cA(P), cB(P), cC(P)
    du_dt = -(0.5 * rho * B * u * u + C * R) / (m + rho * A)
    return MotionResult(
        t=t, P=P, u=u, du_dt=du_dt, force=-m * du_dt, final_depth=float(P[-1]), penetration_time=t_end,
        mass=m, U0=float(U0), _dense=sol.sol,
    )


# --------------------------------------------------------------------------------------
# P as the independent variable: all striking velocities at once


def _chebyshev_panel_rule(n: int):
    """Chebyshev-Lobatto nodes x (n, on [-1, 1], ascending), barycentric weights, and the
    spectral integration matrix Q with (Q f)_i = int_{-1}^{x_i} p_f, p_f the interpolant of f."""
    from numpy.polynomial import chebyshev as ch

    x = -np.cos(np.pi * np.arange(n) / (n - 1))
    V = ch.chebvander(x, n - 1)  # V[i, j] = T_j(x_i)
    coef_of_values = np.linalg.inv(V)
    integ = np.column_stack([ch.chebint(np.eye(n)[j]) for j in range(n)])  # (n+1, n) antiderivative coefficients
    W = ch.chebvander(x, n) @ integ - ch.chebvander(np.array([-1.0]), n) @ integ
    bw = (-1.0) ** np.arange(n)
    bw[0] *= 0.5
    bw[-1] *= 0.5
    return x, bw, W @ coef_of_values


_NODES = 16
_X, _BW, _Q = _chebyshev_panel_rule(_NODES)


@dataclass(frozen=True, eq=False)
class DepthProfile:
    """F(P), G(P) of the linear form of eq. (11) in w = u^2 (see the module docstring) on
    [0, ``P_end``], where G(P_end) > U_max^2.  SI units.

    F and G are computed by spectral (Chebyshev) integration on panels whose ends include
    the breakpoints of piecewise-smooth coefficients (a ``depth`` attribute, as the BEM
    table's interpolation knots), so that every panel sees a smooth integrand; between the
    nodes they are evaluated by barycentric interpolation.

    ``speed2(U0, P)`` = u^2 at depth P for start velocity U0 (broadcasting);
    ``final_depth(U0)`` solves G(P_f) = U0^2; ``dG(P)`` = G'(P) exactly from the coefficients.
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

    def M(self, P):
        return self.mass + self.target_density * np.asarray(self.coefficients.A(P), float)

    def _eval(self, P):
        """(F, G) at P of any shape, 0 <= P <= P_end (barycentric interpolation per panel)."""
        P = np.asarray(P, float)
        flat = P.ravel()
        e = self._edges
        k = np.clip(np.searchsorted(e, flat, side="right") - 1, 0, len(e) - 2)
        x = 2.0 * (flat - e[k]) / (e[k + 1] - e[k]) - 1.0
        d = x[:, None] - _X[None, :]
        exact = d == 0.0
        with np.errstate(divide="ignore", invalid="ignore"):
            c = _BW[None, :] / d
        hit = exact.any(axis=1)
        c[hit] = exact[hit].astype(float)
        c /= c.sum(axis=1, keepdims=True)
        F = np.einsum("ij,ij->i", c, self._F[k])
        G = np.einsum("ij,ij->i", c, self._G[k])
        return F.reshape(P.shape), G.reshape(P.shape)

    def F(self, P):
        return self._eval(P)[0]

    def G(self, P):
        return self._eval(P)[1]

    def dG(self, P):
        """G'(P) = 2 C R_t exp(F) / (m + rho A)."""
        P = np.asarray(P, float)
        return 2.0 * np.asarray(self.coefficients.C(P), float) * self.resistance_pa * np.exp(self.F(P)) / self.M(P)

    def speed2(self, U0, P):
        """u^2 = exp(-F(P)) (U0^2 - G(P)) (>= 0 before the stop)."""
        F, G = self._eval(P)
        return np.exp(-F) * (np.asarray(U0, float) ** 2 - G)

    def final_depth(self, U0):
        """P_f with G(P_f) = U0^2, vectorised (safeguarded Newton inside the bracketing panel node pair)."""
        U0 = np.asarray(U0, float)
        if np.any(U0 > self.U_max * (1 + 1e-12)) or np.any(U0 < 0):
            raise ValueError("U0 must lie in [0, U_max] of the profile")
        g = U0.ravel() ** 2
        e = self._edges
        Pn = (e[:-1, None] + 0.5 * (e[1:] - e[:-1])[:, None] * (_X + 1.0)[None, :]).ravel()
        Gn = np.maximum.accumulate(self._G.ravel())
        k = np.clip(np.searchsorted(Gn, g, side="left"), 1, len(Gn) - 1)
        lo, hi = Pn[k - 1].copy(), Pn[k].copy()
        Glo, Ghi = Gn[k - 1], Gn[k]
        with np.errstate(invalid="ignore", divide="ignore"):
            frac = np.where(Ghi > Glo, (g - Glo) / (Ghi - Glo), 0.5)
        P = lo + np.clip(frac, 0.0, 1.0) * (hi - lo)
        C, A = self.coefficients.C, self.coefficients.A
        for _ in range(50):
            F, G = self._eval(P)
            r = G - g
            lo = np.where(r < 0, P, lo)
            hi = np.where(r >= 0, P, hi)
            dG = 2.0 * np.asarray(C(P), float) * self.resistance_pa * np.exp(F) / (
                self.mass + self.target_density * np.asarray(A(P), float)
            )
            with np.errstate(invalid="ignore", divide="ignore"):
                Pn_ = P - r / dG
            bad = ~np.isfinite(Pn_) | (Pn_ < lo) | (Pn_ > hi)
            Pn_ = np.where(bad, 0.5 * (lo + hi), Pn_)
            done = (np.abs(Pn_ - P) <= 1e-13 * np.abs(P)) | (hi - lo <= 1e-15 * hi)
            P = Pn_
            if np.all(done):
                break
        P = np.where(g == 0, 0.0, P)
        return P.reshape(U0.shape)[()]


def _panels(breaks: np.ndarray, P_to: float, max_len: float, start: float = 0.0) -> np.ndarray:
    """Panel ends on [start, P_to]: the breakpoints inside, each gap cut into pieces <= max_len."""
    pts = np.unique(np.concatenate([[start, P_to], breaks[(breaks > start) & (breaks < P_to)]]))
    out = [pts[:1]]
    for a, b in zip(pts[:-1], pts[1:]):
        n = int(np.ceil((b - a) / max_len))
        out.append(np.linspace(a, b, n + 1)[1:])
    return np.concatenate(out)


def depth_profile(
    coefficients, mass: float, target_density: float, resistance_pa: float, U_max: float, *, panel_scale: float = 1.0
) -> DepthProfile:
    """F and G of the w = u^2 form of Part I, eq. (11), integrated in P until G > U_max^2.

    Panels: the coefficients' breakpoints (``coefficients.depth`` if present) plus pieces no
    longer than a fortieth of the deep-limit stopping depth of U_max (times ``panel_scale``),
    16 Chebyshev nodes each.
    """
    _check_inputs(mass, target_density, resistance_pa)
    if not (np.isfinite(U_max) and U_max > 0):
        raise ValueError(f"U_max must be positive; got {U_max!r}")
    rho, R, m = float(target_density), float(resistance_pa), float(mass)
    d = float(coefficients.diameter)
    breaks = np.asarray(getattr(coefficients, "depth", np.empty(0)), float).ravel()
    A8, B8, C8 = deep_coefficients(coefficients)
    P_scale = ConstantCoefficientSolution(A8, B8, C8, m, rho, R, U_max).final_depth + 2.0 * d
    max_len = panel_scale * P_scale / 40.0
    g_end = U_max**2 * (1.0 + 1e-9)
    edges = np.array([0.0])
    Fs, Gs = np.empty((0, _NODES)), np.empty((0, _NODES))
    F0 = G0 = 0.0
    P_to = 1.5 * P_scale
    for _ in range(60):
        new = _panels(breaks, P_to, max_len, start=edges[-1])
        a, b = new[:-1], new[1:]
        h = 0.5 * (b - a)
        nodes = a[:, None] + h[:, None] * (_X + 1.0)[None, :]
        A = np.asarray(coefficients.A(nodes), float)
        B = np.asarray(coefficients.B(nodes), float)
        C = np.asarray(coefficients.C(nodes), float)
        M = m + rho * A
        fF = rho * B / M
        Floc = h[:, None] * (fF @ _Q.T)
        F = F0 + np.concatenate([[0.0], np.cumsum(Floc[:, -1])[:-1]])[:, None] + Floc
        fG = 2.0 * C * R * np.exp(F) / M
        Gloc = h[:, None] * (fG @ _Q.T)
        G = G0 + np.concatenate([[0.0], np.cumsum(Gloc[:, -1])[:-1]])[:, None] + Gloc
        edges = np.concatenate([edges, new[1:]])
        Fs, Gs = np.vstack([Fs, F]), np.vstack([Gs, G])
        F0, G0 = F[-1, -1], G[-1, -1]
        if G0 > g_end:
            break
        P_to = edges[-1] * 2.0
    else:
        raise RuntimeError("eq. (11) in P: G did not reach U_max^2 (does the projectile stop?)")
    return DepthProfile(coefficients, m, rho, R, float(U_max), float(edges[-1]), edges, Fs, Gs)


def final_depth(coefficients, mass: float, target_density: float, resistance_pa: float, U0):
    """Final depth [m] of Part I, eq. (11) for every U0 [m/s] (array in, array out), from one
    integration in P (see the module docstring).  U0 = 0 gives 0."""
    U0 = np.asarray(U0, float)
    if np.any(~np.isfinite(U0)) or np.any(U0 < 0):
        raise ValueError("U0 must be finite and non-negative")
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
        self._full = []
        from semianalytic.coefficients.contact import pressure_terms

        for nodes in table.nodes:
            phi, q = pressure_terms(nodes, self.reading)
            wn = nodes["weight"] * nodes["nx"]
            self._full.append((float(np.sum(wn * phi)), float(np.sum(wn * q)), float(np.sum(wn))))

    def _delta(self, k: int, u: float) -> np.ndarray:
        from semianalytic.coefficients.contact import separated_acceleration

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
        return -(0.5 * self.rho * B * u * u + C * self.R) / (self.mass + self.rho * A)


@dataclass(frozen=True, eq=False)
class SeparatedProfile:
    """u^2(P) of Part I, eq. (11) with the contact region of eq. (15) for each start velocity
    (one integration in P per velocity, w = u^2, dw/dP = 2 du/dt; DOP853 with an event at
    w = 0).  Offers the methods of :class:`DepthProfile` that the models use."""

    wetted: WettedCorrection
    rtol: float = 1e-10
    _runs: dict = field(default_factory=dict, repr=False)

    def _run(self, U0: float):
        U0 = float(U0)
        if U0 not in self._runs:
            wc = self.wetted
            d = float(wc.table.diameter)

            def rhs(P, y):
                w = max(y[0], 0.0)
                return [2.0 * wc.acceleration(max(P, 0.0), math.sqrt(w))]

            def stop(P, y):
                return y[0]

            stop.terminal, stop.direction = True, -1
            A8, B8, C8 = deep_coefficients(wc.table)
            P_end = 10.0 * ConstantCoefficientSolution(A8, B8, C8, wc.mass, wc.rho, wc.R, U0).final_depth + 100.0 * d
            from scipy.integrate import solve_ivp  # separated contact only (start-up time)

            sol = solve_ivp(rhs, (0.0, P_end), [U0 * U0], method="DOP853", rtol=self.rtol, atol=self.rtol * U0 * U0,
                            events=stop, dense_output=True)
            if U0 == 0.0:
                self._runs[U0] = (0.0, None, 0.0)
            else:
                if sol.status != 1 or not len(sol.t_events[0]):
                    raise RuntimeError(f"eq. (11) with separation did not stop before P = {P_end:g} m")
                P_f = float(sol.t_events[0][0])
                slope = -2.0 * wc.acceleration(P_f, 0.0)  # -dw/dP at the stop
                self._runs[U0] = (P_f, sol.sol, slope)
        return self._runs[U0]

    def final_depth(self, U0):
        U0 = np.asarray(U0, float)
        return np.array([self._run(u)[0] for u in U0.ravel()]).reshape(U0.shape)[()]

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

    def dG(self, P):
        """-dw/dP at the stop of the run whose final depth is P (used for the time at the stop)."""
        P = np.asarray(P, float)
        lookup = {run[0]: run[2] for run in self._runs.values()}
        return np.array([lookup.get(float(p), np.nan) for p in P.ravel()]).reshape(P.shape)


def separated_profile(table, mass: float, target_density: float, resistance_pa: float, rtol: float = 1e-10):
    """The :class:`SeparatedProfile` of a BEM table (Part I, eqs. (11), (15))."""
    return SeparatedProfile(WettedCorrection(table, mass, target_density, resistance_pa), rtol)


def separation_onset(table, mass: float, target_density: float, resistance_pa: float, profile, U0) -> list:
    """Per start velocity: the first knot depth [m] at which the full-contact pressure of
    eq. (9) would turn negative somewhere on the nose (eq. (15)), or None.

    All knots and velocities at once: the nodes' pressure terms do not depend on the velocity,
    so they are gathered once and p_c is evaluated on a (velocities x nodes) array."""
    from semianalytic.coefficients.contact import pressure_terms

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
    out = []
    for lo in range(0, U.size, 64):  # blocks of velocities bound the (velocities x nodes) arrays
        u2 = np.maximum(profile.speed2(U[lo:lo + 64, None], P_k[None, inside]), 0.0)
        w = u2[:, owner]
        a = -(0.5 * rho * B * w + C * R) / (m + rho * A)  # du/dt of eq. (11), full contact
        p = rho * phi * a + q * rho * w / 2 + R  # p_c of eq. (9) at every node
        sep = np.logical_or.reduceat(p <= 0, starts, axis=1) & (P_k[None, inside] < P_f[lo:lo + 64, None])
        sep &= np.diff(np.append(starts, len(owner)))[None, :] > 0  # a knot without such nodes never separates
        first = np.argmax(sep, axis=1)
        out.extend(float(P_k[inside[f]]) if sep[i, f] else None for i, f in enumerate(first))
    return out
