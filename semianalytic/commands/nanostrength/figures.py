"""PNG figures of the Part III report (matplotlib Figure + Agg, never pyplot)."""

from __future__ import annotations

import io
import itertools

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from semianalytic.nanostrength import data
from semianalytic.nanostrength.analysis import CrystalResult, StudyResult
from semianalytic.nanostrength.crystal import Crystal
from semianalytic.nanostrength.interplanar import calibrate

_COLOURS = ("tab:blue", "tab:red", "tab:green", "tab:purple", "tab:orange", "tab:brown", "tab:gray", "tab:olive")


def png_bytes(fig: Figure) -> bytes:
    FigureCanvasAgg(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, metadata={"Software": None})
    return buf.getvalue()


def law_figure(crystals: dict[str, CrystalResult]) -> Figure:
    """Fig. 2 analogue: sigma(e) of eq. (14) and Phi(c)/|Phi_0| for each crystal, calibrated
    law (solid) against the universal binding-energy relation (dotted); Table 2 peaks as dots."""
    fig = Figure(figsize=(11, 4.4))
    ax1, ax2 = fig.add_subplot(1, 2, 1), fig.add_subplot(1, 2, 2)
    e = np.linspace(-0.16, 0.30, 1200)
    for colour, (name, r) in zip(_COLOURS, crystals.items()):
        c = r.crystal
        ax1.plot(e, r.law.stress(e) / 1e9, color=colour, label=f"{name}")
        ax1.plot(e, r.uber.stress(e) / 1e9, color=colour, ls=":", lw=1)
        ax1.plot([c.e_t, -c.e_c], [c.sigma_t / 1e9, -c.sigma_c / 1e9], "o", color=colour, ms=5)
        cpar = 4 * c.d0 * (1 + e) / data.BOHR  # lattice parameter c [bohr], as on Fig. 2
        ax2.plot(cpar, r.law.energy(c.d0 * (1 + e)) / -c.phi0, color=colour, label=name)
    ax1.axhline(0, color="k", lw=0.5)
    ax1.set_xlabel("strain e = (d - d0)/d0 along [111]")
    ax1.set_ylabel("sigma_z of eq. (14) [GPa]")
    ax1.set_title("stress: calibrated law (solid), UBER (dotted), Table 2 (dots)", fontsize=9)
    ax1.set_ylim(-260, 200)
    ax1.grid(alpha=0.3)
    ax1.legend(fontsize=8)
    ax2.set_xlabel("lattice parameter c = 4 d [bohr]")
    ax2.set_ylabel("Phi(d) / |Phi_0|")
    ax2.set_title("interlayer energy of the weakest pair (c/4 apart)", fontsize=9)
    ax2.grid(alpha=0.3)
    ax2.legend(fontsize=8)
    fig.tight_layout()
    return fig


def measure_figure(crystal: Crystal) -> Figure:
    """The calibrated law with the two stress measures of eq. (14) for one crystal."""
    fig = Figure(figsize=(6, 4))
    ax = fig.add_subplot(1, 1, 1)
    e = np.linspace(-0.16, 0.30, 1200)
    for colour, measure in zip(_COLOURS, ("current", "reference")):
        law = calibrate(crystal, "cutoff", measure)
        ax.plot(e, law.stress(e) / 1e9, color=colour, label=f"1/d: {measure} spacing")
    ax.plot([crystal.e_t, -crystal.e_c], [crystal.sigma_t / 1e9, -crystal.sigma_c / 1e9], "ko", ms=5, label="Table 2")
    ax.set_xlabel("strain e")
    ax.set_ylabel("sigma_z [GPa]")
    ax.set_title(f"{crystal.name}: law calibrated with either stress measure", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def study_figure(study: StudyResult, bulk: dict[str, CrystalResult]) -> Figure:
    """sigma_1 (compression) and sigma_2 (tension) against the study's plot axis."""
    axis = study.spec.plot
    fig = Figure(figsize=(11, 4.2))
    axes = fig.add_subplot(1, 2, 1), fig.add_subplot(1, 2, 2)
    key_of = {
        "i": lambda r: (r.material, r.geometry.basis, r.geometry.l, r.geometry.m),
        "mn": lambda r: (r.material, r.geometry.basis, r.geometry.l, r.geometry.i),
        "l": lambda r: (r.material, r.geometry.basis, r.geometry.m, r.geometry.i),
    }[axis]
    x_of = {"i": lambda r: r.geometry.i, "mn": lambda r: r.geometry.m, "l": lambda r: r.geometry.l}[axis]
    names = {"i": ("material", "basis", "l", "m=n"), "mn": ("material", "basis", "l", "i"), "l": ("material", "basis", "m=n", "i")}[axis]
    groups: dict[tuple, list] = {}
    for r in study.rows:
        groups.setdefault(key_of(r), []).append(r)
    varying = [k for k in range(4) if len({g[k] for g in groups}) > 1]
    for colour, (key, rows) in zip(itertools.cycle(_COLOURS), groups.items()):
        rows = sorted(rows, key=x_of)
        x = np.array([x_of(r) for r in rows], dtype=float)
        label = ", ".join(f"{names[k]}={key[k]}" for k in varying) or key[0]
        style = dict(color=colour, marker="o" if len(x) < 30 else None, ms=3)
        axes[0].plot(x, [r.strength.sigma_c / 1e9 for r in rows], label=label, **style)
        axes[1].plot(x, [r.strength.sigma_t / 1e9 for r in rows], label=label, **style)
        printed = [(xx, r.printed) for xx, r in zip(x, rows) if r.printed is not None]
        if printed:
            axes[0].plot([p[0] for p in printed], [p[1][0] for p in printed], "x", color="k", ms=7)
            axes[1].plot([p[0] for p in printed], [p[1][1] for p in printed], "x", color="k", ms=7)
    for name in {r.material for r in study.rows}:
        b = bulk[name].bulk
        axes[0].axhline(b.sigma_c / 1e9, color="k", lw=0.6, ls="--")
        axes[1].axhline(b.sigma_t / 1e9, color="k", lw=0.6, ls="--")
    xlabel = {"i": "mesolayer i (from surface 1)", "mn": "basis size m = n", "l": "number of atomic planes l"}[axis]
    for ax, what in zip(axes, ("sigma_1 (compression)", "sigma_2 (tension)")):
        if axis == "mn":
            ax.set_xscale("log")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(f"{what} [GPa]")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    axes[1].set_title("dashed: bulk; x: printed values", fontsize=8)
    axes[0].set_title(study.spec.title, fontsize=8, loc="left")
    fig.tight_layout()
    return fig
