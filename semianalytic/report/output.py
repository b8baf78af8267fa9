"""The output folder of a run: built in a staging folder, swapped in at the end.

Nothing appears under ``DIR`` until every file is written; a failure (bad input found late,
an exception, Ctrl-C) leaves ``DIR`` exactly as it was.  An existing ``DIR`` is replaced only
with ``force``; every relative path goes through :func:`semianalytic.io.contained_path`, so
no name taken from a case file can escape the folder.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from pathlib import Path
from typing import Any

from semianalytic.errors import InputError
from semianalytic.io import atomic_write_bytes, atomic_write_json, atomic_write_text, contained_path


def check_output_dir(out: str | os.PathLike, force: bool, field: str = "--out") -> Path:
    """Refuse an existing ``out`` without ``force``, a path that is a file, and the working
    folder or any folder above it: the output folder is replaced as a whole (``StagedDir``),
    so ``--out .`` or ``--out ''`` with ``--force`` would delete the user's files."""
    if not str(out).strip():
        raise InputError(field, "expected a folder; got an empty path")
    out = Path(out)
    try:
        resolved, cwd = out.resolve(), Path.cwd().resolve()
        if resolved == cwd or resolved in cwd.parents:
            raise InputError(field, f"{str(out)!r} is the working folder or contains it; the output folder is "
                                    "replaced as a whole, so name a new folder (e.g. out/run1)")
        if out.exists() and not out.is_dir():
            raise InputError(field, f"{str(out)!r} exists and is not a folder")
        if out.exists() and not force and any(out.iterdir()):
            raise InputError(field, f"{str(out)!r} exists; pass --force to overwrite it")
    except OSError as exc:
        raise InputError(field, f"cannot use {str(out)!r}: {exc.strerror or exc}") from None
    return out


STALE_AGE = 24 * 3600.0  # a staging folder this old [s] is stale whoever made it


def _owner() -> str:
    """``HOST.PID`` of this process, written into the name of its staging folders."""
    import socket

    host = "".join(c for c in socket.gethostname() if c.isalnum() or c == "-")[:40] or "host"
    return f"{host}.{os.getpid()}"


def _process_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's live process
        return True
    return True


def remove_stale_staging(final: Path, now: float | None = None) -> list[Path]:
    """Remove the hidden ``.NAME.partial-*`` and ``.NAME.old-*`` siblings of ``final`` left by
    killed runs: those whose owning process (same host) is gone, and any older than
    :data:`STALE_AGE`.  A live run's folder (same host, process alive, recent) is kept, and so
    is anything that is not a folder or not named after ``final``.  Returns what was removed."""
    import re
    import socket
    import time

    now = time.time() if now is None else now
    host = "".join(c for c in socket.gethostname() if c.isalnum() or c == "-")[:40] or "host"
    pattern = re.compile(re.escape(f".{final.name}.") + r"(partial|old)-(?:(?P<host>[A-Za-z0-9-]+)\.(?P<pid>\d+)-)?[^/]*")
    removed = []
    try:
        siblings = list(final.parent.iterdir())
    except OSError:
        return removed
    for path in siblings:
        match = pattern.fullmatch(path.name)
        if not match or path.is_symlink() or not path.is_dir():
            continue
        try:
            age = now - path.lstat().st_mtime
        except OSError:
            continue
        ours = match.group("host") == host and match.group("pid") is not None
        gone = ours and not _process_alive(int(match.group("pid")))
        if gone or age > STALE_AGE:
            shutil.rmtree(path, ignore_errors=True)
            removed.append(path)
    return removed


class StagedDir:
    """``with StagedDir(out, force) as d: d.write_text("report.md", ...)``.

    Files go to a hidden sibling folder; on a clean exit it replaces ``out`` (the old folder is
    moved aside first and removed after the swap).  On an exception the staging folder is
    removed and ``out`` is untouched.
    """

    def __init__(self, out: str | os.PathLike, force: bool = False, field: str = "--out"):
        self.final = check_output_dir(out, force, field).absolute()
        self.force = force
        self.field = field
        self.root: Path | None = None
        self.files: list[str] = []

    # -- context -------------------------------------------------------------------------
    def __enter__(self) -> "StagedDir":
        try:
            self.final.parent.mkdir(parents=True, exist_ok=True)
            remove_stale_staging(self.final)
            self.root = Path(tempfile.mkdtemp(prefix=f".{self.final.name}.partial-{_owner()}-", dir=self.final.parent))
        except OSError as exc:
            raise InputError(self.field, f"cannot create {str(self.final)!r}: {exc.strerror or exc}") from None
        from semianalytic.io import _umask

        os.chmod(self.root, 0o777 & ~_umask())  # mkdtemp makes 0700; the report folder is for reading
        return self

    def __exit__(self, exc_type, exc, tb) -> bool:
        if exc_type is not None:
            shutil.rmtree(self.root, ignore_errors=True)
            return False
        self._commit()
        return False

    def _commit(self) -> None:
        old = None
        if self.final.exists():
            check_output_dir(self.final, self.force)  # it may have appeared meanwhile
            old = Path(tempfile.mkdtemp(prefix=f".{self.final.name}.old-{_owner()}-", dir=self.final.parent))
            os.replace(self.final, old / "previous")
        try:
            os.replace(self.root, self.final)
        except BaseException:
            if old is not None:  # put the previous folder back
                os.replace(old / "previous", self.final)
            shutil.rmtree(self.root, ignore_errors=True)
            raise
        finally:
            if old is not None:
                shutil.rmtree(old, ignore_errors=True)
        self.root = self.final

    # -- writing -------------------------------------------------------------------------
    def path(self, relative: str, field: str = "output") -> Path:
        """Absolute staging path of ``relative``; refuses anything that leaves the folder."""
        assert self.root is not None, "use StagedDir as a context manager"
        p = contained_path(self.root, relative, field)
        p.parent.mkdir(parents=True, exist_ok=True)
        rel = p.relative_to(self.root.resolve()).as_posix()
        if rel not in self.files:
            self.files.append(rel)
        return p

    def write_bytes(self, relative: str, data: bytes, field: str = "output") -> str:
        atomic_write_bytes(self.path(relative, field), data)
        return relative

    def write_text(self, relative: str, text: str, field: str = "output") -> str:
        atomic_write_text(self.path(relative, field), text)
        return relative

    def write_json(self, relative: str, obj: Any, field: str = "output") -> str:
        atomic_write_json(self.path(relative, field), json_safe(obj))
        return relative


def json_safe(obj: Any) -> Any:
    """Convert numpy scalars/arrays and non-finite floats (-> None) into plain JSON values."""
    import math

    import numpy as np

    if isinstance(obj, dict):
        return {str(k): json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_safe(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return json_safe(obj.tolist())
    if isinstance(obj, (np.bool_,)):
        return bool(obj)
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        v = float(obj)
        return v if math.isfinite(v) else None
    if isinstance(obj, Path):
        return obj.as_posix()
    if obj is None or isinstance(obj, (str, int, bool)):
        return obj
    return json.loads(json.dumps(obj, default=str))


def stamp_version(markdown: str) -> str:
    """``markdown`` with a line naming the version that made it (package version and
    ``git describe``) after its title: a committed report says what made it."""
    from semianalytic.report.provenance import version

    title, _, rest = markdown.partition("\n")
    return f"{title}\n\nVersion: {version()}.\n" + (rest if rest.startswith("\n") else "\n" + rest)


def report_command(prog: str, description: str, filename: str, build, argv: list[str] | None = None) -> int:
    """``main`` shared by the report modules: ``--out DIR [--force]``.

    ``build(out) -> (markdown, {png name: bytes})``; the figures and then the report are
    written atomically; an existing report is kept unless ``--force`` (exit status 2).
    """
    import argparse
    import sys

    from semianalytic.io import check_report_target

    from semianalytic.cli_types import OneLineParser, output_dir

    parser = OneLineParser(prog=prog, description=description)
    parser.add_argument("--out", default="reports", type=output_dir, help="output folder (default reports/)")
    parser.add_argument("--force", action="store_true", help="overwrite an existing report")
    args = parser.parse_args(argv)
    out = Path(args.out)
    try:
        target = check_report_target(out / filename, args.force)
        text, figs = build(out)
        text = stamp_version(text)
        for name, data in figs.items():
            atomic_write_bytes(out / name, data)
        atomic_write_text(target, text)
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(f"wrote {target}")
    return 0
