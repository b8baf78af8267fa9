"""Perforation of finite (layered) targets by a rigid projectile: Part I, eq. (11) through
plates of finite thickness, with the resistance falling near each back face.

The equation of motion is Part I, eq. (11),

    (m + sum_k rho_k A_k) du/dt = -(sum_k rho_k B_k) u^2 / 2 - sum_k f_k C_k R_k,

summed over the layers k the nose is in: A_k, B_k, C_k are the coefficients of layer k at the
tip depth measured from its impact face (a plate table, valid from first contact to the exit
of the nose, P in [0, H_k + L_h]), rho_k its density, R_k its resistance (eqs. (16)-(19)) and
f_k the back-face factor below.  All layers are folded into one coefficient object,
:class:`LayeredCoefficients`, with rho and R inside (A~ = sum rho_k A_k [kg], B~ = sum rho_k B_k
[kg/m], C~ = sum f_k R_k C_k [N]), so that the public integrators of
:mod:`semianalytic.penetration.motion` solve it unchanged with ``target_density = 1`` and
``resistance_pa = 1``:

* :func:`~semianalytic.penetration.motion.depth_profile`: eq. (11) in P for all striking
  velocities at once, w = u^2 = exp(-F(P)) (U_s^2 - G(P)).  The nose leaves the last layer at
  P_exit; the residual velocity is V_r = sqrt(exp(-F(P_exit)) (U_s^2 - G(P_exit))) and the
  ballistic limit is the U_s with w(P_exit) = 0.  Past P_exit the projectile is free; the
  object continues with a constant fictitious resistance only so that depth_profile's
  integration (which runs until G > U_max^2) ends; nothing past P_exit is reported.
* :func:`~semianalytic.penetration.motion.solve_motion`: the same equation in time (the
  independent check used by the tests).

Back face (the resistance falls as the plastic zone reaches it), ``back_face``:

* ``"finite-sphere"``: the quasi-static pressure to expand a spherical cavity of
  radius a in an incompressible elastic-perfectly plastic sphere of finite outer radius b
  (Hill 1950, *The Mathematical Theory of Plasticity*, ch. V, sec. 3: the thick spherical
  shell; partly plastic p = 2Y ln(c/a) + (2Y/3)(1 - c^3/b^3), fully plastic p = 2Y ln(b/a),
  with c^3/a^3 = 2E/(3Y) for a cavity opened from zero), divided by its value for b -> inf,
  (2Y/3)(1 + ln(2E/(3Y))).  The finite cavity expansion as a model of a nearby free surface
  is the method of Macek & Duffey (2000), Int. J. Impact Eng. 24:239-258 ("Finite cavity
  expansion method for near-surface effects and layering during earth penetration"): the
  outer radius is the distance from the cavity to the free surface.  Taking a = d/2 and
  b = H - P (the cavity centred at the tip, the back face its free surface) is this
  project's own choice of geometry; the resistance is zero once the tip is within d/2 of the
  back face.
* ``"constant"``: R_t of eq. (16) (or the case's resistance model) up to the exit.

Failure mode of the last ligament, ``failure``:

* ``"hole-growth"``: the nose pushes through (ductile hole growth; the back-face factor only);
* ``"plug"``: a shear plug of the nose diameter forms once the braking force N of eq. (11)
  exceeds the shear force the ligament h = H - P can carry, pi d h tau (the plugging
  criterion of Chen & Li 2003, Int. J. Impact Eng. 28:743-759, with tau = Y / sqrt(3),
  von Mises).  Projectile and plug then move on together (momentum conservation, Recht &
  Ipson 1963, J. Appl. Mech. 30:384-390): v_0 = m u / (m + m_plug), m_plug = rho pi d^2 h / 4,
  and push the plug out against the shear force pi d tau (h - x), which takes the work
  pi d tau h^2 / 2 (their energy balance): V_r^2 = v_0^2 - pi d tau h^2 / (m + m_plug), or a
  stop inside the ligament.  With a plug the back-face factor is not applied (the resistance is
  R_t until the plug forms: the plug is the back face's failure, as in Chen & Li 2003).
* ``"auto"`` (default): plug for a flat (blunt) nose, hole growth for the others (this
  project's own rule; the literature above reports plugging for blunt and ductile hole
  growth for sharp noses in ductile plates).

Lambert-Jonas: V_r = a (V_s^p - V_bl^p)^(1/p) for V_s > V_bl, else 0 (Lambert & Jonas 1976,
BRL-R-1852), fitted by least squares (:func:`lambert_jonas_fit`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from semianalytic.penetration.motion import depth_profile

__all__ = [
    "BACK_FACES",
    "FAILURES",
    "PlateLayer",
    "LayeredCoefficients",
    "HalfSpaceDifference",
    "back_face_factor",
    "PerforationCurve",
    "perforation_curve",
    "residual_velocity",
    "ballistic_limit",
    "BallisticLimit",
    "ballistic_limit_search",
    "resistance_work",
    "lambert_jonas",
    "lambert_jonas_fit",
]

BACK_FACES = ("auto", "finite-sphere", "constant", "cylindrical", "sphere-to-cylinder")
FAILURES = ("auto", "hole-growth", "plug")


def back_face_factor(ligament, radius: float, plastic_ratio: float):
    """R(b)/R(inf) of a spherical cavity of radius a = ``radius`` in an incompressible
    elastic-perfectly plastic sphere of outer radius b = ``ligament`` (Hill 1950, ch. V,
    sec. 3; Macek & Duffey 2000 for its use near a free surface; see the module docstring).

    ``plastic_ratio`` = c/a = (2E/(3Y))^(1/3), the plastic-zone radius of the infinite medium.
    Partly plastic (b >= c): [1 + ln(2E/3Y) - (c/b)^3] / [1 + ln(2E/3Y)]; fully plastic
    (a <= b <= c): 3 ln(b/a) / [1 + ln(2E/3Y)]; 0 for b <= a.  C^1 in b; -> 1 as b -> inf.
    """
    b = np.asarray(ligament, float)
    a, q = float(radius), float(plastic_ratio)
    if not (a > 0 and q > 1):
        raise ValueError("radius must be positive and plastic_ratio > 1")
    c = q * a
    L = 3.0 * math.log(q)  # ln(2E/(3Y))
    with np.errstate(divide="ignore", invalid="ignore"):
        partly = (1.0 + L - (c / b) ** 3) / (1.0 + L)
        fully = 3.0 * np.log(np.maximum(b, a) / a) / (1.0 + L)
    return np.where(b >= c, partly, np.where(b > a, fully, 0.0))[()]


@dataclass(frozen=True, eq=False)
class PlateLayer:
    """One plate of a target (SI): ``front`` depth of its impact face [m] (0 for the first;
    gaps are the space between a back face and the next front), ``thickness`` H [m],
    ``density`` rho [kg/m^3], ``resistance`` R_t [Pa], ``coefficients`` its plate table (A, B,
    C of the tip depth measured from ``front``, valid up to H + L_h), ``plastic_ratio``
    (2E/(3Y))^(1/3) for the finite-sphere back face (None: constant R_t), ``shear_strength``
    tau [Pa] of the plug criterion (None: no plugging), ``cylinder_resistance`` sigma_s of the
    cylindrical cavity (:func:`~semianalytic.perforation.thin_plate.cylindrical_cavity_stress`), the
    floor of the finite-sphere resistance (``back_face = "sphere-to-cylinder"``; None: no floor)."""

    front: float
    thickness: float
    density: float
    resistance: float
    coefficients: object
    plastic_ratio: float | None = None
    shear_strength: float | None = None
    cylinder_resistance: float | None = None

    @property
    def back(self) -> float:
        return self.front + self.thickness


class LayeredCoefficients:
    """A~(P), B~(P), C~(P) of the layered target (rho and R folded in; module docstring), with
    the ``depth`` breakpoints and ``deep_limit`` that :func:`depth_profile` uses.

    Past ``exit_depth`` (the nose out of the last layer) A~ = B~ = 0 and C~ is the fictitious
    constant ``continuation`` [N] that lets the integration in P end (never reported)."""

    def __init__(self, layers, nose_length: float, diameter: float):
        self.layers = tuple(layers)
        self.nose_length = float(nose_length)
        self.diameter = float(diameter)
        self.exit_depth = self.layers[-1].back + self.nose_length
        first = self.layers[0]
        A8, B8, C8 = _deep(first.coefficients)
        self._deep = (first.density * A8, first.density * B8, first.resistance * C8)
        self.continuation = first.resistance * C8
        brk = {0.0, self.exit_depth}
        for ly in self.layers:
            end = ly.thickness + self.nose_length
            knots = np.asarray(getattr(ly.coefficients, "depth", ()), float)
            brk.update((ly.front + knots[(knots > 0) & (knots < end)]).tolist())
            brk.update([ly.front, ly.back, ly.front + end])
            if ly.plastic_ratio is not None:
                a = 0.5 * self.diameter
                for s in (a, ly.plastic_ratio * a):
                    if 0 < ly.back - s:
                        brk.add(ly.back - s)
        pts = np.array(sorted(b for b in brk if b >= 0))
        keep = np.concatenate([[True], np.diff(pts) > 1e-9 * max(self.exit_depth, self.diameter)])
        self.depth = pts[keep]

    def deep_limit(self):
        return self._deep

    def _groups(self):
        """Layers grouped by everything but their front (one table evaluation per group)."""
        g = getattr(self, "_group_cache", None)
        if g is None:
            d: dict = {}
            for ly in self.layers:
                key = (id(ly.coefficients), ly.thickness, ly.density, ly.resistance, ly.plastic_ratio,
                       ly.cylinder_resistance)
                d.setdefault(key, []).append(ly)
            g = [(lys[0], np.array([ly.front for ly in lys])) for lys in d.values()]
            self._group_cache = g
        return g

    def _sum(self, P, which: str):
        P = np.asarray(P, float)
        flat = P.ravel()
        out = np.zeros(flat.shape)
        span = None
        for ly, fronts in self._groups():
            span = ly.thickness + self.nose_length
            x = flat[None, :] - fronts[:, None]
            inside = (x > 0) & (x < span)
            if not np.any(inside):
                continue
            xs = x[inside]
            coef = ly.coefficients
            if which == "A":
                v = ly.density * np.asarray(coef.A(xs), float)
            elif which == "B":
                v = ly.density * np.asarray(coef.B(xs), float)
            else:
                R = ly.resistance
                if ly.plastic_ratio is not None:
                    R = R * back_face_factor(ly.thickness - xs, 0.5 * self.diameter, ly.plastic_ratio)
                    if ly.cylinder_resistance is not None:
                        R = np.maximum(R, ly.cylinder_resistance)
                v = R * np.asarray(coef.C(xs), float)
            contrib = np.zeros(x.shape)
            contrib[inside] = np.broadcast_to(v, xs.shape)
            out = out + contrib.sum(axis=0)
        out = out.reshape(P.shape)
        if which == "C":
            out = np.where(P >= self.exit_depth, self.continuation, out)
        return out[()]

    def A(self, P):
        return self._sum(P, "A")

    def B(self, P, reading=None):
        return self._sum(P, "B")

    def C(self, P):
        return self._sum(P, "C")


def _deep(coef):
    """Deep-limit (A, B, C) of a layer's coefficients: only the scale of depth_profile's panels
    and of the continuation past the exit depend on it (a plate table may have none)."""
    deep = getattr(coef, "deep_limit", None)
    if callable(deep):
        try:
            return tuple(float(v) for v in deep())
        except (AttributeError, KeyError, ValueError):
            pass
    d = float(coef.diameter)
    return 0.0, 0.0, math.pi * d * d / 4.0


class HalfSpaceDifference:
    """Stand-in plate coefficients from a half-space table (this project's own approximation,
    used only when no plate table is available): X_plate(P) = X(P) - X(P - H) for X = A, B, C
    and P > H, X(P) below.  For C (= integral of n_x, the projected contact area in full contact)
    this is exact: the part of the nose past the back face is out of contact.  For A and B it
    ignores the back face's effect on the potential (the plate table of Part I with phi = 0 at
    x = H replaces it).  ``error(name, P)`` adds the table's errors of both terms."""

    def __init__(self, table, thickness: float):
        self.table = table
        self.thickness = float(thickness)
        self.diameter = float(table.diameter)
        self.nose_length = float(getattr(table, "nose_length", 0.0))
        knots = np.asarray(getattr(table, "depth", ()), float)
        self.depth = np.unique(np.concatenate([knots, knots + self.thickness]))

    def _diff(self, f, P):
        P = np.asarray(P, float)
        back = np.maximum(P - self.thickness, 0.0)
        return (np.asarray(f(P), float) - np.where(P > self.thickness, np.asarray(f(back), float), 0.0))[()]

    def A(self, P):
        return self._diff(self.table.A, P)

    def B(self, P, reading=None):
        return self._diff(lambda x: self.table.B(x, reading) if reading else self.table.B(x), P)

    def C(self, P):
        return self._diff(self.table.C, P)

    def error(self, name, P):
        P = np.asarray(P, float)
        back = np.maximum(P - self.thickness, 0.0)
        e = np.asarray(self.table.error(name, P), float)
        return (e + np.where(P > self.thickness, np.asarray(self.table.error(name, back), float), 0.0))[()]

    def deep_limit(self):
        return self.table.deep_limit()


@dataclass(frozen=True, eq=False)
class PerforationCurve:
    """Per striking velocity (SI): ``perforated``, ``residual_velocity`` (0 where it stops),
    ``depth`` (the final tip depth where it stops, NaN where it perforates), ``exit_time``
    (time until the nose leaves the last layer; NaN where it stops), ``plug`` (the layer index
    whose plug was pushed out, or -1), and ``ballistic_limit_estimate`` = sqrt(G(P_exit))
    (the U_s with w(P_exit) = 0, hole growth only)."""

    velocities: np.ndarray
    perforated: np.ndarray
    residual_velocity: np.ndarray
    depth: np.ndarray
    exit_time: np.ndarray
    plug: np.ndarray
    exit_depth: float
    ballistic_limit_estimate: float
    profile: object = field(repr=False, default=None)
    energy_bounded: np.ndarray | None = None
    resistance_work: float = float("nan")


def _gauss(n=16):
    x, w = np.polynomial.legendre.leggauss(n)
    return x, w


def _exit_time(profile, U, P_exit, edges):
    """t = int_0^P_exit dP / u (Gauss-Legendre per panel; u > 0 for perforating U)."""
    x, w = _gauss()
    t = np.zeros(U.shape)
    for a, b in zip(edges[:-1], edges[1:]):
        P = a + 0.5 * (b - a) * (x + 1.0)
        w2 = profile.speed2(U[:, None], P[None, :])
        with np.errstate(invalid="ignore", divide="ignore"):
            t += 0.5 * (b - a) * np.sum(w[None, :] / np.sqrt(np.maximum(w2, 0.0)), axis=1)
    return t


def resistance_work(coefficients: LayeredCoefficients, upto: float | None = None, panels: int = 256) -> tuple[np.ndarray, np.ndarray]:
    """(P, W(P)): the work of the resistance alone, W(P) = int_0^P sum_k f_k R_k C_k dP [J] (no inertial
    term), on a grid to ``upto`` (default the exit depth).  W(P_exit) is what the plate takes from the
    projectile at the least; Gauss-Legendre (16 points) on the breakpoints refined to P_exit/``panels``."""
    Pe = coefficients.exit_depth if upto is None else float(upto)
    edges = coefficients.depth[coefficients.depth < Pe]
    edges = _refine(np.append(edges, Pe), Pe / float(panels))
    x, w = _gauss()
    a, b = edges[:-1], edges[1:]
    P = a[:, None] + 0.5 * (b - a)[:, None] * (x[None, :] + 1.0)
    C = np.asarray(coefficients.C(P.ravel()), float).reshape(P.shape)
    cell = 0.5 * (b - a) * np.sum(w[None, :] * C, axis=1)
    return edges, np.concatenate([[0.0], np.cumsum(cell)])


def perforation_curve(coefficients: LayeredCoefficients, mass: float, velocities, *, panel_scale: float = 1.0,
                      profile=None) -> PerforationCurve:
    """Residual velocity, depth and exit time for every striking velocity (Part I, eq. (11)
    through the layers; one integration in P for all velocities, see the module docstring).

    No energy from nowhere: V_r is at most sqrt(V_s^2 - 2 W / m), W = :func:`resistance_work` at the
    exit (the resistance's work alone; eq. (11)'s inertial terms only take energy, but a reading of B
    that is not dA/dP, or the stand-in coefficients, could return some); ``energy_bounded`` marks the
    velocities where that bound decides.  ``profile``: the integration in P, if already done to at
    least max(velocities) (reused)."""
    U = np.atleast_1d(np.asarray(velocities, float))
    if np.any(~np.isfinite(U)) or np.any(U <= 0):
        raise ValueError("striking velocities must be positive")
    m = float(mass)
    Pe = coefficients.exit_depth
    if profile is not None and getattr(profile, "U_max", 0.0) >= float(U.max()) and profile.P_end > Pe:
        prof = profile
    else:
        prof = _profile_to_exit(coefficients, m, float(U.max()), panel_scale)
    F_e, G_e = float(prof.F(Pe)), float(prof.G(Pe))
    w_exit = np.exp(-F_e) * (U * U - G_e)
    perforated = w_exit > 0
    Vr = np.where(perforated, np.sqrt(np.maximum(w_exit, 0.0)), 0.0)
    depth = np.full(U.shape, np.nan)
    if np.any(~perforated):
        depth[~perforated] = prof.final_depth(U[~perforated])
    plug = np.full(U.shape, -1)
    edges = coefficients.depth[coefficients.depth <= Pe]
    edges = _refine(edges, Pe / 64.0)
    texit = np.full(U.shape, np.nan)
    for k, ly in enumerate(coefficients.layers):
        if ly.shear_strength is None:
            continue
        Pp, up = _plug_onset(coefficients, prof, m, k, U)
        hit = np.isfinite(Pp) & (np.isnan(depth) | (Pp < depth)) & (plug < 0)
        if not np.any(hit):
            continue
        h = ly.back - Pp[hit]
        m_plug = ly.density * math.pi * coefficients.diameter**2 / 4.0 * h
        v0 = m * up[hit] / (m + m_plug)  # momentum conservation at plug formation (Recht & Ipson 1963)
        # shear work of pushing the plug out: the shear force pi d (h - x) tau falls linearly with the
        # remaining ligament, W = pi d tau h^2 / 2 (the energy balance of Recht & Ipson 1963)
        k_sh = math.pi * coefficients.diameter * ly.shear_strength
        v2 = v0 * v0 - k_sh * h * h / (m + m_plug)
        v_after = np.sqrt(np.maximum(v2, 0.0))
        stuck = v2 <= 0
        x_stop = h - np.sqrt(np.maximum(h * h - (m + m_plug) * v0 * v0 / k_sh, 0.0))
        # this project's own continuation: after the plug the projectile (with its plug) moves on
        # through the remaining layers; with a single layer it leaves at v_after
        Vr_h, t_h = _continue_after_plug(coefficients, m, ly, Pp[hit], v0, k_sh, h, m_plug, v_after, prof, U[hit])
        plug[hit] = k
        perforated = perforated.copy()
        perforated[hit] = Vr_h > 0
        Vr[hit] = Vr_h
        depth[hit] = np.where(Vr_h > 0, np.nan, np.where(stuck, Pp[hit] + x_stop, ly.back))
        texit[hit] = t_h
    # the energy bound (docstring): the resistance alone takes W from the projectile
    Pw, Wc = resistance_work(coefficients)
    W = float(Wc[-1])
    bound2 = U * U - 2.0 * W / m
    nop = plug < 0  # a plug path has its own energy balance (Recht & Ipson); the bound holds there too
    bound = np.sqrt(np.maximum(bound2, 0.0))
    bounded = nop & perforated & (Vr > bound)
    Vr = np.where(bounded, bound, Vr)
    stop = bounded & (bound2 <= 0)
    if np.any(stop):  # the resistance alone stops it: where W(P) = m U^2 / 2
        perforated = perforated & ~stop
        depth[stop] = np.interp(0.5 * m * U[stop] ** 2, Wc, Pw)
    Vr = np.minimum(Vr, U)  # V_r <= V_s also where a plug was pushed out
    ok = perforated & (plug < 0)
    if np.any(ok):
        texit[ok] = _exit_time(prof, U[ok], Pe, edges)
    texit[~perforated] = np.nan
    return PerforationCurve(U, perforated, Vr, depth, texit, plug, Pe, max(math.sqrt(max(G_e, 0.0)), math.sqrt(2.0 * W / m)),
                            prof, bounded, W)


def _profile_to_exit(coefficients, m, U_max, panel_scale):
    """depth_profile integrated at least to the exit depth (its integration ends where
    G > U_max^2: a U_max below the ballistic limit is raised until the profile passes P_exit)."""
    Pe = coefficients.exit_depth
    for _ in range(60):
        prof = depth_profile(coefficients, m, 1.0, 1.0, U_max, panel_scale=panel_scale)
        if prof.P_end > Pe:
            return prof
        U_max = 2.0 * max(U_max, math.sqrt(max(float(prof.G(prof.P_end)), 0.0)))
    raise RuntimeError("eq. (11) in P: the integration did not reach the exit depth")


def _refine(edges, max_len):
    out = [edges[:1]]
    for a, b in zip(edges[:-1], edges[1:]):
        n = max(int(np.ceil((b - a) / max_len)), 1)
        out.append(np.linspace(a, b, n + 1)[1:])
    return np.concatenate(out)


def _plug_onset(coef: LayeredCoefficients, prof, m, k, U):
    """First tip depth P (and speed u there) at which the braking force of eq. (11) reaches the
    ligament's shear capacity pi d (H - P) tau (Chen & Li 2003), per striking velocity; NaN if
    never (before the tip reaches the back face)."""
    ly = coef.layers[k]
    d = coef.diameter
    P = np.linspace(ly.front, ly.back, 801)[1:]
    w = np.maximum(prof.speed2(U[:, None], P[None, :]), 0.0)
    M = m + coef.A(P)
    N = m * (0.5 * coef.B(P) * w + coef.C(P)) / M  # rho and R are folded into A~, B~, C~
    cap = math.pi * d * (ly.back - P) * ly.shear_strength
    moving = w > 0
    cross = (N >= cap[None, :]) & moving
    Pp = np.full(U.shape, np.nan)
    up = np.full(U.shape, np.nan)
    for i in range(U.size):
        j = np.argmax(cross[i])
        if cross[i, j]:
            if j > 0:  # linear interpolation of N - cap between the grid points
                r0 = N[i, j - 1] - cap[j - 1]
                r1 = N[i, j] - cap[j]
                s = r0 / (r0 - r1) if r1 != r0 else 1.0
                Pp[i] = P[j - 1] + s * (P[j] - P[j - 1])
            else:
                Pp[i] = P[j]
            up[i] = math.sqrt(max(float(prof.speed2(U[i], Pp[i])), 0.0))
    return Pp, up


def _continue_after_plug(coef: LayeredCoefficients, m, layer, P_plug, v0, k_sh, h, m_plug, v_after, prof, U):
    """Residual velocity and exit time after a plug formed at ``P_plug``: the time to the plug
    (eq. (11) in P, Gauss), the push-out over the ligament h with v^2 = v0^2 - k_sh (2 h x - x^2)
    / (m + m_plug) (Gauss), then free flight until the nose has left (single layer) or eq. (11)
    in the later layers from their front face on (this project's own continuation; the plug is
    not carried into the next layer)."""
    later = [ly for ly in coef.layers if ly.front > layer.front]
    x, w = _gauss()
    t = np.zeros(U.shape)
    for i in range(U.size):
        b = float(P_plug[i])  # time to the plug
        Ps = 0.5 * b * (x + 1.0)
        t[i] = 0.5 * b * float(np.sum(w / np.sqrt(np.maximum(prof.speed2(U[i], Ps), 1e-300))))
        if v_after[i] > 0:  # push-out time
            xs = 0.5 * h[i] * (x + 1.0)
            v2 = v0[i] ** 2 - k_sh * (2.0 * h[i] * xs - xs * xs) / (m + m_plug[i])
            t[i] += 0.5 * h[i] * float(np.sum(w / np.sqrt(np.maximum(v2, 1e-300))))
    v_after = np.asarray(v_after, float)
    pos = v_after > 0
    if not later:
        tt = np.where(pos, t + coef.nose_length / np.where(pos, v_after, 1.0), np.nan)
        return v_after, tt
    sub = LayeredCoefficients([PlateLayer(ly.front - later[0].front, ly.thickness, ly.density, ly.resistance,
                                          ly.coefficients, ly.plastic_ratio, ly.shear_strength) for ly in later],
                              coef.nose_length, coef.diameter)
    gap = later[0].front - layer.back
    Vr = np.zeros(U.shape)
    tt = np.full(U.shape, np.nan)
    if np.any(pos):
        res = perforation_curve(sub, m, v_after[pos])
        Vr[pos] = res.residual_velocity
        tt[pos] = t[pos] + gap / v_after[pos] + res.exit_time
    return Vr, tt


def residual_velocity(coefficients: LayeredCoefficients, mass: float, velocities):
    """V_r [m/s] per striking velocity (0 where the projectile stops): the optimiser's entry point
    (Part I, eq. (11) through the layers; :func:`perforation_curve`)."""
    return perforation_curve(coefficients, mass, velocities).residual_velocity


@dataclass(frozen=True)
class BallisticLimit:
    """The ballistic limit V_bl [m/s] found by bisection on eq. (11), with its error estimate:
    ``bracket`` (half the final bracket), ``integration`` (change when the integration in P is
    refined, panels halved), ``coefficients`` (sum of the changes when A, B, C are each shifted
    by their error estimate; 0 when the coefficients carry none), ``error`` the sum [m/s]."""

    value: float
    error: float
    bracket: float
    integration: float
    coefficients: float
    tolerance: float
    iterations: int
    bound: str = "exact"
    reason: str = ""
    converged: bool = True


def _bisected(lo0, hi0, lo, hi, tol, n):
    """The midpoint, half-bracket and step count of a finished bisection; RuntimeError when it
    did not converge (200 steps) or one end never moved (the bracket held no sign change)."""
    if hi - lo > tol:
        raise RuntimeError(f"ballistic-limit bisection: bracket {hi - lo:g} m/s > tolerance {tol:g} after {n} steps")
    if n and (lo == lo0 or hi == hi0):
        raise RuntimeError(f"ballistic-limit bisection: no change of 'perforates' inside [{lo0:g}, {hi0:g}] m/s")
    return 0.5 * (lo + hi), 0.5 * (hi - lo), n


def _bisect(coef, mass, lo, hi, tol, panel_scale=1.0, prof=None):
    """Bisection on 'perforates' between lo (stops) and hi: w(P_exit) = exp(-F) (V^2 - G(P_exit)) > 0
    of eq. (11) in P, integrated once (the integration does not depend on V below ``hi``); with a
    plug criterion, the full :func:`perforation_curve` at every step.  ``prof``: that integration,
    if already done (:func:`_profile_to_exit` at ``hi`` and ``panel_scale``)."""
    lo0, hi0 = lo, hi
    if any(ly.shear_strength is not None for ly in coef.layers):
        n = 0
        while hi - lo > tol and n < 200:
            mid = 0.5 * (lo + hi)
            if perforation_curve(coef, mass, [mid], panel_scale=panel_scale).perforated[0]:
                hi = mid
            else:
                lo = mid
            n += 1
        return _bisected(lo0, hi0, lo, hi, tol, n)
    if prof is None:
        prof = _profile_to_exit(coef, float(mass), float(hi), panel_scale)
    Pe = coef.exit_depth
    G_e = float(prof.G(Pe))
    n = 0
    while hi - lo > tol and n < 200:
        mid = 0.5 * (lo + hi)
        if np.exp(-float(prof.F(Pe))) * (mid * mid - G_e) > 0:
            hi = mid
        else:
            lo = mid
        n += 1
    return _bisected(lo0, hi0, lo, hi, tol, n)


def ballistic_limit(coefficients: LayeredCoefficients, mass: float, upper: float, *, tolerance: float = 0.05,
                    lower: float = 0.0, shifted=None) -> BallisticLimit:
    """V_bl by bisection between ``lower`` (must stop) and ``upper`` (must perforate) on the
    dynamics of eq. (11) until the bracket is below ``tolerance`` [m/s]; the error estimate adds
    the integration's and the coefficients' parts (``shifted``: coefficient objects with A, B
    or C shifted by its error estimate, see :class:`semianalytic.penetration.accuracy.ShiftedCoefficients`)."""
    top = perforation_curve(coefficients, mass, [upper])
    if not top.perforated[0]:
        raise ValueError(f"the upper bracket {upper:g} m/s does not perforate")
    V, half, n = _bisect(coefficients, mass, float(lower), float(upper), tolerance, prof=top.profile)
    V2 = _bisect_near(coefficients, mass, V, 50 * tolerance + 5.0, lower, upper, tolerance, panel_scale=0.5)
    integ = abs(V2 - V)
    cpart = 0.0
    for sc in shifted or ():
        cpart += abs(_bisect_near(sc, mass, V, 20.0, lower, 2 * upper, tolerance) - V)
    return BallisticLimit(V, half + integ + cpart, half, integ, cpart, float(tolerance), n)


def _bisect_near(coef, mass, V, width, lower, upper, tol, panel_scale=1.0) -> float:
    """V_bl of a perturbed problem (finer integration, shifted coefficients) by bisection in a
    bracket about the unperturbed ``V`` that doubles until it holds the limit (the perturbation may
    move it by more than ``width``), at most to [lower, upper]; RuntimeError if even that does not."""
    while True:
        lo, hi = max(lower, V - width), min(upper, V + width)
        try:
            return _bisect(coef, mass, lo, hi, tol, panel_scale=panel_scale)[0]
        except RuntimeError:
            if lo <= lower and hi >= upper:
                raise
            width *= 2.0


def _perforates(coef, mass, V, prof, panel_scale=1.0) -> bool:
    return bool(perforation_curve(coef, mass, [V], profile=prof, panel_scale=panel_scale).perforated[0])


def _bisect_curve(coef, mass, lo, hi, tol, prof, panel_scale=1.0):
    """Bisection on :func:`perforation_curve`'s 'perforates' (energy bound and plugs included) between
    lo (stops) and hi (perforates); (midpoint, half bracket, steps)."""
    n = 0
    while hi - lo > tol and n < 200:
        mid = 0.5 * (lo + hi)
        if _perforates(coef, mass, mid, prof, panel_scale):
            hi = mid
        else:
            lo = mid
        n += 1
    return 0.5 * (lo + hi), 0.5 * (hi - lo), n


def _bracket(coef, mass, v_max, prof, panel_scale=1.0, start=None):
    """(lo, hi, status) of the ballistic-limit bracket found from the physics: start at the energy
    estimate (the larger of sqrt(G(P_exit)) of eq. (11) and sqrt(2 W / m) of the resistance's work),
    go down until a velocity stops, up (doubling) until one perforates, at most to ``v_max``.
    status: "ok", "lower" (nothing perforates up to v_max) or "zero" (every velocity perforates)."""
    if start is None:
        start = perforation_curve(coef, mass, [min(1.0, v_max)], profile=prof, panel_scale=panel_scale).ballistic_limit_estimate
    v0 = min(max(float(start), 1e-3), v_max)
    lo = 0.5 * v0
    while _perforates(coef, mass, lo, prof, panel_scale):
        if lo < 1e-6:
            return 0.0, lo, "zero"
        lo *= 0.25
    hi = max(1.25 * v0, 2.0 * lo)
    while True:
        hi = min(hi, v_max)
        if _perforates(coef, mass, hi, prof, panel_scale):
            return lo, hi, "ok"
        if hi >= v_max:
            return lo, v_max, "lower"
        lo, hi = hi, 2.0 * hi


def _limit_value(coef, m, panel_scale=1.0):
    """V_bl without a plug: perforates <=> V^2 > G(P_exit) (eq. (11) in P) and V^2 > 2 W / m (the energy
    bound of :func:`perforation_curve`), so V_bl = max(sqrt G(P_exit), sqrt(2 W / m)) exactly.
    ``panel_scale`` < 1 refines both integrations (the error estimate's second evaluation)."""
    Pe = coef.exit_depth
    _, Wc = resistance_work(coef, panels=int(round(256 / panel_scale)))
    v_w = math.sqrt(2.0 * float(Wc[-1]) / m)
    prof = _profile_to_exit(coef, m, max(v_w, 1.0), panel_scale)
    return max(math.sqrt(max(float(prof.G(Pe)), 0.0)), v_w)


def _closed_limit(coef, m, v_max, tolerance, shifted, v_max_reason):
    V = _limit_value(coef, m)
    if V > v_max:
        return BallisticLimit(v_max, 0.0, 0.0, 0.0, 0.0, float(tolerance), 0, "lower",
                              f"no velocity up to the model's validity limit {v_max:.6g} m/s perforates (eq. (11) gives "
                              f"{V:.6g} m/s, outside it)" + (f"; {v_max_reason}" if v_max_reason else ""))
    integ = abs(_limit_value(coef, m, 0.5) - V)
    cpart = sum(abs(_limit_value(sc, m) - V) for sc in shifted or ())
    return BallisticLimit(V, integ + cpart, 0.0, integ, cpart, float(tolerance), 0, "exact",
                          "V_bl = max(sqrt G(P_exit), sqrt(2 W/m)) of eq. (11) through the plate (no plug: exact, no bisection)")


def ballistic_limit_search(coefficients: LayeredCoefficients, mass: float, v_max: float, *, tolerance: float = 0.05,
                           shifted=None, v_max_reason: str = "") -> BallisticLimit:
    """V_bl found by the model itself: bracketed from the physics (:func:`_bracket`: the lowest
    velocity that stops, widened until one perforates, up to the model's validity limit ``v_max``)
    and bisected on :func:`perforation_curve` until the bracket is below ``tolerance`` [m/s];
    independent of any listed velocities.  If nothing perforates up to ``v_max``, V_bl > v_max is
    returned as a lower bound (``bound = "lower"``, ``reason`` says why).  The error estimate adds the
    integration's part (panels halved) and the coefficients' parts (``shifted``) as
    :func:`ballistic_limit`."""
    m = float(mass)
    v_max = float(v_max)
    if not any(ly.shear_strength is not None for ly in coefficients.layers):
        return _closed_limit(coefficients, m, v_max, tolerance, shifted, v_max_reason)
    prof = _profile_to_exit(coefficients, m, v_max, 1.0)
    lo, hi, status = _bracket(coefficients, m, v_max, prof)
    if status == "lower":
        return BallisticLimit(v_max, 0.0, 0.0, 0.0, 0.0, float(tolerance), 0, "lower",
                              f"no velocity up to the model's validity limit {v_max:.6g} m/s perforates"
                              + (f" ({v_max_reason})" if v_max_reason else ""))
    if status == "zero":
        return BallisticLimit(0.0, hi, hi, 0.0, 0.0, float(tolerance), 0, "exact",
                              "every velocity perforates (the plate offers no resistance)")
    V, half, n = _bisect_curve(coefficients, m, lo, hi, tolerance, prof)
    converged = 2 * half <= tolerance

    def near(coef, scale):
        p2 = _profile_to_exit(coef, m, v_max, scale)
        a, b, st = _bracket(coef, m, v_max, p2, scale, start=V)
        return V if st != "ok" else _bisect_curve(coef, m, a, b, tolerance, p2, scale)[0]

    integ = abs(near(coefficients, 0.5) - V)
    cpart = sum(abs(near(sc, 1.0) - V) for sc in shifted or ())
    return BallisticLimit(V, half + integ + cpart, half, integ, cpart, float(tolerance), n, "exact",
                          "bracketed and bisected on eq. (11) through the plate", converged)


def lambert_jonas(Vs, a: float, p: float, V_bl: float):
    """V_r = a (V_s^p - V_bl^p)^(1/p) for V_s > V_bl, else 0 (Lambert & Jonas 1976)."""
    Vs = np.asarray(Vs, float)
    with np.errstate(invalid="ignore"):
        return np.where(Vs > V_bl, a * np.maximum(Vs**p - V_bl**p, 0.0) ** (1.0 / p), 0.0)[()]


def lambert_jonas_fit(Vs, Vr, V_bl_guess: float | None = None) -> dict | None:
    """Least-squares fit of :func:`lambert_jonas` to (V_s, V_r) pairs (all pairs; V_r = 0 for a
    stop).  Needs at least three perforating pairs; returns {a, p, V_bl_m_s, rms_m_s}, or None
    (too few pairs, or the least-squares solver did not converge: a RuntimeWarning says so)."""
    import warnings

    from scipy.optimize import least_squares

    Vs = np.asarray(Vs, float)
    Vr = np.asarray(Vr, float)
    perf = Vr > 0
    if perf.sum() < 3:
        return None
    if V_bl_guess is None:
        V_bl_guess = float(Vs[~perf].max()) if np.any(~perf) else 0.8 * float(Vs[perf].min())
    V_bl_guess = min(V_bl_guess, 0.999 * float(Vs[perf].min()))
    scale = float(Vs.max())

    def resid(x):
        a, p, vb = x
        return (lambert_jonas(Vs, a, p, vb * scale) - Vr) / scale

    x0 = [1.0, 2.0, V_bl_guess / scale]
    sol = least_squares(resid, x0, bounds=([0.05, 1.0, 0.0], [1.5, 10.0, 1.0]), x_scale=[1.0, 1.0, 0.1])
    if not sol.success:
        warnings.warn(f"Lambert-Jonas fit: least_squares did not converge ({sol.message}); no fit reported",
                      RuntimeWarning, stacklevel=2)
        return None
    a, p, vb = sol.x
    return {"a": float(a), "p": float(p), "V_bl_m_s": float(vb * scale),
            "rms_m_s": float(np.sqrt(np.mean((sol.fun * scale) ** 2)))}
