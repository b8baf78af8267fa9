"""State shared by the analysis steps of one ``run``: the case, the staged output folder,
the report being built and the results collected for ``results.json``."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

from semianalytic.case import Case
from semianalytic.report.document import Document
from semianalytic.report.figures import png_bytes
from semianalytic.report.output import StagedDir
from semianalytic.run.case import RunSection


@dataclass
class Context:
    case: Case
    out: StagedDir
    run: RunSection
    doc: Document
    render: bool = True
    cache_dir: str | None = None
    results: dict[str, Any] = field(default_factory=dict)
    memo: dict[str, Any] = field(default_factory=dict)  # shared between steps (table, motion, ...)
    timings: dict[str, float] = field(default_factory=dict)
    figures: list[str] = field(default_factory=list)
    _t0: float = field(default_factory=time.perf_counter)

    def figure(self, name: str, fig, caption: str) -> str:
        """Save ``fig`` as ``<figures_dir>/<name>.png`` and put it in the report."""
        rel = f"{self.run.figures_dir.rstrip('/')}/{name}.png"
        self.out.write_bytes(rel, png_bytes(fig), field="run.figures_dir")
        self.doc.image(rel, caption)
        self.figures.append(rel)
        return rel

    def png(self, name: str, data: bytes, caption: str) -> str:
        """Put an already rendered PNG (e.g. a pyvista screenshot) into the report."""
        rel = f"{self.run.figures_dir.rstrip('/')}/{name}.png"
        self.out.write_bytes(rel, data, field="run.figures_dir")
        self.doc.image(rel, caption)
        self.figures.append(rel)
        return rel

    def vtk_path(self, name: str):
        """Staging path of ``<vtk_dir>/<name>`` (may not leave the output folder)."""
        rel = f"{self.run.vtk_dir.rstrip('/')}/{name}"
        return rel, self.out.path(rel, field="run.vtk_dir")
