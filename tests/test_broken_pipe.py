"""A reader that goes away (``python -m semianalytic ... | head``) is not an internal error:
no traceback, and the command stops (found while piping ``coefficients --json`` into ``head``)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_closed_stdout_gives_no_traceback():
    proc = subprocess.Popen([sys.executable, "-m", "semianalytic", "ballistic-limit", str(ROOT / "cases" / "part4_table2.toml"),
                             "--json"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=ROOT)
    proc.stdout.close()  # the reader is gone before the command writes: its first write raises EPIPE
    err = proc.stderr.read().decode()
    proc.wait(timeout=120)
    assert "Traceback" not in err and "internal error" not in err, err
    assert proc.returncode in (0, 1)
