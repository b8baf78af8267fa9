"""Figures of the report, drawn with matplotlib's object API (Figure + Agg canvas).

No pyplot and no global state: each function builds a :class:`matplotlib.figure.Figure`
and :func:`png_bytes` renders it.  Axis labels carry units; the captions name the paper's
figure each plot mirrors (Part I, Figs. 6-16).
"""

from __future__ import annotations

import io
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

LAYOUT = "constrained"
LEGEND_LOC = "best"

__all__ = [
    "Series",
    "Points",
    "png_bytes",
    "line_figure",
    "panels_figure",
    "side_by_side_figure",
    "velocity_field_figure",
    "meridian_outline",
]


@dataclass(frozen=True)
class Series:
    """One curve: x, y in display units, a label and an optional matplotlib style."""

    x: np.ndarray
    y: np.ndarray
    label: str
    style: str = "-"


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


def _draw(ax, series: Sequence[Series], points: Sequence[Points] = ()):
    for s in series:
        ax.plot(np.asarray(s.x), np.asarray(s.y), s.style, label=s.label, lw=1.6)
    for p in points:
        ax.plot(np.asarray(p.x), np.asarray(p.y), p.marker, ls="none", label=p.label, ms=5, **p.kwargs)
    if series or points:
        ax.legend(fontsize=8, loc=LEGEND_LOC)
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
    fig = Figure(figsize=size, layout=LAYOUT)
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
    fig = Figure(figsize=size or (6.4, 2.2 * n + 0.6), layout=LAYOUT)
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
    fig = Figure(figsize=size or (4.6 * n, 3.9), layout=LAYOUT)
    axes = fig.subplots(1, n, squeeze=False)[0]
    for ax, (xlabel, ylabel, series) in zip(axes, panels):
        _draw(ax, series)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
    fig.suptitle(title, fontsize=10)
    return fig


def meridian_outline(profile_xr: np.ndarray, depth: float) -> np.ndarray:
    """Closed outline (x, r) in the target frame of a body-frame meridian (tip at x = 0) at depth P."""
    pts = np.asarray(profile_xr, float).copy()
    pts[:, 0] += depth
    return pts


def velocity_field_figure(
    x: np.ndarray,
    r: np.ndarray,
    vx: np.ndarray,
    vr: np.ndarray,
    outline: np.ndarray,
    title: str,
    length_unit: float = 1e-3,
    max_arrows: int = 30,
) -> Figure:
    """Meridian-plane picture of the velocity field (Part I Figs. 12-13): |v| in colour,
    arrows for direction, the projectile outline and its mirror in r < 0.

    ``x, r``: 1D node coordinates (m); ``vx, vr``: arrays of shape (len(x), len(r)) with NaN
    inside the projectile; ``outline``: (m, 2) meridian in the target frame.
    """
    X, R = np.meshgrid(x, r, indexing="ij")
    speed = np.hypot(vx, vr)
    s = 1.0 / length_unit
    fig = Figure(figsize=(7.2, 4.6), layout=LAYOUT)
    ax = fig.add_subplot()
    finite = np.isfinite(speed)
    vmax = float(np.nanpercentile(speed[finite], 98)) if finite.any() else 1.0
    for sign in (1.0, -1.0):
        pcm = ax.pcolormesh(X * s, sign * R * s, np.ma.masked_invalid(speed), shading="gouraud",
                            cmap="viridis", vmin=0.0, vmax=vmax)
    stride_x = max(1, len(x) // max_arrows)
    stride_r = max(1, len(r) // max(4, max_arrows // 2))
    sl = (slice(None, None, stride_x), slice(None, None, stride_r))
    with np.errstate(invalid="ignore", divide="ignore"):
        ux = np.where(finite, vx / np.where(speed > 0, speed, 1.0), np.nan)
        ur = np.where(finite, vr / np.where(speed > 0, speed, 1.0), np.nan)
    for sign in (1.0, -1.0):
        ax.quiver(X[sl] * s, sign * R[sl] * s, ux[sl], sign * ur[sl], color="w", scale=35, width=0.003,
                  alpha=0.85)
    o = np.asarray(outline)
    for sign in (1.0, -1.0):
        ax.fill(o[:, 0] * s, sign * o[:, 1] * s, color="0.55", zorder=3)
        ax.plot(o[:, 0] * s, sign * o[:, 1] * s, "k-", lw=1.0, zorder=4)
    ax.axvline(0.0, color="k", lw=0.8, ls="--")
    ax.set_aspect("equal")
    ax.set_xlim(x.min() * s, x.max() * s)
    ax.set_ylim(-r.max() * s, r.max() * s)
    unit = {1e-3: "mm", 1.0: "m", 1e-2: "cm"}.get(length_unit, f"{length_unit:g} m")
    ax.set_xlabel(f"x (target frame, free surface at 0) [{unit}]")
    ax.set_ylabel(f"r [{unit}]")
    ax.set_title(title, fontsize=10)
    fig.colorbar(pcm, ax=ax, label="|v| [m/s]", shrink=0.85)
    return fig
