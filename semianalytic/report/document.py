"""A report as a list of blocks, rendered to Markdown here and to HTML in :mod:`.html`.

Inline markup in text: ``code`` in backticks and **bold**; nothing else, so both renderers
agree.  Tables hold strings already formatted with their units in the header.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field


@dataclass(frozen=True)
class Heading:
    text: str
    level: int = 2


@dataclass(frozen=True)
class Paragraph:
    text: str


@dataclass(frozen=True)
class Note:
    """A highlighted remark (deviation from the paper, skipped analysis, validity warning)."""

    text: str
    kind: str = "note"  # "note" | "warning"


@dataclass(frozen=True)
class Table:
    header: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    caption: str = ""


@dataclass(frozen=True)
class Image:
    path: str  # relative to the report
    caption: str
    alt: str = ""


@dataclass(frozen=True)
class Code:
    text: str


Block = Heading | Paragraph | Note | Table | Image | Code


@dataclass
class Document:
    title: str
    blocks: list[Block] = field(default_factory=list)

    def add(self, *blocks: Block) -> Document:
        self.blocks.extend(blocks)
        return self

    def heading(self, text: str, level: int = 2) -> Document:
        return self.add(Heading(text, level))

    def para(self, text: str) -> Document:
        return self.add(Paragraph(text))

    def note(self, text: str, kind: str = "note") -> Document:
        return self.add(Note(text, kind))

    def table(self, header: Sequence[str], rows: Sequence[Sequence[object]], caption: str = "") -> Document:
        return self.add(
            Table(tuple(str(h) for h in header), tuple(tuple(str(c) for c in r) for r in rows), caption)
        )

    def image(self, path: str, caption: str, alt: str = "") -> Document:
        return self.add(Image(path, caption, alt or caption))


def _md_cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def to_markdown(doc: Document) -> str:
    """GitHub-flavoured Markdown of ``doc``."""
    out = [f"# {doc.title}", ""]
    for b in doc.blocks:
        if isinstance(b, Heading):
            out += ["#" * max(2, min(b.level, 6)) + " " + b.text, ""]
        elif isinstance(b, Paragraph):
            out += [b.text, ""]
        elif isinstance(b, Note):
            label = "Warning" if b.kind == "warning" else "Note"
            out += [f"> **{label}.** {b.text}", ""]
        elif isinstance(b, Table):
            if b.caption:
                out += [f"*{b.caption}*", ""]
            out.append("| " + " | ".join(_md_cell(h) for h in b.header) + " |")
            out.append("|" + "|".join("---" for _ in b.header) + "|")
            out += ["| " + " | ".join(_md_cell(c) for c in row) + " |" for row in b.rows]
            out.append("")
        elif isinstance(b, Image):
            out += [f"![{b.alt}]({b.path})", "", f"*{b.caption}*", ""]
        elif isinstance(b, Code):
            out += ["```", b.text.rstrip("\n"), "```", ""]
    return "\n".join(out).rstrip("\n") + "\n"


def fmt(value, digits: int = 4) -> str:
    """A number for a table: ``digits`` significant figures; '-' for None/NaN."""
    import math

    if value is None:
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, (int,)) and not isinstance(value, bool):
        return str(value)
    try:
        v = float(value)
    except (TypeError, ValueError):
        return str(value)
    if not math.isfinite(v):
        return "-"
    return f"{v:.{digits}g}"
