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


def interrupt_on_termination():
    """SIGTERM and SIGHUP raise KeyboardInterrupt (as Ctrl-C does) until the returned undo is
    called, so that staging folders and temporary files are removed on the way out.
    Only in the main thread, and only where the signal has its default handler."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        return lambda: None

    def interrupt(signum, frame):
        raise KeyboardInterrupt(f"signal {signal.Signals(signum).name}")

    old = {}
    for sig in (signal.SIGTERM, getattr(signal, "SIGHUP", None)):
        if sig is None:
            continue
        try:
            if signal.getsignal(sig) in (signal.SIG_DFL, None):
                old[sig] = signal.signal(sig, interrupt)
        except (ValueError, OSError):
            pass

    def restore():
        for sig, handler in old.items():
            try:
                signal.signal(sig, handler)
            except (ValueError, OSError):
                pass
        old.clear()

    return restore


def check_file_target(path: str | os.PathLike, field: str, inputs=()) -> Path:
    """Refuse (issue 40), before anything is written, an output file that is one of ``inputs``
    (the case files of the same command line: ``penetrate CASE --csv CASE --force`` would
    replace the case) or that exists and is not a regular file (a FIFO, a device, a socket:
    ``--force`` would replace it by a regular file, or block on it).  A symbolic link is judged
    by what it points to."""
    path = Path(path)
    try:
        st = path.stat() if os.path.lexists(path) else None
    except OSError as exc:
        raise InputError(field, f"cannot use {str(path)[:60]!r}: {exc.strerror}") from None
    if st is None:
        return path
    import stat

    if not stat.S_ISREG(st.st_mode):
        kind = ("a folder" if stat.S_ISDIR(st.st_mode) else "a named pipe (FIFO)" if stat.S_ISFIFO(st.st_mode) else
                "a device" if stat.S_ISCHR(st.st_mode) or stat.S_ISBLK(st.st_mode) else
                "a socket" if stat.S_ISSOCK(st.st_mode) else "not a regular file")
        raise InputError(field, f"{str(path)!r} is {kind}, not a regular file; name a new file")
    for given in inputs:
        try:
            same = os.path.samefile(path, given)
        except OSError:
            same = False
        if same:
            raise InputError(field, f"{str(path)!r} is the input file {str(given)!r} of this command; "
                                    "name another file (nothing was written)")
    return path


def check_report_target(path: str | os.PathLike, force: bool, inputs=()) -> Path:
    """A report path that may be written: refuse to overwrite an existing one without force, and
    a report into ``/``, the home folder (or above it) or a folder above the working
    folder (``--report OUT/../../..``)."""
    path = Path(path)
    try:
        exists = path.exists()
        folder = path.parent.resolve()
        cwd, home = Path.cwd().resolve(), Path.home().resolve()
        if folder == Path(folder.anchor) or folder == home or folder in home.parents or folder in cwd.parents:
            raise InputError("--report", f"{str(path.parent)!r} is the root or home folder or lies above the working "
                                         "folder; write reports into a folder of their own")
    except OSError as exc:  # e.g. a name longer than the file system allows
        raise InputError("--report", f"cannot use {str(path)[:60]!r}: {exc.strerror}") from None
    check_file_target(path, "--report", inputs)
    if exists and not force:
        raise InputError(str(path), "exists; pass --force to overwrite it")
    if exists and not written_by_the_tool(path):
        raise InputError(str(path), "exists and was not written by this tool (no 'Generated by' line): --force replaces "
                                    "only the tool's own reports; move it away or write elsewhere")
    return path


def written_by_the_tool(path: str | os.PathLike) -> bool:
    """Whether the existing report ``path`` is one a command of this project wrote: a Markdown or
    HTML report names the command that made it ("Generated by `...`") in its first lines; any other
    kind of file (a benchmark's JSON, a figure) is judged by its report, not here."""
    path = Path(path)
    if path.suffix.lower() not in (".md", ".html", ".htm"):
        return True
    if not path.is_file():
        return False
    try:
        with path.open("rb") as fh:  # an HTML report embeds its figures before the line may come
            text = fh.read(16384 if path.suffix.lower() == ".md" else 64 * 2**20)
    except OSError:
        return False
    return b"Generated by `" in text or b"Generated by <code>" in text


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


# ------------------------------------------------------------------------------------------
# Self-verifying cache entries (issue 27; this project's own format): a file is
#   b"SEMIANALYTIC-CACHE 1\n" + one JSON line {"key", "sha256", "size", ...} + b"\n" + payload,
# written atomically (temporary file + rename: concurrent writers of one key each rename a
# whole file, the last one wins, a reader never sees a mix).  On read the key, the size and the
# SHA-256 of the payload are checked; a damaged, truncated, empty, old-format or mismatched
# entry (another key's file copied under this name) is removed with a warning and the caller
# rebuilds it.

CACHE_MAGIC = b"SEMIANALYTIC-CACHE 1\n"


class CacheWarning(UserWarning):
    """A cache entry was found damaged or mismatched and is rebuilt."""


def write_cache_entry(path: str | os.PathLike, key: str, payload: bytes, **describe: Any) -> Path:
    """Store ``payload`` under ``key`` in ``path`` with its checksum (atomically)."""
    import hashlib

    header = {"key": key, "sha256": hashlib.sha256(payload).hexdigest(), "size": len(payload), **describe}
    line = json.dumps(header, sort_keys=True, default=str).encode("utf-8")
    return atomic_write_bytes(path, CACHE_MAGIC + line + b"\n" + payload)


def read_cache_entry(path: str | os.PathLike, key: str, what: str = "cache") -> bytes | None:
    """The payload stored under ``key`` in ``path``; None when absent.  A damaged or mismatched
    entry is removed with a :class:`CacheWarning` naming what was wrong (then None)."""
    import warnings

    path = Path(path)
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        return None
    except OSError as exc:
        why = f"unreadable ({exc.strerror or exc})"
    else:
        why = _cache_entry_fault(data, key)
        if why is None:
            return data[len(CACHE_MAGIC):].partition(b"\n")[2]
    warnings.warn(f"{what}: discarded the entry {path.name!r}: {why}; it is rebuilt", CacheWarning, stacklevel=2)
    try:
        path.unlink()
    except OSError:
        pass
    return None


def _cache_entry_fault(data: bytes, key: str) -> str | None:
    import hashlib

    if not data:
        return "empty file"
    if not data.startswith(CACHE_MAGIC):
        if data.startswith(b"PK\x03\x04"):
            return "a bare archive without key or checksum (an earlier version's, or copied there)"
        return "not a verified cache entry (damaged)"
    head, sep, payload = data[len(CACHE_MAGIC):].partition(b"\n")
    if not sep:
        return "truncated header"
    try:
        header = json.loads(head.decode("utf-8"))
        if not isinstance(header, dict):
            raise ValueError
    except (UnicodeDecodeError, ValueError):
        return "damaged header"
    if header.get("key") != key:
        return f"stored under key {str(header.get('key'))[:24]!r}, not {key[:24]!r} (an entry of something else)"
    if header.get("size") != len(payload):
        return f"truncated ({len(payload)} of {header.get('size')} bytes)"
    if header.get("sha256") != hashlib.sha256(payload).hexdigest():
        return "checksum mismatch (damaged)"
    return None


def case_input_path(case_path: str | os.PathLike | None, name: str, field: str) -> Path:
    """The file ``name`` that a case file names (a data table, a shot table, another case), read
    from the case file's folder or below it only: an absolute path, a ``..`` or a
    symbolic link leading out of that folder is refused naming ``field``, so that a case cannot
    make a command read any file of the system.  Without a case path: the working folder."""
    base = Path(case_path).parent if case_path is not None else Path(".")
    try:
        root = base.resolve()
        candidate = (root / str(name)).resolve()
    except (OSError, RuntimeError, ValueError) as exc:
        raise InputError(field, f"cannot use the path {str(name)!r}: {exc}") from None
    if Path(str(name)).is_absolute() or (candidate != root and root not in candidate.parents):
        raise InputError(field, f"{str(name)!r} lies outside the case file's folder; a file named by a case is read "
                                "only from that folder or below it (copy the file beside the case)")
    return candidate
