"""Issue 27: faults a hostile user meets (fast; part of ``make test``).

- ``--force`` replaces only the files a command wrote (its manifest), never a user's file, and
  the home folder, ``/``, the working folder and a case file's folder are refused outright;
- SIGTERM and SIGINT remove the staging folder and print one line; a second writer of one
  ``--out`` stops with exit status 2;
- caches verify themselves: a damaged, truncated, empty or foreign coefficient-table entry is
  discarded with a warning and rebuilt (the depths equal those of a clean cache); gmsh writes
  nothing into ``$HOME``; the mesh cache lives in the per-user cache;
- a damaged sweep store on resume is exit 2; a file name with a newline is shown escaped.

The expectations are the issue's (what must happen to the user's files), independent of the code.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from semianalytic.cli import main

ROOT = Path(__file__).resolve().parents[1]
SPHERE_BODY = ROOT / "cases" / "body_sphere.toml"  # a run of about a second
FIG15A = ROOT / "cases" / "fig15a_ogive_6061T651.toml"


def _run(capsys, *argv) -> tuple[int, str]:
    rc = main([str(a) for a in argv])
    return rc, capsys.readouterr().err


# ------------------------------------------------------------------------------------------
# --force and the manifest


def test_force_replaces_only_the_tools_files(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "out"
    rc, err = _run(capsys, "run", SPHERE_BODY, "--out", out, "--no-render")
    assert rc == 0, err
    manifest = json.loads((out / ".semianalytic-manifest.json").read_text())
    written = sorted(p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()
                     and p.name != ".semianalytic-manifest.json")
    assert manifest["files"] == written  # the manifest lists exactly what the command wrote
    (out / "notes.txt").write_text("my notes")  # a user's file beside the output
    before = sorted(p.name for p in out.iterdir())
    rc, err = _run(capsys, "run", SPHERE_BODY, "--out", out, "--no-render", "--force")
    assert rc == 2 and err.startswith("error: --out") and "'notes.txt'" in err, err
    assert len(err.strip().splitlines()) == 1
    assert (out / "notes.txt").read_text() == "my notes" and sorted(p.name for p in out.iterdir()) == before
    (out / "notes.txt").unlink()
    rc, err = _run(capsys, "run", SPHERE_BODY, "--out", out, "--no-render", "--force")
    assert rc == 0, err  # only the tool's files: replaced
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no staging folder left


def test_a_folder_without_manifest_is_never_replaced(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "mine"
    (out / "sub").mkdir(parents=True)
    (out / "sub" / "thesis.tex").write_text("years of work")
    rc, err = _run(capsys, "run", SPHERE_BODY, "--out", out, "--no-render", "--force")
    assert rc == 2 and "'sub/thesis.tex'" in err, err
    assert (out / "sub" / "thesis.tex").read_text() == "years of work"


@pytest.mark.parametrize("where", ["home", "root", "cwd", "case_folder", "above_case"])
def test_folders_refused_outright(tmp_path, monkeypatch, capsys, where):
    home = tmp_path / "home"
    home.mkdir()
    (home / "precious.txt").write_text("keep")
    monkeypatch.setenv("HOME", str(home))
    work = tmp_path / "work"
    (work / "cases").mkdir(parents=True)
    case = work / "cases" / "c.toml"
    case.write_text(SPHERE_BODY.read_text())
    monkeypatch.chdir(work)
    out = {"home": home, "root": Path("/"), "cwd": Path("."), "case_folder": work / "cases", "above_case": work}[where]
    snapshot = sorted(str(p) for p in tmp_path.rglob("*"))
    rc, err = _run(capsys, "run", case, "--out", out, "--no-render", "--force")
    assert rc == 2 and err.startswith("error: --out"), err
    assert sorted(str(p) for p in tmp_path.rglob("*")) == snapshot  # nothing removed, nothing written


@pytest.mark.parametrize("command", ["run", "calibrate", "optimize", "demo"])
def test_out_dot_refused_writes_nothing(tmp_path, monkeypatch, capsys, command):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SEMIANALYTIC_CACHE_DIR", str(tmp_path.parent / f"cache-{command}"))
    argv = {"run": ["run", SPHERE_BODY, "--out", ".", "--no-render"],
            "calibrate": ["calibrate", ROOT / "cases" / "piekutowski1999_var4340.toml", "--out", ".", "--quiet"],
            "optimize": ["optimize", ROOT / "cases" / "optimize_fig5_into_fig15a.toml", "--out", ".",
                         "--vary", "projectile.crh=2:4", "--no-progress"],
            "demo": ["demo", "--out", ".", "--no-render"]}[command]
    rc, err = _run(capsys, *argv, *(["--force"] if command != "demo" else []))
    assert rc == 2 and "--out" in err, err
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------------------------------
# signals and concurrent writers: a helper command that stages a file and waits


HELPER = textwrap.dedent('''
    import sys, time
    from semianalytic.cli import dispatch

    def add_arguments(parser):
        parser.add_argument("--out", required=True)
        parser.add_argument("--wait", type=float, default=60.0)
        parser.add_argument("--force", action="store_true")

    def run(args):
        from semianalytic.report.output import StagedDir
        with StagedDir(args.out, args.force) as d:
            d.write_text("a.txt", "partial")
            print("staged", flush=True)
            time.sleep(args.wait)
        return 0

    if __name__ == "__main__":
        sys.exit(dispatch("helper", {"slow": ("slowcmd", "a slow writer")}, sys.argv[1:]))
''')


def _helper(tmp_path: Path, *argv: str) -> subprocess.Popen:
    (tmp_path / "slowcmd.py").write_text(HELPER)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), str(ROOT)])}
    proc = subprocess.Popen([sys.executable, str(tmp_path / "slowcmd.py"), "slow", *argv], cwd=tmp_path, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    return proc


def _wait_staged(proc: subprocess.Popen) -> None:
    line = proc.stdout.readline()
    assert line.strip() == "staged", (line, proc.stderr.read() if proc.poll() is not None else "")


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_signal_removes_the_partial_output(tmp_path, sig):
    proc = _helper(tmp_path, "--out", "out")
    _wait_staged(proc)
    assert [p for p in tmp_path.iterdir() if p.name.startswith(".out.partial-")]  # staged, hidden
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 1
    assert len(err.strip().splitlines()) == 1 and err.startswith("interrupted"), err
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".out.")]  # no .partial left
    assert not (tmp_path / "out").exists()


def test_second_writer_of_one_out_fails_cleanly(tmp_path):
    first = _helper(tmp_path, "--out", "out")
    try:
        _wait_staged(first)
        second = _helper(tmp_path, "--out", "out", "--wait", "0")
        _, err = second.communicate(timeout=60)
        assert second.returncode == 2 and err.startswith("error: --out: another command"), err
        assert len(err.strip().splitlines()) == 1
        assert len([p for p in tmp_path.iterdir() if p.name.startswith(".out.partial-")]) == 1  # the first's only
    finally:
        first.terminate()
        first.communicate(timeout=60)
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".out.")]


# ------------------------------------------------------------------------------------------
# caches


def test_damaged_or_foreign_table_entries_are_rebuilt(tmp_path, capsys):
    """A truncated, empty, bit-flipped or foreign (another nose's table under this key) entry:
    discarded with a warning, rebuilt, and the depths are those of a clean cache."""
    import contextlib
    import io

    # small tables (8 fixed depths, order 4, 20 nose lengths): the check is of the cache, not the BEM
    small = "\n[coefficients]\ndepths = 8\nmax_depth_nose_lengths = 20.0\n[bem]\norder = 4\n"
    ogive, sphere = tmp_path / "ogive.toml", tmp_path / "sphere.toml"
    ogive.write_text(FIG15A.read_text() + small)
    sphere.write_text((ROOT / "cases" / "fig14_sphere_6061T651.toml").read_text() + small)
    cache = tmp_path / "cache"

    def depths() -> tuple[list[float], str]:
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            rc = main(["penetrate", str(ogive), "--json", "--cache-dir", str(cache)])
        assert rc == 0, err.getvalue()
        got = json.loads(out.getvalue())
        got = got[0] if isinstance(got, list) else got
        return json.dumps(got.get("rigid", got), sort_keys=True), err.getvalue()

    clean, err = depths()
    assert "discarded" not in err
    (entry,) = cache.glob("*.npz")
    good = entry.read_bytes()
    main(["penetrate", str(sphere), "--json", "--cache-dir", str(cache)])  # another nose's entry
    capsys.readouterr()
    other = next(p for p in cache.glob("*.npz") if p != entry).read_bytes()
    flipped = bytearray(good)
    flipped[len(good) // 2] ^= 0xFF
    for bad in (good[: len(good) // 3], b"", bytes(flipped), other):
        entry.write_bytes(bad)
        again, err = depths()
        assert "coefficient-table cache: discarded" in err, err
        assert again == clean  # the same numbers as from a clean cache, never the foreign table's
        assert entry.read_bytes() == good  # rebuilt and stored with its key again


def test_gmsh_writes_nothing_into_home_and_mesh_cache_is_per_user(tmp_path, monkeypatch):
    from fem_check import meshing
    from fem_check.coefficients import halfspace_mesh
    from fem_check.meshing import MeshOptions
    from semianalytic.geometry import sphere_nose

    home = tmp_path / "home"
    home.mkdir()
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.delenv("FEM_CHECK_MESH_CACHE", raising=False)
    monkeypatch.setenv("SEMIANALYTIC_CACHE_DIR", str(tmp_path / "cache"))
    assert meshing.cache_dir() == tmp_path / "cache" / "meshes"  # not the project's meshes/cache
    halfspace_mesh(sphere_nose(2.0), 0.5, MeshOptions(h=0.4, order=1))
    assert list(home.rglob("*")) == []  # no ~/.fltk/fltk.org/fltk.prefs
    assert os.environ["HOME"] == str(home)  # restored after gmsh
    assert list((tmp_path / "cache" / "meshes").glob("*.npz"))


def test_damaged_sweep_store_on_resume_is_exit_2(tmp_path, capsys):
    out = tmp_path / "sw"
    argv = ["sweep", FIG15A, "--out", out, "--vary", "impact.striking_velocity=400:600:100 m/s",
            "--scheduler", "inline", "--no-progress"]
    rc, err = _run(capsys, *argv)
    assert rc == 0, err
    for damage in ("{{{", "", "[1, 2]"):
        (out / "sweep.json").write_text(damage)
        rc, err = _run(capsys, *argv, "--resume")
        assert rc == 2 and err.startswith("error: --resume"), err
        assert "Traceback" not in err


def test_sweep_refuses_a_folder_with_foreign_files(tmp_path, capsys):
    out = tmp_path / "sw"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    rc, err = _run(capsys, "sweep", FIG15A, "--out", out, "--vary", "impact.striking_velocity=400:500:100 m/s",
                   "--scheduler", "inline", "--no-progress", "--force")
    assert rc == 2 and "'notes.txt'" in err, err
    assert [p.name for p in out.iterdir()] == ["notes.txt"]


def test_file_name_with_a_newline_is_shown_escaped(tmp_path):
    odd = tmp_path / "bad\nname.toml"
    odd.write_text("[projectile\nnose = 'ogive'\n")  # not TOML: the message names the file
    proc = subprocess.run([sys.executable, "-m", "semianalytic", "penetrate", str(odd)], capture_output=True,
                          text=True, timeout=120, cwd=tmp_path)
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    assert "\\n" in proc.stderr


def test_bench_bem_quick_names_a_case_that_exists():
    from benchmarks import bench_bem as bench

    text = Path(bench.__file__).read_text()
    named = [w.strip('"') for w in text.split() if w.startswith('"cases/') or w.startswith('["cases/')]
    assert named
    for name in named:
        assert (ROOT / name.strip('[]",')).is_file(), name


def test_case_named_files_stay_in_the_case_folder(tmp_path, capsys):
    case = tmp_path / "c.toml"
    case.write_text('[ballistic_limit]\ntable = "../../../../etc/hostname"\n')
    rc, err = _run(capsys, "ballistic-limit", case)
    assert rc == 2 and err.startswith("error: ballistic_limit.table") and "outside the case file's folder" in err, err


def test_time_and_memory_budgets_refuse_before_work(capsys, tmp_path, monkeypatch):
    monkeypatch.delenv("SEMIANALYTIC_TIME_LIMIT", raising=False)
    monkeypatch.delenv("SEMIANALYTIC_MEMORY_LIMIT", raising=False)
    flat = tmp_path / "crh3e5.toml"
    flat.write_text(FIG15A.read_text().replace("crh = 3.0", "crh = 300000.0"))
    cases = [
        (["calibrate", ROOT / "cases" / "piekutowski1999_var4340.toml", "--out", tmp_path / "c", "--steps", "1000000000"],
         "--steps"),
        (["optimize", ROOT / "cases" / "optimize_fig5_into_fig15a.toml", "--out", tmp_path / "o", "--vary",
          "projectile.crh=1:6", "--coarse", "1000", "--no-progress"], "--coarse"),
        (["optimize", ROOT / "cases" / "optimize_fig5_into_fig15a.toml", "--out", tmp_path / "o", "--vary",
          "projectile.crh=1:6", "--method", "de", "--popsize", "1000", "--maxiter", "1000", "--no-progress"], "--popsize"),
        (["sweep", FIG15A, "--out", tmp_path / "s", "--vary", "projectile.crh=3,1000000", "--scheduler", "inline"],
         "--vary projectile.crh"),
        (["sweep", FIG15A, "--out", tmp_path / "s", "--samples", "10000000", "--sample",
          "target.density=normal(2710 kg/m^3, 10 kg/m^3)", "--scheduler", "inline"], "--samples"),
        (["penetrate", FIG15A, "--memory-limit", "1e30"], "--memory-limit"),
        (["penetrate", flat], "projectile.crh"),  # fits 4 GB, but its table would take about half an hour
    ]
    for argv, field in cases:
        rc, err = _run(capsys, *argv)
        assert rc == 2 and err.startswith(f"error: {field}"), (argv, err)
        assert len(err.strip().splitlines()) == 1
    assert not (tmp_path / "c").exists() and not (tmp_path / "o").exists() and not (tmp_path / "s").exists()


def test_posterior_with_string_samples_or_too_large_is_bad_input(tmp_path):
    """A posterior whose draws are strings ("1.5e8" would convert silently) or a file of 100 MB
    (no posterior of calibrate is: ~0.5 MB for 1000 draws) is refused naming the field."""
    from semianalytic.errors import InputError
    from semianalytic.sections.calibration import read_posterior

    good = json.loads((ROOT / "reports" / "calibration_piekutowski1999" / "posterior.json").read_text())
    read_posterior(ROOT / "reports" / "calibration_piekutowski1999" / "posterior.json")  # the real one reads
    bad = json.loads(json.dumps(good))
    samples = bad["models"]["rigid"]["samples"]
    samples["sigma"] = [str(v) for v in samples["sigma"]]
    path = tmp_path / "strings.json"
    path.write_text(json.dumps(bad))
    with pytest.raises(InputError) as err:
        read_posterior(path)
    assert err.value.field == "models.rigid.samples.sigma"
    huge = tmp_path / "huge.json"
    with huge.open("wb") as fh:  # a sparse file of 100 MB: refused by its size, before it is read
        fh.truncate(100 * 10**6)
    with pytest.raises(InputError) as err:
        read_posterior(huge)
    assert err.value.field == "--posterior" and "100 MB" in err.value.message
