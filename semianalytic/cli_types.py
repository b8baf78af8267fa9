"""Command-line option types shared by every CLI (``semianalytic`` and ``fem_check``).

Each type is an ``argparse`` ``type=`` callable: a bad value stops the command before any work
with exit status 2 and one line naming the flag, e.g. ``error: --max-depth: must be above 1;
got -5``.  :class:`OneLineParser` turns argparse's own errors (unknown flag, missing value,
bad choice) into the same one line.  No default is ever substituted silently for a value the
user typed (``--refinement 0`` is an error, not "use the default").
"""

from __future__ import annotations

import argparse
import math
import os
import re
import sys
from pathlib import Path

__all__ = [
    "OneLineParser",
    "integer",
    "number",
    "number_list",
    "output_dir",
    "file_stem",
    "memory_size",
    "quantity",
]


class OneLineParser(argparse.ArgumentParser):
    """An ``ArgumentParser`` whose errors are one line ``error: FLAG: message`` (exit status 2)."""

    def error(self, message: str):  # noqa: D401 (argparse API)
        match = re.match(r"argument ([^:]+): (.*)", message, re.S)
        if match:
            flag = match.group(1).split("/")[-1]
            text = match.group(2)
        else:
            flag, text = "arguments", message
        text = " ".join(text.split())
        print(f"error: {flag}: {text}", file=sys.stderr)
        raise SystemExit(2)


def _fail(text: str):
    raise argparse.ArgumentTypeError(text)


def _parse_float(text: str) -> float:
    try:
        value = float(text)
    except (TypeError, ValueError):
        _fail(f"expected a number; got {text!r}")
    if not math.isfinite(value):
        _fail(f"expected a finite number; got {text!r}")
    return value


def integer(low: int | None = None, high: int | None = None):
    """An integer in [low, high] (either bound optional)."""

    def parse(text: str) -> int:
        try:
            value = int(str(text).strip())
        except ValueError:
            _fail(f"expected an integer; got {text!r}")
        if low is not None and value < low:
            _fail(f"must be at least {low}; got {text!r}")
        if high is not None and value > high:
            _fail(f"must be at most {high}; got {text!r}")
        return value

    parse.__name__ = "integer"
    return parse


def number(low: float | None = None, high: float | None = None, *, low_open: bool = False, high_open: bool = False):
    """A finite number in the interval from ``low`` to ``high`` (open ends where asked)."""

    def parse(text: str) -> float:
        value = _parse_float(text)
        if low is not None and (value <= low if low_open else value < low):
            _fail(f"must be {'above' if low_open else 'at least'} {low:g}; got {text!r}")
        if high is not None and (value >= high if high_open else value > high):
            _fail(f"must be {'below' if high_open else 'at most'} {high:g}; got {text!r}")
        return value

    parse.__name__ = "number"
    return parse


def number_list(low: float, high: float, *, low_open: bool = True, max_items: int = 64,
                exclude: dict[float, str] | None = None):
    """Comma-separated finite numbers, each in (low, high] and none of ``exclude`` (value ->
    why not); returns a tuple."""
    number_in_range = number(low, high, low_open=low_open)

    def one(text: str) -> float:
        value = number_in_range(text)
        if exclude and value in exclude:
            _fail(f"{text!r}: {exclude[value]}")
        return value

    def parse(text: str) -> tuple[float, ...]:
        items = [t for t in str(text).split(",") if t.strip()]
        if not items:
            _fail(f"expected comma-separated numbers; got {text!r}")
        if len(items) > max_items:
            _fail(f"at most {max_items} values; got {len(items)}")
        return tuple(one(t.strip()) for t in items)

    parse.__name__ = "number list"
    return parse


def _check_name_lengths(path: Path, text: str) -> None:
    """Refuse what the file system would refuse (ENAMETOOLONG) before any stat or write."""
    name_max = 255  # bytes per path component on Linux file systems
    for part in path.parts:
        if len(os.fsencode(part)) > name_max:
            _fail(f"a folder or file name may have at most {name_max} bytes; {part[:20]!r}... has {len(os.fsencode(part))}")
    if len(os.fsencode(str(path.absolute()))) > 4000:
        _fail(f"the path {text[:40]!r}... is too long")


def output_dir(text: str) -> str:
    """A folder that can be created (or exists as a folder) and written into.

    Refused: an empty path, a path through an existing file (``FILE/sub``), a path that exists
    as a file, a path whose nearest existing folder is not writable (``/proc/x``)."""
    if not str(text).strip():
        _fail("expected a folder; got an empty path")
    if "\x00" in text:
        _fail("a path may not contain a NUL character")
    if not all(c.isprintable() for c in text):  # issue 27: a name that would break every line that shows it
        _fail(f"a folder name may not contain control characters (newline, tab, ...); got {text!r}")
    path = Path(text).expanduser()
    _check_name_lengths(path, text)
    if path.exists() and not path.is_dir():
        _fail(f"{text!r} exists and is not a folder")
    probe = path.absolute()
    while not os.path.lexists(probe) and probe != probe.parent:
        probe = probe.parent
    if not probe.is_dir():
        _fail(f"cannot create {text!r}: {str(probe)!r} is a file, not a folder")
    if not os.access(probe, os.W_OK | os.X_OK) or str(probe.resolve()).startswith(("/proc", "/sys")):
        _fail(f"cannot write into {text!r}: {str(probe)!r} is not writable")
    return str(text)


_STEM = re.compile(r"[A-Za-z0-9][A-Za-z0-9._+-]{0,119}")


def file_stem(text: str) -> str:
    """A file name stem that stays inside its folder: letters, digits, ``._+-``, no path
    separator, no leading dot, at most 120 characters."""
    if not _STEM.fullmatch(str(text)) or ".." in text:
        _fail(
            f"expected a plain file name (letters, digits, '._+-', no '/' or '..', not starting with a dot); got {text!r}"
        )
    return text


_BYTES = {"": 1, "b": 1, "k": 1e3, "kb": 1e3, "m": 1e6, "mb": 1e6, "g": 1e9, "gb": 1e9, "t": 1e12, "tb": 1e12,
          "kib": 2**10, "mib": 2**20, "gib": 2**30, "tib": 2**40}
MIN_MEMORY = 64e6  # below this not even the interpreter with numpy and scipy fits


def memory_size(text: str) -> float:
    """A memory size in bytes: ``4GB``, ``500 MB``, ``8GiB``, ``2e9`` (bytes); at least 64 MB."""
    match = re.fullmatch(r"\s*([0-9.eE+-]+)\s*([A-Za-z]*)\s*", str(text))
    if not match or match.group(2).lower() not in _BYTES:
        _fail(f"expected a size such as '4GB', '500MB' or '8GiB'; got {text!r}")
    value = _parse_float(match.group(1)) * _BYTES[match.group(2).lower()]
    if not value >= MIN_MEMORY:
        _fail(f"must be at least 64MB; got {text!r}")
    physical = physical_memory()
    if not value <= physical:  # a budget the machine cannot give would let an allocation fail mid-run
        _fail(f"must be at most this machine's memory ({physical / 1e9:.3g} GB); got {text!r}")
    return value


def physical_memory() -> float:
    """Bytes of physical memory of this machine (1 TB where the system does not say)."""
    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return 1e12


def quantity(kind: str, positive: bool = True):
    """A quantity with a unit (``'1 GPa'``), as an SI float (see :mod:`semianalytic.units`)."""

    def parse(text: str) -> float:
        from semianalytic.errors import InputError
        from semianalytic.units import parse_quantity

        try:
            value = parse_quantity(text, kind)
        except InputError as exc:
            _fail(exc.message)
        if positive and not value > 0:
            _fail(f"must be positive; got {text!r}")
        return value

    parse.__name__ = kind
    return parse


def checked(parse):
    """The type ``parse`` used only to check: the option keeps the text the user typed (for
    commands that interpret the text themselves later)."""

    def check(text: str) -> str:
        parse(text)
        return text

    check.__name__ = getattr(parse, "__name__", "value")
    return check
