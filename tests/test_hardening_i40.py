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
            except (socket.timeout, OSError):
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
])
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
