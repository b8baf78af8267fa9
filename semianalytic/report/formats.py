"""Output formats of the commands' standard output: one registry, one emitter.

A command hands :func:`emit` an :class:`Output` (what it can give: ``data``, a JSON-able
object; ``text``, a writer of its human-readable summary; ``rows``, the CSV text of its
table) and the format the user chose with ``--format`` (``--json`` is ``--format json``).
Each format is registered once, here or in its own module, with :func:`register_format`;
``--format``'s allowed values on a command are the registered formats whose need the
command's output provides (``csv`` only where the command has rows).

Adding a format (docs/extending.md has the worked example)::

    from semianalytic.report.formats import register_format

    @register_format("keys", needs="data", help="the top-level keys, one a line")
    def write_keys(output, stream):
        stream.write("\\n".join(output.data) + "\\n")
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, TextIO

from semianalytic.errors import InputError

__all__ = [
    "FORMATS",
    "NEEDS",
    "Format",
    "Output",
    "add_format_arguments",
    "chosen_format",
    "emit",
    "formats_for",
    "register_format",
]

NEEDS = ("data", "text", "rows")
"""What a format reads from an :class:`Output`."""


@dataclass(frozen=True)
class Output:
    """What one command prints, in every form it has.

    Parameters
    ----------
    data
        The JSON-able result (the ``--json`` object).
    text
        ``text(stream)`` writes the human-readable summary to ``stream``; None: the command has none.
    rows
        ``rows()`` returns the CSV text of the command's table; None: the command has no rows.
    json_options
        Keyword arguments of :func:`json.dumps` that fix the command's JSON bytes (indent, allow_nan, default).
    """

    data: Any = None
    text: Callable[[TextIO], None] | None = None
    rows: Callable[[], str] | None = None
    json_options: Mapping[str, Any] = field(default_factory=dict)

    def provides(self) -> tuple[str, ...]:
        """The needs this output can meet."""
        return tuple(n for n, v in (("data", self.data), ("text", self.text), ("rows", self.rows)) if v is not None)


@dataclass(frozen=True)
class Format:
    """One registered output format: ``write(output, stream)`` reads ``output.<needs>``."""

    name: str
    needs: str
    write: Callable[[Output, TextIO], None]
    help: str = ""


FORMATS: dict[str, Format] = {}
"""The registered output formats, by name (registration order is the order of ``--format``'s values)."""


def register_format(name: str, *, needs: str, help: str = "") -> Callable:
    """Decorator: register ``write(output, stream)`` as the output format ``name``.

    ``needs`` is ``"data"``, ``"text"`` or ``"rows"``: the commands whose output provides it
    accept ``--format name``.  Registering a name twice replaces the first writer.
    """
    if needs not in NEEDS:
        raise ValueError(f"needs must be one of {', '.join(NEEDS)}; got {needs!r}")

    def decorate(write: Callable[[Output, TextIO], None]) -> Callable[[Output, TextIO], None]:
        FORMATS[name] = Format(name, needs, write, help)
        return write

    return decorate


def formats_for(provides: tuple[str, ...]) -> list[str]:
    """The names of the formats a command whose output provides ``provides`` accepts."""
    return [f.name for f in FORMATS.values() if f.needs in provides]


@register_format("json", needs="data", help="one JSON object (SI units in the keys)")
def _write_json(output: Output, stream: TextIO) -> None:
    stream.write(json.dumps(output.data, **dict(output.json_options)) + "\n")


@register_format("text", needs="text", help="the human-readable summary (default)")
def _write_text(output: Output, stream: TextIO) -> None:
    output.text(stream)


@register_format("csv", needs="rows", help="the table as CSV (units in the header)")
def _write_csv(output: Output, stream: TextIO) -> None:
    stream.write(output.rows())


def add_format_arguments(parser: argparse.ArgumentParser, provides: tuple[str, ...] = ("data", "text"),
                         json_help: str = "print the results as JSON (same as --format json)") -> None:
    """Add ``--format`` (the registered formats the command's output ``provides``) and ``--json``.

    The allowed values are read when the command is run, so a format registered before
    (e.g. by a test or a plugin module) is accepted; any other value exits with status 2 naming
    ``--format`` and the allowed values.
    """
    def fmt(text: str) -> str:
        allowed = formats_for(provides)
        if text not in allowed:
            raise argparse.ArgumentTypeError(f"must be one of {', '.join(allowed)}; got {text!r}")
        return text

    parser.add_argument("--format", dest="format", type=fmt, default=None, metavar="FORMAT",
                        help=f"output on stdout: {' | '.join(formats_for(provides))} (default: text)")
    parser.add_argument("--json", action="store_true", help=json_help)


def chosen_format(args: argparse.Namespace) -> str:
    """The format of ``--format``/``--json`` (default ``text``); both, disagreeing, is an error (exit 2)."""
    fmt = getattr(args, "format", None)
    if getattr(args, "json", False):
        if fmt not in (None, "json"):
            raise InputError("--format", f"--json means --format json; got --format {fmt} as well")
        fmt = "json"
    return fmt or "text"


def emit(output: Output, fmt: str, stream: TextIO | None = None) -> None:
    """Write ``output`` to ``stream`` (default stdout) in the registered format ``fmt``."""
    if fmt not in FORMATS:
        raise InputError("--format", f"must be one of {', '.join(FORMATS)}; got {fmt!r}")
    f = FORMATS[fmt]
    if f.needs not in output.provides():
        raise InputError("--format", f"must be one of {', '.join(formats_for(output.provides()))}; got {fmt!r}")
    f.write(output, sys.stdout if stream is None else stream)
