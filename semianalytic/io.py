"""Safe outputs: atomic writes, no silent overwrite, no path escaping its directory."""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path
from typing import Any

from semianalytic.errors import InputError


def atomic_write_bytes(path: str | os.PathLike, data: bytes, *, overwrite: bool = True) -> Path:
    """Write ``data`` to ``path`` through a temporary file in the same folder, then rename.

    Readers never see a half-written file.  With ``overwrite=False`` an existing file is an
    ``InputError`` and nothing is written.
    """
    path = Path(path)
    if path.exists() and not overwrite:
        raise InputError(str(path), "exists; pass --force to overwrite it")
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give the file the usual permissions
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise
    return path


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def atomic_write_text(path: str | os.PathLike, text: str, *, overwrite: bool = True) -> Path:
    """Text version of :func:`atomic_write_bytes` (UTF-8)."""
    return atomic_write_bytes(path, text.encode("utf-8"), overwrite=overwrite)


def atomic_write_json(path: str | os.PathLike, obj: Any, *, overwrite: bool = True) -> Path:
    """Write ``obj`` as indented JSON, atomically."""
    return atomic_write_text(path, json.dumps(obj, indent=2, allow_nan=False) + "\n", overwrite=overwrite)


def contained_path(root: str | os.PathLike, relative: str, field: str) -> Path:
    """``root / relative``, refusing any path (absolute, ``..``, symlink) that leaves ``root``."""
    root = Path(root).resolve()
    candidate = (root / relative).resolve()
    if candidate != root and root not in candidate.parents:
        raise InputError(field, f"path {relative!r} leaves the output folder {str(root)!r}")
    return candidate


def check_report_target(path: str | os.PathLike, force: bool) -> Path:
    """A report path that may be written: refuse to overwrite an existing one without force."""
    path = Path(path)
    try:
        exists = path.exists()
    except OSError as exc:  # e.g. a name longer than the file system allows
        raise InputError("--report", f"cannot use {str(path)[:60]!r}: {exc.strerror}") from None
    if exists and not force:
        raise InputError(str(path), "exists; pass --force to overwrite it")
    return path


def extract_revision(revision: str, dest: str | os.PathLike, *paths: str, field: str = "--base") -> Path:
    """The folders ``paths`` of git ``revision`` of this repository, extracted into ``dest``
    (benchmarks against an earlier version).  A revision git does not know: InputError."""
    import subprocess

    root = Path(__file__).resolve().parent.parent
    got = subprocess.run(["git", "archive", revision, *paths], cwd=root, capture_output=True)
    if got.returncode != 0:
        raise InputError(field, f"git does not know the revision {revision!r} ({got.stderr.decode().strip()[:80]})")
    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    subprocess.run(["tar", "-x", "-C", str(dest)], input=got.stdout, check=True)
    return dest
