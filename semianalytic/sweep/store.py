"""Results of a sweep, appended as cases finish, readable after any interruption.

Two formats, both resumable by ``case_id``:

- ``csv``: one file ``results.csv``; each finished batch is appended with one ``write`` and
  ``fsync``.  A process killed in the middle of a write can leave a last line without its
  newline; :meth:`ResultStore.open` cuts it off, so that case is simply run again.
- ``parquet``: a folder ``results.parquet/`` of ``part-*.parquet`` files, each written
  atomically (temporary file, then rename); it reads as one table with pandas/pyarrow.

Beside them, ``sweep.json`` (written atomically) records the case file, the spec and its
fingerprint; ``--resume`` refuses a folder whose fingerprint differs.
"""

from __future__ import annotations

import csv
import io
import math
import os
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path

import numpy as np

from semianalytic.errors import InputError
from semianalytic.io import atomic_write_bytes

FORMATS = ("csv", "parquet")


def results_path(out: Path, fmt: str) -> Path:
    return out / ("results.csv" if fmt == "csv" else "results.parquet")


def _cell(v) -> str:
    t = type(v)
    if t is float:  # the common case first (rows hold Python floats from .tolist())
        return repr(v) if math.isfinite(v) else ""
    if t is str:
        return v
    if v is None:
        return ""
    if isinstance(v, (bool, np.bool_)):
        return "true" if v else "false"
    if isinstance(v, (float, np.floating)):
        f = float(v)
        return repr(f) if math.isfinite(f) else ""
    return str(v)


class Columns:
    """A batch of results as columns (name -> array), the Monte-Carlo array path's output: written
    without building a dict per row."""

    def __init__(self, data: Mapping[str, np.ndarray]):
        self.data = dict(data)

    def __len__(self) -> int:
        return len(next(iter(self.data.values()))) if self.data else 0

    def rows(self) -> list[dict]:
        cols = {c: np.asarray(v).tolist() for c, v in self.data.items()}
        return [dict(zip(cols, vals)) for vals in zip(*cols.values())]


def _cells(values) -> list[str]:
    """The CSV cells of a column, as :func:`_cell` writes them one by one."""
    a = np.asarray(values)
    if a.dtype.kind == "f":
        out = list(map(repr, a.tolist()))  # Python floats: repr round-trips
        if not np.all(np.isfinite(a)):
            for i in np.flatnonzero(~np.isfinite(a)).tolist():
                out[i] = ""
        return out
    if a.dtype.kind == "b":
        return np.where(a, "true", "false").tolist()
    if a.dtype.kind in "iu":
        return list(map(str, a.tolist()))
    return [_cell(v) for v in a.tolist()]


class ResultStore:
    """Append-only results of one sweep (see the module docstring)."""

    def __init__(self, out: Path, fmt: str, columns: Sequence[str]):
        if fmt not in FORMATS:
            raise InputError("--format", f"must be one of {', '.join(FORMATS)}; got {fmt!r}")
        self.out = Path(out)
        self.fmt = fmt
        self.columns = list(columns)
        self.path = results_path(self.out, fmt)
        self._fh = None
        self._part = 0

    # -- reading -------------------------------------------------------------------------
    def finished_ids(self) -> set[int]:
        """Ids of the cases already in the results (any status)."""
        if not self.path.exists():
            return set()
        if self.fmt == "csv":
            self._repair_csv()
            ids = set()
            with self.path.open(newline="") as fh:
                reader = csv.reader(fh)
                header = next(reader, None)
                if header is None:
                    return set()
                if header != self.columns:
                    raise InputError("--resume", f"{self.path} has different columns from this sweep")
                for row in reader:
                    if row and len(row) == len(header):
                        ids.add(int(row[0]))
            return ids
        ids = set()
        for part in sorted(self.path.glob("part-*.parquet")):
            import pyarrow.parquet as pq

            ids.update(int(i) for i in pq.read_table(part, columns=["case_id"]).column("case_id").to_pylist())
        return ids

    def _repair_csv(self) -> None:
        """Cut a trailing partial line (a write interrupted by a kill)."""
        size = self.path.stat().st_size
        if size == 0:
            return
        with self.path.open("rb+") as fh:
            fh.seek(-1, os.SEEK_END)
            if fh.read(1) == b"\n":
                return
            data = self.path.read_bytes()
            cut = data.rfind(b"\n") + 1
            fh.truncate(cut)

    def read(self):
        """All results as a pandas DataFrame sorted by case id."""
        import pandas as pd

        if self.fmt == "csv":
            self._repair_csv()
            df = pd.read_csv(self.path)
        else:
            parts = sorted(self.path.glob("part-*.parquet"))
            df = pd.concat([pd.read_parquet(p) for p in parts], ignore_index=True) if parts else pd.DataFrame(columns=self.columns)
        return df.sort_values("case_id").reset_index(drop=True)

    # -- writing -------------------------------------------------------------------------
    def open(self, fresh: bool) -> ResultStore:
        self.out.mkdir(parents=True, exist_ok=True)
        if self.fmt == "csv":
            if fresh or not self.path.exists() or self.path.stat().st_size == 0:
                header = io.StringIO()
                csv.writer(header, lineterminator="\n").writerow(self.columns)
                atomic_write_bytes(self.path, header.getvalue().encode())
            else:
                self._repair_csv()
            self._fh = open(self.path, "ab", buffering=0)
        else:
            self.path.mkdir(parents=True, exist_ok=True)
            existing = sorted(self.path.glob("part-*.parquet"))
            self._part = 1 + max((int(p.stem.split("-")[1]) for p in existing), default=-1)
        return self

    def append(self, rows: Iterable[Mapping]) -> int:
        """Append finished rows (dicts keyed by column); returns how many were written."""
        if isinstance(rows, Columns):
            return self._append_columns(rows)
        rows = list(rows)
        if not rows:
            return 0
        if self.fmt == "csv":
            buf = io.StringIO()
            w = csv.writer(buf, lineterminator="\n")
            for r in rows:
                w.writerow([_cell(r.get(c)) for c in self.columns])
            data = buf.getvalue().encode()
            os.write(self._fh.fileno(), data)  # one write per batch
            os.fsync(self._fh.fileno())
        else:
            import pandas as pd

            df = pd.DataFrame([{c: r.get(c) for c in self.columns} for r in rows], columns=self.columns)
            buf = io.BytesIO()
            df.to_parquet(buf, index=False)
            atomic_write_bytes(self.path / f"part-{self._part:06d}.parquet", buf.getvalue())
            self._part += 1
        return len(rows)

    def _append_columns(self, batch: Columns) -> int:
        n = len(batch)
        if n == 0:
            return 0
        if self.fmt != "csv":
            return self.append(batch.rows())
        empty = [""] * n
        cells = [_cells(batch.data[c]) if c in batch.data else empty for c in self.columns]
        buf = io.StringIO()
        csv.writer(buf, lineterminator="\n").writerows(zip(*cells))
        os.write(self._fh.fileno(), buf.getvalue().encode())  # one write per batch
        os.fsync(self._fh.fileno())
        return n

    def close(self) -> None:
        if self._fh is not None:
            self._fh.close()
            self._fh = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False
