"""Meshes of the axisymmetric meridian domains: gmsh (Python API) -> .msh -> meshio -> scikit-fem.

Two domains (Part I, section 1.2 and Fig. 1; sign conventions of errata item 1b):

* ``body_domain``: a closed body of revolution in unbounded fluid.  The meridian half-plane
  r >= 0 minus the body, closed by a half-circle of radius ``far_radius`` centred on the body.
* ``halfspace_domain``: the target x >= 0 around a nose at depth P (tip at x = P, moving in
  +x).  For P < L_h the nose is cut by the free surface x = 0 at the waterline radius r_w;
  for P >= L_h the entry hole and the shank form one cylinder r = d/2, 0 <= x <= P - L_h
  (n_x = 0 there, so the projectile length L does not enter, errata item 1b).  Closed by a
  quarter circle of radius ``far_radius`` = far (d + P) centred on the origin (the centre of
  the mirrored source, errata item 2f).

Boundary tags: ``body`` (Neumann -n_x), ``wall`` (hole and shank, 0), ``free`` (x = 0, 0),
``axis`` (r = 0, natural), ``far`` (Robin far field).  A third domain, ``annulus_domain``, is
the quarter annulus around a spherical cavity for the elastic problems of Part II.  Elements are graded towards the
nose tip, the nose-shank junction and the free-surface corner or waterline.  Quadratic
meshes (``order=2``) carry curved (isoparametric) boundary edges; every node of a curved
boundary is moved onto the exact meridian curve of :mod:`semianalytic.geometry`.

Generated meshes are cached in the per-user cache (``meshes`` under :func:`semianalytic.cache.cache_root`,
or ``$FEM_CHECK_MESH_CACHE``), keyed by a hash of the geometry and mesh parameters, each entry
with its key and checksum; a cache hit skips gmsh entirely.
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import io
import json
import math
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import meshio
import numpy as np
from skfem import MeshTri1, MeshTri2

from semianalytic.errors import InputError
from semianalytic.geometry import Arc, Line, Meridian, Nose, SplineCurve

MESH_FORMAT_VERSION = 8  # bump when the domain construction changes (invalidates the cache)

# ------------------------------------------------------------------------------------
# curve pieces


@dataclass(frozen=True)
class Piece:
    """A part ``t0 -> t1`` of a meridian segment (either direction), shifted by ``shift`` in x."""

    segment: object
    t0: float
    t1: float
    shift: float = 0.0

    def point(self, t):
        x, r = self.segment.point(t)
        return np.asarray(x, float) + self.shift, np.asarray(r, float)

    def derivative(self, t):
        dx, dr = self.segment.derivative(t)
        return np.asarray(dx, float), np.asarray(dr, float)

    def second_derivative(self, t):
        dx, dr = self.segment.second_derivative(t)
        return np.asarray(dx, float), np.asarray(dr, float)

    @property
    def start(self) -> tuple[float, float]:
        x, r = self.point(self.t0)
        return float(x), float(r)

    @property
    def end(self) -> tuple[float, float]:
        x, r = self.point(self.t1)
        return float(x), float(r)

    @property
    def straight(self) -> bool:
        return isinstance(self.segment, Line)

    def describe(self) -> dict:
        """JSON-able description (for the cache key)."""
        seg = self.segment
        if isinstance(seg, SplineCurve):
            sd = {"type": "spline", "xs": list(seg.xs), "rs": list(seg.rs)}
        else:
            sd = {"type": type(seg).__name__, **{k: v for k, v in dataclasses.asdict(seg).items()}}
        return {"segment": sd, "t0": self.t0, "t1": self.t1, "shift": self.shift}

    def project(self, q: np.ndarray) -> np.ndarray:
        """Closest points of the piece to the points ``q`` (M, 2) (Newton on the parameter)."""
        q = np.atleast_2d(np.asarray(q, float))
        lo, hi = min(self.t0, self.t1), max(self.t0, self.t1)
        ts = np.linspace(lo, hi, 801)
        xs, rs = self.point(ts)
        d2 = (xs[None, :] - q[:, :1]) ** 2 + (rs[None, :] - q[:, 1:2]) ** 2
        t = ts[np.argmin(d2, axis=1)]
        for _ in range(8):
            x, r = self.point(t)
            dx, dr = self.derivative(t)
            ddx, ddr = self.second_derivative(t)
            ex, er = x - q[:, 0], r - q[:, 1]
            f = ex * dx + er * dr
            fp = dx * dx + dr * dr + ex * ddx + er * ddr
            fp = np.where(np.abs(fp) > 0, fp, 1.0)
            t = np.clip(t - f / fp, lo, hi)
        x, r = self.point(t)
        return np.column_stack([x, r])


def _line(p0, p1) -> Piece:
    return Piece(Line(tuple(map(float, p0)), tuple(map(float, p1))), 0.0, 1.0)


# ------------------------------------------------------------------------------------
# domains


@dataclass(frozen=True)
class MeshOptions:
    """Mesh parameters, all relative to the length scale d of the domain (body or projectile diameter).

    ``h``: element size on the body / d; ``corner``: size at the junctions, the free-surface
    corner or the waterline as a fraction of ``h``; ``tip``: the same at a pointed tip (a cone
    point, whose gradient singularity is the strongest); ``growth``: the
    element size at distance s from the body is h (d + growth s), so that refining ``h``
    refines the whole mesh uniformly (needed for clean convergence rates); ``far``:
    far radius / d (for the half-space: R = far (d + P), since the image of the hole makes the
    quadrupole part of the far field grow with P);
    ``order``: geometric order (1 straight edges, 2 curved isoparametric edges);
    ``grading``: at a singular corner (see :func:`singular_corners`, solution ~ rho^lambda) the
    element size is h d (rho/rho0)^(1 - mu) within rho0 = d/2, with mu = grading * lambda / order,
    capped at 1, down to ``corner_min`` d (the
    graded meshes of Babuska, Kellogg and Pitkaranta: mu < lambda/order restores the optimal
    rate h^order of the energy norm, h^(2 order) of A); 0 switches the grading off (fixed
    ``corner``/``tip`` factors only).
    """

    h: float = 0.08
    corner: float = 0.25
    tip: float = 0.1
    growth: float = 3.0
    far: float = 20.0
    order: int = 2
    grading: float = 0.4  # mu = grading * lambda / order at a singular corner; 0: no grading
    corner_min: float = 1e-7  # smallest graded element size / d (scikit-fem's element maps need > ~1e-8)

    def __post_init__(self):
        if not 0 < self.h <= 1:
            raise InputError("mesh.h", f"element size over diameter must lie in (0, 1]; got {self.h!r}")
        if not 0 < self.corner <= 1:
            raise InputError("mesh.corner", f"must lie in (0, 1]; got {self.corner!r}")
        if not 0 < self.tip <= 1:
            raise InputError("mesh.tip", f"must lie in (0, 1]; got {self.tip!r}")
        if not 0 < self.growth <= 50:
            raise InputError("mesh.growth", f"must lie in (0, 50]; got {self.growth!r}")
        if not self.far > 1:
            raise InputError("mesh.far", f"far radius over diameter must exceed 1; got {self.far!r}")
        if self.order not in (1, 2):
            raise InputError("mesh.order", f"must be 1 or 2; got {self.order!r}")
        if not 1e-9 <= self.corner_min <= 1:
            raise InputError("mesh.corner_min", f"must lie in [1e-9, 1]; got {self.corner_min!r}")
        if not 0 <= self.grading <= 1:
            raise InputError("mesh.grading", f"must lie in [0, 1]; got {self.grading!r}")

    def refined(self, factor: float) -> MeshOptions:
        """The same grading with all element sizes divided by ``factor``."""
        return dataclasses.replace(self, h=self.h / factor)


@dataclass(frozen=True)
class Domain:
    """A meridian domain: its boundary loop (counter-clockwise around the fluid), tagged."""

    kind: str  # "body" | "halfspace"
    loop: tuple[tuple[str, Piece], ...]
    far_center: tuple[float, float]
    far_radius: float
    length_scale: float
    refine_points: tuple[tuple[float, float], ...]
    info: dict = field(default_factory=dict, compare=False)
    interfaces: tuple[tuple[str, Piece], ...] = ()  # curves embedded in the domain (material interfaces)
    tip_points: tuple[tuple[float, float], ...] = ()  # pointed tips (refined with options.tip)
    corners: tuple[Corner, ...] = ()  # singular corners (graded with options.grading)

    def key(self, options: MeshOptions) -> str:
        blob = {
            "version": MESH_FORMAT_VERSION,
            "kind": self.kind,
            "loop": [(tag, p.describe()) for tag, p in self.loop],
            "interfaces": [(tag, p.describe()) for tag, p in self.interfaces],
            "far": [self.far_center, self.far_radius],
            "scale": self.length_scale,
            "refine": self.refine_points,
            "tips": self.tip_points,
            "corners": [dataclasses.astuple(c) for c in self.corners],
            "options": dataclasses.asdict(options),
        }
        text = json.dumps(blob, sort_keys=True, default=float)
        return hashlib.sha256(text.encode()).hexdigest()[:24]


@dataclass(frozen=True)
class Corner:
    """A boundary point where the solution is singular: phi - phi(corner) ~ rho^exponent.

    ``angle``: the fluid's opening angle at the point (rad); ``exponent``: lambda = pi/angle at a
    ring corner off the axis (2D corner of the meridian, Neumann on both sides), or nu + 1/2 at
    a conical point on the axis (phi ~ rho^nu P_nu(cos psi) in 3D; the extra 1/2 is the
    axisymmetric weight r, which makes the 3D vertex as regular as a 2D corner of exponent nu + 1/2).
    """

    point: tuple[float, float]
    angle: float
    exponent: float
    on_axis: bool


def cone_tip_exponent(half_angle: float) -> float:
    """Smallest nu > 0 with d/dpsi P_nu(cos psi) = 0 at psi = pi - half_angle: the potential outside a
    cone of that half-angle (Neumann on its surface) behaves as rho^nu P_nu(cos psi) near the point.
    P_nu(x) = 2F1(-nu, nu+1; 1; (1-x)/2), so P_nu'(x) is proportional to 2F1(1-nu, nu+2; 2; (1-x)/2).
    nu -> 1 for a needle (a thin Neumann obstacle barely disturbs a linear field), 2 for a flat tip."""
    from scipy.optimize import brentq
    from scipy.special import hyp2f1

    z = 0.5 * (1 + math.cos(half_angle))
    f = lambda nu: hyp2f1(1 - nu, nu + 2, 2, z)  # noqa: E731
    grid = np.linspace(1e-6, 2.0 + 1e-9, 401)
    vals = [f(v) for v in grid]
    for a, b, fa, fb in zip(grid[:-1], grid[1:], vals[:-1], vals[1:]):
        if fa == 0:
            return float(a)
        if fa * fb < 0:
            return float(brentq(f, a, b, xtol=1e-14))
    return 2.0


def _tangent(piece: Piece, end: bool) -> np.ndarray:
    t = piece.t1 if end else piece.t0
    dx, dr = piece.derivative(t)
    v = np.array([float(dx), float(dr)]) * (1.0 if piece.t1 >= piece.t0 else -1.0)
    return v / np.hypot(*v)


def singular_corners(loop, tol: float = 1e-9) -> tuple[Corner, ...]:
    """Corners of a boundary loop (counter-clockwise around the fluid) found from the geometry: the
    jumps of the unit tangent between consecutive pieces (joints with the far boundary excluded).

    The fluid's opening angle at a joint is omega = pi - turn, turn the signed tangent turning
    angle.  Off the axis the solution of the Neumann problem goes like rho^(pi/omega): singular
    (in the gradient) for omega > pi, and below the P2 rate for omega in (pi/2, pi).  On the axis a
    body meeting the axis at a cone of half-angle beta = pi - omega (omega: the fluid angle)
    gives the 3D exponent nu of :func:`cone_tip_exponent`; beta = pi/2 (a flat or round tip)
    is smooth.  Only corners with an exponent below 2 (the rate of P2) are returned."""
    out = []
    n = len(loop)
    for i in range(n):
        (tag_a, a), (tag_b, b) = loop[i], loop[(i + 1) % n]
        if "far" in (tag_a, tag_b):
            continue
        ta, tb = _tangent(a, end=True), _tangent(b, end=False)
        turn = math.atan2(ta[0] * tb[1] - ta[1] * tb[0], float(ta @ tb))
        omega = math.pi - turn
        if abs(turn) < tol:
            continue
        x, r = b.start
        if "axis" in (tag_a, tag_b):
            if abs(omega - 0.5 * math.pi) < tol:
                continue
            exponent = cone_tip_exponent(math.pi - omega) + 0.5  # half-angle beta = pi - omega
            on_axis = True
        else:
            exponent = math.pi / omega
            on_axis = False
        if exponent < 2.0 - 1e-9:
            out.append(Corner((float(x), float(r)), float(omega), float(exponent), on_axis))
    return tuple(out)


def _far_arc(center, radius, a0, a1) -> Piece:
    return Piece(Arc((float(center[0]), float(center[1])), float(radius), a0, a1), a0, a1)


def body_domain(meridian: Meridian, options: MeshOptions) -> Domain:
    """Closed body in unbounded fluid: half-plane r >= 0 outside the body, far half-circle."""
    if not meridian.closed:
        raise InputError("body", "needs a closed meridian (from one axis point to the other)")
    front, rear = meridian.start(), meridian.end()
    pts = meridian.sample(60)
    d = 2.0 * float(pts[:, 1].max())
    length = front[0] - rear[0]
    xc = 0.5 * (front[0] + rear[0])
    R = options.far * max(d, length)
    pieces = [("axis", _line(front, (xc + R, 0.0))), ("far", _far_arc((xc, 0.0), R, 0.0, 0.5 * math.pi)),
              ("far", _far_arc((xc, 0.0), R, 0.5 * math.pi, math.pi)), ("axis", _line((xc - R, 0.0), rear))]
    for seg in reversed(meridian.segments):
        pieces.append(("body", Piece(seg, seg.t1, seg.t0)))
    angles = meridian.axis_angles()
    tips = [p for p, ang in zip((front, rear), angles) if ang > 1e-6]
    refine = [p for p, ang in zip((front, rear), angles) if ang <= 1e-6]
    refine += [pieces[-1 - i][1].start for i in range(len(meridian.segments) - 1)] if len(meridian.segments) > 1 else []
    return Domain("body", tuple(pieces), (xc, 0.0), R, d, tuple(tuple(map(float, p)) for p in refine),
                  {"volume": meridian.volume(), "diameter": d, "length": length},
                  tip_points=tuple(tuple(map(float, p)) for p in tips), corners=singular_corners(pieces))


def _nose_waterline(nose: Nose, depth: float) -> tuple[int, float]:
    """(segment index, parameter) of the nose point at body x = -depth (0 < depth < L_h)."""
    for i, seg in enumerate(nose.segments):
        x0, _ = seg.point(seg.t0)
        x1, _ = seg.point(seg.t1)
        if min(x0, x1) - 1e-15 <= -depth <= max(x0, x1) + 1e-15:
            lo, hi = seg.t0, seg.t1
            flo = float(seg.point(lo)[0]) + depth
            for _ in range(200):  # bisection: x(t) is monotone along a nose segment
                mid = 0.5 * (lo + hi)
                fm = float(seg.point(mid)[0]) + depth
                if (fm > 0) == (flo > 0):
                    lo, flo = mid, fm
                else:
                    hi = mid
                if abs(hi - lo) < 1e-15 * max(1.0, abs(hi)):
                    break
            return i, 0.5 * (lo + hi)
    raise InputError("depth", f"depth {depth!r} m does not cut the nose")


def halfspace_domain(nose: Nose, depth: float, options: MeshOptions) -> Domain:
    """Target x >= 0 around a nose at depth P (tip at x = P), quarter circle at R = far (d + P)."""
    if not depth > 0:
        raise InputError("depth", f"must be positive; got {depth!r} m")
    d, Rb, Lh = nose.diameter, nose.radius, nose.length
    Rf = options.far * (d + depth)
    tip = (depth, 0.0)
    pieces: list[tuple[str, Piece]] = [("axis", _line(tip, (Rf, 0.0))), ("far", _far_arc((0.0, 0.0), Rf, 0.0, 0.5 * math.pi))]
    pointed = nose.tip_half_angle() < 0.5 * math.pi - 1e-6
    refine = [] if pointed else [tip]
    tol = 1e-9 * Lh
    if depth < Lh - tol:
        k, tw = _nose_waterline(nose, depth)
        rw = float(nose.segments[k].point(tw)[1])
        pieces.append(("free", _line((0.0, Rf), (0.0, rw))))
        nose_pieces = [Piece(nose.segments[k], tw, nose.segments[k].t0, depth)]
        nose_pieces += [Piece(s, s.t1, s.t0, depth) for s in reversed(nose.segments[:k])]
        refine.append((0.0, rw))
        info = {"waterline_radius": rw, "waterline_segment": k, "waterline_t": tw}
    else:
        pieces.append(("free", _line((0.0, Rf), (0.0, Rb))))
        if depth > Lh + tol:
            pieces.append(("wall", _line((0.0, Rb), (depth - Lh, Rb))))
            refine.append((0.0, Rb))
        nose_pieces = [Piece(s, s.t1, s.t0, depth) for s in reversed(nose.segments)]
        info = {"waterline_radius": Rb}
        refine.append((depth - Lh, Rb))
    for p in nose_pieces:
        pieces.append(("body", p))
    for p in nose_pieces[1:]:
        refine.append(p.start)
    info.update({"depth": depth, "nose_length": Lh, "diameter": d})
    return Domain("halfspace", tuple(pieces), (0.0, 0.0), Rf, d, tuple(tuple(map(float, p)) for p in refine), info,
                  tip_points=(tip,) if pointed else (), corners=singular_corners(pieces))


def annulus_domain(a: float, outer: float, options: MeshOptions, interface: float | None = None) -> Domain:
    """Quarter annulus a <= R <= outer in the meridian plane (x >= 0, r >= 0) around a spherical
    cavity of radius a (Part II, Fig. 1): tags ``cavity`` (R = a), ``far`` (R = outer),
    ``axis`` (r = 0) and ``sym`` (x = 0, symmetry plane); optional embedded arc ``interface``
    at R = ``interface`` (the crack front r = c of Part II), splitting axis and plane there."""
    if not 0 < a < outer:
        raise InputError("cavity.radius", f"need 0 < a < outer radius; got a={a!r}, outer={outer!r}")
    radii = [a] + ([float(interface)] if interface is not None else []) + [outer]
    if interface is not None and not a < interface < outer:
        raise InputError("cavity.interface", f"must lie between a and the outer radius; got {interface!r}")
    pieces: list[tuple[str, Piece]] = []
    for r0, r1 in zip(radii[:-1], radii[1:]):
        pieces.append(("axis", _line((r0, 0.0), (r1, 0.0))))
    pieces.append(("far", _far_arc((0.0, 0.0), outer, 0.0, 0.5 * math.pi)))
    for r0, r1 in zip(radii[::-1][:-1], radii[::-1][1:]):
        pieces.append(("sym", _line((0.0, r0), (0.0, r1))))
    pieces.append(("cavity", _far_arc((0.0, 0.0), a, 0.5 * math.pi, 0.0)))
    interfaces = ()
    if interface is not None:
        interfaces = (("interface", _far_arc((0.0, 0.0), float(interface), 0.0, 0.5 * math.pi)),)
    return Domain("annulus", tuple(pieces), (0.0, 0.0), outer, 2.0 * a, (), {"a": a, "outer": outer, "interface": interface},
                  interfaces)


# ------------------------------------------------------------------------------------
# gmsh


def cache_dir() -> Path:
    """The mesh cache: ``$FEM_CHECK_MESH_CACHE``, else the folder ``meshes`` of the per-user cache
    (:func:`semianalytic.cache.cache_root`: ``$SEMIANALYTIC_CACHE_DIR`` or platformdirs'
    ``~/.cache/semianalytic``).  Never a folder of the project or the working directory."""
    env = os.environ.get("FEM_CHECK_MESH_CACHE")
    if env:
        return Path(env).expanduser()
    from semianalytic.cache import cache_root

    return cache_root() / "meshes"


@contextlib.contextmanager
def _private_home():
    """``HOME`` and the XDG folders pointed at a temporary folder while gmsh runs (FLTK, linked into
    gmsh, writes ``~/.fltk/fltk.org/fltk.prefs``; gmsh its option files): nothing of gmsh lands in
    the user's home folder.  Restored, and the folder removed, afterwards."""
    keys = ("HOME", "XDG_CONFIG_HOME", "XDG_CACHE_HOME", "XDG_DATA_HOME")
    saved = {k: os.environ.get(k) for k in keys}
    with tempfile.TemporaryDirectory(prefix="fem_check_gmsh_home-") as tmp:
        try:
            for k in keys:
                os.environ[k] = tmp
            yield tmp
        finally:
            for k, v in saved.items():
                if v is None:
                    os.environ.pop(k, None)
                else:
                    os.environ[k] = v


@contextlib.contextmanager
def _gmsh_session():
    import gmsh

    with _private_home():
        started = not gmsh.isInitialized()
        if started:
            gmsh.initialize(readConfigFiles=False)
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.option.setNumber("General.Verbosity", 1)
        name = f"fem_check_{os.getpid()}_{id(object())}"
        gmsh.model.add(name)
        try:
            yield gmsh
        finally:
            gmsh.model.remove()
            if started:
                gmsh.finalize()


def _generate(domain: Domain, options: MeshOptions, path: Path) -> None:
    """Run gmsh on ``domain`` and write the mesh (msh 4.1) to ``path`` atomically."""
    with _gmsh_session() as gmsh:
        geo = gmsh.model.geo
        d = domain.length_scale
        h = options.h * d
        point_tags: dict[tuple[float, float], int] = {}

        def point(p):
            key = (round(p[0], 14), round(p[1], 14))
            for k, tag in point_tags.items():
                if abs(k[0] - key[0]) <= 1e-12 * domain.far_radius and abs(k[1] - key[1]) <= 1e-12 * domain.far_radius:
                    return tag
            tag = geo.addPoint(float(p[0]), float(p[1]), 0.0, h)
            point_tags[key] = tag
            return tag

        def curve(piece: Piece) -> int:
            a, b = point(piece.start), point(piece.end)
            if piece.straight:
                return geo.addLine(a, b)
            if isinstance(piece.segment, Arc) and piece.shift == 0.0 and abs(piece.t1 - piece.t0) < 0.99 * math.pi:
                cx, cr = piece.segment.center
                return geo.addCircleArc(a, geo.addPoint(cx, cr, 0.0, h), b)
            ts = np.linspace(piece.t0, piece.t1, 97)[1:-1]
            xs, rs = piece.point(ts)
            inner = [geo.addPoint(float(x), float(r), 0.0, h) for x, r in zip(xs, rs)]
            return geo.addSpline([a, *inner, b])

        curves: list[int] = []
        groups: dict[str, list[int]] = {}
        for i, (tag, piece) in enumerate(domain.loop):
            curves.append(curve(piece))
            groups.setdefault(f"{tag}#{i}", []).append(curves[-1])
        embedded = []
        for j, (tag, piece) in enumerate(domain.interfaces):
            embedded.append(curve(piece))
            groups.setdefault(f"{tag}#{len(domain.loop) + j}", []).append(embedded[-1])
        loop = geo.addCurveLoop(curves)
        surf = geo.addPlaneSurface([loop])
        geo.synchronize()
        if embedded:
            gmsh.model.mesh.embed(1, embedded, 2, surf)
        for name, tags in groups.items():
            gmsh.model.addPhysicalGroup(1, tags, name=name)
        gmsh.model.addPhysicalGroup(2, [surf], name="fluid")

        # size field: h d on the body, h d corner at the singular points, growing like h (d + g s)
        fm = gmsh.model.mesh.field
        body_curves = [c for c, (tag, _) in zip(curves, domain.loop) if tag in ("body", "cavity")]
        f1 = fm.add("Distance")
        fm.setNumbers(f1, "CurvesList", body_curves)
        fm.setNumber(f1, "Sampling", 400)
        g = options.h * options.growth
        hmax = 0.25 * domain.far_radius
        terms = [f"{h} + {g}*F{f1}"]
        graded = {c.point: c for c in domain.corners} if options.grading > 0 else {}
        rho0 = 0.5 * d  # radius of the graded zone around a corner
        for c in graded.values():
            # (h + g rho) (rho/rho0)^(1-mu): the smooth size field at rho0, graded inside, down to
            # rho_min = rho0 (h/rho0)^(1/mu) where the size equals the distance
            mu = min(1.0, options.grading * c.exponent / options.order)
            rho_min = max(rho0 * (h / rho0) ** (1.0 / mu), options.corner_min * d)
            fc = fm.add("Distance")
            fm.setNumbers(fc, "PointsList", [point(c.point)])
            terms.append(f"({h} + {g}*F{fc}) * (Max(F{fc}, {rho_min!r}) / {rho0!r})^{1.0 - mu!r}")
        # the fixed corner/tip refinements stay (Min): grading only ever refines the smooth size field
        for pts, factor in ((domain.refine_points, options.corner), (domain.tip_points, options.tip)):
            if pts:
                fp = fm.add("Distance")
                fm.setNumbers(fp, "PointsList", [point(p) for p in pts])
                terms.append(f"{h * factor} + {g}*F{fp}")
        expr = terms[0]
        for t in terms[1:]:
            expr = f"Min({expr}, {t})"
        f3 = fm.add("MathEval")
        fm.setString(f3, "F", f"Min({hmax}, {expr})")
        fm.setAsBackgroundMesh(f3)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
        gmsh.option.setNumber("Mesh.Algorithm", 6)
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.model.mesh.generate(2)
        if options.order == 2:
            gmsh.model.mesh.setOrder(2)
        n_elem = sum(len(t) for t in gmsh.model.mesh.getElements(2)[1])
        if n_elem == 0:
            raise RuntimeError("gmsh produced no elements for the domain")
        fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=".msh", dir=path.parent)
        os.close(fd)
        try:
            gmsh.write(tmp)
            os.replace(tmp, path)
        except BaseException:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(tmp)
            raise


# ------------------------------------------------------------------------------------
# meshio -> scikit-fem


@dataclass
class DomainMesh:
    """A scikit-fem mesh of a :class:`Domain` with tagged boundary facets."""

    domain: Domain
    options: MeshOptions
    mesh: MeshTri1 | MeshTri2
    boundaries: dict[str, np.ndarray]  # tag -> facet indices
    pieces: dict[int, np.ndarray]  # loop index -> facet indices
    path: Path | None = None

    @property
    def order(self) -> int:
        return self.options.order

    def facet_nodes(self, facets: np.ndarray) -> np.ndarray:
        """Indices (into ``mesh.doflocs``) of all geometry nodes on the given facets."""
        nodes = [self.mesh.facets[:, facets].ravel()]
        if isinstance(self.mesh, MeshTri2):
            nodes.append(self.mesh.dofs.facet_dofs[:, facets].ravel())
        return np.unique(np.concatenate(nodes))

    def with_doflocs(self, doflocs: np.ndarray) -> DomainMesh:
        """Same topology and tags, moved nodes (for shape finite differences)."""
        return dataclasses.replace(self, mesh=moved_mesh(self.mesh, np.ascontiguousarray(doflocs)))


# the connectivity scikit-fem derives from the elements alone (t), not from the node positions
_TOPOLOGY = ("_facets", "_t2f", "_f2t", "_edges", "_t2e", "_f2e")


def moved_mesh(mesh, doflocs: np.ndarray):
    """``mesh`` with its nodes at ``doflocs`` (same elements), sharing the facet and edge arrays
    scikit-fem derives from the elements: a new Mesh would sort them out again (a sort of all
    facets) for every moved or shifted copy.  The arrays are the same ones, so the results are."""
    mesh.t2f  # noqa: B018 - derive the facets once, on the original
    moved = dataclasses.replace(mesh, doflocs=doflocs)
    if moved.t is mesh.t or np.array_equal(moved.t, mesh.t):
        for name in _TOPOLOGY:
            if name in vars(mesh):
                setattr(moved, name, getattr(mesh, name))
    return moved


def _to_skfem(msh: meshio.Mesh, domain: Domain, order: int):
    cells = msh.cells_dict
    ttype, ltype = ("triangle6", "line3") if order == 2 else ("triangle", "line")
    if ttype not in cells:
        raise RuntimeError(f"mesh file holds no {ttype} cells")
    tri = cells[ttype]
    used = np.unique(tri[:, :3])
    renum = -np.ones(len(msh.points), dtype=np.int64)
    renum[used] = np.arange(len(used))
    p = msh.points[:, :2].T
    if order == 1:
        mesh = MeshTri1(np.ascontiguousarray(p[:, used]), np.ascontiguousarray(renum[tri].T))
    else:
        # MeshTri2 reorders: vertices first (in np.unique order, as ``used``), then edge nodes
        mesh = MeshTri2(np.ascontiguousarray(p), np.ascontiguousarray(tri.T))
    # boundary facets from the physical line groups
    bf = mesh.boundary_facets()
    fv = np.sort(mesh.facets, axis=0)
    lookup = {(int(a), int(b)): f for f, (a, b) in enumerate(zip(fv[0].tolist(), fv[1].tolist()))}
    phys = msh.cell_data_dict["gmsh:physical"][ltype]
    names = {int(v[0]): k for k, v in msh.field_data.items() if v[1] == 1}
    lines = cells[ltype][:, :2]
    pieces: dict[int, list[int]] = {}
    for (a, b), tag in zip(renum[lines], phys):
        key = (int(min(a, b)), int(max(a, b)))
        idx = int(names[int(tag)].split("#")[1])
        pieces.setdefault(idx, []).append(lookup[key])
    pieces_arr = {k: np.array(v, dtype=np.int64) for k, v in pieces.items()}
    boundaries: dict[str, list] = {}
    curves = domain.loop + domain.interfaces
    for idx, facets in pieces_arr.items():
        boundaries.setdefault(curves[idx][0], []).append(facets)
    boundaries_arr = {k: np.concatenate(v) for k, v in boundaries.items()}
    missing = set(bf) - set(np.concatenate(list(boundaries_arr.values())).tolist())
    if missing:
        raise RuntimeError(f"{len(missing)} boundary facets carry no tag")
    return mesh, boundaries_arr, pieces_arr


def _snap_curved(dm: DomainMesh) -> DomainMesh:
    """Move every node of a curved boundary piece onto the exact curve."""
    doflocs = dm.mesh.doflocs.copy()
    curves = dm.domain.loop + dm.domain.interfaces
    for idx, facets in dm.pieces.items():
        tag, piece = curves[idx]
        if piece.straight:
            continue
        nodes = dm.facet_nodes(facets)
        doflocs[:, nodes] = piece.project(doflocs[:, nodes].T).T
    return dm.with_doflocs(doflocs)


def build_mesh(domain: Domain, options: MeshOptions, use_cache: bool = True) -> DomainMesh:
    """The scikit-fem mesh of ``domain``: from the cache when a verified entry is there, else gmsh
    (into a temporary folder), meshio and the facet matching, stored in the cache."""
    key = f"{domain.kind}_{domain.key(options)}"
    path = _arrays_path(cache_dir() / f"{key}.msh")
    arrays = _read_arrays(path, key) if use_cache else None
    if arrays is None:
        with tempfile.TemporaryDirectory(prefix="fem_check_mesh-") as tmp:
            msh_path = Path(tmp) / f"{key}.msh"
            _generate(domain, options, msh_path)
            with contextlib.redirect_stdout(io.StringIO()):  # meshio prints an empty line for msh 4.1
                msh = meshio.read(msh_path)
        mesh, boundaries, pieces = _to_skfem(msh, domain, options.order)
        if use_cache:
            _write_arrays(path, key, mesh, boundaries, pieces)
    else:
        mesh, boundaries, pieces = arrays
    return _snap_curved(DomainMesh(domain, options, mesh, boundaries, pieces, path if use_cache else None))


# The cache holds, per mesh, the scikit-fem arrays (nodes in scikit-fem's order, elements, tagged
# facets) of the gmsh mesh as a self-verifying entry (semianalytic.io.write_cache_entry: key and
# checksum, written atomically): reading them back is several times faster than parsing a .msh with
# meshio and matching its tagged lines to facets again, and gives the same arrays.  A damaged,
# truncated or mismatched entry is discarded with a warning and the mesh made again.  Bumped when
# _to_skfem changes.
ARRAYS_VERSION = 2


def _arrays_path(path: Path) -> Path:
    return path.with_name(f"{path.stem}.skfem{ARRAYS_VERSION}.npz")


def _write_arrays(path: Path, key: str, mesh, boundaries: dict, pieces: dict) -> None:
    from semianalytic.io import write_cache_entry

    buf = io.BytesIO()
    np.savez(buf, order=np.array(2 if isinstance(mesh, MeshTri2) else 1), doflocs=mesh.doflocs, t=mesh.t,
             **{f"boundary:{k}": v for k, v in boundaries.items()}, **{f"piece:{k}": v for k, v in pieces.items()})
    try:
        write_cache_entry(path, key, buf.getvalue(), what="fem_check mesh arrays", version=ARRAYS_VERSION)
    except OSError:
        pass  # a read-only cache: the mesh is made each time


def _read_arrays(path: Path, key: str):
    """(mesh, boundaries, pieces) of the verified entry ``path`` stored under ``key``, or None
    (absent; damaged or mismatched: removed with a warning)."""
    import warnings

    from semianalytic.io import CacheWarning, read_cache_entry

    payload = read_cache_entry(path, key, "fem_check mesh cache")
    if payload is None:
        return None
    try:
        with np.load(io.BytesIO(payload), allow_pickle=False) as z:
            cls = MeshTri2 if int(z["order"]) == 2 else MeshTri1
            mesh = cls(np.ascontiguousarray(z["doflocs"]), np.ascontiguousarray(z["t"]))
            boundaries = {k.split(":", 1)[1]: z[k] for k in z.files if k.startswith("boundary:")}
            pieces = {int(k.split(":", 1)[1]): z[k] for k in z.files if k.startswith("piece:")}
    except Exception as exc:  # noqa: BLE001 - an entry that cannot be read is made again, never trusted
        warnings.warn(f"fem_check mesh cache: discarded the entry {path.name!r}: unreadable ({type(exc).__name__}); "
                      "it is rebuilt", CacheWarning, stacklevel=2)
        with contextlib.suppress(OSError):
            path.unlink()
        return None
    return mesh, boundaries, pieces
