"""The output folder of a run: built in a staging folder, swapped in at the end.

Nothing appears under ``DIR`` until every file is written; a failure (bad input found late,
an exception, Ctrl-C, SIGTERM) leaves ``DIR`` exactly as it was and removes the staging folder.
Every folder written this way carries a manifest (:data:`MANIFEST`) of the files the command
wrote: ``--force`` replaces a folder only when it holds nothing else (this project's own rule,
issue 27: a file the tool did not write is never deleted).  The home folder, ``/``, the working
folder, any folder above it and any folder holding a case file are refused outright.  Every
relative path goes through :func:`semianalytic.io.contained_path`, so no name taken from a case
file can escape the folder.  Two commands writing into one ``DIR`` at once: the second stops
with exit status 2 (each staging folder names its owner's host and process id).
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from semianalytic.errors import InputError
from semianalytic.io import atomic_write_bytes, atomic_write_json, atomic_write_text, contained_path, interrupt_on_termination

MANIFEST = ".semianalytic-manifest.json"


def manifest_files(folder: Path) -> set[str] | None:
    """The files (POSIX paths relative to ``folder``) listed in its manifest; None when the
    folder has no readable manifest."""
    try:
        data = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
        files = data["files"]
        if not isinstance(files, list) or not all(isinstance(f, str) for f in files):
            return None
        return set(files)
    except (OSError, ValueError, KeyError, TypeError):
        return None


def first_foreign(folder: Path) -> str | None:
    """The first entry (sorted walk) of ``folder`` that its manifest does not list, or None when
    every file was written by this tool.  Folders count as ours when they hold only our files."""
    listed = manifest_files(folder)
    for dirpath, dirnames, filenames in os.walk(folder):
        dirnames.sort()
        rel_dir = Path(dirpath).relative_to(folder)
        for name in sorted(filenames) + [d for d in dirnames if os.path.islink(os.path.join(dirpath, d))]:
            rel = (rel_dir / name).as_posix()
            if rel == MANIFEST and listed is not None:
                continue
            if listed is None or rel not in listed:
                return rel
    return None


def write_manifest(folder: Path, command: str | None = None) -> None:
    """List every file now under ``folder`` in its manifest (called on the staging folder)."""
    files = sorted((Path(d) / f).relative_to(folder).as_posix() for d, _, fs in os.walk(folder) for f in fs
                   if not (Path(d) == folder and f == MANIFEST))
    payload = {"tool": "semianalytic", "what": "files written by the command; --force replaces only these",
               "files": files}
    if command:
        payload["command"] = command
    atomic_write_json(folder / MANIFEST, payload)


def _forbidden(resolved: Path, protect: Iterable[str | os.PathLike] = ()) -> str | None:
    """Why ``resolved`` may never be an output folder, or None."""
    if resolved == Path(resolved.anchor):
        return "is the root folder"
    try:
        home = Path.home().resolve()
    except (RuntimeError, OSError):
        home = None
    if home is not None and (resolved == home or resolved in home.parents):
        return "is the home folder or contains it"
    cwd = Path.cwd().resolve()
    if resolved == cwd or resolved in cwd.parents:
        return "is the working folder or contains it"
    for p in protect:
        try:
            parent = Path(p).resolve().parent
        except (OSError, RuntimeError):
            continue
        if resolved == parent or resolved in parent.parents:
            return f"holds the case file {Path(p).name!r}"
    return None


def forbidden_output(out: str | os.PathLike, field: str = "--out", protect: Iterable[str | os.PathLike] = ()) -> None:
    """Refuse, outright, an output folder that is ``/``, the home folder, the working folder (or
    above it) or the folder of a case file in ``protect`` (commands that write named files into
    a folder instead of replacing it, e.g. ``sweep``)."""
    try:
        why = _forbidden(Path(out).resolve(), protect)
    except (OSError, RuntimeError) as exc:
        raise InputError(field, f"cannot use {str(out)!r}: {exc}") from None
    if why is not None:
        raise InputError(field, f"{str(out)!r} {why}; name a new folder (e.g. out/sweep1)")


def check_output_dir(out: str | os.PathLike, force: bool, field: str = "--out",
                     protect: Iterable[str | os.PathLike] = ()) -> Path:
    """Refuse an existing non-empty ``out`` without ``force``; with ``force``, one holding any
    file its manifest does not list (naming the first); a path that is a file; and, outright,
    ``/``, the home folder, the working folder (or a folder above it) and the folder of any
    case file in ``protect`` (or a folder above it)."""
    if not str(out).strip():
        raise InputError(field, "expected a folder; got an empty path")
    out = Path(out)
    try:
        resolved = out.resolve()
        why = _forbidden(resolved, protect)
        if why is not None:
            raise InputError(field, f"{str(out)!r} {why}; the output folder is replaced as a whole, "
                                    "so name a new folder (e.g. out/run1)")
        if out.exists() and not out.is_dir():
            raise InputError(field, f"{str(out)!r} exists and is not a folder")
        if out.exists() and any(out.iterdir()):
            if not force:
                raise InputError(field, f"{str(out)!r} exists; pass --force to overwrite it")
            foreign = first_foreign(out)
            if foreign is not None:
                raise InputError(field, f"{str(out)!r} holds {foreign!r}, which this tool did not write (not in "
                                        f"{MANIFEST}); --force replaces only the tool's own files: move it or "
                                        "choose another folder")
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


class OutputBusy(InputError):
    """Another live command is writing into the same output folder."""


def _live_rivals(final: Path, mine: Path) -> list[Path]:
    """Staging folders of ``final`` (other than ``mine``) whose owner is a live process of this
    host, that were made before ``mine`` (ties: by name): the earlier writer goes on."""
    import re
    import socket

    host = "".join(c for c in socket.gethostname() if c.isalnum() or c == "-")[:40] or "host"
    pattern = re.compile(re.escape(f".{final.name}.partial-") + r"(?P<host>[A-Za-z0-9-]+)\.(?P<pid>\d+)-[^/]*")
    try:
        me = (mine.stat().st_mtime_ns, mine.name)
        siblings = list(final.parent.iterdir())
    except OSError:
        return []
    rivals = []
    for path in siblings:
        m = pattern.fullmatch(path.name)
        if path == mine or not m or m.group("host") != host or int(m.group("pid")) == os.getpid():
            continue
        try:
            when = (path.stat().st_mtime_ns, path.name)
        except OSError:
            continue
        if _process_alive(int(m.group("pid"))) and when < me:
            rivals.append(path)
    return rivals


class StagedDir:
    """``with StagedDir(out, force) as d: d.write_text("report.md", ...)``.

    Files go to a hidden sibling folder; on a clean exit the manifest is written and the folder
    replaces ``out`` (the old folder, checked to hold only the tool's files, is moved aside first
    and removed after the swap).  On an exception, Ctrl-C or SIGTERM the staging folder is
    removed and ``out`` is untouched.  ``protect``: case files whose folders may not be replaced.
    """

    def __init__(self, out: str | os.PathLike, force: bool = False, field: str = "--out",
                 protect: Iterable[str | os.PathLike] = ()):
        self.protect = tuple(protect)
        self.final = check_output_dir(out, force, field, self.protect).absolute()
        self.force = force
        self.field = field
        self.root: Path | None = None
        self.files: list[str] = []
        self._restore_signals = lambda: None

    # -- context -------------------------------------------------------------------------
    def __enter__(self) -> StagedDir:
        try:
            self.final.parent.mkdir(parents=True, exist_ok=True)
            remove_stale_staging(self.final)
            self.root = Path(tempfile.mkdtemp(prefix=f".{self.final.name}.partial-{_owner()}-", dir=self.final.parent))
        except OSError as exc:
            raise InputError(self.field, f"cannot create {str(self.final)!r}: {exc.strerror or exc}") from None
        rivals = _live_rivals(self.final, self.root)
        if rivals:
            shutil.rmtree(self.root, ignore_errors=True)
            pid = rivals[0].name.split("partial-", 1)[1].split("-")[0].rsplit(".", 1)[-1]
            raise OutputBusy(self.field, f"another command (process {pid}) is writing into {str(self.final)!r}; "
                                         "wait for it to finish or choose another folder")
        from semianalytic.io import _umask

        os.chmod(self.root, 0o777 & ~_umask())  # mkdtemp makes 0700; the report folder is for reading
        self._restore_signals = interrupt_on_termination()  # SIGTERM/SIGHUP remove the staging folder as Ctrl-C does
        return self

    def __exit__(self, exc_type, exc, tb) -> bool:
        try:
            if exc_type is not None:
                shutil.rmtree(self.root, ignore_errors=True)
                return False
            self._commit()
            return False
        finally:
            self._restore_signals()

    def _commit(self) -> None:
        write_manifest(self.root)
        old = None
        if self.final.exists():
            check_output_dir(self.final, self.force, self.field, self.protect)  # it may have changed meanwhile
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
    import sys

    from semianalytic.cli_types import OneLineParser, output_dir
    from semianalytic.io import check_report_target

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
