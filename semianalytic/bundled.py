"""The bundled case files (``cases/`` of the project, installed as the package data
``semianalytic.cases``, read with :mod:`importlib.resources`).

In a checkout ``cases/`` is the real folder (the README's commands name ``cases/X.toml``); a
wheel installs the same files as ``semianalytic/cases/`` (setup.py maps the package
``semianalytic.cases`` onto ``cases/``).  :func:`resolve_arguments` lets the README's commands run
verbatim from any folder of an installed package: an argument ``cases/NAME`` (or ``--flag=cases/NAME``)
that names no file in the working folder but a bundled case is replaced by the bundled file, with
one note on stderr.  A file of that name in the working folder is always the one read.
"""

from __future__ import annotations

import sys
from pathlib import Path

__all__ = ["cases_dir", "case_file", "resolve_arguments"]

PREFIX = "cases/"


def cases_dir() -> Path | None:
    """The folder of the bundled cases: the checkout's ``cases/`` when the package runs from a
    checkout (``cases/`` beside the package, with the project's ``pyproject.toml``), else the
    installed package data ``semianalytic.cases``; None when neither is there."""
    here = Path(__file__).resolve().parent.parent
    if (here / "pyproject.toml").is_file() and (here / "cases" / "__init__.py").is_file():
        return here / "cases"
    try:
        from importlib.resources import files

        root = files("semianalytic.cases")
    except (ModuleNotFoundError, TypeError):
        return None
    path = Path(str(root))  # a folder on disk for a normal or editable install (not a zip)
    return path if path.is_dir() else None


def case_file(name: str) -> Path:
    """The bundled case file ``name`` (e.g. ``"demo_fig5_ogive.toml"``); the path may not exist
    (the caller's check names it)."""
    root = cases_dir()
    return (root if root is not None else Path(PREFIX)) / name


def resolve_arguments(argv: list[str], stream=None) -> list[str]:
    """``argv`` with each ``cases/NAME`` that is missing in the working folder but bundled
    replaced by the bundled file (one note per replacement on ``stream``, default stderr)."""
    out = []
    for arg in argv:
        head, sep, value = arg.partition("=") if arg.startswith("--") else ("", "", arg)
        name = value[2:] if value.startswith("./") else value
        if name.startswith(PREFIX) and "/" not in name[len(PREFIX):] and not Path(value).exists():
            root = cases_dir()
            bundled = None if root is None else root / name[len(PREFIX):]
            if bundled is not None and bundled.is_file():
                print(f"note: {value} is not in this folder; reading the bundled {bundled}", file=stream or sys.stderr)
                arg = f"{head}{sep}{bundled}"
        out.append(arg)
    return out
