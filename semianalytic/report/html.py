"""Render a :class:`~semianalytic.report.document.Document` as one self-contained HTML page.

Images are embedded as ``data:`` URIs when their bytes are given (``images``), so the page
can be moved or mailed alone; the PNG files stay beside it for reuse.  An image without bytes
is linked by its relative path.  All text is escaped, so nothing from a case file (titles,
notes) can inject markup.
"""

from __future__ import annotations

import base64
import html
import re
from typing import Callable

from semianalytic.report.document import Code, Document, Heading, Image, Note, Paragraph, Table

_CSS = """
body { font-family: system-ui, -apple-system, "Segoe UI", sans-serif; max-width: 62rem; margin: 2rem auto;
       padding: 0 1rem; color: #1b1b1b; line-height: 1.45; }
h1 { border-bottom: 2px solid #446; padding-bottom: .3rem; }
h2 { border-bottom: 1px solid #ccd; padding-bottom: .2rem; margin-top: 2rem; }
table { border-collapse: collapse; margin: .6rem 0 1.2rem; font-size: .92rem; }
th, td { border: 1px solid #bbc; padding: .25rem .55rem; text-align: right; }
th { background: #eef; } td:first-child, th:first-child { text-align: left; }
caption { caption-side: top; font-style: italic; text-align: left; padding-bottom: .3rem; }
figure { margin: 1rem 0 1.6rem; } figure img { max-width: 100%; border: 1px solid #dde; }
figcaption { font-style: italic; font-size: .92rem; }
.note { border-left: 4px solid #58a; background: #f3f7fb; padding: .4rem .8rem; margin: .8rem 0; }
.warning { border-left: 4px solid #c73; background: #fdf5ee; padding: .4rem .8rem; margin: .8rem 0; }
code, pre { font-family: ui-monospace, monospace; background: #f4f4f6; }
pre { padding: .6rem; overflow-x: auto; }
"""


def _inline(text: str) -> str:
    """Escape, then turn `code` and **bold** into tags (the only inline markup we use)."""
    parts = re.split(r"(`[^`]*`)", text)
    out = []
    for part in parts:
        if len(part) >= 2 and part.startswith("`") and part.endswith("`"):
            out.append(f"<code>{html.escape(part[1:-1])}</code>")
        else:
            esc = html.escape(part)
            out.append(re.sub(r"\*\*(.+?)\*\*", r"<strong>\1</strong>", esc))
    return "".join(out)


_MIME = {".png": "image/png", ".jpg": "image/jpeg", ".jpeg": "image/jpeg", ".svg": "image/svg+xml"}


def _image_src(path: str, images: Callable[[str], bytes | None] | None) -> str:
    """A ``data:`` URI of the image's bytes (from ``images(path)``), else the escaped relative path."""
    data = images(path) if images is not None else None
    if data is None:
        return html.escape(path, quote=True)
    mime = _MIME.get(path[path.rfind("."):].lower(), "application/octet-stream")
    return f"data:{mime};base64,{base64.b64encode(data).decode('ascii')}"


def to_html(doc: Document, images: Callable[[str], bytes | None] | None = None) -> str:
    """The page as a string (UTF-8).  ``images(relative path) -> bytes | None`` gives the bytes
    of each figure to embed; with it the page has no external resources at all."""
    body = [f"<h1>{_inline(doc.title)}</h1>"]
    for b in doc.blocks:
        if isinstance(b, Heading):
            lvl = max(2, min(b.level, 6))
            body.append(f"<h{lvl}>{_inline(b.text)}</h{lvl}>")
        elif isinstance(b, Paragraph):
            body.append(f"<p>{_inline(b.text)}</p>")
        elif isinstance(b, Note):
            cls = "warning" if b.kind == "warning" else "note"
            label = "Warning" if b.kind == "warning" else "Note"
            body.append(f'<div class="{cls}"><strong>{label}.</strong> {_inline(b.text)}</div>')
        elif isinstance(b, Table):
            rows = ["<table>"]
            if b.caption:
                rows.append(f"<caption>{_inline(b.caption)}</caption>")
            rows.append("<tr>" + "".join(f"<th>{_inline(h)}</th>" for h in b.header) + "</tr>")
            rows += ["<tr>" + "".join(f"<td>{_inline(c)}</td>" for c in r) + "</tr>" for r in b.rows]
            rows.append("</table>")
            body.append("\n".join(rows))
        elif isinstance(b, Image):
            src = _image_src(b.path, images)
            body.append(
                f'<figure><img src="{src}" data-file="{html.escape(b.path, quote=True)}" '
                f'alt="{html.escape(b.alt, quote=True)}">'
                f"<figcaption>{_inline(b.caption)}</figcaption></figure>"
            )
        elif isinstance(b, Code):
            body.append(f"<pre>{html.escape(b.text)}</pre>")
    return (
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
        f"<title>{html.escape(doc.title)}</title>\n<style>{_CSS}</style>\n</head>\n<body>\n"
        + "\n".join(body)
        + "\n</body>\n</html>\n"
    )
