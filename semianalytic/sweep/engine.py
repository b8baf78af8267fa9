"""The sweep engine: cases -> batches -> dask -> results appended as batches finish.

Execution: a dask ``LocalCluster`` (processes, one thread each) by default, an existing
cluster with ``scheduler="tcp://host:port"``, or ``scheduler="inline"`` (this process, no
dask; for small runs and tests).  The client process is the only writer of the results
file, so appends never interleave.  Shared resources (coefficient tables) are prepared once
per geometry, before the batches run, and sent to the workers with the tasks; the tables
themselves are cached on disk by the content hash of the geometry and the BEM options
(:func:`semianalytic.cache.cached_coefficient_table`), so a velocity sweep solves
the BEM once, and a second sweep on the same geometry not at all.
"""

from __future__ import annotations

import functools
import hashlib
import json
import math
import os
import shutil
import sys
import time
from collections import defaultdict
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from semianalytic.case import Case, load_case, parse_case
from semianalytic.errors import InputError
from semianalytic.io import atomic_write_json
from semianalytic.sweep.kernels import Kernel, select_kernel
from semianalytic.sweep.spec import SweepSpec, apply_overrides, raw_value
from semianalytic.sweep.store import Columns, ResultStore, results_path
from semianalytic.thirdparty import deferred_interrupts

BASE_COLUMNS = ("case_id", "status", "message")
MANIFEST = "sweep.json"
STATISTICS = "statistics.json"  # distribution of every output over the finished cases


@dataclass(frozen=True)
class Payload:
    """Everything a worker needs to evaluate a batch (sent once, shared by all tasks)."""

    raw_json: str  # the base case (parsed TOML) as JSON
    case_path: str | None
    spec: SweepSpec
    kernel: Kernel
    draws: Mapping[str, np.ndarray]
    resources: Mapping[Any, Any]  # geometry key -> prepared resource (coefficient table)
    arrays_valid: bool = False  # the sampled box of the whole run checked once (Monte Carlo on arrays)


@dataclass
class SweepSummary:
    out: Path
    results: Path
    n_cases: int
    n_skipped: int  # finished before (--resume)
    n_run: int
    n_ok: int = 0
    n_invalid: int = 0
    n_error: int = 0
    seconds_total: float = 0.0
    seconds_prepare: float = 0.0
    seconds_cases: float = 0.0
    scheduler: str = ""
    workers: int = 0

    @property
    def cases_per_second(self) -> float:
        return self.n_run / self.seconds_cases if self.seconds_cases > 0 else math.nan

    def to_json(self) -> dict:
        return {
            "results": str(self.results),
            "n_cases": self.n_cases,
            "n_skipped_finished_before": self.n_skipped,
            "n_run": self.n_run,
            "n_ok": self.n_ok,
            "n_invalid": self.n_invalid,
            "n_error": self.n_error,
            "seconds_total": self.seconds_total,
            "seconds_prepare": self.seconds_prepare,
            "seconds_cases": self.seconds_cases,
            "cases_per_second": self.cases_per_second,
            "scheduler": self.scheduler,
            "workers": self.workers,
        }


# --------------------------------------------------------------------------------------
# worker side


@functools.lru_cache(maxsize=512)
def _parse_cached(raw_json: str, overrides_json: str, case_path: str | None) -> Case:
    """Validate the base case with overrides (cached per worker process: pure function)."""
    raw = apply_overrides(json.loads(raw_json), json.loads(overrides_json))
    return parse_case(raw, Path(case_path) if case_path else None)


def evaluate_batch(payload: Payload, ids: np.ndarray) -> list[dict] | Columns:
    """Rows for the case ids: inputs (SI), status and the kernel's outputs (as columns on the
    Monte-Carlo array path).

    Cases that differ only in the kernel's fast keys (the striking velocity) share one
    validated case and are evaluated together, vectorised.
    """
    spec, kernel = payload.spec, payload.kernel
    ids = np.asarray(ids, dtype=np.int64)
    values = spec.values(ids, payload.draws)
    units = spec.units()
    integer = spec.integer_keys()
    columns = spec.columns
    slow = [k for k in spec.keys if k not in kernel.fast_keys]
    fast = [k for k in spec.keys if k in kernel.fast_keys]
    arrays = [k for k in slow if kernel.is_array_key(k)]
    if arrays and (payload.arrays_valid or _ranges_valid(payload, values, arrays)):
        return _evaluate_arrays(payload, ids, values, [k for k in slow if k not in arrays], fast + arrays)

    groups: dict[tuple, list[int]] = defaultdict(list)
    for j in range(len(ids)):
        groups[tuple(float(values[k][j]) for k in slow)].append(j)

    rows: list[dict | None] = [None] * len(ids)
    for gvals, idx in groups.items():
        idx = np.asarray(idx)
        overrides = {k: raw_value(v, units[k], k in integer) for k, v in zip(slow, gvals)}
        # the fast keys are validated by the kernel; the case is parsed with the first value
        first = {k: raw_value(values[k][idx[0]], units[k], k in integer) for k in fast}
        base_rows = [
            {"case_id": int(ids[j]), **{columns[k]: float(values[k][j]) for k in spec.keys}} for j in idx
        ]
        try:
            case = _parse_cached(payload.raw_json, json.dumps({**overrides, **first}, sort_keys=True), payload.case_path)
            resource = payload.resources.get(kernel.resource_key(case))
            if resource is None:
                resource = kernel.prepare(case)
            out = kernel.evaluate(case, resource, {k: values[k][idx] for k in fast})
        except InputError as exc:
            for r in base_rows:
                r.update(status="invalid", message=str(exc))
            out = None
        except Exception as exc:  # one bad group must not stop the sweep
            for r in base_rows:
                r.update(status="error", message=f"{type(exc).__name__}: {exc}")
            out = None
        if out is not None:
            status = out.pop("_status", None)
            message = out.pop("_message", None)
            for n, r in enumerate(base_rows):
                r["status"] = "ok" if status is None else str(status[n])
                r["message"] = "" if message is None else str(message[n])
                for col, arr in out.items():
                    v = arr[n] if len(arr) == len(base_rows) else arr[0]
                    r[col] = v.item() if hasattr(v, "item") else v
        for j, r in zip(idx, base_rows):
            rows[j] = r
    return rows  # type: ignore[return-value]


def _ranges_valid(payload: Payload, values: Mapping[str, np.ndarray], keys: list[str]) -> bool:
    """Monte Carlo: the case with each sampled field at the ends of its range in this batch (every
    corner of the box) is valid.  The fields' validity is a range (bounds, and monotone
    conditions like eq. (16)'s E > 3 Y (1 - nu)), so then every sample in the box is valid;
    otherwise the batch goes case by case (each invalid sample reported)."""
    import itertools

    units, integer = payload.spec.units(), payload.spec.integer_keys()
    ends = [(float(np.min(values[k])), float(np.max(values[k]))) for k in keys]
    for corner in itertools.product(*ends):
        over = {k: raw_value(v, units[k], k in integer) for k, v in zip(keys, corner)}
        try:
            case = _parse_cached(payload.raw_json, json.dumps(over, sort_keys=True), payload.case_path)
        except InputError:
            return False
    return payload.kernel.accepts_arrays(case, keys)


def _check_arrays_once(payload: Payload, pending: np.ndarray) -> Payload:
    """Monte Carlo on arrays: check the corners of the whole run's sampled box once, here, so the
    batches need not (a batch whose box is not known valid checks its own corners)."""
    import dataclasses

    kernel, spec = payload.kernel, payload.spec
    is_array = kernel.is_array_key
    arrays = [k for k in spec.keys if k not in kernel.fast_keys and is_array(k)]
    if not arrays or len(arrays) > 6:
        return payload
    values = spec.values(pending, payload.draws)
    return dataclasses.replace(payload, arrays_valid=_ranges_valid(payload, values, arrays))


def _evaluate_arrays(payload: Payload, ids: np.ndarray, values, slow: list[str], vector: list[str]) -> Columns:
    """Columns of a batch whose sampled fields are evaluated on arrays (kernel.evaluate_arrays): one
    validated case per combination of the remaining slow (grid) keys."""
    spec, kernel = payload.spec, payload.kernel
    units, integer, columns = spec.units(), spec.integer_keys(), spec.columns
    n = len(ids)
    if slow:
        groups: dict[tuple, list[int]] = defaultdict(list)
        for j in range(n):
            groups[tuple(float(values[k][j]) for k in slow)].append(j)
        parts = [(g, np.asarray(i)) for g, i in groups.items()]
    else:
        parts = [((), np.arange(n))]
    names = list(kernel.columns)
    data: dict[str, np.ndarray] = {"case_id": np.asarray(ids, np.int64)}
    data.update({columns[k]: np.asarray(values[k], float) for k in spec.keys})
    data["status"] = np.full(n, "", dtype=object)
    data["message"] = np.full(n, "", dtype=object)
    for gvals, idx in parts:
        overrides = {k: raw_value(v, units[k], k in integer) for k, v in zip(slow, gvals)}
        try:
            case = _parse_cached(payload.raw_json, json.dumps(overrides, sort_keys=True), payload.case_path)
            resource = payload.resources.get(kernel.resource_key(case))
            if resource is None:
                resource = kernel.prepare(case)
            res = kernel.evaluate_arrays(case, resource, {k: values[k][idx] for k in vector})
            status, message = res["_status"], res["_message"]
        except InputError as exc:
            res = {c: np.full(len(idx), np.nan) for c in names}
            status, message = np.full(len(idx), "invalid", object), np.full(len(idx), str(exc), object)
        for c in names:
            col = np.asarray(res[c])
            if c not in data:
                data[c] = np.empty(n, dtype=col.dtype if col.dtype.kind in "fb" else object)
            data[c][idx] = col
        data["status"][idx] = status
        data["message"][idx] = message
    return Columns(data)


def warm_up() -> bool:
    """Import the models and build the unit registry in a worker before the clock starts."""
    import importlib

    from semianalytic.units import registry

    registry()
    for m in ("semianalytic.case", "semianalytic.penetration", "semianalytic.cavity"):
        importlib.import_module(m)
    return True


# --------------------------------------------------------------------------------------
# client side


def _case_digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()[:16]


def _validate_spec(case: Case, spec: SweepSpec, kernel: Kernel) -> None:
    """Every grid value and every sampler's central value must make a valid case (exit 2)."""
    units, integer = spec.units(), spec.integer_keys()
    checks: list[tuple[str, float, str]] = []
    for a in spec.axes:
        vals = a.values if len(a.values) <= 64 else (a.values[0], a.values[len(a.values) // 2], a.values[-1])
        checks += [(a.key, v, "--vary") for v in vals]
    for s in spec.samplers:
        checks.append((s.key, s.params[1] if s.dist == "triangular" else s.params[0], "--sample"))
    for key, v, opt in checks:
        try:
            if key in kernel.fast_keys:
                kernel.check_fast(key, np.array([v]))
            else:
                parse_case(apply_overrides(case.raw, {key: raw_value(v, units[key], key in integer)}), case.path)
        except InputError as exc:
            shown = f"{v:g} {units[key]}".strip()
            raise InputError(exc.field, f"{exc.message} (value {shown} from {opt} {key})") from None


def _resource_cases(case: Case, spec: SweepSpec, kernel: Kernel, pending: np.ndarray, draws) -> dict:
    """One validated case per distinct resource key among the pending cases."""
    geo = [k for k in spec.keys if kernel.affects_resource(k)]
    if not geo:
        return {kernel.resource_key(case): case}
    units, integer = spec.units(), spec.integer_keys()
    vals = spec.values(pending, draws)
    seen: dict = {}
    combos = {tuple(float(vals[k][j]) for k in geo) for j in range(len(pending))}
    for combo in sorted(combos):
        overrides = {k: raw_value(v, units[k], k in integer) for k, v in zip(geo, combo)}
        try:
            c = parse_case(apply_overrides(case.raw, overrides), case.path)
        except InputError:
            continue  # those cases will be reported invalid
        seen.setdefault(kernel.resource_key(c), c)
    return seen


def _batches(ids: np.ndarray, size: int) -> list[np.ndarray]:
    return [ids[i : i + size] for i in range(0, len(ids), size)]


def _geometry_batches(spec: SweepSpec, kernel: Kernel, pending: np.ndarray, draws, size: int) -> list[np.ndarray]:
    """Batches that each hold the cases of one geometry (one coefficient table), at most ``size``."""
    geo = [k for k in spec.keys if kernel.affects_resource(k)]
    vals = spec.values(pending, draws)
    groups: dict[tuple, list[int]] = defaultdict(list)
    for j, cid in enumerate(pending.tolist()):
        groups[tuple(float(vals[k][j]) for k in geo)].append(cid)
    return [b for ids in groups.values() for b in _batches(np.asarray(ids, np.int64), size)]


def check_output(out: Path, fmt: str, resume: bool, force: bool, manifest: dict) -> bool:
    """Check the output folder (nothing is changed); returns True for a fresh start."""
    res = results_path(out, fmt)
    man = out / MANIFEST
    if out.exists() and not out.is_dir():
        raise InputError("--out", f"{str(out)!r} exists and is not a folder")
    if out.is_dir():  # issue 27: a sweep writes only into an empty folder or its own earlier sweep's
        from semianalytic.report.output import forbidden_output

        forbidden_output(out)
        own = {"results.csv", "results.parquet", MANIFEST, STATISTICS}
        foreign = sorted(p.name for p in out.iterdir() if p.name not in own)
        if foreign:
            raise InputError("--out", f"{str(out)!r} holds {foreign[0]!r}, which no sweep wrote; use a new or empty "
                                      "folder (a sweep never writes beside other files, --force replaces only its own)")
    has_results = res.exists() or man.exists()
    if resume:
        if not has_results:
            return True
        if not man.exists():
            raise InputError("--resume", f"{str(out)!r} has results but no {MANIFEST}; cannot tell which sweep they belong to")
        try:  # a damaged store (issue 27): exit 2 naming it, never a traceback
            old = json.loads(man.read_text())
            if not isinstance(old, dict):
                raise ValueError("not a JSON object")
        except (OSError, UnicodeDecodeError, ValueError) as exc:
            raise InputError("--resume", f"{str(man)!r} is damaged ({exc}); pass --force to start the sweep over") from None
        if old.get("fingerprint") != manifest["fingerprint"]:
            raise InputError(
                "--resume",
                f"{str(out)!r} holds a different sweep (case file or --vary/--sample changed); use another --out or --force",
            )
        if old.get("format") != fmt:
            raise InputError("--format", f"the sweep in {str(out)!r} was written as {old.get('format')}")
        return False
    if has_results and not force:
        raise InputError("--out", f"{str(out)!r} already holds sweep results; pass --resume to continue or --force to start over")
    return True


def _clear_results(out: Path) -> None:
    """--force: remove an earlier sweep's results and manifest (only those files)."""
    for p in (results_path(out, "csv"), results_path(out, "parquet"), out / MANIFEST, out / STATISTICS):
        if p.is_dir():
            shutil.rmtree(p)
        elif p.exists():
            p.unlink()


# Engine choice (issue 14): a LocalCluster costs about LOCAL_START_SECONDS to start and warm
# up (reports/bench_sweep.md), so it pays only for work well above that; one BEM table costs
# about GEOMETRY_SECONDS, a cheap (vectorised) case microseconds.
LOCAL_START_SECONDS = 4.0
GEOMETRY_SECONDS = 1.0


def choose_engine(scheduler: str | None, n_cases: int, n_geometries: int, seconds_per_case: float = 0.0,
                  workers: int = 2) -> str:
    """The engine of a sweep: the ``scheduler`` given (``inline``, ``local`` or an address), else
    ``inline`` when the work is cheap (velocity and material sweeps on one table: microseconds
    per case) and ``local`` when it is not (a geometry sweep builds one BEM table per design)."""
    if scheduler:
        return scheduler.strip()
    if workers < 2:
        return "inline"
    work = max(n_geometries - 1, 0) * GEOMETRY_SECONDS + n_cases * seconds_per_case
    return "local" if work > 2.0 * LOCAL_START_SECONDS else "inline"


def own_session() -> int:
    """Move this (worker) process into a session of its own (``setsid``); returns its session id.

    Linux's autogroup scheduling (``/proc/sys/kernel/sched_autogroup_enabled``) shares the CPU
    fairly between sessions, not processes: a LocalCluster's workers, started by the sweep's
    process, would share its session's one share, so on a machine where other sessions keep the
    cores busy two local workers run no faster than one inline process (measured: two workers at
    about 50 % of a core each beside another session's process at 95 %; reports/bench_sweep.md).
    In their own sessions they get a share each, as workers started by a dask scheduler service
    or a batch system do.  Harmless otherwise: the nanny still supervises and stops the worker
    (it exits with its nanny's pipe, not with the terminal), and no CPU is taken that another
    session of the same size would not get."""
    try:
        os.setsid()
    except OSError:  # already a session or group leader (e.g. an external worker): nothing to do
        pass
    return os.getsid(0)


# A dask scheduler writes its handshake as soon as it accepts a connection (distributed.comm.core
# Listener.on_connection): a TCP frame whose first 8 bytes are the little-endian byte count of the
# message (a few hundred) and the next 8 its frame count.  The probe connects, reads those 16
# bytes and names a peer that sends nothing (an HTTP server waits for a request) or other bytes
# (dask read an SSH banner as a frame of 3 EiB and reported "out of memory").
PROBE_CONNECT_SECONDS = 3.0
PROBE_HANDSHAKE_SECONDS = 5.0


def _scheduler_host_port(address: str) -> tuple[str, int] | None:
    """(host, port) of a ``tcp://host:port`` or ``host:port`` address; None for another protocol
    (tls://, ucx://, inproc://: left to dask)."""
    text = address.strip()
    if "://" in text:
        scheme, _, text = text.partition("://")
        if scheme != "tcp":
            return None
    host, sep, port = text.rpartition(":")
    if not sep or not port.isdigit() or not 0 < int(port) < 65536:
        raise InputError("--scheduler", f"expected a dask scheduler address tcp://HOST:PORT (or HOST:PORT, or "
                                        f"'inline' or 'local'); got {address!r}")
    return host.strip("[]") or "127.0.0.1", int(port)


def probe_scheduler(address: str, connect_seconds: float = PROBE_CONNECT_SECONDS,
                    handshake_seconds: float = PROBE_HANDSHAKE_SECONDS) -> None:
    """Refuse (InputError on ``--scheduler``) an address where no dask scheduler answers, within
    about ``connect_seconds + handshake_seconds``: nothing listening, no answer, a peer that sends
    no handshake or bytes that are not dask's frame header."""
    import socket
    import struct

    where = _scheduler_host_port(address)
    if where is None:
        return
    host, port = where
    try:
        sock = socket.create_connection((host, port), timeout=connect_seconds)
    except ConnectionRefusedError:
        raise InputError("--scheduler", f"nothing listens at {host}:{port} (connection refused); start the dask "
                                        "scheduler there or give 'local'") from None
    except TimeoutError:
        raise InputError("--scheduler", f"{host}:{port} did not answer within {connect_seconds:g} s") from None
    except OSError as exc:
        raise InputError("--scheduler", f"cannot connect to {host}:{port}: {exc.strerror or exc}") from None
    data = b""
    try:
        deadline = time.monotonic() + handshake_seconds
        while len(data) < 16:
            left = deadline - time.monotonic()
            if left <= 0:
                break
            sock.settimeout(left)
            try:
                chunk = sock.recv(16 - len(data))
            except TimeoutError:
                break
            if not chunk:
                break
            data += chunk
    except OSError as exc:
        raise InputError("--scheduler", f"{host}:{port} broke the connection: {exc.strerror or exc}") from None
    finally:
        sock.close()
    if not data:
        raise InputError("--scheduler", f"{host}:{port} accepted the connection but sent no dask handshake within "
                                        f"{handshake_seconds:g} s: not a dask scheduler (a dask scheduler speaks "
                                        "first; an HTTP server waits for a request)")
    if len(data) < 16:
        raise InputError("--scheduler", f"{host}:{port} is not a dask scheduler: it sent {data[:16]!r} and stopped")
    total, frames = struct.unpack("<QQ", data)
    if not (16 <= total <= 2**20 and 1 <= frames <= 64):
        raise InputError("--scheduler", f"{host}:{port} is not a dask scheduler: it answers with other bytes "
                                        f"({data[:16]!r}, not dask's frame header)")


def connect(scheduler: str | None, workers: int):
    """(client, cluster, name): None/None for "inline", a new LocalCluster for "local"/None,
    else a client of the scheduler at that address, or of the one a scheduler file names
    (``dask scheduler --scheduler-file F.json``: a path ending in ``.json``; docs/cluster.md);
    InputError if it cannot be used."""
    sched = (scheduler or "local").strip()
    if sched == "inline":
        return None, None, "inline"
    from dask.distributed import Client, LocalCluster

    if sched == "local":
        import dask

        # dask sets MALLOC_TRIM_THRESHOLD_ = 65536 in the workers it spawns; an explicit trim threshold turns
        # off glibc's dynamic mmap threshold, so every large array is mmap-ed and page-faulted afresh: a BEM
        # table then costs 1.6x the CPU (0.71 -> 1.12 s, mostly system time; reports/bench_sweep.md)
        environ = {k: v for k, v in dask.config.get("distributed.nanny.pre-spawn-environ", {}).items()
                   if k != "MALLOC_TRIM_THRESHOLD_"}
        environ.update(OPENBLAS_NUM_THREADS=1, OMP_NUM_THREADS=1, MKL_NUM_THREADS=1)
        # and no statistical profiler in the workers (a thread that samples the task's stack every 10 ms,
        # for the dashboard, which a sweep does not open)
        import atexit
        import logging
        import tempfile

        # the workers' scratch space (dask-scratch-space, its lock files) in a folder of ours, removed at exit,
        # also after Ctrl-C or SIGTERM (issue 40: dask left it in $TMPDIR)
        scratch = tempfile.mkdtemp(prefix="semianalytic-dask-")
        atexit.register(shutil.rmtree, scratch, True)
        environ.update(DASK_TEMPORARY_DIRECTORY=scratch)
        config = {"distributed.nanny.pre-spawn-environ": environ, "distributed.worker.profile.enabled": False,
                  "temporary-directory": scratch}
        with dask.config.set(config), deferred_interrupts() as interrupted:
            cluster = LocalCluster(
                n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                silence_logs=logging.CRITICAL, local_directory=scratch,
                env={"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
                     "DASK_TEMPORARY_DIRECTORY": scratch},
            )
            client = Client(cluster)
            client.run(own_session)
        if interrupted:  # a Ctrl-C or SIGTERM while the cluster started: stop it whole, then say so
            logging.getLogger("distributed").setLevel(logging.CRITICAL)
            client.close()
            cluster.close()
            raise KeyboardInterrupt(interrupted[0])
        return client, cluster, "local"
    client = None
    try:
        if sched.endswith(".json"):  # a scheduler file (dask scheduler --scheduler-file F): its address inside
            try:
                address = json.loads(Path(sched).expanduser().read_text())["address"]
            except (OSError, ValueError, KeyError, TypeError) as exc:
                raise ValueError(f"not a readable dask scheduler file (no 'address'): {exc}") from None
        else:
            address = sched
        probe_scheduler(address)
        import dask

        with dask.config.set({"distributed.comm.timeouts.connect": "10s"}):  # the handshake too
            client = Client(address, timeout="10s")
        client.wait_for_workers(1, timeout=60)
    except (OSError, TimeoutError, ValueError) as exc:
        if client is not None:
            client.close()
        raise InputError("--scheduler", f"cannot use the dask scheduler {sched!r}: {exc}") from None
    return client, None, address


def run_sweep(
    case_path: str | os.PathLike,
    spec: SweepSpec,
    out: str | os.PathLike,
    *,
    fmt: str = "csv",
    analysis: str | None = None,
    resume: bool = False,
    force: bool = False,
    scheduler: str | None = None,
    workers: int = 2,
    batch_size: int | None = None,
    cache_dir: str | os.PathLike | None = None,
    progress: bool = True,
    kernel: Kernel | None = None,
    on_batch: Callable[[int], None] | None = None,
) -> SweepSummary:
    """Run (or resume) a sweep; see :mod:`semianalytic.sweep`.  Bad input (case, spec, output
    folder, scheduler address) raises InputError before anything is written."""
    t0 = time.perf_counter()
    case_path = Path(case_path)
    case = load_case(case_path)
    kernel = kernel or select_kernel(case, analysis, cache_dir=cache_dir)
    spec = kernel.complete_spec(case, spec)
    _validate_spec(case, spec, kernel)
    out = Path(out)
    manifest = {
        "case": str(case_path),
        "case_sha256_16": _case_digest(case_path),
        "analysis": kernel.name,
        "format": fmt,
        "spec": spec.to_json(),
    }
    manifest["fingerprint"] = hashlib.sha256(
        json.dumps({k: manifest[k] for k in ("case_sha256_16", "analysis", "spec")}, sort_keys=True).encode()
    ).hexdigest()[:16]
    fresh = check_output(out, fmt, resume, force, manifest)
    columns = list(BASE_COLUMNS) + list(spec.columns.values()) + list(kernel.columns)
    store = ResultStore(out, fmt, columns)
    try:
        done = set() if fresh else store.finished_ids()
    except InputError:
        raise
    except Exception as exc:  # noqa: BLE001 - a damaged results file of an earlier run (issue 27)
        raise InputError("--resume", f"the results in {str(out)!r} are damaged ({type(exc).__name__}); "
                                     "pass --force to start the sweep over") from None
    all_ids = np.arange(spec.n_cases, dtype=np.int64)
    pending = all_ids[~np.isin(all_ids, np.fromiter(done, dtype=np.int64, count=len(done)))] if done else all_ids
    summary = SweepSummary(out, store.path, spec.n_cases, len(done), len(pending))
    draws = spec.draws() if spec.samplers else {}
    t_prep = time.perf_counter()
    rcases = _resource_cases(case, spec, kernel, pending, draws) if len(pending) else {}
    engine = choose_engine(scheduler, len(pending), len(rcases), kernel.seconds_per_case, workers)
    client, cluster, summary.scheduler = connect(engine, workers) if len(pending) else (None, None, "none")
    try:
        # from here on the folder is written
        if fresh and force:
            _clear_results(out)
        out.mkdir(parents=True, exist_ok=True)
        atomic_write_json(out / MANIFEST, manifest)
        store.open(fresh)
        if len(pending) == 0:
            return summary
        # shared resources (coefficient tables), one per geometry
        if len(rcases) > 20:
            print(f"warning: {len(rcases)} distinct nose geometries: each needs its own BEM coefficient table "
                  "(seconds each, cached on disk)", file=sys.stderr)
        per_geometry = client is not None and len(rcases) > 1
        if client is None:
            resources = {k: kernel.prepare(c) for k, c in rcases.items()}
            summary.workers = 1
        elif per_geometry:
            # a geometry sweep on workers: each task builds (or loads from the disk cache) the table of its
            # own geometry and evaluates that geometry's cases, so no table travels to the client and back
            # to every worker, and no worker waits for all tables before the cases start
            summary.workers = len(client.scheduler_info().get("workers", {})) or workers
            client.run(warm_up)
            resources = {}
        else:
            summary.workers = len(client.scheduler_info().get("workers", {})) or workers
            client.run(warm_up)
            futures = {k: client.submit(kernel.prepare, c, pure=False) for k, c in rcases.items()}
            resources = {k: f.result() for k, f in futures.items()}
        summary.seconds_prepare = time.perf_counter() - t_prep

        payload = Payload(json.dumps(case.raw), str(case_path), spec, kernel, draws, resources)
        payload = _check_arrays_once(payload, pending)
        nw = max(1, summary.workers)
        size = batch_size or int(min(2000, max(20, math.ceil(len(pending) / (8 * nw)))))
        batches = _geometry_batches(spec, kernel, pending, draws, size) if per_geometry else _batches(pending, size)
        t_cases = time.perf_counter()
        bar = _progress(len(pending), progress)
        try:
            if client is None:
                for b in batches:
                    rows = evaluate_batch(payload, b)
                    _record(store, rows, summary, bar, on_batch)
            else:
                from dask.distributed import as_completed

                [pay] = client.scatter([payload], broadcast=True)
                futs = [client.submit(evaluate_batch, pay, b, pure=False) for b in batches]
                for fut in as_completed(futs):
                    _record(store, fut.result(), summary, bar, on_batch)
                    fut.release()
        finally:
            summary.seconds_cases = time.perf_counter() - t_cases
            if bar is not None:
                bar.close()
    finally:
        store.close()
        if client is not None:
            import logging

            # a cluster stopped by Ctrl-C or SIGTERM logs its workers' closed connections with tracebacks:
            # not the user's business (the one line of the dispatcher says what happened)
            logging.getLogger("distributed").setLevel(logging.CRITICAL)
            client.close()
        if cluster is not None:
            cluster.close()
        summary.seconds_total = time.perf_counter() - t0
    if store.path.exists():
        atomic_write_json(out / STATISTICS, output_statistics(store, kernel.columns))
    return summary


def output_statistics(store: ResultStore, columns) -> dict:
    """Per output column, over the cases with status ok: n, mean, std, min, 5/50/95 % and max
    (for a Monte-Carlo study, the distribution of each result)."""
    df = store.read()
    ok = df[df["status"] == "ok"]
    out = {"n_cases": int(len(df)), "n_ok": int(len(ok))}
    for c in columns:
        if c not in ok or ok[c].dtype.kind not in "fi":
            continue
        v = ok[c].to_numpy(dtype=float)
        v = v[np.isfinite(v)]
        if v.size == 0:
            continue
        q = np.percentile(v, [5, 50, 95])
        out[c] = {"n": int(v.size), "mean": float(v.mean()), "std": float(v.std(ddof=1)) if v.size > 1 else 0.0,
                  "min": float(v.min()), "p05": float(q[0]), "p50": float(q[1]), "p95": float(q[2]), "max": float(v.max())}
    return out


def _record(store: ResultStore, rows: list[dict] | Columns, summary: SweepSummary, bar, on_batch) -> None:
    store.append(rows)
    statuses = rows.data["status"].tolist() if isinstance(rows, Columns) else [r.get("status") for r in rows]
    n_ok, n_invalid = statuses.count("ok"), statuses.count("invalid")
    summary.n_ok += n_ok
    summary.n_invalid += n_invalid
    summary.n_error += len(statuses) - n_ok - n_invalid
    if bar is not None:
        bar.update(len(rows))
    if on_batch is not None:
        on_batch(len(rows))


def _progress(total: int, enabled: bool):
    from semianalytic.progress import counter, mode

    if not enabled or mode() == "off":
        return None
    if mode() == "lines":  # a log: a start and an end line, not a bar's carriage returns
        return counter(total, "sweep", "case")
    from tqdm import tqdm

    return tqdm(total=total, unit="case", file=sys.stderr, dynamic_ncols=True, mininterval=0.5)
