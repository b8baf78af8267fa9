"""Issue 13: the memory budget's sources, files only where asked, stale staging folders.

The guard's thresholds are checked against the sizes they are derived from (panel counts of
the real panel plan, the revolved grid's node count), not against earlier output.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from semianalytic import guards
from semianalytic.case import load_case
from semianalytic.cli import main
from semianalytic.errors import InputError

ROOT = Path(__file__).resolve().parents[1]
OGIVE = ROOT / "cases" / "fig5_ogive.toml"


def test_budget_sources(monkeypatch):
    monkeypatch.delenv(guards.MEMORY_ENV, raising=False)
    assert guards.memory_limit() == 4e9
    monkeypatch.setenv(guards.MEMORY_ENV, "8GiB")
    assert guards.memory_limit() == 8 * 2**30
    guards.set_memory_limit(1e9)
    try:
        assert guards.memory_limit() == 1e9  # the flag wins over the environment
    finally:
        guards.set_memory_limit(None)
    monkeypatch.setenv(guards.MEMORY_ENV, "plenty")
    with pytest.raises(InputError) as err:
        guards.memory_limit()
    assert err.value.field == guards.MEMORY_ENV


def test_panel_estimate_matches_the_panel_plan():
    """For a nose small enough to lay out, the unknown count is the real layout's
    (order x panels), so the budget is compared with what the solver will assemble."""
    from semianalytic.bem.panels import LayoutOptions, halfspace_layout
    from semianalytic.geometry import nose_from_section

    nose = nose_from_section(load_case(OGIVE).projectile)
    layout = halfspace_layout(nose, 300 * nose.length, LayoutOptions(8, 0.3))
    assert guards.bem_halfspace_unknowns(nose, 8, 0.3, 300) == 8 * sum(len(p.panels) for p in layout.pieces)
    # the arithmetic estimate used for absurd noses counts full grading at both ends of every
    # segment: an upper bound of the plan (refusing too early, never too late), within 2x here
    est = 8 * guards._estimated_nose_panels(nose, 0.3, 12)
    actual = 8 * sum(len(p.panels) for p in layout.pieces[:-1])
    assert actual <= est <= 2 * actual


def test_memory_limit_flag_and_env_through_the_cli(monkeypatch, capsys):
    assert main(["coefficients", str(OGIVE), "--refinement", "8", "--memory-limit", "100MB"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --refinement:") and "100 MB" in err and "largest refinement that fits" in err
    monkeypatch.setenv(guards.MEMORY_ENV, "100MB")
    assert main(["coefficients", str(OGIVE), "--refinement", "8"]) == 2
    assert "100 MB" in capsys.readouterr().err
    assert guards.memory_limit() == 100e6  # the flag of the previous command did not stay behind


def test_field_grid_guard_counts_nodes(tmp_path):
    case = tmp_path / "grid.toml"
    case.write_text(OGIVE.read_text() + '[impact]\nstriking_velocities = ["1 km/s"]\n'
                    "[run]\nfield_grid = [801, 801]\nfield_segments = 180\n")
    with pytest.raises(InputError) as err:
        guards.check_field_grid(load_case(case))
    assert err.value.field == "run.field_segments"
    best = int(err.value.message.rsplit(" ", 1)[1])
    # 801 x 801 x (best + 1) nodes at 400 B each fit in 4 GB, one more segment does not
    assert 801 * 801 * (best + 1) * 400 <= 4e9 < 801 * 801 * (best + 2) * 400


def test_fem_check_writes_only_with_out(tmp_path, monkeypatch):
    from fem_check.cli import main as fem_main

    monkeypatch.chdir(tmp_path)
    assert fem_main(["rod", "--elements", "40", "--round-trips", "10", "--json"]) == 0
    assert list(tmp_path.iterdir()) == []  # --json alone: nothing, no ./reports
    assert fem_main(["rod", "--elements", "40", "--round-trips", "10", "--out", "rep", "--name", "r1"]) == 0
    assert sorted(p.suffix for p in (tmp_path / "rep").iterdir())[-1] == ".png" and (tmp_path / "rep" / "r1.md").is_file()
    assert fem_main(["rod", "--elements", "40", "--out", "rep", "--no-report", "--name", "r2"]) == 0
    assert not (tmp_path / "rep" / "r2.md").exists()


def test_bench_bem_needs_out(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["bench-bem"]) == 2
    assert "--out" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_stale_staging_folders_removed_live_ones_kept(tmp_path):
    from semianalytic.report.output import StagedDir, _owner, remove_stale_staging

    out = tmp_path / "report"
    host = _owner().split(".")[0]
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    dead_pid = int(dead.stdout)  # a process that has exited
    killed = tmp_path / f".report.partial-{host}.{dead_pid}-abc"
    live = tmp_path / f".report.partial-{host}.{os.getpid()}-def"
    legacy_old = tmp_path / ".report.partial-xyz"  # no owner in the name, a day old
    legacy_new = tmp_path / ".report.partial-uvw"  # no owner, recent: perhaps another machine's live run
    other = tmp_path / ".other.partial-x.1-q"  # another output's folder
    for d in (killed, live, legacy_old, legacy_new, other):
        d.mkdir()
        (d / "f.txt").write_text("x")
    day_ago = time.time() - 2 * 24 * 3600
    os.utime(legacy_old, (day_ago, day_ago))
    removed = remove_stale_staging(out)
    assert sorted(p.name for p in removed) == sorted([killed.name, legacy_old.name])
    assert live.exists() and legacy_new.exists() and other.exists()
    with StagedDir(out) as staged:  # the next run cleans up on its way in and commits
        staged.write_text("a.txt", "a")
    assert (out / "a.txt").read_text() == "a"


def test_out_through_a_file_or_proc_is_exit_2(tmp_path, capsys):
    (tmp_path / "afile").write_text("x")
    for out in (tmp_path / "afile" / "sub", Path("/proc/x")):
        assert main(["run", str(OGIVE), "--out", str(out)]) == 2
        err = capsys.readouterr().err
        assert err.startswith("error: --out:") and len(err.strip().splitlines()) == 1


def test_run_and_penetrate_write_no_cache_into_the_cwd(tmp_path):
    """Without $SEMIANALYTIC_CACHE_DIR the tables go to the per-user cache (platformdirs,
    here $XDG_CACHE_HOME), never to ./.cache of the folder the command runs in."""
    work = tmp_path / "work"
    work.mkdir()
    env = {k: v for k, v in os.environ.items() if k != "SEMIANALYTIC_CACHE_DIR"}
    env["XDG_CACHE_HOME"] = str(tmp_path / "xdg")
    for argv in (["run", str(OGIVE), "--out", "out", "--only", "coefficients", "--no-render"],
                 ["penetrate", str(ROOT / "cases" / "fig15a_ogive_6061T651.toml"), "--json"]):
        proc = subprocess.run([sys.executable, "-m", "semianalytic", *argv], cwd=work, env=env,
                              capture_output=True, text=True, timeout=600)
        assert proc.returncode == 0, proc.stderr[-1500:]
    assert sorted(p.name for p in work.iterdir()) == ["out"]
    assert any((tmp_path / "xdg" / "semianalytic").rglob("*.npz"))


@pytest.mark.parametrize("out", ["", ".", ".."])
def test_output_folder_never_the_working_folder(tmp_path, monkeypatch, capsys, out):
    """The output folder is replaced as a whole; `--out .` (or '' or a parent) with --force must
    be refused with exit 2 before anything is deleted: the user's file stays."""
    from semianalytic.cli import main

    work = tmp_path / "work"
    work.mkdir()
    (work / "sentinel.txt").write_text("keep me")
    monkeypatch.chdir(work)
    case = str(Path(__file__).resolve().parent.parent / "cases" / "fig5_ogive.toml")
    assert main(["run", case, "--out", out, "--force"]) == 2
    assert "--out" in capsys.readouterr().err
    assert sorted(p.name for p in work.iterdir()) == ["sentinel.txt"]


LONG_NAME = "x" * 300  # longer than a file name may be (255 bytes): the file system says ENAMETOOLONG


@pytest.mark.parametrize("argv", [
    ["run", "cases/fig5_ogive.toml", "--out", LONG_NAME],
    ["penetrate", "cases/fig5_ogive.toml", "--report", LONG_NAME],
    ["calibrate", "cases/piekutowski1999_var4340.toml", "--out", "ok", "--report", LONG_NAME + ".md"],
    ["calibrate", "cases/piekutowski1999_var4340.toml", "--out", LONG_NAME],
    ["bench-bem", "--out", LONG_NAME],
    ["coefficients", "cases/fig5_ogive.toml", "--cache-dir", LONG_NAME],
    ["sweep", "cases/fig5_ogive.toml", "--out", LONG_NAME, "--vary", "impact.striking_velocity=400:600:100"],
])
def test_too_long_a_name_is_bad_input(argv, tmp_path, monkeypatch, capsys):
    """A path the file system cannot hold: exit 2 naming the flag, no traceback, nothing written."""
    root = Path(__file__).resolve().parent.parent
    argv = [str(root / a) if a.startswith("cases/") else a for a in argv]
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --") and "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert list(tmp_path.iterdir()) == []


def test_fem_check_too_long_a_name_is_bad_input(tmp_path, monkeypatch, capsys):
    from fem_check.cli import main as fem_main

    monkeypatch.chdir(tmp_path)
    case = str(Path(__file__).resolve().parent.parent / "cases" / "fig5_ogive.toml")
    assert fem_main(["verify", case, "--out", LONG_NAME]) == 2
    assert capsys.readouterr().err.startswith("error: --out")
    assert list(tmp_path.iterdir()) == []


def test_field_depths_of_a_flat_nose_are_in_its_depth_unit(tmp_path):
    """[run] field_depths of a flat nose (L_h = 0): the guard counts them in radii, as the tables
    do (it divided by L_h and asked for ~1e297 nose lengths of panels)."""
    case = tmp_path / "flat_field.toml"
    case.write_text(Path(__file__).resolve().parent.parent.joinpath("cases", "flat_nose.toml").read_text()
                    + '\n[run]\nanalyses = ["coefficients", "velocity_field"]\nfield_depths = ["10 mm"]\n')
    guards.check_case(load_case(case), field=True)  # 10 mm = 2.8 radii: far inside the default budget


def test_spline_nose_too_slow_names_its_control_radii(monkeypatch, capsys, tmp_path):
    """A spline nose whose table does not fit the time budget names the key that shapes it (not
    just 'projectile'), as the ogive's names crh."""
    case = Path(__file__).resolve().parents[1] / "cases" / "optimize_spline_into_fig15a.toml"
    monkeypatch.setenv(guards.TIME_ENV, "0.001")
    monkeypatch.setenv("SEMIANALYTIC_CACHE_DIR", str(tmp_path))  # no cached table: the budget is checked
    assert main(["coefficients", str(case)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: projectile.control_radii:") and "time budget" in err
