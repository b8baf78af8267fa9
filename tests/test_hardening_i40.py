"""Issue 40: the findings of the fourth hardening round that are not case files (those are in
``tests/corpus/i40_*.toml``): schedulers that are not dask, ``--csv``/``--report`` targets, bounds
on flags, signals, third-party caches, the smaller findings.

Each expectation is the issue's (what the user must see, what must happen to their files), not the
code's output: exit status 2 with one line naming the field, within a stated time, nothing written.
"""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from semianalytic.cli import main

ROOT = Path(__file__).resolve().parents[1]
FIG15A = ROOT / "cases" / "fig15a_ogive_6061T651.toml"


def _run(capsys, *argv) -> tuple[int, str]:
    rc = main([str(a) for a in argv])
    return rc, capsys.readouterr().err


def _one_line_error(rc: int, err: str, field: str) -> None:
    assert rc == 2, err
    assert err.startswith(f"error: {field}"), err
    assert len(err.strip().splitlines()) == 1, err


# ------------------------------------------------------------------------------------------
# schedulers that are not dask (local socket servers on 127.0.0.1 only, each bounded)


class _Server:
    """A TCP server on 127.0.0.1 that answers every connection with ``reply`` (or stays silent),
    for at most ``lifetime`` seconds."""

    def __init__(self, reply: bytes | None, lifetime: float = 30.0):
        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(8)
        self.sock.settimeout(0.2)
        self.port = self.sock.getsockname()[1]
        self.reply, self.stop_at, self.conns = reply, time.monotonic() + lifetime, []
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    def _serve(self):
        while time.monotonic() < self.stop_at and self.sock.fileno() >= 0:
            try:
                conn, _ = self.sock.accept()
            except (TimeoutError, OSError):
                continue
            self.conns.append(conn)
            if self.reply is not None:
                try:
                    conn.sendall(self.reply)
                except OSError:
                    pass

    def close(self):
        self.stop_at = 0
        self.thread.join(2)
        for c in self.conns:
            c.close()
        self.sock.close()


def _sweep_at(capsys, tmp_path, address):
    out = tmp_path / "sw"
    t0 = time.monotonic()
    rc, err = _run(capsys, "sweep", FIG15A, "--out", out, "--scheduler", address,
                   "--vary", "impact.striking_velocity=400:600:100 m/s", "--no-progress")
    return rc, err, time.monotonic() - t0, out


@pytest.mark.parametrize("reply, says", [
    (b"SSH-2.0-OpenSSH_9.6\r\n", "not a dask scheduler"),  # other bytes: dask read a 3 EiB frame length
    (None, "sent no dask handshake"),  # an HTTP server waits for a request: dask hung past 120 s
    (b"", "sent no dask handshake"),  # accepts, says nothing (b"" sends nothing either)
], ids=["ssh-banner", "http-like-silent", "empty-reply"])
def test_a_peer_that_is_not_dask_is_named_within_seconds(tmp_path, capsys, reply, says):
    server = _Server(reply)
    try:
        rc, err, seconds, out = _sweep_at(capsys, tmp_path, f"tcp://127.0.0.1:{server.port}")
    finally:
        server.close()
    _one_line_error(rc, err, "--scheduler")
    assert says in err, err
    # the probe's bounds: 3 s to connect + 5 s for the handshake, plus the start-up of the command
    assert seconds < 20, seconds
    assert not out.exists()


def test_nothing_listening_fails_at_once(tmp_path, capsys):
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()  # a port where nothing listens (dask retried for 15-22 s)
    rc, err, seconds, out = _sweep_at(capsys, tmp_path, f"127.0.0.1:{port}")
    _one_line_error(rc, err, "--scheduler")
    assert "nothing listens" in err and seconds < 10, (seconds, err)
    assert not out.exists()


def test_probe_accepts_a_dask_frame_header():
    """The probe's reading of dask's frame header, checked on bytes made by distributed itself
    (its own packing of a handshake-sized message), so that a real scheduler passes."""
    from distributed.comm.tcp import _add_frames_header
    from distributed.protocol import dumps

    from semianalytic.sweep.engine import probe_scheduler

    frames, _, _ = _add_frames_header(dumps({"compression": None, "python": (3, 11, 7), "pickle-protocol": 5}))
    server = _Server(b"".join(bytes(f) for f in frames))  # what distributed.comm.tcp writes: header, frames
    try:
        probe_scheduler(f"tcp://127.0.0.1:{server.port}")  # no error
    finally:
        server.close()


# ------------------------------------------------------------------------------------------
# --csv and --report targets: never a case file, never a non-regular file; refused before writing


def test_csv_never_replaces_the_case_a_fifo_or_a_users_file(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    case = tmp_path / "case.toml"
    text = FIG15A.read_text()
    case.write_text(text)
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    (tmp_path / "link.csv").symlink_to(case)
    mine = tmp_path / "mine.csv"
    mine.write_text("my,own,data\n")
    for target, says in ((case, "input file"), (tmp_path / "link.csv", "input file"), (fifo, "FIFO"),
                         (mine, "not written by this tool")):
        for command in (["penetrate", case], ["run", case, "--out", tmp_path / "o", "--no-render"]):
            rc, err = _run(capsys, *command, "--csv", target, "--force")
            _one_line_error(rc, err, "--csv")
            assert says in err, err
    assert case.read_text() == text and mine.read_text() == "my,own,data\n"  # untouched
    assert fifo.is_fifo() and not (tmp_path / "o").exists()
    # the tool's own CSV is replaced with --force (the header line is the tool's)
    rc, err = _run(capsys, "penetrate", case, "--csv", tmp_path / "d.csv")
    assert rc == 0, err
    rc, err = _run(capsys, "penetrate", case, "--csv", tmp_path / "d.csv", "--force")
    assert rc == 0, err


@pytest.mark.long
@pytest.mark.parametrize("command", ["calibrate", "optimize"])
def test_report_above_the_working_folder_leaves_no_file(tmp_path, capsys, monkeypatch, command):
    work = tmp_path / "a" / "b"
    work.mkdir(parents=True)
    monkeypatch.chdir(work)
    argv = {"calibrate": ["calibrate", ROOT / "cases" / "piekutowski1999_var4340.toml", "--steps", "60", "--quiet"],
            "optimize": ["optimize", ROOT / "cases" / "optimize_fig5_into_fig15a.toml", "--vary", "projectile.crh=2:4",
                         "--coarse", "2", "--confirm", "0", "--no-progress"]}[command]
    rc, err = _run(capsys, *argv, "--out", "out", "--report", "out/../../x.md")
    _one_line_error(rc, err, "--report")
    assert sorted(p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*")) == ["a", "a/b"]


# ------------------------------------------------------------------------------------------
# bounds before work on the flags that drive it


def test_flags_that_drive_work_are_bounded_up_front(capsys, tmp_path, monkeypatch):
    monkeypatch.delenv("SEMIANALYTIC_TIME_LIMIT", raising=False)
    monkeypatch.delenv("SEMIANALYTIC_MEMORY_LIMIT", raising=False)
    monkeypatch.setenv("SEMIANALYTIC_CACHE_DIR", str(tmp_path / "cache"))  # nothing cached: the work is real
    ogive = ROOT / "cases" / "fig5_ogive.toml"
    for argv, field, says in [
        # 2000 depths at refinement 8 and order 16: hours of BEM solves (the probe ran past 120 s)
        (["coefficients", ogive, "--refinement", "8", "--order", "16", "--depths", "2000"], "--depths", "time budget"),
        (["coefficients", ogive, "--refinement", "8", "--depths", "2000"], "--depths", "time budget"),
        # 1e6 steps of the regimes model: 32 walkers x 1e6 steps at 2.7e-4 s each, about 2.4 h
        (["calibrate", ROOT / "cases" / "piekutowski1999_var4340_hardness_regimes.toml", "--model", "regimes",
          "--out", tmp_path / "c", "--steps", "1000000", "--quiet"], "--steps", "time budget"),
        (["calibrate", ROOT / "cases" / "piekutowski1999_var4340.toml", "--out", tmp_path / "c", "--steps", "200000",
          "--quiet"], "--steps", "time budget"),
    ]:
        t0 = time.monotonic()
        rc, err = _run(capsys, *argv)
        _one_line_error(rc, err, field)
        assert says in err and time.monotonic() - t0 < 30, err
    assert not (tmp_path / "c").exists()


def test_sweep_values_outside_the_case_are_refused_up_front(capsys, tmp_path):
    for extra, field, says in [
        (["--vary", "impact.striking_velocity=1e-9 m/s,500 m/s"], "impact.striking_velocities", "the value 1e-09 m/s"),
        (["--sample", "target.density=lognormal(2710 kg/m^3, 50)", "--samples", "10"], "target.density",
         "narrow the distribution"),
        (["--sample", "target.resistance.poisson_ratio=uniform(0.3, 0.7)", "--samples", "10"],
         "target.resistance", "--sample target.resistance.poisson_ratio"),
    ]:
        rc, err = _run(capsys, "sweep", FIG15A, "--out", tmp_path / "sw", "--scheduler", "inline", "--no-progress", *extra)
        _one_line_error(rc, err, field)
        assert says in err, err
        assert not (tmp_path / "sw").exists()
    # a narrow lognormal stays inside the physical range: accepted
    rc, err = _run(capsys, "sweep", FIG15A, "--out", tmp_path / "ok", "--scheduler", "inline", "--no-progress",
                   "--sample", "target.density=lognormal(2710 kg/m^3, 0.02)", "--samples", "2",
                   "--vary", "impact.striking_velocity=500 m/s")
    assert rc == 0, err


# ------------------------------------------------------------------------------------------
# faults: signals leave no temporary file and no traceback; third-party caches out of $HOME


def _signalled(tmp_path, argv, sig, ready, timeout=120.0):
    """Start ``python -m semianalytic ARGV`` with its own TMPDIR and HOME, send ``sig`` once
    ``ready()`` holds (or after ``timeout``), and return (returncode, stderr, tmpdir, work)."""
    import signal  # noqa: F401 (the caller's sig)

    tmpdir, work, home = tmp_path / "tmp", tmp_path / "work", tmp_path / "home"
    for d in (tmpdir, work, home):
        d.mkdir()
    env = {**os.environ, "TMPDIR": str(tmpdir), "HOME": str(home), "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg",
           "OPENBLAS_NUM_THREADS": "1", "SEMIANALYTIC_CACHE_DIR": os.environ.get("SEMIANALYTIC_CACHE_DIR")
           or str(tmp_path / "cache")}
    env.pop("MPLCONFIGDIR", None)
    env.pop("XDG_CACHE_HOME", None)
    proc = subprocess.Popen([sys.executable, "-m", "semianalytic", *map(str, argv)], cwd=work, env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and proc.poll() is None and not ready(work):
        time.sleep(0.2)
    assert proc.poll() is None, "the command ended before the signal could be sent"
    proc.send_signal(sig)
    try:
        _, err = proc.communicate(timeout=90)
    except subprocess.TimeoutExpired:
        proc.kill()
        _, err = proc.communicate()
        raise
    return proc.returncode, err, tmpdir, work, home


@pytest.mark.long
@pytest.mark.parametrize("which", ["sweep", "calibrate"])
@pytest.mark.parametrize("signame", ["SIGTERM", "SIGINT"])
def test_signals_leave_no_temporary_file_and_no_traceback(tmp_path, which, signame):
    import signal

    argv, ready = {
        # a resumable sweep on a local dask cluster, stopped once its first cases are written
        "sweep": (["sweep", FIG15A, "--out", "out", "--samples", "4000", "--scheduler", "local", "--no-progress",
                   "--sample", "target.density=normal(2710 kg/m^3, 20 kg/m^3)", "--batch-size", "200"],
                  lambda w: (w / "out" / "results.csv").exists()),
        # the sampler running (its staging folder made)
        # the sampler running: its output is staged only after sampling, so the signal goes 20 s after the start
        # (imports and the table take a few seconds; 20000 steps take minutes, even on an idle machine)
        "calibrate": (["calibrate", ROOT / "cases" / "piekutowski1999_var4340.toml", "--out", "out", "--steps", "20000",
                       "--quiet"], lambda w, t0=time.monotonic(): time.monotonic() - t0 > 20.0),  # noqa: B008
    }[which]
    rc, err, tmpdir, work, home = _signalled(tmp_path, argv, getattr(signal, signame), ready)
    assert rc == 1, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1 and err.startswith("interrupted"), err
    assert not list(tmpdir.rglob("*")), sorted(map(str, tmpdir.rglob("*")))  # no dask-scratch-space, no cc*.s
    left = sorted(p.relative_to(work).as_posix() for p in work.rglob("*"))
    if which == "sweep":  # the finished cases kept for --resume, nothing else (no .tmp beside them)
        assert set(left) <= {"out", "out/results.csv", "out/sweep.json"}, left
    else:
        assert left == [], left
    assert not list(home.rglob("*")), sorted(map(str, home.rglob("*")))  # nothing in $HOME


@pytest.mark.long
def test_calibrate_writes_nothing_into_home(tmp_path):
    """matplotlib's font cache and arviz's daily_warning stay out of $HOME (no option asked for
    them); the report's figures are still made."""
    home, work = tmp_path / "home", tmp_path / "work"
    home.mkdir()
    work.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("MPLCONFIGDIR", "XDG_CACHE_HOME", "XDG_CONFIG_HOME")}
    env.update(HOME=str(home), PYTHONPATH=str(ROOT), MPLBACKEND="Agg", OPENBLAS_NUM_THREADS="1",
               SEMIANALYTIC_CACHE_DIR=str(tmp_path / "cache"))
    proc = subprocess.run([sys.executable, "-m", "semianalytic", "calibrate",
                           str(ROOT / "cases" / "piekutowski1999_var4340.toml"), "--out", "out", "--steps", "60",
                           "--quiet"], cwd=work, env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert list((work / "out").glob("*.png"))
    assert not list(home.rglob("*")), sorted(map(str, home.rglob("*")))
    assert (tmp_path / "cache" / "matplotlib").is_dir()  # the font cache: in this project's per-user cache


def test_matplotlib_config_of_the_user_is_kept(tmp_path, monkeypatch):
    from semianalytic import thirdparty

    monkeypatch.delenv("MPLCONFIGDIR", raising=False)
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "cfg"))
    monkeypatch.setenv("SEMIANALYTIC_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.delitem(sys.modules, "matplotlib", raising=False)
    (tmp_path / "cfg" / "matplotlib").mkdir(parents=True)
    (tmp_path / "cfg" / "matplotlib" / "matplotlibrc").write_text("figure.dpi: 80\n")
    assert thirdparty.keep_caches_out_of_home() is None and "MPLCONFIGDIR" not in os.environ  # theirs
    (tmp_path / "cfg" / "matplotlib" / "matplotlibrc").unlink()
    assert thirdparty.keep_caches_out_of_home() == str(tmp_path / "cache" / "matplotlib")  # ours
    monkeypatch.setenv("MPLCONFIGDIR", str(tmp_path / "mine"))
    assert thirdparty.keep_caches_out_of_home() is None and os.environ["MPLCONFIGDIR"] == str(tmp_path / "mine")


# ------------------------------------------------------------------------------------------
# smaller findings


def test_bare_command_prints_one_line():
    for package in ("semianalytic", "fem_check"):
        proc = subprocess.run([sys.executable, "-m", package], capture_output=True, text=True, timeout=60,
                              env={**os.environ, "PYTHONPATH": str(ROOT)})
        assert proc.returncode == 2 and proc.stdout == "", proc.stdout
        assert len(proc.stderr.strip().splitlines()) == 1 and proc.stderr.startswith("error: command"), proc.stderr
