"""The bundled case files (``cases/`` of the project, installed as the package data
``semianalytic.cases``, read with :mod:`importlib.resources`).

In a checkout ``cases/`` is the real folder (the README's commands name ``cases/X.toml``); a
wheel installs the same files as ``semianalytic/cases/`` (setup.py maps the package
``semianalytic.cases`` onto ``cases/``).  :func:`resolve_arguments` lets the README's commands run
verbatim from any folder of an installed package: an argument ``cases/NAME`` (or ``--flag=cases/NAME``)
that names no file in the working folder but a bundled case is replaced by the bundled file, with
one note on stderr (:func:`semianalytic.case.load_case` does the same for the API and the docs'
examples).  A file of that name in the working folder is always the one read.
"""

from __future__ import annotations

import sys
from pathlib import Path

__all__ = ["cases_dir", "case_file", "resolve_path", "resolve_arguments"]

PREFIX = "cases/"


def cases_dir() -> Path | None:
    """The folder of the bundled cases: the checkout's ``cases/`` when the package runs from a
    checkout (``cases/`` beside the package, with the project's ``pyproject.toml``), else the
    installed package data ``semianalytic.cases``; None when neither is there."""
    here = Path(__file__).resolve().parent.parent
    if (here / "pyproject.toml").is_file() and (here / "cases" / "__init__.py").is_file():
        return here / "cases"
    import importlib.util

    if importlib.util.find_spec("semianalytic.cases") is None:  # a build without the package data
        return None
    from importlib.resources import files

    path = Path(str(files("semianalytic.cases")))  # a folder on disk for a normal or editable install (not a zip)
    return path if path.is_dir() else None


def case_file(name: str) -> Path:
    """The bundled case file ``name`` (e.g. ``"demo_fig5_ogive.toml"``); the path may not exist
    (the caller's check names it)."""
    root = cases_dir()
    return (root if root is not None else Path(PREFIX)) / name


def resolve_path(value: str | Path, stream=None) -> str | Path:
    """``value`` itself, or, when it is ``cases/NAME`` (or ``./cases/NAME``) and names no file in
    the working folder but a bundled case, the bundled file (one note on ``stream``, default
    stderr)."""
    text = str(value)
    name = text[2:] if text.startswith("./") else text
    if not name.startswith(PREFIX) or "/" in name[len(PREFIX):] or Path(text).exists():
        return value
    root = cases_dir()
    bundled = None if root is None else root / name[len(PREFIX):]
    if bundled is None or not bundled.is_file() or bundled.resolve() == Path(text).resolve():
        return value
    print(f"note: {text} is not in this folder; reading the bundled {bundled}", file=stream or sys.stderr)
    return bundled if isinstance(value, Path) else str(bundled)


def resolve_arguments(argv: list[str], stream=None) -> list[str]:
    """``argv`` with each ``cases/NAME`` (also ``--flag=cases/NAME``) that is missing in the
    working folder but bundled replaced by the bundled file (:func:`resolve_path`)."""
    out = []
    for arg in argv:
        head, sep, value = arg.partition("=") if arg.startswith("--") else ("", "", arg)
        if value:
            arg = f"{head}{sep}{resolve_path(value, stream)}"
        out.append(arg)
    return out
