"""The per-user cache folder, and the C kernels compiled when the package is built (this project's own).

:func:`cache_root` is the folder of every per-user cache (coefficient tables, fem_check meshes):
``$SEMIANALYTIC_CACHE_DIR`` if set, else platformdirs' user cache folder (``~/.cache/semianalytic``
on Linux).  It lives here, at the bottom of the layers, so that the models (``bem``) need not import
:mod:`semianalytic.cache`.  Nothing in that folder is ever executed or loaded as code.

:func:`load_library` loads, with ctypes, a shared library that ``pip install`` (or ``pip install
-e``, or ``python -m build``) compiled next to its C source inside the installed package
(``setup.py``: a setuptools ``Extension`` named after the source, e.g.
``semianalytic/bem/_ring.cpython-311-x86_64-linux-gnu.so``), and only that file: no compiler runs
at run time and no path a user can write to is searched.  The library carries the SHA-256 of the
source it was built from (``ring_source_sha256()``); a library built from another version of the
source (an editable install whose ``.c`` changed since), a library that does not load, or none at
all (no compiler when the package was built: the extension is optional) give ``None`` and the
caller keeps its numpy code; the first two with one warning, the last with one debug line.

Flags (setup.py): ``-O3 -fno-fast-math -ffp-contract=off -fno-math-errno``; not ``-march=native``.
IEEE arithmetic with each operation rounded as written: no contraction of ``a*b + c`` into a fused
multiply-add (GCC contracts by default wherever the target has FMA, aarch64 always, x86-64 with
``-march=native``), so the compiled kernels round like the numpy ones, operation for operation,
except the polynomials' order of summation.  ``-march=native`` would make a wheel built on one
machine crash with an illegal instruction on an older one; the AVX2 clones of ``_ring.c`` are picked
by the processor at load time instead.  ``-fno-math-errno`` only lets ``sqrt`` be one instruction (no
``errno`` is read anywhere); the results are the same.
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import warnings
from pathlib import Path

_char, _addressof = ctypes.c_char, ctypes.addressof

__all__ = ["CACHE_ENV", "cache_root", "library_path", "load_library", "address"]

CACHE_ENV = "SEMIANALYTIC_CACHE_DIR"


def address(a) -> int | None:
    """The address of the data of a C-contiguous numpy array ``a`` (None for None), for a
    ctypes call; the caller keeps ``a`` alive during the call.

    ``ctypes.c_char.from_buffer`` takes 0.7 microseconds where numpy's ``a.ctypes.data`` takes
    2.2 (it builds a Python helper object each time); a table makes about 17000 such calls.
    Read-only, empty or non-contiguous arrays, which the buffer route refuses, fall back to
    ``a.ctypes.data``."""
    if a is None:
        return None
    if not a.flags.writeable:  # the buffer route raises for these: no exception to catch
        return a.ctypes.data
    try:
        return _addressof(_char.from_buffer(a))
    except (TypeError, ValueError, BufferError):
        return a.ctypes.data


def _debug(msg: str, *args) -> None:
    import logging  # here: the cache module imports this one, and a command's start-up need not pay for it

    logging.getLogger(__name__).debug(msg, *args)


def cache_root() -> Path:
    """``$SEMIANALYTIC_CACHE_DIR`` if set, else the per-user cache folder (platformdirs)."""
    env = os.environ.get(CACHE_ENV)
    if env:
        return Path(env).expanduser()
    from platformdirs import user_cache_dir

    return Path(user_cache_dir("semianalytic", appauthor=False))


def library_path(source: Path) -> Path | None:
    """The library built from the C ``source`` at install time, next to it (the interpreter's
    extension-module suffixes, in its order of preference), or None."""
    import importlib.machinery

    for suffix in importlib.machinery.EXTENSION_SUFFIXES:
        path = source.with_name(source.stem + suffix)
        if path.is_file():
            return path
    return None


def load_library(source: Path, check: str = "ring_source_sha256"):
    """The library built from the C ``source`` when the package was installed, loaded (a
    ``ctypes.CDLL``), or None: not built, not loadable, or built from another version of
    ``source`` (its function ``check`` returns the SHA-256 of the source it was compiled from)."""
    path = library_path(source)
    if path is None:
        _debug("no compiled %s next to %s (built without a C compiler): numpy kernels", source.stem, source)
        return None
    try:
        lib = ctypes.CDLL(str(path))
        fn = getattr(lib, check)
    except (OSError, AttributeError) as exc:
        warnings.warn(f"{path} does not load ({exc}); the numpy kernels are used (reinstall the package)",
                      RuntimeWarning, stacklevel=3)
        return None
    fn.restype, fn.argtypes = ctypes.c_char_p, []
    try:
        want = hashlib.sha256(source.read_bytes()).hexdigest()
    except OSError:  # the source is not installed beside its library: nothing to compare
        return lib
    got = (fn() or b"").decode("ascii", "replace")
    if got != want:
        warnings.warn(f"{path.name} was built from another version of {source.name}; the numpy kernels are used "
                      "(rebuild: pip install -e . in a checkout, or reinstall)", RuntimeWarning, stacklevel=3)
        return None
    return lib
