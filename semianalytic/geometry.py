"""Meridian profiles of bodies of revolution (Part I, section 1.1 and Fig. 5).

A meridian is a chain of analytic segments in the (x, r) half-plane, each a curve
``y(t) = (x(t), r(t))`` for ``t`` in ``[t0, t1]``, traversed from the front (largest x)
towards the rear.  With that orientation the normal pointing out of the body (into the
target material) is ``n = (t_r, -t_x)`` for the unit tangent ``t`` (so ``n_x > 0`` on a
nose; errata item 1b).

Projectiles are described in a body frame with the tip at ``x = 0`` and the body along
``-x``; in the target frame of a penetration to depth ``P`` the tip is at ``x = P``.
Closed bodies (sphere, spheroid, table) are centred on the origin.
"""

from __future__ import annotations

import bisect
import functools
import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from semianalytic.errors import InputError

# ------------------------------------------------------------------------------------
# segments


@dataclass(frozen=True)
class Line:
    """Straight segment from ``p0`` to ``p1``; ``t`` in [0, 1]."""

    p0: tuple[float, float]
    p1: tuple[float, float]
    t0: float = 0.0
    t1: float = 1.0

    def point(self, t):
        t = np.asarray(t, dtype=float)
        return (self.p0[0] + (self.p1[0] - self.p0[0]) * t, self.p0[1] + (self.p1[1] - self.p0[1]) * t)

    def derivative(self, t):
        t = np.asarray(t, dtype=float)
        one = np.ones_like(t)
        return ((self.p1[0] - self.p0[0]) * one, (self.p1[1] - self.p0[1]) * one)

    def displacement(self, t, dt):
        """point(t + dt) - point(t), free of cancellation for small dt."""
        dt = np.asarray(dt, dtype=float)
        return ((self.p1[0] - self.p0[0]) * dt, (self.p1[1] - self.p0[1]) * dt)

    def second_derivative(self, t):
        z = np.zeros_like(np.asarray(t, dtype=float))
        return (z, z)


@dataclass(frozen=True)
class Arc:
    """Circular arc ``(xc + R cos t, rc + R sin t)``, angle ``t`` from ``t0`` to ``t1``."""

    center: tuple[float, float]
    radius: float
    t0: float
    t1: float

    def point(self, t):
        t = np.asarray(t, dtype=float)
        return (self.center[0] + self.radius * np.cos(t), self.center[1] + self.radius * np.sin(t))

    def derivative(self, t):
        t = np.asarray(t, dtype=float)
        return (-self.radius * np.sin(t), self.radius * np.cos(t))

    def displacement(self, t, dt):
        """point(t + dt) - point(t) by the half-angle formulas (no cancellation)."""
        dt = np.asarray(dt, dtype=float)
        s2 = 2.0 * self.radius * np.sin(0.5 * dt)
        mid = t + 0.5 * dt
        return (-s2 * np.sin(mid), s2 * np.cos(mid))

    def second_derivative(self, t):
        t = np.asarray(t, dtype=float)
        return (-self.radius * np.cos(t), -self.radius * np.sin(t))


@dataclass(frozen=True)
class EllipseArc:
    """Ellipse arc ``(xc + a cos t, b sin t)`` (a spheroid meridian for t in [0, pi])."""

    xc: float
    a: float  # semi-axis along x
    b: float  # semi-axis along r
    t0: float = 0.0
    t1: float = math.pi

    def point(self, t):
        t = np.asarray(t, dtype=float)
        return (self.xc + self.a * np.cos(t), self.b * np.sin(t))

    def derivative(self, t):
        t = np.asarray(t, dtype=float)
        return (-self.a * np.sin(t), self.b * np.cos(t))

    def displacement(self, t, dt):
        """point(t + dt) - point(t) by the half-angle formulas (no cancellation)."""
        dt = np.asarray(dt, dtype=float)
        s2 = 2.0 * np.sin(0.5 * dt)
        mid = t + 0.5 * dt
        return (-self.a * s2 * np.sin(mid), self.b * s2 * np.cos(mid))

    def second_derivative(self, t):
        t = np.asarray(t, dtype=float)
        return (-self.a * np.cos(t), -self.b * np.sin(t))


@dataclass(frozen=True, eq=False)
class SplineCurve:
    """Parametric cubic spline through table points, parameter = cumulative chord length."""

    xs: tuple[float, ...]
    rs: tuple[float, ...]
    lo: float | None = None  # a sub-range [lo, hi] of the parameter (one interval between knots)
    hi: float | None = None

    def between_knots(self) -> tuple[SplineCurve, ...]:
        """The curve cut at its knots: one segment per interval, so that panels never
        straddle a knot (where the third derivative jumps).  Built once per curve; the
        pieces share its splines."""
        return self._between_knots

    @cached_property
    def _between_knots(self) -> tuple[SplineCurve, ...]:
        k = self.knots
        pieces = tuple(SplineCurve(self.xs, self.rs, float(a), float(b)) for a, b in zip(k[:-1], k[1:]))
        table = self._scalar_table  # one copy of the coefficients for all pieces (a copy per piece: n^2)
        for p in pieces:
            p.__dict__["_splines"] = self._splines  # same curve: share the fitted splines
            p.__dict__["_scalar_table"] = table
        return pieces

    @cached_property
    def _splines(self):
        from scipy.interpolate import CubicSpline  # imported when a table shape needs it (start-up time)

        x, r = np.array(self.xs), np.array(self.rs)
        s = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(x), np.diff(r)))])
        return s, CubicSpline(s, x), CubicSpline(s, r)

    @property
    def t0(self) -> float:
        return 0.0 if self.lo is None else self.lo

    @property
    def t1(self) -> float:
        return float(self._splines[0][-1]) if self.hi is None else self.hi

    @property
    def knots(self) -> np.ndarray:
        return self._splines[0]

    @cached_property
    def _scalar_table(self):
        """Knots and, per interval, the power-basis coefficients of x and r as Python floats."""
        s, sx, sr = self._splines
        return [float(v) for v in sx.x], sx.c.T.tolist(), sr.c.T.tolist()

    def _at_scalar(self, t: float, nu: int):
        """Both splines (nu = 0) or their first derivatives (nu = 1) at one parameter, as 0-d
        arrays: scipy's PPoly evaluation (its interval search and its sum of the terms from the
        lowest power up) in Python floats, the same numbers without the ~5 us of a PPoly call
        (this project's own shortcut: the layouts of a table nose and their root searches
        evaluate the spline at single points hundreds of times per depth; on arrays of panel points
        the compiled geometry does the same in C, spline_eval of semianalytic/bem/_ring.c)."""
        knots, cx, cr = self._scalar_table
        i = min(max(bisect.bisect_right(knots, t) - 1, 0), len(knots) - 2)
        s = t - knots[i]
        out = []
        for c0, c1, c2, c3 in (cx[i], cr[i]):
            if nu == 0:
                z2 = s * s
                out.append(np.asarray(0.0 + c3 + c2 * s + c1 * z2 + c0 * (z2 * s)))
            else:
                out.append(np.asarray(0.0 + c2 + c1 * s * 2.0 + c0 * (s * s) * 3.0))
        return tuple(out)

    def point(self, t):
        if isinstance(t, float) and t == t:
            return self._at_scalar(t, 0)
        _, sx, sr = self._splines
        return (sx(t), sr(t))

    def derivative(self, t):
        if isinstance(t, float) and t == t:
            return self._at_scalar(t, 1)
        _, sx, sr = self._splines
        return (sx(t, 1), sr(t, 1))

    def displacement(self, t, dt):
        """point(t + dt) - point(t) (by difference: splines are not graded finely)."""
        x0, r0 = self.point(t)
        x1, r1 = self.point(np.asarray(t) + np.asarray(dt))
        return (x1 - x0, r1 - r0)

    def second_derivative(self, t):
        _, sx, sr = self._splines
        return (sx(t, 2), sr(t, 2))


@dataclass(frozen=True)
class PowerCurve:
    """Power-law nose meridian r = R (xi/L)^n, xi = distance back from the tip (this
    project's own parametrisation: t = r/R in [0, 1], so x = -L t^(1/n), r = R t).

    With t = r/R the speed |dy/dt| stays >= R at the tip, where dr/dxi is infinite for n < 1
    (the tip is blunt: the tangent is normal to the axis); x(t) = -L t^(1/n) is then not
    analytic at t = 0 (unless 1/n is an integer), which the BEM layout grades towards."""

    length: float  # L_h
    radius: float  # R = d/2
    exponent: float  # n in (0, 1]
    t0: float = 0.0
    t1: float = 1.0

    @property
    def singular_at_t0(self) -> bool:
        """x(t) is not analytic at the tip (1/n not an integer): the BEM grades panels there."""
        p = 1.0 / self.exponent
        return abs(p - round(p)) > 1e-12

    def point(self, t):
        t = np.asarray(t, dtype=float)
        return (-self.length * t ** (1.0 / self.exponent), self.radius * t)

    def derivative(self, t):
        t = np.asarray(t, dtype=float)
        p = 1.0 / self.exponent
        with np.errstate(divide="ignore", invalid="ignore"):
            dx = np.where(t > 0, -self.length * p * t ** np.maximum(p - 1.0, 0.0), -self.length if p == 1.0 else 0.0)
        return (dx, self.radius * np.ones_like(t))

    def displacement(self, t, dt):
        """point(t + dt) - point(t) (by difference: panels near the tip are anchored at t = 0,
        where the difference is the point itself)."""
        t, dt = np.broadcast_arrays(np.asarray(t, dtype=float), np.asarray(dt, dtype=float))
        p = 1.0 / self.exponent
        with np.errstate(divide="ignore", invalid="ignore"):
            # t^p expm1(p log1p(dt/t)): no cancellation for small dt at the shoulder or a cut
            rel = np.where(t > 0, t**p * np.expm1(p * np.log1p(dt / np.where(t > 0, t, 1.0))), 0.0)
        x = np.where(t == 0.0, -self.length * np.abs(dt) ** p * np.sign(dt), -self.length * rel)
        return (x, self.radius * dt)

    def second_derivative(self, t):
        t = np.asarray(t, dtype=float)
        p = 1.0 / self.exponent
        with np.errstate(divide="ignore", invalid="ignore"):
            ddx = np.where(t > 0, -self.length * p * (p - 1.0) * t ** (p - 2.0), 0.0 if p != 2.0 else -2.0 * self.length)
        return (ddx, np.zeros_like(t))


@dataclass(frozen=True)
class BezierCurve:
    """Nose meridian r(xi) = R sum_k c_k C(N, k) t^k (1 - t)^(N - k), xi = t L back from the tip,
    t in [0, 1]: the Bezier curve of the control points (k L / N, c_k R), k = 0..N (control
    abscissae equally spaced, so x is linear in t).  A Bernstein polynomial keeps the shape of
    its control polygon (variation diminishing: Farin, Curves and Surfaces for CAGD, 5th ed.,
    2002, sections 5.4 and 6.4; Lorentz, Bernstein Polynomials, 1953, ch. 1.7): a monotone
    polygon gives a monotone meridian, a concave one a concave r(xi) (a convex nose); control
    points on a straight line give that line exactly."""

    length: float  # L_h
    radius: float  # R = d/2
    weights: tuple[float, ...]  # c_0 = 0 .. c_N = 1 (fractions of R)
    t0: float = 0.0
    t1: float = 1.0

    @cached_property
    def _power(self) -> np.ndarray:
        """Coefficients a_j of r(t) = sum_j a_j t^j (power basis, [m])."""
        from math import comb

        N = len(self.weights) - 1
        a = np.zeros(N + 1)
        for k, c in enumerate(self.weights):  # C(N,k) t^k (1-t)^(N-k) = sum_i C(N,k) C(N-k,i) (-1)^i t^(k+i)
            for i in range(N - k + 1):
                a[k + i] += c * comb(N, k) * comb(N - k, i) * (-1) ** i
        return self.radius * a

    def _r(self, t, order: int = 0):
        a = np.polynomial.polynomial.polyder(self._power, order) if order else self._power
        return np.polynomial.polynomial.polyval(np.asarray(t, dtype=float), a)

    def point(self, t):
        t = np.asarray(t, dtype=float)
        return (-self.length * t, self._r(t))

    def derivative(self, t):
        t = np.asarray(t, dtype=float)
        return (-self.length * np.ones_like(t), self._r(t, 1))

    def displacement(self, t, dt):
        """point(t + dt) - point(t) without cancellation: r by the divided difference
        sum_j a_j ((t + dt)^j - t^j) / dt = sum_j a_j h_j, h_j = (t + dt) h_(j-1) + t^(j-1)."""
        t, dt = np.broadcast_arrays(np.asarray(t, dtype=float), np.asarray(dt, dtype=float))
        u = t + dt
        h, tp, acc = np.zeros_like(t), np.ones_like(t), np.zeros_like(t)
        for a in self._power[1:]:
            h = u * h + tp  # h_j
            tp = tp * t
            acc = acc + a * h
        return (-self.length * dt, acc * dt)

    def second_derivative(self, t):
        t = np.asarray(t, dtype=float)
        return (np.zeros_like(t), self._r(t, 2))


Segment = Line | Arc | EllipseArc | SplineCurve | PowerCurve | BezierCurve


@functools.cache
def _leggauss(n: int):
    return np.polynomial.legendre.leggauss(n)


def segment_arc_length(seg: Segment, ta: float, tb: float) -> float:
    """Arc length of a segment between parameters ``ta`` and ``tb`` (24-point Gauss-Legendre:
    the measure the BEM layout and the memory guard count panels by)."""
    u, w = _leggauss(24)
    t = 0.5 * (ta + tb) + 0.5 * (tb - ta) * u
    dx, dr = seg.derivative(t)
    return float(0.5 * abs(tb - ta) * np.sum(w * np.hypot(dx, dr)))


def _gauss_integrate(segment: Segment, f, n: int = 48) -> float:
    """Integrate ``f(x, r, dx, dr)`` dt over a segment with composite Gauss-Legendre."""
    u, w = _leggauss(n)
    if isinstance(segment, SplineCurve):
        k = np.asarray(segment.knots)
        inner = k[(k > segment.t0) & (k < segment.t1)]
        edges = np.concatenate([[segment.t0], inner, [segment.t1]])
    else:
        edges = np.linspace(segment.t0, segment.t1, 5)
    total = 0.0
    for a, b in zip(edges[:-1], edges[1:]):
        t = 0.5 * (a + b) + 0.5 * (b - a) * u
        x, r = segment.point(t)
        dx, dr = segment.derivative(t)
        total += 0.5 * (b - a) * float(np.sum(w * f(x, r, dx, dr)))
    return total


# ------------------------------------------------------------------------------------
# meridians


@dataclass(frozen=True)
class Meridian:
    """A chain of segments traversed from the front towards the rear.

    ``closed`` meridians start and end on the axis (r = 0) and bound a body.
    """

    segments: tuple[Segment, ...]
    closed: bool = True

    def start(self) -> tuple[float, float]:
        s = self.segments[0]
        x, r = s.point(s.t0)
        return float(x), float(r)

    def end(self) -> tuple[float, float]:
        s = self.segments[-1]
        x, r = s.point(s.t1)
        return float(x), float(r)

    def arc_length(self) -> float:
        return sum(_gauss_integrate(s, lambda x, r, dx, dr: np.hypot(dx, dr)) for s in self.segments)

    def volume(self) -> float:
        """V = pi * integral r^2 (-dx) along the meridian (exact to quadrature round-off)."""
        return math.pi * sum(_gauss_integrate(s, lambda x, r, dx, dr: -(r**2) * dx) for s in self.segments)

    def surface_area(self) -> float:
        return 2 * math.pi * sum(_gauss_integrate(s, lambda x, r, dx, dr: r * np.hypot(dx, dr)) for s in self.segments)

    def projected_area(self) -> float:
        """C = integral of n_x dS = pi * integral 2 r (-dr)... over the part with n_x > 0."""
        return 2 * math.pi * sum(
            _gauss_integrate(s, lambda x, r, dx, dr: np.maximum(r * dr, 0.0)) for s in self.segments
        )

    def corners(self, tol: float = 1e-9) -> list[float]:
        """Turning angle (rad) at each joint between consecutive segments."""
        out = []
        for a, b in zip(self.segments[:-1], self.segments[1:]):
            ta = np.array(a.derivative(a.t1), dtype=float)
            tb = np.array(b.derivative(b.t0), dtype=float)
            ang = math.atan2(ta[0] * tb[1] - ta[1] * tb[0], float(ta @ tb))
            out.append(ang if abs(ang) > tol else 0.0)
        return out

    def axis_angles(self) -> tuple[float, float]:
        """Angle between the tangent and the axis-normal at the two axis ends (0 = smooth pole)."""

        def angle(seg, t, sign):
            dx, dr = (float(v) for v in seg.derivative(t))
            return abs(math.atan2(sign * dx, abs(dr))) if (dx or dr) else 0.0

        s0, s1 = self.segments[0], self.segments[-1]
        return angle(s0, s0.t0, 1.0), angle(s1, s1.t1, 1.0)

    def sample(self, n_per_segment: int = 50) -> np.ndarray:
        """Points along the meridian, shape (m, 2), for plots and meshes."""
        pts = []
        for s in self.segments:
            t = np.linspace(s.t0, s.t1, n_per_segment)
            x, r = s.point(t)
            pts.append(np.column_stack([x, r]))
        return np.vstack(pts)


# ------------------------------------------------------------------------------------
# noses (body frame: tip at the origin, body along -x, shoulder at (-L_h, d/2))


@dataclass(frozen=True)
class Nose:
    """A nose profile from the tip (0, 0) to the shoulder (-length, diameter/2).

    ``kind`` names the shape; ``segments`` trace it; ``length`` is L_h.
    """

    kind: str
    diameter: float
    length: float
    segments: tuple[Segment, ...]
    parameters: dict = field(default_factory=dict, compare=False)

    @property
    def radius(self) -> float:
        return 0.5 * self.diameter

    @property
    def depth_unit(self) -> float:
        """The unit of a table's depth range (``max_depth_nose_lengths``): L_h, or the radius
        where the nose is shorter than its radius (flat, short blunted noses), so that the
        deep limit is always reached within the same number of calibres."""
        return max(self.length, self.radius)

    def meridian(self) -> Meridian:
        return Meridian(self.segments, closed=False)

    def volume(self) -> float:
        """Volume of the nose (between tip and shoulder)."""
        return self.meridian().volume()

    def tip_half_angle(self) -> float:
        """Half-angle of the tip (pi/2 for a flat or spherical tip)."""
        s = self.segments[0]
        dx, dr = (float(v) for v in s.derivative(s.t0))
        return math.atan2(abs(dr), abs(dx))

    def corners(self, tol: float = 1e-9) -> list[tuple[float, float, float]]:
        """Corners of the nose found from its geometry (tangent jumps), tip to shoulder:
        (x, r, turning angle in rad, > 0 convex) in the body frame (tip at x = 0, body
        along -x).  A conical tip (half-angle below 90 deg) counts as a corner with its
        turning angle pi/2 - half-angle; the shoulder counts where the last tangent is not
        along the shank."""
        out = []
        half = self.tip_half_angle()
        if half < 0.5 * math.pi - tol:
            out.append((0.0, 0.0, 0.5 * math.pi - half))
        turning = Meridian(self.segments, closed=False).corners(tol) if len(self.segments) > 1 else []
        for seg, ang in zip(self.segments[:-1], turning):
            if ang:
                x, r = seg.point(seg.t1)
                out.append((float(x), float(r), ang))
        seg = self.segments[-1]
        dx, dr = (float(v) for v in seg.derivative(seg.t1))
        shoulder = math.atan2(dr, -dx)  # from the last tangent to the shank direction (-1, 0)
        if abs(shoulder) > tol:
            out.append((-self.length, self.radius, shoulder))
        return out

    @property
    def corner_positions(self) -> tuple[float, ...]:
        """Axial distances back from the tip [m] of the corners (:meth:`corners`): the
        depths P at which a corner enters the target, where A, B, C change character."""
        return tuple(-x for x, _, _ in self.corners())


def ogive_nose(diameter: float, crh: float, meplat_diameter: float = 0.0, tip_radius: float = 0.0) -> Nose:
    """Tangent ogive of caliber radius head psi = s/d (Fig. 5: psi = 3; psi = 0.5 is a hemisphere).

    Arc of radius s = psi d centred at (-L_h, R - s), nose length L_h = d sqrt(psi - 1/4).
    ``meplat_diameter`` > 0 truncates it with a flat face of that diameter (a corner at its
    edge); ``tip_radius`` > 0 blunts it with a sphere tangent to the arc.
    """
    if not diameter > 0:
        raise InputError("projectile.diameter", "must be positive")
    if not crh >= 0.5:
        raise InputError("projectile.crh", f"must be >= 0.5 for a tangent ogive; got {crh!r}")
    R = 0.5 * diameter
    s = crh * diameter
    _check_tip_options(diameter, meplat_diameter, tip_radius)
    if meplat_diameter > 0:
        rm = 0.5 * meplat_diameter
        L = math.sqrt(max(s * s - (s - R + rm) ** 2, 0.0))
        theta = math.atan2(s - R + rm, L)
        segs = (Line((0.0, 0.0), (0.0, rm)), Arc(center=(-L, R - s), radius=s, t0=theta, t1=0.5 * math.pi))
        return Nose("ogive", diameter, L, segs, {"crh": crh, "meplat_diameter": meplat_diameter})
    L = math.sqrt(max(2 * s * R - R * R, 0.0))
    if tip_radius > 0:
        b = tip_radius
        if not b < R:
            raise InputError("projectile.tip_radius", f"must be below d/2 = {R * 1e3:.4g} mm for an ogive")
        rc = R - s  # ogive centre (-L, rc); the cap's centre (xb, 0) lies s - b from it
        xb = -L + math.sqrt((s - b) ** 2 - rc * rc)
        theta = math.atan2(-rc, xb + L)  # direction from the ogive centre through the cap's centre
        shift = -(xb + b)  # tip to x = 0
        cap = Arc(center=(xb + shift, 0.0), radius=b, t0=0.0, t1=theta)
        arc = Arc(center=(-L + shift, rc), radius=s, t0=theta, t1=0.5 * math.pi)
        return Nose("ogive", diameter, L - shift, (cap, arc), {"crh": crh, "tip_radius": tip_radius})
    theta_tip = math.atan2(s - R, L)
    arc = Arc(center=(-L, R - s), radius=s, t0=theta_tip, t1=0.5 * math.pi)
    kind = "sphere" if crh == 0.5 else "ogive"
    return Nose(kind, diameter, L, (arc,), {"crh": crh})


def power_nose(diameter: float, exponent: float, nose_length: float) -> Nose:
    """Power-law nose r = (d/2) (xi/L_h)^n, xi measured back from the tip, 0 < n <= 1
    (n = 1: the cone of half-angle atan(d/(2 L_h)); n = 1/2: the paraboloid).  Its volume is
    pi (d/2)^2 L_h / (2n + 1) (the integral of pi r^2 dxi)."""
    if not diameter > 0:
        raise InputError("projectile.diameter", "must be positive")
    if exponent is None or not (math.isfinite(exponent) and 0 < exponent <= 1):
        raise InputError("projectile.exponent", f"must lie in (0, 1] (r = (d/2) (x/L_h)^n); got {exponent!r}")
    if nose_length is None or not (math.isfinite(nose_length) and nose_length > 0):
        raise InputError("projectile.nose_length", f"must be a positive length (e.g. '11.8 mm'); got {nose_length!r} m")
    curve = PowerCurve(nose_length, 0.5 * diameter, float(exponent))
    return Nose("power", diameter, nose_length, (curve,), {"exponent": exponent, "nose_length": nose_length})


def spline_stations(control_radii, nose_length: float, diameter: float) -> np.ndarray:
    """The control points (xi, r) of a spline nose: the tip (0, 0), (k L_h / (m + 1), c_k d/2)
    for k = 1..m, the shoulder (L_h, d/2) (:func:`spline_nose`)."""
    c = np.asarray(control_radii, dtype=float)
    xi = np.linspace(0.0, nose_length, len(c) + 2)
    return np.column_stack([xi, 0.5 * diameter * np.concatenate([[0.0], c, [1.0]])])


def spline_nose(diameter: float, control_radii, nose_length: float, field_name: str = "projectile.control_radii") -> Nose:
    """Free-form nose from a few control points (this project's own shape family):
    the control radii c_1..c_m (fractions of d/2, each in (0, 1]) at the m equally spaced
    stations xi_k = k L_h / (m + 1) back from the tip, with the tip (0, 0) and the shoulder
    (L_h, d/2) as end points, define the Bezier curve (one-interval clamped B-spline) of degree
    m + 1, :class:`BezierCurve`: it starts at the tip and ends at the shoulder, and lies inside
    its control polygon.

    Monotone and convex at the door (this project's own rule, sufficient by the variation-
    diminishing property): the control radii increase (0 < c_1 < .. < c_m <= 1; c_m = 1: a shoulder
    tangent to the shank) and the polygon's
    increments c_(k+1) - c_k never increase from the tip to the shoulder; else InputError naming
    ``field_name`` and the control radius at fault (0-based index)."""
    if not diameter > 0:
        raise InputError("projectile.diameter", "must be positive")
    if nose_length is None or not (math.isfinite(nose_length) and nose_length > 0):
        raise InputError("projectile.nose_length", f"must be a positive length (e.g. '11.8 mm'); got {nose_length!r} m")
    c = np.asarray(control_radii if control_radii is not None else [], dtype=float)
    if c.ndim != 1 or not 1 <= len(c) <= 16:
        raise InputError(field_name, f"give 1 to 16 radii (fractions of d/2 in (0, 1]), e.g. [0.45, 0.75, 0.92]; got {c.size}")
    for i, ci in enumerate(c):
        if not (math.isfinite(ci) and 0.0 < ci <= 1.0):
            raise InputError(field_name, f"index {i}: {float(ci)!r} must lie in (0, 1] (a fraction of the radius d/2; "
                                         "1 for the last one: a shoulder tangent to the shank)")
    full = np.concatenate([[0.0], c, [1.0]])
    for i in range(1, len(c)):
        if not full[i + 1] > full[i]:
            raise InputError(field_name, f"index {i}: {full[i + 1]:g} is not above the previous radius {full[i]:g}: "
                                         "the meridian must widen monotonically from the tip to the shoulder")
    steps = np.diff(full)
    for i in range(1, len(steps)):
        if steps[i] > steps[i - 1] * (1 + 1e-12):
            raise InputError(field_name, f"index {min(i, len(c)) - 1}: the control polygon is not convex there (the "
                                         f"radius grows by {steps[i - 1]:.4g} of d/2 before station {i} and by "
                                         f"{steps[i]:.4g} after it: the increments must not increase towards the shoulder)")
    curve = BezierCurve(float(nose_length), 0.5 * diameter, tuple(float(v) for v in full))
    return Nose("spline", diameter, float(nose_length), (curve,),
                {"control_radii": [float(v) for v in c], "nose_length": float(nose_length)})


def _check_tip_options(diameter: float, meplat_diameter: float, tip_radius: float) -> None:
    if meplat_diameter and tip_radius:
        raise InputError("projectile.tip_radius", "give either 'meplat_diameter' (flat tip) or 'tip_radius' (rounded tip), not both")
    if not 0 <= meplat_diameter < diameter:
        raise InputError("projectile.meplat_diameter", f"must lie in [0, d) = [0, {diameter * 1e3:.4g} mm); got {meplat_diameter * 1e3:.4g} mm")  # noqa: E501
    if not tip_radius >= 0:
        raise InputError("projectile.tip_radius", f"must not be negative; got {tip_radius * 1e3:.4g} mm")


def sphere_nose(diameter: float) -> Nose:
    """Hemispherical nose (psi = 0.5 in Fig. 5): L_h = d/2."""
    return ogive_nose(diameter, 0.5)


def cone_nose(diameter: float, half_angle: float, meplat_diameter: float = 0.0, tip_radius: float = 0.0) -> Nose:
    """Conical nose of tip half-angle ``half_angle`` (rad): L_h = (d/2)/tan(half_angle).

    ``meplat_diameter`` > 0: truncated cone with a flat face of that diameter;
    ``tip_radius`` > 0: the apex replaced by a sphere of that radius tangent to the cone.
    """
    if not 0 < half_angle < 0.5 * math.pi:
        raise InputError("projectile.half_angle", "must lie strictly between 0 and 90 deg")
    _check_tip_options(diameter, meplat_diameter, tip_radius)
    R = 0.5 * diameter
    if meplat_diameter > 0:
        rm = 0.5 * meplat_diameter
        L = (R - rm) / math.tan(half_angle)
        segs = (Line((0.0, 0.0), (0.0, rm)), Line((0.0, rm), (-L, R)))
        return Nose("cone", diameter, L, segs, {"half_angle": half_angle, "meplat_diameter": meplat_diameter})
    L = R / math.tan(half_angle)
    if tip_radius > 0:
        b = tip_radius
        sb, cb = math.sin(half_angle), math.cos(half_angle)
        if not b * cb < R:
            raise InputError(
                "projectile.tip_radius",
                f"too large for this cone: the sphere must touch the cone before the shoulder (tip_radius < {R / cb * 1e3:.4g} mm)",
            )
        xc = -b / sb  # sphere centre behind the apex (apex at 0)
        shift = -(xc + b)
        tx, tr = -(b / sb) * cb * cb, b * cb  # tangent point
        cap = Arc(center=(xc + shift, 0.0), radius=b, t0=0.0, t1=0.5 * math.pi - half_angle)
        line = Line((tx + shift, tr), (-L + shift, R))
        return Nose("cone", diameter, L - shift, (cap, line), {"half_angle": half_angle, "tip_radius": tip_radius})
    return Nose("cone", diameter, L, (Line((0.0, 0.0), (-L, R)),), {"half_angle": half_angle})


def flat_nose(diameter: float, corner_radius: float = 0.0) -> Nose:
    """Flat (blunt) nose: a disk of radius d/2 - rc, then a quarter-circle corner of radius rc."""
    R = 0.5 * diameter
    if not 0 <= corner_radius <= R:
        raise InputError("projectile.corner_radius", "must lie between 0 and d/2")
    segs: list[Segment] = []
    if corner_radius < R:
        segs.append(Line((0.0, 0.0), (0.0, R - corner_radius)))
    if corner_radius > 0:
        segs.append(Arc((-corner_radius, R - corner_radius), corner_radius, 0.0, 0.5 * math.pi))
    return Nose("flat", diameter, corner_radius, tuple(segs), {"corner_radius": corner_radius})


def table_nose(points: list[tuple[float, float]], diameter: float, field_name: str = "projectile.points") -> Nose:
    """Nose through user points (x back from the tip, r), from (0, 0) to (L_h, d/2).

    The points must form a simple meridian: x non-decreasing, r > 0 after the tip, the
    last radius equal to d/2.  A parametric cubic spline joins them.
    """
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 3:
        raise InputError(field_name, f"needs at least three [x, r] pairs (tip, ..., shoulder); got {len(pts)}")

    def bad(i: int, why: str) -> InputError:
        x, r = pts[i]
        return InputError(field_name, f"index {i} ([{x * 1e3:.6g}, {r * 1e3:.6g}] mm): {why}")

    for i in range(len(pts)):
        if not np.all(np.isfinite(pts[i])):
            raise bad(i, "must be finite numbers")
    if abs(pts[0, 0]) > 0 or abs(pts[0, 1]) > 0:
        raise bad(0, "the first point is the tip and must be [0, 0] (on the axis)")
    for i in range(1, len(pts)):
        if pts[i, 0] < pts[i - 1, 0]:
            raise bad(i, "x (distance back from the tip) decreases: x must increase from tip to shoulder")
        if pts[i, 0] == pts[i - 1, 0] and pts[i, 1] == pts[i - 1, 1]:
            raise bad(i, "repeats the previous point")
        if pts[i, 1] < 0:
            raise bad(i, "radius r < 0")
        if pts[i, 1] == 0:
            raise bad(i, "radius must be positive after the tip (the meridian would touch the axis again)")
        if pts[i, 1] > 0.5 * diameter * (1 + 1e-9):
            raise bad(i, f"radius exceeds half the diameter d/2 = {0.5 * diameter * 1e3:.6g} mm")
    if not math.isclose(pts[-1, 1], 0.5 * diameter, rel_tol=1e-6):
        raise bad(len(pts) - 1, f"the last point is the shoulder: its radius must be d/2 = {0.5 * diameter * 1e3:.6g} mm")
    if np.any(np.diff(pts[:, 0]) == 0) and np.all(np.diff(pts[:, 0]) == 0):
        raise bad(len(pts) - 1, "all points have the same x: the nose has no length")
    spline = SplineCurve(tuple(-pts[:, 0]), tuple(pts[:, 1]))
    knots = spline.knots
    for i in range(len(pts) - 1):
        t = np.linspace(knots[i], knots[i + 1], 41)
        x, r = spline.point(t)
        if np.any(np.diff(x) > 1e-9 * diameter) or np.any(r[1:] <= 0) or np.any(r > 0.5 * diameter * (1 + 1e-6)):
            raise bad(i + 1, "the spline through the points folds back or crosses itself before this point "
                             "(self-intersecting meridian); add points or smooth the table")
    return Nose("table", diameter, float(pts[-1, 0]), (spline,), {"points": pts.tolist()})


# ------------------------------------------------------------------------------------
# projectile and bodies


@dataclass(frozen=True)
class Projectile:
    """A nose on a cylindrical shank (Fig. 5).  Lengths in m, density in kg/m^3."""

    nose: Nose
    shank_length: float
    density: float | None = None
    mass_override: float | None = None

    @property
    def diameter(self) -> float:
        return self.nose.diameter

    @property
    def nose_length(self) -> float:
        return self.nose.length

    @property
    def length(self) -> float:
        """L = L_c + L_h."""
        return self.shank_length + self.nose.length

    def meridian(self) -> Meridian:
        """Closed meridian: nose, shank, flat rear face."""
        R = self.nose.radius
        segs = list(self.nose.segments)
        if self.shank_length > 0:
            segs.append(Line((-self.nose.length, R), (-self.length, R)))
        segs.append(Line((-self.length, R), (-self.length, 0.0)))
        return Meridian(tuple(segs), closed=True)

    def volume(self) -> float:
        return self.meridian().volume()

    @property
    def mass(self) -> float:
        """Measured mass if given, else density times volume."""
        if self.mass_override is not None:
            return self.mass_override
        if self.density is None:
            raise InputError("projectile.density", "needed for the projectile mass (or give 'mass')")
        return self.density * self.volume()


def sphere_body(diameter: float) -> Meridian:
    """Sphere of the given diameter, centred on the origin."""
    if not diameter > 0:
        raise InputError("body.diameter", "must be positive")
    return Meridian((Arc((0.0, 0.0), 0.5 * diameter, 0.0, math.pi),))


def spheroid_body(length: float, diameter: float) -> Meridian:
    """Spheroid with semi-axes length/2 (along x) and diameter/2, centred on the origin."""
    if not (length > 0 and diameter > 0):
        raise InputError("body.length", "length and diameter must be positive")
    return Meridian((EllipseArc(0.0, 0.5 * length, 0.5 * diameter),))


def cylinder_body(length: float, diameter: float) -> Meridian:
    """Flat-ended circular cylinder (two 90 deg edges), centred on the origin."""
    if not (length > 0 and diameter > 0):
        raise InputError("body.length", "length and diameter must be positive")
    h, R = 0.5 * length, 0.5 * diameter
    return Meridian((Line((h, 0.0), (h, R)), Line((h, R), (-h, R)), Line((-h, R), (-h, 0.0))))


def double_cone_body(length: float, diameter: float) -> Meridian:
    """Two equal cones base to base (conical tips at x = +-length/2, an edge at x = 0)."""
    if not (length > 0 and diameter > 0):
        raise InputError("body.length", "length and diameter must be positive")
    h, R = 0.5 * length, 0.5 * diameter
    return Meridian((Line((h, 0.0), (0.0, R)), Line((0.0, R), (-h, 0.0))))


def table_body(points: list[tuple[float, float]], field_name: str = "body.points") -> Meridian:
    """Closed meridian through user points from one axis point to the other."""
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 4:
        raise InputError(field_name, "needs at least four [x, r] pairs")
    if pts[0, 1] != 0 or pts[-1, 1] != 0:
        raise InputError(field_name, "must start and end on the axis (r = 0)")
    if np.any(pts[1:-1, 1] <= 0):
        raise InputError(field_name, "radius must be positive between the two axis points")
    if np.any(np.diff(pts[:, 0]) >= 0) and np.any(np.diff(pts[:, 0]) <= 0):
        if not (np.all(np.diff(pts[:, 0]) <= 0) or np.all(np.diff(pts[:, 0]) >= 0)):
            raise InputError(field_name, "x must change monotonically: the table is not a simple meridian")
    if pts[0, 0] < pts[-1, 0]:
        pts = pts[::-1]
    return Meridian((SplineCurve(tuple(pts[:, 0]), tuple(pts[:, 1])),))


@dataclass(frozen=True)
class NoseKind:
    """A registered nose kind: ``build(section) -> Nose`` from the ``[projectile]`` keys ``keys``."""

    name: str
    build: object
    keys: tuple[str, ...] = ()


NOSE_KINDS: dict[str, NoseKind] = {}
"""The nose kinds of ``[projectile] nose``, by name: the case schema's choices and the keys each
kind uses are read from here (:func:`register_nose`)."""


def register_nose(name: str, *, keys: tuple[str, ...] = ()):
    """Decorator: ``build(section) -> Nose`` is the nose kind ``name``, using the section keys ``keys``
    (any other nose key given with it is an error).  Register before :mod:`semianalytic.case` is imported."""
    def decorate(build):
        NOSE_KINDS[name] = NoseKind(name, build, tuple(keys))
        return build

    return decorate


def _tip(sec) -> tuple[float, float]:
    return getattr(sec, "meplat_diameter", None) or 0.0, getattr(sec, "tip_radius", None) or 0.0


@register_nose("ogive", keys=("crh", "meplat_diameter", "tip_radius"))
def _ogive_from_section(sec) -> Nose:
    return ogive_nose(sec.diameter, sec.crh, *_tip(sec))


@register_nose("sphere")
def _sphere_from_section(sec) -> Nose:
    return ogive_nose(sec.diameter, 0.5)


@register_nose("cone", keys=("half_angle", "meplat_diameter", "tip_radius"))
def _cone_from_section(sec) -> Nose:
    return cone_nose(sec.diameter, sec.half_angle, *_tip(sec))


@register_nose("flat", keys=("corner_radius",))
def _flat_from_section(sec) -> Nose:
    return flat_nose(sec.diameter, sec.corner_radius or 0.0)


@register_nose("table", keys=("points", "points_unit"))
def _table_from_section(sec) -> Nose:
    return table_nose(sec.points_si(), sec.diameter)


@register_nose("power", keys=("exponent", "nose_length"))
def _power_from_section(sec) -> Nose:
    return power_nose(sec.diameter, sec.exponent, sec.nose_length)


@register_nose("spline", keys=("control_radii", "nose_length"))
def _spline_from_section(sec) -> Nose:
    return spline_nose(sec.diameter, sec.control_radii, sec.nose_length)


def nose_from_section(sec) -> Nose:
    """Build the nose of a ``[projectile]`` case section (its kind's registered builder)."""
    return NOSE_KINDS[sec.nose].build(sec)


@dataclass(frozen=True)
class ProjectileGeometry:
    """The projectile's derived geometry (SI): what the case implies but does not state."""

    diameter_m: float
    nose_length_m: float
    shank_length_m: float
    length_m: float
    length_over_diameter: float
    volume_m3: float
    mass_kg: float | None

    def to_dict(self) -> dict:
        """The fields as a dict (JSON-ready)."""
        from dataclasses import asdict

        return asdict(self)


def derived_geometry(sec) -> ProjectileGeometry:
    """The derived geometry of a ``[projectile]`` section (nose length, length, L/D, volume, mass)."""
    pr = projectile_from_section(sec)
    try:
        mass = float(pr.mass)
    except (TypeError, ValueError):  # neither a density nor a measured mass
        mass = None
    return ProjectileGeometry(float(pr.diameter), float(pr.nose_length), float(pr.shank_length), float(pr.length),
                              float(pr.length / pr.diameter), float(pr.volume()), mass)


def projectile_from_section(sec) -> Projectile:
    """Build the projectile of a ``[projectile]`` case section."""
    return Projectile(nose_from_section(sec), sec.shank, sec.density, sec.mass)


def body_from_section(sec) -> Meridian:
    """Build the closed meridian of a ``[body]`` case section."""
    if sec.shape == "sphere":
        return sphere_body(sec.diameter)
    if sec.shape == "spheroid":
        return spheroid_body(sec.length, sec.diameter)
    if sec.shape == "cylinder":
        return cylinder_body(sec.length, sec.diameter)
    if sec.shape == "double_cone":
        return double_cone_body(sec.length, sec.diameter)
    return table_body(sec.points_si())
