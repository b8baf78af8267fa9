"""Resource guards: refuse, before anything is allocated, what would not fit in memory.

Every command that solves estimates the size of its largest arrays from the geometry and the
options (cheap: arithmetic on the panel plan, no assembly, no gmsh) and stops with exit status
2 when the estimate exceeds the memory budget, naming the field that drives the size and the
largest (or smallest) value of it that fits.

The budget is, in order: the command's ``--memory-limit`` (set by the dispatcher with
:func:`set_memory_limit`), ``$SEMIANALYTIC_MEMORY_LIMIT`` (e.g. ``8GB``), or 4 GB.

Memory models (measured; see ``tests/test_guards.py`` and ``reports/hardening.md``):

- BEM: the assembly holds the single and double layer of N primary unknowns against 2N
  (with the mirror image) nodes and the kernel temporaries: 150-162 bytes per N^2 measured
  for coefficient tables of the Fig. 5 ogive at refinements 1-4 (tracemalloc peak); 170 is
  used.  N = order x panels of the deepest layout.
- Velocity field of ``run``: the revolved 3D grid of nx x nr x segments nodes (points, hexahedra,
  point data and the VTK copy): 400 bytes per node.
- FEM (fem_check): triangles ~ 2.3 [L_b / (h^2 g d) + (pi/2) ln(R_far/d) / (h^2 g^2)] for
  the size field h (d + g s) of :mod:`fem_check.meshing` (L_b the wetted length, g = 3),
  two P2 unknowns per triangle, 3 kB per unknown (mesh, sparse matrix and its LU factors).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable

from semianalytic.errors import InputError

__all__ = [
    "DEFAULT_MEMORY_LIMIT",
    "MEMORY_ENV",
    "memory_limit",
    "set_memory_limit",
    "bem_halfspace_unknowns",
    "bem_body_unknowns",
    "check_case",
    "check_coefficients",
    "check_body",
    "check_field_grid",
    "check_fem",
    "format_bytes",
]

DEFAULT_MEMORY_LIMIT = 4e9
MEMORY_ENV = "SEMIANALYTIC_MEMORY_LIMIT"
BASE_BYTES = 0.0  # the budget is for the arrays of the problem (the interpreter itself takes ~300 MB more)
BEM_BYTES_PER_UNKNOWN2 = 170.0
FIELD_BYTES_PER_NODE = 400.0
FEM_BYTES_PER_DOF = 3000.0
EXACT_PLAN_PANELS = 20_000  # below this many (estimated) panels the real panel plan is counted

_limit: float | None = None


def set_memory_limit(limit: float | None) -> None:
    """The budget of this process (the ``--memory-limit`` flag); ``None``: environment/default."""
    global _limit
    _limit = limit


def memory_limit() -> float:
    """The memory budget in bytes: ``--memory-limit``, else ``$SEMIANALYTIC_MEMORY_LIMIT``, else 4 GB."""
    if _limit is not None:
        return float(_limit)
    env = os.environ.get(MEMORY_ENV)
    if env:
        import argparse

        from semianalytic.cli_types import memory_size

        try:
            return memory_size(env)
        except argparse.ArgumentTypeError as exc:
            raise InputError(MEMORY_ENV, str(exc)) from None
    return DEFAULT_MEMORY_LIMIT


def format_bytes(n: float) -> str:
    for unit, scale in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6)):
        if n >= scale:
            return f"{n / scale:.3g} {unit}"
    return f"{n / 1e3:.3g} kB"


def _budget_text(limit: float) -> str:
    return f"the memory budget of {format_bytes(limit)} (--memory-limit or ${MEMORY_ENV})"


# ------------------------------------------------------------------------------------
# BEM unknowns from the panel plan


def _estimated_nose_panels(nose, refinement: float, levels: int) -> float:
    """Panels of the whole nose as :func:`semianalytic.bem.panels.halfspace_layout` would lay
    them at full submersion, by arithmetic only (a float: may be astronomically large)."""
    from semianalytic.geometry import SplineCurve, segment_arc_length

    R = nose.radius
    total = 0.0
    for seg in nose.segments:
        arc = segment_arc_length(seg, seg.t0, seg.t1)
        n = max(2.0, math.ceil(refinement * 1.6 * arc / R)) if math.isfinite(arc) else math.inf
        if isinstance(seg, SplineCurve):
            n = max(n, len(seg.knots))
        total += n + 2 * levels
    return total


def _arithmetic_unknowns(nose, order: int, refinement: float, max_depth_nose_lengths: float, levels: int = 12) -> float:
    """Primary unknowns of the deepest half-space layout by arithmetic only (no layout built)."""
    estimate = _estimated_nose_panels(nose, refinement, levels)
    length = (max_depth_nose_lengths - 1) * nose.depth_unit
    shank = levels + max(0.0, math.log2(max(length / nose.radius, 1.0)) * refinement) + 2
    return order * (estimate + shank)


def _least_unknowns(nose, order: int) -> tuple[float, int]:
    """A lower bound of the primary unknowns of the deepest half-space layout, by counting only
    (no layout built): :func:`semianalytic.bem.panels.halfspace_layout` lays at least one panel
    per interval between a table spline's knots (it cuts the spline there) and at least two on
    every other segment, and at least one on the shank.  Returns (unknowns, knot intervals)."""
    from semianalytic.geometry import SplineCurve

    panels, intervals = 1.0, 0
    for seg in nose.segments:
        if isinstance(seg, SplineCurve):
            k = max(len(seg.knots) - 1, 1)
            intervals += k
            panels += k
        else:
            panels += 2
    return order * panels, intervals


def bem_halfspace_unknowns(nose, order: int = 8, refinement: float = 1.0, max_depth_nose_lengths: float = 300.0,
                           levels: int = 12) -> float:
    """Primary unknowns N of the largest half-space layout of ``nose`` (order x panels): the
    deepest one, and the layouts at the shallowest depth a table solves (a flat tip's first
    knots reach 1e-6 R; a cut segment is counted on its wetted length) and on either side of
    the shoulder, where the layout changes topology; the largest of them."""
    from semianalytic.bem.panels import LayoutOptions, halfspace_layout

    estimate = _estimated_nose_panels(nose, refinement, levels)
    if estimate > EXACT_PLAN_PANELS:
        return _arithmetic_unknowns(nose, order, refinement, max_depth_nose_lengths, levels)
    opts = LayoutOptions(order, refinement, levels)
    probes = [max_depth_nose_lengths * nose.depth_unit, 1e-6 * nose.radius]
    if nose.length > 0:
        probes += [1e-6 * nose.length, 0.5 * nose.length, nose.length * (1 - 1e-6), nose.length * (1 + 1e-6)]
    best = 0
    for P in probes:
        layout = halfspace_layout(nose, P, opts)
        best = max(best, sum(len(p.panels) for p in layout.pieces))
    return float(order * best)


def bem_body_unknowns(meridian, order: int = 8, refinement: float = 1.0, levels: int = 12) -> float:
    """Unknowns N of a closed body in unbounded fluid (order x panels of the body layout)."""
    from semianalytic.bem.panels import LayoutOptions, body_panels
    from semianalytic.geometry import EllipseArc, segment_arc_length

    segs = meridian.segments
    scale = _max_radius(meridian)
    estimate = 0.0
    for seg in segs:
        arc = segment_arc_length(seg, seg.t0, seg.t1)
        n = refinement * 1.6 * arc / scale
        if isinstance(seg, EllipseArc):
            n = max(n, refinement * 1.2 * max(seg.a, seg.b) / max(min(seg.a, seg.b), 1e-300))
        estimate += n + 2 * levels + 2
    if estimate > EXACT_PLAN_PANELS:
        return order * estimate
    return float(order * body_panels(meridian, LayoutOptions(order, refinement, levels)).n_panels)


def _max_radius(meridian) -> float:
    import numpy as np

    return max(float(np.max(np.abs(s.point(np.linspace(s.t0, s.t1, 33))[1]))) for s in meridian.segments)


def bem_bytes(unknowns: float, mirror: bool = True) -> float:
    """Peak bytes of one BEM solve with ``unknowns`` primary unknowns."""
    return BASE_BYTES + BEM_BYTES_PER_UNKNOWN2 * unknowns**2 * (1.0 if mirror else 0.5)


# ------------------------------------------------------------------------------------
# the checks


def _largest(fits: Callable[[float], bool], good: float, bad: float, steps: int = 40) -> float:
    """Bisection (geometric when both ends are positive) between a value that fits and one
    that does not; returns the last value that fits."""
    for _ in range(steps):
        mid = math.sqrt(good * bad) if good > 0 and bad > 0 else 0.5 * (good + bad)
        if fits(mid):
            good = mid
        else:
            bad = mid
        if abs(bad - good) <= 1e-3 * abs(good):
            break
    return good


def _refuse(field: str, what: str, need: float, limit: float, hint: str) -> None:
    raise InputError(field, f"{what} needs about {format_bytes(need)}, above {_budget_text(limit)}; {hint}")


def check_coefficients(case, order: int | None = None, refinement: float | None = None,
                       max_depth: float | None = None, *, default_refinement: float = 0.3,
                       option_prefix: str = "bem", depths: int | None = None) -> float:
    """Refuse a coefficient table (or a half-space solve) of the case's ``[projectile]`` that
    does not fit; returns the estimated bytes.  The field named is the one that drives the size:
    the refinement or order when they were raised, else the nose shape (``crh`` of an ogive,
    ``half_angle`` of a cone, the table ``points``)."""
    from semianalytic.geometry import nose_from_section

    psec = case.projectile
    order = order or case.bem.order
    ref_given = refinement or case.bem.refinement
    ref = ref_given or default_refinement
    depth = max_depth or case.coefficients.max_depth_nose_lengths
    limit = memory_limit()
    nose = nose_from_section(psec)

    def need_for(n, o=order, r=ref) -> float:
        return bem_bytes(bem_halfspace_unknowns(n, o, r, depth))

    # Fast path: the arithmetic count of panels (no layout), taken four times over (sixteen
    # times the bytes) for the grading the arithmetic does not see, fits easily: no exact plan
    # needed (building the deepest layout costs most of a second).
    rough = _arithmetic_unknowns(nose, order, ref, depth)
    if math.isfinite(rough) and bem_bytes(4.0 * rough) <= limit:
        return check_table_time(case, bem_bytes(rough), depths)
    _refuse_by_least_unknowns(case, nose, order, limit, order_given=order != case.bem.order)
    need = need_for(nose)
    if need <= limit:
        return check_table_time(case, need, depths)
    what = f"the BEM solve of the {nose.kind} nose (~{bem_halfspace_unknowns(nose, order, ref, depth):.3g} unknowns)"
    if ref > default_refinement and need_for(nose, r=default_refinement) <= limit:
        best = _largest(lambda r: need_for(nose, r=r) <= limit, default_refinement, ref)
        _refuse("--refinement" if refinement else f"{option_prefix}.refinement", what, need, limit,
                f"the largest refinement that fits is {best:.3g}")
    if order > 8 and need_for(nose, o=8) <= limit:
        best = max(o for o in range(2, order) if need_for(nose, o=o) <= limit)
        _refuse("--order" if order != case.bem.order else f"{option_prefix}.order", what, need, limit,
                f"the largest order that fits is {best}")
    if psec.nose == "ogive" and need_for(nose_from_section(psec.model_copy(update={"crh": 0.5}))) <= limit:
        best = _largest(lambda c: need_for(nose_from_section(psec.model_copy(update={"crh": c}))) <= limit, 0.5, psec.crh)
        _refuse("projectile.crh", what, need, limit, f"the largest crh that fits is {best:.4g}")
    if psec.nose == "cone" and need_for(nose_from_section(psec.model_copy(update={"half_angle": math.radians(60)}))) <= limit:
        worst = psec.half_angle
        best = _largest(lambda a: need_for(nose_from_section(psec.model_copy(update={"half_angle": a}))) <= limit,
                        math.radians(60), worst)
        _refuse("projectile.half_angle", what, need, limit, f"the smallest half_angle that fits is {math.degrees(best):.4g} deg")
    if psec.nose == "table":
        _refuse("projectile.points", what, need, limit, f"use fewer points ({len(psec.points)} given: each adds panels; "
                                                         "a few dozen describe a smooth nose) or lower the refinement")
    if psec.nose == "spline":
        _refuse("projectile.control_radii", what, need, limit, "make the nose less slender (larger control radii near "
                                                               "the tip) or lower the refinement")
    _refuse(shape_field(psec.nose), what, need, limit, "make the nose less slender or lower the refinement")
    return need


def _refuse_by_least_unknowns(case, nose, order: int, limit: float, *, order_given: bool) -> None:
    """Refuse, before any panel plan is built, a nose whose lower bound of unknowns
    (:func:`_least_unknowns`) already exceeds the budget: a table nose of thousands of points
    (each knot interval is a panel; building the real plan of 10 000 of them takes seconds)."""
    least, intervals = _least_unknowns(nose, order)
    need = bem_bytes(least)
    if need <= limit:
        return
    what = f"the BEM solve of the {nose.kind} nose (at least {least:.3g} unknowns"
    what += f": {intervals} point intervals x order {order})" if intervals else ")"
    if order_given and order > 2 and bem_bytes(_least_unknowns(nose, 2)[0]) <= limit:
        best = max(o for o in range(2, order) if bem_bytes(_least_unknowns(nose, o)[0]) <= limit)
        _refuse("--order", what, need, limit, f"the largest order that could fit is {best}")
    if case.projectile.nose == "table":
        fit = int(math.sqrt(limit / BEM_BYTES_PER_UNKNOWN2) / order) - 1
        _refuse("projectile.points", what, need, limit,
                f"use fewer points ({len(case.projectile.points)} given, at most about {max(fit, 2)} could fit at "
                f"order {order}; a few dozen describe a smooth nose)")
    _refuse(shape_field(case.projectile.nose), what, need, limit, "make the nose less slender or lower the order")


def check_body(case, order: int | None = None, refinement: float | None = None) -> float:
    """Refuse a ``[body]`` BEM solve that does not fit; returns the estimated bytes."""
    from semianalytic.geometry import body_from_section

    order = order or case.bem.order
    ref = refinement or case.bem.refinement or 1.0
    limit = memory_limit()
    meridian = body_from_section(case.body)
    unknowns = bem_body_unknowns(meridian, order, ref)
    need = bem_bytes(unknowns, mirror=False)
    if need > limit:
        what = f"the BEM solve of the {case.body.shape} body (~{unknowns:.3g} unknowns)"
        if ref > 1.0 and bem_bytes(bem_body_unknowns(meridian, order, 1.0), mirror=False) <= limit:
            best = _largest(lambda r: bem_bytes(bem_body_unknowns(meridian, order, r), mirror=False) <= limit, 1.0, ref)
            _refuse("--refinement" if refinement else "bem.refinement", what, need, limit,
                    f"the largest refinement that fits is {best:.3g}")
        field = {"spheroid": "body.length", "table": "body.points"}.get(case.body.shape, "body")
        _refuse(field, what, need, limit, "make the body less slender or lower the refinement")
    return need


def check_field_grid(case) -> float:
    """Refuse a ``[run]`` velocity field whose revolved grid does not fit."""
    run = case.section("run")
    if run is None:
        return 0.0
    nx, nr = run.field_grid
    limit = memory_limit()

    def need_for(segments: int, nodes: float = nx * nr) -> float:
        return BASE_BYTES + FIELD_BYTES_PER_NODE * nodes * (segments + 1)

    need = need_for(run.field_segments)
    if need <= limit:
        return need
    what = f"the revolved field grid of {nx} x {nr} nodes x {run.field_segments} segments"
    if need_for(3) <= limit:
        best = max(s for s in range(3, run.field_segments) if need_for(s) <= limit)
        _refuse("run.field_segments", what, need, limit, f"the largest field_segments that fits is {best}")
    _refuse("run.field_grid", what, need, limit, "use fewer nodes (the default is [49, 25])")
    return need


# The velocity field of ``run``: the BEM gradient at every node of the meridian grid (2 nx x nr
# nodes per depth) sums over the N unknowns: 6.3e-7 s per node and unknown measured (fig13 ogive,
# N ~ 380, grid 61 x 31 -> 201 x 101: 8.8 s more CPU for 36 800 more nodes, load 4; the CPU time
# is what an idle core takes); 6e-7 is taken.
FIELD_SECONDS_PER_NODE_UNKNOWN = 6e-7


def check_field_time(case, unknowns: float) -> float:
    """Refuse a ``[run]`` velocity field whose BEM evaluation at the grid's nodes would run past
    the time budget; returns the estimated seconds."""
    run = case.section("run")
    if run is None or (run.analyses is not None and "velocity_field" not in run.analyses):
        return 0.0
    nx, nr = run.field_grid
    depths = len(run.field_depths or [None])
    seconds = depths * 2 * nx * nr * unknowns * FIELD_SECONDS_PER_NODE_UNKNOWN
    per_grid = seconds / (nx * nr)
    fit = int(time_limit() / per_grid) if per_grid > 0 else 0
    check_work("run.field_grid", f"the velocity field ({depths} depth(s) x {2 * nx} x {nr} nodes against "
                                 f"~{unknowns:.3g} BEM unknowns)", seconds=seconds,
               hint=f"use fewer nodes (the default is [49, 25]; nx x nr at most about {fit} fit) or fewer "
                    "run.field_depths (or raise the time budget)")
    return seconds


def fem_unknowns(diameter: float, wetted_length: float, far_radius: float, h: float, growth: float = 3.0) -> float:
    """P2 unknowns of a fem_check mesh (see the module docstring)."""
    d = diameter
    tri = 2.3 * (wetted_length / (h * h * growth * d) + 0.5 * math.pi * math.log(max(far_radius / d, 2.0)) / (h * h * growth**2))
    return 2.0 * tri


def check_fem(case, h: float, depths_nose_lengths=(), far: float = 20.0) -> float:
    """Refuse a fem_check mesh (element size ``h`` d) that does not fit."""
    limit = memory_limit()
    if case.body is not None:
        from semianalytic.geometry import body_from_section

        meridian = body_from_section(case.body)
        d = 2 * _max_radius(meridian)
        length = sum(_arc(seg) for seg in meridian.segments)
        dofs = fem_unknowns(d, length, far * max(d, length), h)
        field = "body"
    elif case.projectile is not None:
        from semianalytic.geometry import nose_from_section

        nose = nose_from_section(case.projectile)
        d = nose.diameter
        deepest = max(depths_nose_lengths or (1.0,)) * nose.depth_unit  # fem_check's depths are in this unit
        wetted = sum(_arc(seg) for seg in nose.segments) + max(deepest - nose.length, 0.0)
        dofs = fem_unknowns(d, wetted, far * (d + deepest), h)
        field = shape_field(case.projectile.nose)
    else:
        return 0.0
    need = BASE_BYTES + FEM_BYTES_PER_DOF * dofs
    if need > limit:
        what = f"the FEM mesh (~{dofs:.3g} P2 unknowns at h = {h:g} d)"
        # unknowns scale like 1/h^2: the smallest h that fits
        best = h * math.sqrt(FEM_BYTES_PER_DOF * dofs / max(limit - BASE_BYTES, 1.0))
        if best <= 0.5:
            _refuse("--h", what, need, limit, f"the smallest h that fits is {best:.3g}")
        _refuse(field, what, need, limit, "the body is too slender for the FEM mesh")
    return need


def _arc(seg) -> float:
    from semianalytic.geometry import segment_arc_length

    return segment_arc_length(seg, seg.t0, seg.t1)


def check_case(case, *, order: int | None = None, refinement: float | None = None, max_depth: float | None = None,
               field: bool = False) -> None:
    """Every BEM guard that applies to ``case`` (and the ``[run]`` field grid with ``field``)."""
    if case.projectile is not None:
        check_coefficients(case, order, refinement, max_depth)
        if field and case.section("run") is not None:
            need = check_coefficients(case, order, refinement, 1.0 + 1e-9 + max(
                [d / _depth_unit(case) for d in (case.section("run").field_depths or [])] or [1.0]),
                default_refinement=1.0)
            check_field_time(case, math.sqrt(need / BEM_BYTES_PER_UNKNOWN2))
    if case.body is not None:
        check_body(case, order, refinement)
    if field:
        check_field_grid(case)


# One adaptive coefficient table (~70 depths) costs about 1e-4 s per N^2 (N unknowns) on this
# project's machine under load (N = 224: 5.2 s; N = 304: 9.7 s, load 7-10, both in one run);
# 5e-5 s is taken (an idle core, about twice as fast), so that only what runs past the budget
# on any core of this kind is refused.
TABLE_SECONDS_PER_UNKNOWN2 = 5e-5
ADAPTIVE_DEPTHS = 70  # depths of an adaptive table, to which the time above refers


SHAPE_FIELDS = {"ogive": "projectile.crh", "cone": "projectile.half_angle", "table": "projectile.points",
                "spline": "projectile.control_radii", "power": "projectile.exponent"}


def shape_field(nose: str) -> str:
    """The case key that sets how many panels a nose kind needs (named by a refusal)."""
    return SHAPE_FIELDS.get(nose, "projectile")


def check_table_time(case, need_bytes: float, depths: int | None = None) -> float:
    """Refuse a coefficient table whose estimated time exceeds the time budget (issue 27); its
    size is the BEM guard's (bytes = BEM_BYTES_PER_UNKNOWN2 N^2).  A fixed grid of ``depths``
    depths (``--depths``, ``coefficients.depths``) costs ``depths / ADAPTIVE_DEPTHS`` adaptive
    tables.  Returns ``need_bytes``."""
    unknowns2 = need_bytes / BEM_BYTES_PER_UNKNOWN2
    seconds = unknowns2 * TABLE_SECONDS_PER_UNKNOWN2
    psec = case.projectile
    field = shape_field(psec.nose)
    hint = "make the nose less slender, give fewer points or a lower refinement (or raise the time budget)"
    n_depths = depths if depths is not None else getattr(case.coefficients, "depths", None)
    if n_depths:
        adaptive = seconds
        seconds *= n_depths / ADAPTIVE_DEPTHS
        # the depth count is named when it is what breaks the budget (more depths than an adaptive
        # table, which would fit); otherwise the key that shapes the nose
        if seconds > time_limit() and n_depths > ADAPTIVE_DEPTHS and adaptive <= time_limit():
            field = "--depths" if depths is not None else "coefficients.depths"
            fit = int(time_limit() / (unknowns2 * TABLE_SECONDS_PER_UNKNOWN2 / ADAPTIVE_DEPTHS))
            hint = (f"use fewer depths (at most about {fit} fit; the adaptive table, without a depth count, uses "
                    f"about {ADAPTIVE_DEPTHS}) or a lower refinement or order (or raise the time budget)")
    check_work(field, f"the coefficient table of the {psec.nose} nose (~{math.sqrt(unknowns2):.3g} unknowns"
                      f"{f' at {n_depths} depths' if n_depths else ''})", seconds=seconds, hint=hint)
    return need_bytes


def _depth_unit(case) -> float:
    """The tables' depth unit of the case's nose (L_h, or the radius of a nose shorter than it)."""
    from semianalytic.geometry import nose_from_section

    return nose_from_section(case.projectile).depth_unit


# ------------------------------------------------------------------------------------
# Work counted before it starts (issue 27): sample and step counts, optimiser sizes.  The time
# estimate uses the cheapest measured cost of one unit of work (so that it refuses only what
# would certainly run long); the memory estimate the bytes each unit keeps.

DEFAULT_TIME_LIMIT = 600.0  # s: 10 minutes
TIME_ENV = "SEMIANALYTIC_TIME_LIMIT"
# seconds per unit of work, lower bounds measured on this project's machine (2 cores, loaded):
DESIGN_SECONDS = 1.0  # one optimiser design: one BEM coefficient table (sweep.engine.GEOMETRY_SECONDS)
# one emcee log-posterior evaluation over a few dozen shots: 2.7e-4 s measured per walker, step and
# model on the bundled Piekutowski cases (calibrate --steps 500 vs 2500, 34.5 s CPU for 128 000
# evaluations, load 2.4; the regimes model the same, 1200 steps x 32 walkers in 10.4 s; CPU times,
# what an idle core takes); 2.5e-4 is taken
LIKELIHOOD_SECONDS = 2.5e-4
SWEEP_CASE_SECONDS = 1e-6  # one vectorised sweep case (a few microseconds)
# bytes each unit keeps until the end:
CHAIN_BYTES_PER_DRAW = 8.0  # one float of an emcee chain (per walker, step and parameter + log-prob)
SWEEP_BYTES_PER_CASE = 1000.0  # one case of a sweep: its draws, results row, data-frame and file copies


def time_limit() -> float:
    """The time budget in seconds: ``$SEMIANALYTIC_TIME_LIMIT`` (seconds), else 10 minutes."""
    env = os.environ.get(TIME_ENV)
    if env:
        try:
            value = float(env)
        except ValueError:
            raise InputError(TIME_ENV, f"expected seconds, e.g. 3600; got {env!r}") from None
        if not (math.isfinite(value) and value > 0):
            raise InputError(TIME_ENV, f"expected a positive number of seconds; got {env!r}")
        return value
    return DEFAULT_TIME_LIMIT


def format_seconds(s: float) -> str:
    if s >= 86400 * 365:
        return f"{s / (86400 * 365):.3g} years"
    if s >= 86400:
        return f"{s / 86400:.3g} days"
    if s >= 3600:
        return f"{s / 3600:.3g} h"
    if s >= 60:
        return f"{s / 60:.3g} min"
    return f"{s:.3g} s"


def check_work(field: str, what: str, *, seconds: float = 0.0, nbytes: float = 0.0, hint: str = "") -> None:
    """Refuse ``what`` (exit status 2 naming ``field``) when its estimated time or memory exceeds
    the budgets; ``hint`` says what to change."""
    limit = memory_limit()
    if not nbytes <= limit:
        _refuse(field, what, nbytes, limit, hint)
    budget = time_limit()
    if not seconds <= budget:
        raise InputError(field, f"{what} takes at least {format_seconds(seconds)}, above the time budget of "
                                f"{format_seconds(budget)} (${TIME_ENV}, seconds); {hint}")


def check_optimiser(n_variables: int, *, method: str, coarse: int, confirm: int, popsize: int, maxiter: int,
                    maxfev: int = 15) -> float:
    """Refuse an optimisation whose design count (each design one BEM table) exceeds the time
    budget; returns the number of designs."""
    n = max(int(n_variables), 1)
    if method == "de":
        search, field, hint = float(popsize) * n * (maxiter + 1), "--popsize", "lower --popsize or --maxiter"
    else:
        search = float(coarse) ** n + min(maxfev, 15) * (2 * n if method == "grid-pattern" else 1)
        field, hint = "--coarse", "lower --coarse"
    grid = float(confirm) ** n if confirm else 0.0
    if grid > search:
        field, hint = "--confirm", "lower --confirm"
    designs = search + grid
    check_work(field, f"the optimisation ({designs:.3g} designs of {n} variable(s), each a BEM table)",
               seconds=designs * DESIGN_SECONDS, hint=hint)
    return designs


def check_sampler(walkers: int, steps: int, n_parameters: int, n_models: int = 1, field: str = "--steps",
                  seconds_per_draw: float = LIKELIHOOD_SECONDS) -> None:
    """Refuse an emcee run whose chains would not fit in memory or would run past the time budget."""
    draws = float(walkers) * float(steps) * max(n_models, 1)
    check_work(field, f"the sampler ({walkers} walkers x {steps} steps x {n_models} model(s))",
               seconds=draws * seconds_per_draw, nbytes=draws * (n_parameters + 2) * CHAIN_BYTES_PER_DRAW * 2,
               hint="lower --steps (the reports use 1000 to 5000)")


def check_sweep_size(n_cases: int, n_geometries: int = 1, field: str = "--samples") -> None:
    """Refuse a sweep whose cases would not fit in memory, or whose coefficient tables (one per
    geometry) would run past the time budget."""
    check_work(field, f"the sweep ({n_cases} cases, {n_geometries} geometries)",
               seconds=n_cases * SWEEP_CASE_SECONDS + max(n_geometries - 1, 0) * DESIGN_SECONDS,
               nbytes=n_cases * SWEEP_BYTES_PER_CASE,
               hint="use fewer samples or values (or raise the budgets if the machine has them)")
