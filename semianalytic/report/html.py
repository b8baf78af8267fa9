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
from collections.abc import Callable

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


def markdown_to_html(text: str, images: Callable[[str], bytes | None] | None = None) -> str:
    """A report written as Markdown text (the subset the reports use: ``#`` headings, pipe
    tables, ``![alt](file.png)`` figures, fenced code, ``-`` lists, ``>`` notes, paragraphs,
    inline `code` and **bold**) as one self-contained page: figures embedded from
    ``images(relative path)`` as :func:`to_html` does."""
    lines = text.splitlines()
    title = next((ln[2:].strip() for ln in lines if ln.startswith("# ")), "report")
    body: list[str] = []
    para: list[str] = []
    i = 0

    def flush():
        if para:
            body.append(f"<p>{_inline(' '.join(para))}</p>")
            para.clear()

    while i < len(lines):
        ln = lines[i]
        s = ln.strip()
        if s.startswith("```"):
            flush()
            j = i + 1
            while j < len(lines) and not lines[j].strip().startswith("```"):
                j += 1
            body.append(f"<pre>{html.escape(chr(10).join(lines[i + 1:j]))}</pre>")
            i = j + 1
            continue
        m = re.match(r"^(#{1,6})\s+(.*)$", s)
        img = re.match(r"^!\[(.*)\]\(([^)\s]+)\)\s*$", s)  # the alt text may hold [ ] and ( )
        if m:
            flush()
            lvl = len(m.group(1))
            body.append(f"<h{lvl}>{_inline(m.group(2))}</h{lvl}>")
        elif img:
            flush()
            src = _image_src(img.group(2), images)
            body.append(f'<figure><img src="{src}" data-file="{html.escape(img.group(2), quote=True)}" '
                        f'alt="{html.escape(img.group(1), quote=True)}"><figcaption>{_inline(img.group(1))}'
                        "</figcaption></figure>")
        elif s.startswith("|"):
            flush()
            rows = []
            while i < len(lines) and lines[i].strip().startswith("|"):
                cells = [c.strip() for c in lines[i].strip().strip("|").split("|")]
                if not all(re.fullmatch(r":?-{2,}:?", c) for c in cells if c):
                    rows.append(cells)
                i += 1
            out = ["<table>"]
            for k, cells in enumerate(rows):
                tag = "th" if k == 0 else "td"
                out.append("<tr>" + "".join(f"<{tag}>{_inline(c)}</{tag}>" for c in cells) + "</tr>")
            out.append("</table>")
            body.append("\n".join(out))
            continue
        elif re.match(r"^[-*] ", s):
            flush()
            items = []
            while i < len(lines) and re.match(r"^\s*[-*] ", lines[i]):
                items.append(f"<li>{_inline(lines[i].strip()[2:])}</li>")
                i += 1
            body.append("<ul>" + "".join(items) + "</ul>")
            continue
        elif s.startswith(">"):
            flush()
            body.append(f'<div class="note">{_inline(s.lstrip("> "))}</div>')
        elif not s:
            flush()
        elif not (s == f"# {title}"):
            para.append(s)
        i += 1
    flush()
    return (
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
        f"<title>{html.escape(title)}</title>\n<style>{_CSS}</style>\n</head>\n<body>\n"
        + "\n".join(body)
        + "\n</body>\n</html>\n"
    )


def html_beside(md_path, text: str | None = None):
    """Write ``NAME.html`` beside ``NAME.md``: the Markdown as a self-contained page (figures
    embedded from the files beside it; a figure that is not there stays a relative link)."""
    from pathlib import Path

    from semianalytic.io import atomic_write_text, contained_path

    md_path = Path(md_path)
    text = md_path.read_text(encoding="utf-8") if text is None else text
    root = md_path.parent

    def images(rel: str) -> bytes | None:
        try:
            p = contained_path(root, rel, "report figure")
        except Exception:
            return None
        return p.read_bytes() if p.is_file() else None

    return atomic_write_text(md_path.with_suffix(".html"), markdown_to_html(text, images), overwrite=True)
