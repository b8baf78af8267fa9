"""The per-user cache folder, and C sources compiled there on first use (this project's own).

:func:`cache_root` is the folder of every per-user cache (coefficient tables, fem_check meshes,
compiled kernels): ``$SEMIANALYTIC_CACHE_DIR`` if set, else platformdirs' user cache folder
(``~/.cache/semianalytic`` on Linux).  It lives here, at the bottom of the layers, so that the
models (``bem``) can find their compiled kernels without importing :mod:`semianalytic.cache`.

:func:`load_library` compiles a C source of the package with the system C compiler (``$CC`` if
set, else sysconfig's ``CC``, else ``cc``) into ``cache_root()/native/<name>-<hash>.so``, the hash
being of the source and the compiler flags, and loads it with ctypes; later processes only load
it (about a millisecond).  The library is written under a temporary name and renamed, so that
two processes compiling at once (pytest -n 2) never load a half-written file.  Nothing is
written into the source tree.  No compiler, a failed compilation or an unwritable cache give
``None`` (one debug line in the log), and the caller keeps its numpy code.

Flags: ``-O3 -fPIC -shared -fno-fast-math -ffp-contract=off -fno-math-errno``; not
``-march=native``.  IEEE arithmetic with each operation rounded as written: no contraction of
``a*b + c`` into a fused multiply-add (GCC contracts by default wherever the target has FMA,
aarch64 always, x86-64 with ``-march=native``), so the compiled kernels round like the numpy
ones, operation for operation, except the polynomials' order of summation.  ``-march=native``
bought nothing measurable here (the kernel loop calls ``log`` and is not vectorised) and would
make a library built on one machine crash with an illegal instruction on an older one sharing
the same home folder (clusters).  ``-fno-math-errno`` only lets ``sqrt`` be one instruction
(no ``errno`` is read anywhere); the results are the same.
"""

from __future__ import annotations

import ctypes
import os
from pathlib import Path

_char, _addressof = ctypes.c_char, ctypes.addressof

__all__ = ["CACHE_ENV", "NATIVE_ENV", "cache_root", "native_dir", "load_library", "address", "CFLAGS"]

CACHE_ENV = "SEMIANALYTIC_CACHE_DIR"
CFLAGS = ("-O3", "-fPIC", "-shared", "-fno-fast-math", "-ffp-contract=off", "-fno-math-errno")


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


NATIVE_ENV = "SEMIANALYTIC_NATIVE_DIR"


def native_dir() -> Path:
    """The folder of the compiled libraries: ``$SEMIANALYTIC_NATIVE_DIR`` if set, else
    ``cache_root()/native``.  The variable lets processes with their own table caches (the test
    suite gives many tests a fresh ``$SEMIANALYTIC_CACHE_DIR``) share one compiled library
    instead of compiling it again in each (about 0.25 s)."""
    env = os.environ.get(NATIVE_ENV)
    return Path(env).expanduser() if env else cache_root() / "native"


def _compiler() -> list[str] | None:
    """The C compiler command: ``$CC`` when set (and then only it), else sysconfig's ``CC`` or
    ``cc``, the first found on the PATH; None when there is none."""
    import shlex
    import shutil
    import sysconfig

    env = os.environ.get("CC")
    for cand in (env,) if env else (sysconfig.get_config_var("CC"), "cc"):
        cmd = shlex.split(cand or "")
        if cmd and shutil.which(cmd[0]):
            return cmd
    return None


def _compile(source: Path, target: Path) -> bool:
    import subprocess
    import tempfile

    cmd = _compiler()
    if cmd is None:
        _debug("no C compiler found ($CC, sysconfig CC, cc): numpy kernels")
        return False
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    os.close(fd)
    # the compiler's own temporary files (cc*.s, cc*.o) in a folder of ours, removed whatever happens
    # (issue 40: a compiler killed by Ctrl-C or SIGTERM left them in $TMPDIR)
    scratch = tempfile.mkdtemp(prefix=f".{target.name}.cc-", dir=target.parent)
    try:
        try:
            proc = subprocess.run([*cmd, *CFLAGS, "-o", tmp, str(source), "-lm"], capture_output=True, text=True,
                                  timeout=300, env={**os.environ, "TMPDIR": scratch})
        except subprocess.SubprocessError as exc:  # a compiler that hangs
            _debug("compiling %s failed (%s): numpy kernels", source.name, exc)
            return False
        if proc.returncode != 0:
            _debug("compiling %s failed (%s): numpy kernels\n%s", source.name, " ".join(cmd), proc.stderr)
            return False
        os.chmod(tmp, 0o755)
        os.replace(tmp, target)
        return True
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
        import shutil

        shutil.rmtree(scratch, ignore_errors=True)


def load_library(source: Path):
    """The C ``source`` compiled (on first use) into the per-user cache and loaded (a
    ``ctypes.CDLL``), or None."""
    import ctypes
    import hashlib

    try:
        data = source.read_bytes()
        key = hashlib.sha256(data + "\0".join(CFLAGS).encode()).hexdigest()[:20]
        target = native_dir() / f"{source.stem.lstrip('_')}-{key}.so"
        if not target.is_file() and not _compile(source, target):
            return None
        return ctypes.CDLL(str(target))
    except OSError as exc:  # unwritable cache, a library that does not load
        _debug("compiled %s unavailable (%s): numpy kernels", source.name, exc)
        return None
