"""A sweep and an optimisation on an existing dask scheduler started as separate processes
(issue 24 item 4; the path of docs/cluster.md): ``dask scheduler`` and two ``dask worker``
processes on 127.0.0.1, then ``python -m semianalytic sweep ... --scheduler tcp://...`` and
``--scheduler scheduler.json``.  The results must equal the inline run's (the same cases, the
same closed-form Part II model: the engine only moves them), and the sweep must report the
scheduler's address and its two workers.  Bounded in time (every wait has a timeout; the scheduler also dies after 120 s
idle, the workers 60 s after losing it) and cleaned up in a ``finally``.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parent.parent
AD995 = ROOT / "cases" / "cavity_ad995.toml"
VARY = ["--vary", "material.poisson_ratio=0.20:0.26:0.02", "--sample", "material.compressive_strength=uniform(2.5 GPa, 2.7 GPa)",
        "--samples", "5", "--seed", "3"]


def _dask() -> str:
    exe = shutil.which("dask", path=str(Path(sys.executable).parent))
    if exe is None:
        pytest.skip("the dask command is not installed beside this Python")
    return exe


@pytest.fixture(scope="module")
def external_cluster(tmp_path_factory):
    """A dask scheduler and two single-threaded workers, each a separate process on 127.0.0.1."""
    tmp = tmp_path_factory.mktemp("cluster")
    sched_file = tmp / "scheduler.json"
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "SEMIANALYTIC_CACHE_DIR": str(tmp / "cache")}
    dask = _dask()
    procs = [subprocess.Popen([dask, "scheduler", "--host", "127.0.0.1", "--port", "0", "--scheduler-file", str(sched_file),
                               "--no-dashboard", "--idle-timeout", "120s"], env=env,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        deadline = time.monotonic() + 60
        while not (sched_file.exists() and sched_file.stat().st_size > 0):
            if time.monotonic() > deadline or procs[0].poll() is not None:
                pytest.fail("the dask scheduler did not start within 60 s")
            time.sleep(0.1)
        address = json.loads(sched_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        for _ in range(2):
            procs.append(subprocess.Popen([dask, "worker", "--scheduler-file", str(sched_file), "--host", "127.0.0.1",
                                           "--nthreads", "1", "--no-nanny", "--no-dashboard", "--death-timeout", "60s"],
                                          env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        from dask.distributed import Client

        with Client(address, timeout="30s") as c:
            c.wait_for_workers(2, timeout=90)
        yield address, sched_file
    finally:
        if sched_file.exists() and procs[0].poll() is None:
            try:  # the cluster's own shutdown (scheduler and workers), then signals for what is left
                from dask.distributed import Client

                with Client(json.loads(sched_file.read_text())["address"], timeout="10s") as c:
                    c.shutdown()
            except Exception:
                pass
        for p in reversed(procs):
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait(timeout=10)


def _sweep(out: Path, scheduler: str, tmp: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "SEMIANALYTIC_CACHE_DIR": str(tmp / "cache")}
    return subprocess.run([sys.executable, "-m", "semianalytic", "sweep", str(AD995), "--out", str(out), *VARY,
                           "--scheduler", scheduler, "--no-progress", "--json"],
                          capture_output=True, text=True, env=env, timeout=240)


def test_sweep_on_an_external_scheduler(external_cluster, tmp_path):
    from semianalytic.sweep.engine import run_sweep
    from semianalytic.sweep.spec import build_spec

    address, sched_file = external_cluster
    spec = build_spec([VARY[1]], [VARY[3]], 5, 3)
    run_sweep(AD995, spec, tmp_path / "inline", scheduler="inline", progress=False)
    expected = pd.read_csv(tmp_path / "inline" / "results.csv").sort_values("case_id").reset_index(drop=True)
    # the command, given the address; the Python API, given the scheduler file
    r = _sweep(tmp_path / "address", address, tmp_path)
    assert r.returncode == 0, r.stderr
    info = json.loads(r.stdout)
    assert info["scheduler"] == address and info["workers"] == 2, info
    s = run_sweep(AD995, spec, tmp_path / "file", scheduler=str(sched_file), progress=False)
    assert s.scheduler == address and s.workers == 2
    for label in ("address", "file"):
        got = pd.read_csv(tmp_path / label / "results.csv").sort_values("case_id").reset_index(drop=True)
        assert list(got.case_id) == list(range(20))
        # the same model on the same inputs: equal to round-off whichever process evaluated a case
        pd.testing.assert_series_equal(got.cavity_pressure_Pa, expected.cavity_pressure_Pa, rtol=1e-13)


def test_unreachable_scheduler_file(tmp_path, capsys):
    from semianalytic.cli import main

    bad = tmp_path / "scheduler.json"
    bad.write_text("{}")
    rc = main(["sweep", str(AD995), "--out", str(tmp_path / "o"), "--vary", "material.poisson_ratio=0.2:0.22:0.02",
               "--scheduler", str(bad), "--no-progress"])
    assert rc == 2 and capsys.readouterr().err.startswith("error: --scheduler:")
    assert not (tmp_path / "o").exists()


@pytest.mark.slow  # about 30 s of CPU (two clusters started, a malloc diagnostic): run by the report commands
def test_engines_benchmark_small(tmp_path, monkeypatch):
    """``python -m benchmarks.sweep --engines-only --designs 1``: the report states the
    CPU-time efficiency per worker and the machine's load beside every engine (values not asserted:
    they are timings on a shared machine), and every engine ran the design's 7 velocities."""
    import re

    from benchmarks.sweep import main

    monkeypatch.setenv("SEMIANALYTIC_CACHE_DIR", str(tmp_path / "cache"))
    report = tmp_path / "engines.md"
    assert main(["--engines-only", "--designs", "1", "--report", str(report)]) == 0
    text = report.read_text()
    assert "Generated by `python -m benchmarks.sweep --engines-only" in text
    rows = re.findall(r"^\| (inline[^|]*|LocalCluster[^|]*|dask scheduler[^|]*) \|(?:[^|]*\|){4} (\d+) \|([^|]*)\|"
                      r"(?:[^|]*\|){4}([^|]*)\|([^|]*)\|", text, re.M)
    assert [r[1] for r in rows] == ["7", "7", "7"], rows
    for name, _, eff, load, busy in rows:
        assert re.fullmatch(r" \d+ %( / \d+ %)* ", eff), (name, eff)  # one efficiency per worker process
        assert re.fullmatch(r" [0-9.]+ ", load) and "% of" in busy, (name, load, busy)
