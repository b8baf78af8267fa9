"""Report formats: one registry of the files written beside a Markdown report.

Every report of the per-package commands (``penetrate --report``, ``perforate --report``,
``nanostrength --report``) is Markdown first; :func:`write_beside` then writes each registered
format beside ``NAME.md`` (``NAME.html``: the same report as one self-contained page, figures
embedded).  A format is registered once with :func:`register_report_format`::

    from semianalytic.report.report_formats import register_report_format

    @register_report_format("text", suffix=".txt")
    def plain(markdown, images):
        return markdown.replace("**", "")

``render(markdown, images)`` takes the Markdown text and ``images(relative path) -> bytes | None``
(the figure files beside the report) and returns the file's text.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

__all__ = ["REPORT_FORMATS", "ReportFormat", "register_report_format", "targets_beside", "write_beside"]


@dataclass(frozen=True)
class ReportFormat:
    """A registered report format: the file ``NAME<suffix>`` is ``render(markdown, images)``."""

    name: str
    suffix: str
    render: Callable[[str, Callable[[str], bytes | None]], str]


REPORT_FORMATS: dict[str, ReportFormat] = {}
"""The formats written beside a Markdown report, by name (Markdown itself is the source, not listed)."""


def register_report_format(name: str, *, suffix: str) -> Callable:
    """Decorator: write ``render(markdown, images)`` as ``NAME<suffix>`` beside every Markdown report."""
    if not suffix.startswith(".") or suffix == ".md":
        raise ValueError(f"suffix must be a file suffix other than .md; got {suffix!r}")

    def decorate(render):
        REPORT_FORMATS[name] = ReportFormat(name, suffix, render)
        return render

    return decorate


@register_report_format("html", suffix=".html")
def _html(markdown: str, images: Callable[[str], bytes | None]) -> str:
    from semianalytic.report.html import markdown_to_html

    return markdown_to_html(markdown, images)


def targets_beside(md_path) -> list[Path]:
    """The files :func:`write_beside` writes for ``md_path`` (to check them before any is written)."""
    md_path = Path(md_path)
    return [md_path.with_suffix(f.suffix) for f in REPORT_FORMATS.values()]


def write_beside(md_path, text: str | None = None) -> list[Path]:
    """Write every registered format beside ``md_path`` (``text``: its Markdown, default the
    file's); figures are read from the files beside it (a missing one stays a relative link)."""
    from semianalytic.errors import InputError
    from semianalytic.io import atomic_write_text, contained_path

    md_path = Path(md_path)
    text = md_path.read_text(encoding="utf-8") if text is None else text
    root = md_path.parent

    def images(rel: str) -> bytes | None:
        try:
            p = contained_path(root, rel, "report figure")
        except InputError:  # a link outside the report's folder is not embedded
            return None
        return p.read_bytes() if p.is_file() else None

    return [atomic_write_text(md_path.with_suffix(f.suffix), f.render(text, images), overwrite=True)
            for f in REPORT_FORMATS.values()]
