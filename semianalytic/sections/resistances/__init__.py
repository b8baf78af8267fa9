"""Resistance models added one file each: every module in this folder is imported by the case layer
(:mod:`semianalytic.case`, which loads them once), and registers its ``[target.resistance]``
input there with :func:`~semianalytic.sections.penetration.register_resistance`.

A module here holds the model (a frozen dataclass of SI values with ``name``, ``equation`` and
``pressure(diameter)``) and its input (a :class:`~semianalytic.sections.penetration.ResistanceInput`
with ``model: Literal["name"]`` and ``build()``); docs/extending.md walks through one.
"""

from __future__ import annotations

import importlib
import pkgutil

__all__ = ["load_all"]


def load_all() -> list[str]:
    """Import every module of this folder (each registers its model); returns their names."""
    names = [m.name for m in pkgutil.iter_modules(__path__) if not m.name.startswith("_")]
    for name in names:
        importlib.import_module(f"{__name__}.{name}")
    return names
