"""The commands that run the project's benchmarks (``bench-bem``; fem_check's ``bench``) from
``benchmarks/`` of a checkout: that folder is not installed (a wheel holds what users import).

From a checkout (the working folder, or the checkout an editable install points at) the module is
imported from there; from an installed wheel the command exits 2 with one line saying so.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
from pathlib import Path

from semianalytic.errors import InputError

__all__ = ["import_benchmark"]


def import_benchmark(module_name: str, command: str):
    """The module ``benchmarks.X`` of the checkout; InputError (exit 2) outside a checkout."""
    if importlib.util.find_spec("benchmarks") is not None:
        return importlib.import_module(module_name)
    root = Path(__file__).resolve().parent.parent
    if (root / "benchmarks" / "__init__.py").is_file() and (root / "pyproject.toml").is_file():
        sys.path.insert(0, str(root))
        return importlib.import_module(module_name)
    raise InputError("command", f"{command} runs the benchmarks of a checkout of the project (its benchmarks/ folder), "
                     "which an installed package does not include; run it from a clone of the repository")
