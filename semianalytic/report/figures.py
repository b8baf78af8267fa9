"""Figures of the report, drawn with matplotlib's object API (Figure + Agg canvas).

No pyplot and no global state: each function builds a :class:`matplotlib.figure.Figure`
and :func:`png_bytes` renders it.  Axis labels carry units; the captions name the paper's
figure each plot mirrors (Part I, Figs. 6-16).
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

LAYOUT = "constrained"
LEGEND_LOC = "upper left"  # anchored outside the axes, right of the data (LEGEND_ANCHOR): it never covers a point
LEGEND_ANCHOR = (1.02, 1.0)
# Curves without a style of their own get these in turn: distinguishable in grey print too
AUTO_STYLES = ("-", "--", "-.", ":", (0, (5, 1, 1, 1, 1, 1)), (0, (1, 1)), (0, (8, 2)))

__all__ = [
    "Series",
    "Points",
    "png_bytes",
    "line_figure",
    "panels_figure",
    "side_by_side_figure",
    "velocity_field_figure",
    "speed_scale",
    "meridian_outline",
]


@dataclass(frozen=True)
class Series:
    """One curve: x, y in display units, a label and an optional matplotlib style."""

    x: np.ndarray
    y: np.ndarray
    label: str
    style: str | None = None  # None: the next of AUTO_STYLES
    kwargs: dict = field(default_factory=dict)  # e.g. {"lw": 4, "alpha": 0.4} under a coinciding curve


@dataclass(frozen=True)
class Points:
    """Scattered (e.g. experimental) points."""

    x: np.ndarray
    y: np.ndarray
    label: str
    marker: str = "o"
    kwargs: dict = field(default_factory=dict)


def png_bytes(fig: Figure, dpi: int = 110) -> bytes:
    """Render ``fig`` to PNG bytes with the Agg canvas."""
    FigureCanvasAgg(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return buf.getvalue()


def _draw(ax, series: Sequence[Series], points: Sequence[Points] = (), legend: bool = True):
    auto = 0
    for s in series:
        kw = {"lw": 1.6, **s.kwargs}
        if s.style is None:
            ax.plot(np.asarray(s.x), np.asarray(s.y), ls=AUTO_STYLES[auto % len(AUTO_STYLES)], label=s.label, **kw)
            auto += 1
        else:
            ax.plot(np.asarray(s.x), np.asarray(s.y), s.style, label=s.label, **kw)
    for p in points:
        ax.plot(np.asarray(p.x), np.asarray(p.y), p.marker, ls="none", label=p.label, ms=5, **p.kwargs)
    if (series or points) and legend:
        ax.legend(fontsize=8, loc=LEGEND_LOC, bbox_to_anchor=LEGEND_ANCHOR, borderaxespad=0.0)
    ax.grid(True, alpha=0.3)


def line_figure(
    series: Sequence[Series],
    xlabel: str,
    ylabel: str,
    title: str,
    points: Sequence[Points] = (),
    logx: bool = False,
    size=(6.4, 4.2),
) -> Figure:
    """A single-axes plot of curves (and points)."""
    fig = Figure(figsize=(size[0] + 2.2, size[1]), layout=LAYOUT)  # room for the legend beside the axes
    ax = fig.add_subplot()
    _draw(ax, series, points)
    if logx:
        ax.set_xscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    return fig


def panels_figure(
    panels: Sequence[tuple[str, Sequence[Series]]],
    xlabel: str,
    title: str,
    logx: bool = False,
    sharex: bool = True,
    size=None,
) -> Figure:
    """Stacked panels sharing x: ``panels = [(ylabel, [Series, ...]), ...]``."""
    n = len(panels)
    fig = Figure(figsize=size or (8.6, 2.2 * n + 0.6), layout=LAYOUT)
    axes = fig.subplots(n, 1, sharex=sharex, squeeze=False)[:, 0]
    for ax, (ylabel, series) in zip(axes, panels):
        _draw(ax, series)
        ax.set_ylabel(ylabel)
        if logx:
            ax.set_xscale("log")
    axes[-1].set_xlabel(xlabel)
    fig.suptitle(title, fontsize=10)
    return fig


def side_by_side_figure(
    panels: Sequence[tuple[str, str, Sequence[Series]]],
    title: str,
    size=None,
) -> Figure:
    """Panels in one row, each with its own axes: ``[(xlabel, ylabel, [Series, ...]), ...]``."""
    n = len(panels)
    fig = Figure(figsize=size or (4.6 * n + 2.2, 3.9), layout=LAYOUT)
    axes = fig.subplots(1, n, squeeze=False)[0]
    labels = [[s.label for s in series] for _, _, series in panels]
    shared = all(lab == labels[-1] for lab in labels)  # the same curves in every panel: one legend, at the right
    for k, (ax, (xlabel, ylabel, series)) in enumerate(zip(axes, panels)):
        _draw(ax, series, legend=not shared or k == n - 1)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
    fig.suptitle(title, fontsize=10)
    return fig


def meridian_outline(profile_xr: np.ndarray, depth: float) -> np.ndarray:
    """Closed outline (x, r) in the target frame of a body-frame meridian (tip at x = 0) at depth P."""
    pts = np.asarray(profile_xr, float).copy()
    pts[:, 0] += depth
    return pts


def speed_scale(speed: np.ndarray, decades: float = 3.0, wide: float = 30.0):
    """The colour scale of a speed field: linear from 0 to the true maximum when
    max/min <= ``wide``, else logarithmic from max(min, max 10^-decades) to the true maximum.

    Returns ``(norm, extend, text)``: a matplotlib norm, the colour bar's ``extend`` ('min'
    when values below the scale's bottom are drawn in its lowest colour) and a caption text
    that states the range, the scale and any clipping.  The top is never clipped.
    """
    from matplotlib.colors import LogNorm, Normalize

    v = np.asarray(speed, float)
    v = v[np.isfinite(v)]
    top = float(v.max()) if v.size else 1.0
    low = float(v.min()) if v.size else 0.0
    if low > 0 and top / low <= wide or top <= 0:
        return Normalize(0.0, max(top, 1e-300)), "neither", (
            f"linear scale from 0 to the maximum {top:.4g} m/s (unclipped)")
    bottom = max(low, top * 10.0 ** -decades)
    if bottom > low:
        return LogNorm(bottom, top), "min", (
            f"log scale from {bottom:.3g} m/s to the true maximum {top:.4g} m/s; the {low:.3g}-{bottom:.3g} m/s of "
            "the far field are drawn in the lowest colour (arrow of the colour bar)")
    return LogNorm(bottom, top), "neither", f"log scale from the minimum {low:.3g} to the maximum {top:.4g} m/s (unclipped)"


def velocity_field_figure(
    points: np.ndarray,
    quads: np.ndarray,
    vx: np.ndarray,
    vr: np.ndarray,
    outline: np.ndarray,
    window: tuple[float, float, float],
    surface_radius: float,
    title: str,
    length_unit: float = 1e-3,
    streamline_density: float = 1.1,
):
    """Meridian-plane picture of the velocity field (Part I Figs. 12-13) on a body-fitted mesh:
    |v| in colour (:func:`speed_scale`), streamlines of v, the projectile, its wetted surface
    (x >= 0) and the free surface x = 0, mirrored to r < 0.

    ``points`` (n, 2) of (x, r) [m] and ``quads`` (m, 4): the fluid mesh (no cell inside the
    body); ``vx, vr`` (n,) [m/s]; ``outline`` (k, 2): the closed meridian of the projectile in
    the target frame; ``window`` = (0, x_max, r_max) [m]; ``surface_radius``: the body's radius
    at x = 0 [m].  Returns ``(figure, colour-scale text for the caption)``.
    """
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    from matplotlib.tri import LinearTriInterpolator, Triangulation

    s = 1.0 / length_unit
    unit = {1e-3: "mm", 1.0: "m", 1e-2: "cm"}.get(length_unit, f"{length_unit:g} m")
    pts = np.asarray(points, float)
    q = np.asarray(quads)
    tris = np.vstack([q[:, [0, 1, 2]], q[:, [0, 2, 3]]])
    n = len(pts)
    # both halves: the mirror image r -> -r (its triangles reversed to stay counter-clockwise);
    # nodes on the axis are shared, not duplicated (a valid triangulation for the interpolator)
    xy = np.vstack([pts * s, pts * [s, -s]])
    mirror = np.arange(n) + n
    mirror[pts[:, 1] == 0.0] = np.flatnonzero(pts[:, 1] == 0.0)
    tri_all = np.vstack([tris, mirror[tris[:, ::-1]]])
    speed = np.hypot(vx, vr)
    speed2 = np.concatenate([speed, speed])
    norm, extend, scale_text = speed_scale(speed[np.unique(q)])  # the nodes drawn
    tri = Triangulation(xy[:, 0], xy[:, 1], tri_all)

    _, x1, r1 = window
    fig = Figure(figsize=(8.6, 4.4), layout=LAYOUT)
    ax = fig.add_subplot()
    x_lo = -0.07 * x1 * s
    ax.axvspan(x_lo, 0.0, color="0.93", zorder=0)  # above the target: air
    pcm = ax.tripcolor(tri, speed2, shading="gouraud", cmap="viridis", norm=norm, zorder=1)

    # streamlines on a regular lattice, interpolated linearly inside the mesh (masked outside)
    gx = np.linspace(0.0, x1 * s, 120)
    gy = np.linspace(-r1 * s, r1 * s, 66)
    GX, GY = np.meshgrid(gx, gy)
    vx2 = np.concatenate([vx, vx])
    vy2 = np.concatenate([vr, -vr])
    U = LinearTriInterpolator(tri, vx2)(GX, GY)
    V = LinearTriInterpolator(tri, vy2)(GX, GY)
    lines = ax.streamplot(gx, gy, U, V, density=streamline_density, color="white", linewidth=0.6, arrowsize=0.7,
                          zorder=2)
    lines.lines.set_in_layout(False)  # hundreds of small artists: keep them out of the layout's bboxes
    lines.arrows.set_in_layout(False)

    o = np.asarray(outline, float)
    # the wetted surface: the outline clipped at the free surface x = 0
    wet = np.vstack([o[o[:, 0] >= 0.0], [[0.0, surface_radius]]]) if np.any(o[:, 0] < 0.0) else o
    for sign in (1.0, -1.0):
        ax.fill(o[:, 0] * s, sign * o[:, 1] * s, color="0.6", zorder=3)
        ax.plot(wet[:, 0] * s, sign * wet[:, 1] * s, color="tab:orange", lw=2.2, zorder=4)
        ax.plot([0.0, 0.0], [sign * surface_radius * s, sign * r1 * s], color="tab:blue", lw=2.2, zorder=4)
    ax.set_aspect("equal")
    ax.set_xlim(x_lo, x1 * s)
    ax.set_ylim(-r1 * s, r1 * s)
    ax.set_xlabel(f"x, depth below the free surface [{unit}]")
    ax.set_ylabel(f"r, distance from the axis [{unit}]")
    import textwrap

    # the figure's title, not the axes': an equal-aspect axes is shrunk after the layout placed an axes
    # title, which then fell off the top edge; wrapped, it never runs past the sides either
    fig.suptitle("\n".join(textwrap.wrap(title, 90)), fontsize=10)
    cb = fig.colorbar(pcm, ax=ax, extend=extend, shrink=0.9)
    cb.set_label("|v| [m/s]" + (" (log scale)" if type(norm).__name__ == "LogNorm" else ""))
    fig.legend(
        handles=[
            Line2D([], [], color="tab:blue", lw=2.2, label="free surface x = 0"),
            Line2D([], [], color="tab:orange", lw=2.2, label="wetted surface (x >= 0)"),
            Patch(color="0.6", label="projectile"),
            Line2D([], [], color="0.4", lw=0.8, label="streamlines of v"),
        ],
        fontsize=8, loc="outside lower center", ncols=4, frameon=False,
    )
    return fig, scale_text
