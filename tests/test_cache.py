"""The coefficient-table cache (semianalytic/cache.py, issue 16): where it writes, what its key
depends on, and that a table read back is the table that was built.

Independent checks: the file system (which files exist where) and the table built directly by
:func:`semianalytic.coefficients.table.coefficient_table`, bypassing the cache.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

from semianalytic import cache
from semianalytic.geometry import ogive_nose

ROOT = Path(__file__).resolve().parent.parent
SMALL = dict(order=4, n_depths=8, max_depth_nose_lengths=20.0)  # a cheap table (~0.1 s)


def test_folder_env_then_platformdirs(monkeypatch, tmp_path):
    monkeypatch.setenv(cache.CACHE_ENV, str(tmp_path / "c"))
    assert cache.table_dir() == tmp_path / "c" / "coefficients"
    assert cache.table_dir(tmp_path / "x") == tmp_path / "x"  # --cache-dir wins
    monkeypatch.delenv(cache.CACHE_ENV)
    from platformdirs import user_cache_dir

    assert cache.table_dir() == Path(user_cache_dir("semianalytic", appauthor=False)) / "coefficients"


def test_key_follows_geometry_options_and_version(monkeypatch):
    nose = ogive_nose(7.11e-3, 3.0)
    key = cache.table_key(nose, **SMALL)
    assert key == cache.table_key(ogive_nose(7.11e-3, 3.0), **SMALL)
    assert key != cache.table_key(ogive_nose(7.11e-3, 2.0), **SMALL)
    assert key != cache.table_key(nose, **dict(SMALL, order=5))
    import semianalytic.coefficients.table as table

    monkeypatch.setattr(table, "TABLE_VERSION", table.TABLE_VERSION + 1)
    assert key != cache.table_key(nose, **SMALL)


def test_table_read_back_equals_the_built_one(tmp_path):
    from semianalytic.coefficients.table import coefficient_table

    nose = ogive_nose(7.11e-3, 3.0)
    built = cache.cached_coefficient_table(nose, tmp_path, **SMALL)
    files = list(tmp_path.glob("*.npz"))
    assert [f.name for f in files] == [cache.table_key(nose, **SMALL) + ".npz"]
    again = cache.cached_coefficient_table(nose, tmp_path, **SMALL)  # from the file
    direct = coefficient_table(nose, **SMALL)
    P = np.geomspace(1e-4, 0.5, 37)  # off the table's knots
    for tab in (built, again):
        np.testing.assert_array_equal(tab.A(P), direct.A(P))
        np.testing.assert_array_equal(tab.B(P), direct.B(P))
        np.testing.assert_array_equal(tab.C(P), direct.C(P))


def test_commands_write_no_cache_into_the_working_directory(tmp_path):
    """``penetrate --json`` builds the table into $SEMIANALYTIC_CACHE_DIR, nothing into the cwd."""
    work, store = tmp_path / "work", tmp_path / "store"
    work.mkdir()
    env = {**os.environ, cache.CACHE_ENV: str(store), "PYTHONPATH": str(ROOT)}
    out = subprocess.run([sys.executable, "-m", "semianalytic", "penetrate", str(ROOT / "cases/demo_fig5_ogive.toml"),
                          "--json"], cwd=work, env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout)["depth_rigid_m"]
    assert list(work.iterdir()) == []
    assert len(list((store / "coefficients").glob("*.npz"))) == 1
