"""Report helpers shared by the fem_check commands: markdown tables, PNG figures (Agg, no
display), atomic writes that never overwrite an existing report without ``--force``."""

from __future__ import annotations

import argparse
import io
import json
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path

from semianalytic.io import atomic_write_bytes, atomic_write_text, check_report_target


def add_output_arguments(parser: argparse.ArgumentParser, default_name: str) -> None:
    from semianalytic.cli_types import file_stem, output_dir

    parser.add_argument("--json", action="store_true", help="print the results as JSON on stdout")
    # files only where asked: without --out nothing is written (``make reports`` passes --out reports)
    parser.set_defaults(no_report=True)
    parser.add_argument("--out", default="reports", type=output_dir, action=_WriteReportInto,
                        help="write the report (markdown and PNGs) into this folder, e.g. reports; default: write nothing")
    parser.add_argument("--name", default=default_name or None, type=file_stem, help=f"report file stem (default: {default_name})")
    parser.add_argument("--force", action="store_true", help="overwrite an existing report")
    parser.add_argument("--no-report", action=_NoReport, nargs=0, help="compute and print only; write no files (the default without --out)")


class _WriteReportInto(argparse.Action):
    """``--out DIR``: store DIR and ask for the report (``no_report`` is True until then)."""

    def __call__(self, parser, namespace, values, option_string=None):
        setattr(namespace, self.dest, values)
        if not getattr(namespace, "_no_report_given", False):
            namespace.no_report = False


class _NoReport(argparse.Action):
    """``--no-report``: write nothing, wherever it stands among the options."""

    def __call__(self, parser, namespace, values, option_string=None):
        namespace.no_report = True
        namespace._no_report_given = True


def fmt(value, digits: int = 4) -> str:
    """Compact number formatting for tables."""
    if value is None:
        return "-"
    if isinstance(value, str):
        return value
    if isinstance(value, (int,)) and not isinstance(value, bool):
        return str(value)
    v = float(value)
    if not math.isfinite(v):
        return str(v)
    if v == 0:
        return "0"
    if 1e-3 <= abs(v) < 1e5:
        return f"{v:.{digits}g}"
    return f"{v:.{max(digits - 1, 1)}e}"


def md_table(headers: list[str], rows: list[list]) -> str:
    out = ["| " + " | ".join(headers) + " |", "|" + "|".join("---" for _ in headers) + "|"]
    for row in rows:
        out.append("| " + " | ".join(fmt(v) for v in row) + " |")
    return "\n".join(out)


def rate(errors: list[float], sizes: list[float]) -> list[float | None]:
    """Observed orders log(e_i/e_{i+1}) / log(h_i/h_{i+1}) (None for the first entry)."""
    out: list[float | None] = [None]
    for (e0, h0), (e1, h1) in zip(zip(errors, sizes), zip(errors[1:], sizes[1:])):
        if e0 > 0 and e1 > 0 and h0 != h1:
            out.append(math.log(e0 / e1) / math.log(h0 / h1))
        else:
            out.append(None)
    return out


def new_figure(width: float = 6.4, height: float = 4.2):
    """A matplotlib Figure on the Agg canvas (never pyplot, never a display)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height), dpi=110)
    FigureCanvasAgg(fig)
    return fig


def png_bytes(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", bbox_inches="tight")
    return buf.getvalue()


@dataclass
class Report:
    """A markdown report and its figures, written atomically into ``folder``."""

    folder: Path
    name: str
    force: bool = False
    lines: list[str] = field(default_factory=list)
    figures: dict[str, bytes] = field(default_factory=dict)

    @property
    def path(self) -> Path:
        return Path(self.folder) / f"{self.name}.md"

    def check(self) -> None:
        """Refuse up front (before any computation) to overwrite an existing report."""
        check_report_target(self.path, self.force)

    def add(self, *text: str) -> None:
        self.lines.extend(text)

    def figure(self, stem: str, fig, caption: str) -> None:
        file = f"{self.name}_{stem}.png"
        self.figures[file] = png_bytes(fig)
        self.lines.append(f"![{caption}]({file})\n")

    def write(self) -> Path:
        self.check()
        for file, data in self.figures.items():
            atomic_write_bytes(Path(self.folder) / file, data, overwrite=True)
        return atomic_write_text(self.path, "\n".join(self.lines).rstrip() + "\n", overwrite=True)


def emit_json(payload: dict) -> None:
    json.dump(payload, sys.stdout, indent=2, allow_nan=False, default=float)
    sys.stdout.write("\n")
