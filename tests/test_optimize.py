"""`optimize`: nose-shape optimisation with the BEM in the loop (issue 14).

The optimiser is checked against a brute-force grid of the same objective evaluated design by
design (coarse BEM settings: the check is of the search, not of the BEM); the constraints
against the projectile's own volume (geometry.Projectile, exact quadrature); bad input exits 2
naming the flag and writes nothing.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from case_blocks import COARSE_TABLES, TARGET_6061_T651

from semianalytic.cli import main
from semianalytic.geometry import Projectile, ogive_nose
from semianalytic.optimize.model import Infeasible, shank_for_constraints

# Coarse tables (order 4, 16 depths to 30 nose lengths): about 0.5 s per design on one core.
CASE = """
title = "optimize test: ogive into aluminium, coarse BEM"
[projectile]
nose = "ogive"
crh = 3.0
diameter = "7.11 mm"
shank_length = "{shank}"
density = "7830 kg/m^3"
youngs_modulus = "210 GPa"
poisson_ratio = 0.29
yield_stress = "1.5 GPa"
""" + TARGET_6061_T651 + """[impact]
striking_velocities = ["0.6 km/s", "1.2 km/s"]
""" + COARSE_TABLES


@pytest.fixture()
def case_file(tmp_path, monkeypatch):
    monkeypatch.setenv("SEMIANALYTIC_CACHE_DIR", str(tmp_path / "cache"))
    p = tmp_path / "case.toml"
    p.write_text(CASE.format(shank="59.3 mm"))
    return p


def test_fixed_mass_shank_against_the_projectile_volume():
    # the shank of the fixed-mass constraint gives the projectile (nose + shank, by quadrature) the mass m0
    rho, m0 = 7830.0, 20.44e-3
    for crh in (0.5, 1.7, 6.3):
        nose = ogive_nose(7.11e-3, crh)
        c = shank_for_constraints(nose.volume(), nose.length, 7.11e-3, start_shank=0.05, density=rho, mass=m0)
        assert math.isclose(Projectile(nose, c.shank_length, rho).mass, m0, rel_tol=1e-12)  # quadrature round-off
        c = shank_for_constraints(nose.volume(), nose.length, 7.11e-3, start_shank=0.05, density=rho, length=0.07)
        assert math.isclose(Projectile(nose, c.shank_length, rho).length, 0.07, rel_tol=1e-14)
    with pytest.raises(Infeasible):
        shank_for_constraints(1e-6, 0.01, 7.11e-3, start_shank=0.05, density=rho, mass=1e-3)


@pytest.mark.parametrize("method", ["grid-pattern", "grid-nm", "de"])
def test_optimum_against_a_brute_force_grid(case_file, tmp_path, capsys, method):
    from semianalytic.case import load_case
    from semianalytic.optimize.case import build_problem
    from semianalytic.optimize.evaluate import evaluate_design

    out = tmp_path / "opt"
    rc = main(["optimize", str(case_file), "--out", str(out), "--vary", "projectile.crh=1:5", "--objective", "depth",
               "--constraint", "mass", "--scheduler", "inline", "--popsize", "3", "--maxiter", "3", "--confirm", "0",
               "--method", method, "--coarse", "3", "--no-progress"])
    assert rc == 0
    res = json.loads((out / "optimum.json").read_text())
    assert {p.name for p in out.iterdir()} >= {"optimum.json", "history.csv", "history.json", "noses.png", "report.md"}
    # the classic noses are evaluated although the case has a crh (removed for the sphere and the cone)
    assert all(r["status"] == "ok" for r in res["classic"].values()), res["classic"]
    x_opt, f_opt = res["optimum"]["x"][0], res["optimum"]["objective"]
    # the same objective, design by design, on a grid the optimiser did not choose
    problem = build_problem(load_case(case_file), ["projectile.crh=1:5"], "depth", ["mass"])
    grid = np.linspace(1.0, 5.0, 9)
    f = np.array([evaluate_design(problem, {"projectile.crh": float(c)})["objective"] for c in grid])
    k = int(np.argmin(f))
    spacing = grid[1] - grid[0]
    # within the grid's resolution: at most one step from the grid's best, and no worse than the
    # grid's best neighbour of the optimum
    assert abs(x_opt - grid[k]) <= spacing + 1e-12
    assert f_opt <= max(f[max(k - 1, 0)], f[min(k + 1, len(f) - 1)]) + 1e-12
    # every design satisfies the fixed mass (the start's, 7830 kg/m^3 x volume)
    m0 = res["fixed_mass_kg"]
    for r in json.loads((out / "history.json").read_text()):
        if r["status"] == "ok" and r["phase"] != "classic":
            assert math.isclose(r["mass_kg"], m0, rel_tol=1e-9)


@pytest.mark.parametrize(
    "args, flag",
    [
        (["--vary", "projectile.crh=0.3:4"], "--vary projectile.crh"),
        (["--vary", "projectile.half_angle=10 deg:40 deg"], "--vary projectile.half_angle"),
        (["--vary", "projectile.crh=1:4", "--objective", "deep_drag", "--constraint", "mass"], "--constraint"),
        (["--vary", "projectile.crh=1:4", "--objective", "speed"], "--objective"),
        (["--vary", "projectile.crh=1:12", "--constraint", "mass"], "--constraint mass"),
        (["--vary", "projectile.crh=1:4", "--vary", "projectile.meplat_diameter=0 mm:7.11 mm"], "--vary projectile.meplat_diameter"),
        (["--vary", "projectile.tip_radius=0 mm:9 mm"], "--vary projectile.tip_radius"),
        (["--vary", "projectile.crh=1:4", "--table-depths", "4"], "--table-depths"),
        (["--vary", "projectile.crh=1:4", "--table-nose-lengths", "0.5"], "--table-nose-lengths"),
        (["--vary", "projectile.crh=1:4", "--method", "simplex"], "--method"),
        (["--vary", "projectile.crh=1:4", "--coarse", "1"], "--coarse"),
    ],
)
def test_bad_input_exits_2_naming_the_flag(tmp_path, monkeypatch, capsys, args, flag):
    monkeypatch.setenv("SEMIANALYTIC_CACHE_DIR", str(tmp_path / "cache"))
    p = tmp_path / "case.toml"
    p.write_text(CASE.format(shank="2 mm"))  # a short shank: long noses cannot keep the mass
    out = tmp_path / "opt"
    rc = main(["optimize", str(p), "--out", str(out), "--scheduler", "inline", "--no-progress", *args])
    err = capsys.readouterr().err
    assert rc == 2 and err.startswith(f"error: {flag}"), err
    assert not out.exists() and not (tmp_path / "cache").exists()


def test_design_tables_and_the_check_on_the_case_tables(case_file, tmp_path):
    # lighter design tables (--table-depths/--table-nose-lengths): the optimum is evaluated again on the
    # case's own tables, and the difference is the design tables' error in the objective
    out = tmp_path / "opt"
    rc = main(["optimize", str(case_file), "--out", str(out), "--vary", "projectile.crh=2:4", "--constraint", "mass",
               "--scheduler", "inline", "--coarse", "3", "--maxfev", "4", "--confirm", "0", "--table-depths", "10",
               "--table-nose-lengths", "20", "--no-progress"])
    assert rc == 0
    res = json.loads((out / "optimum.json").read_text())
    chk = res["own_tables_check"]
    assert chk["table_overrides"] == {"coefficients.depths": 10, "coefficients.max_depth_nose_lengths": 20.0}
    assert chk["design_tables_objective"] == res["optimum"]["objective"]
    # a coarser table than the case's 16 depths: not the same number, but the same depth to 1e-3 (a table
    # of 10 depths interpolates the coefficients to about 1e-4, and the depth integrates them)
    assert 0 < chk["relative_difference"] < 1e-3
    assert "on the case's own tables" in (out / "report.md").read_text()


def test_objective_not_defined_for_the_case(tmp_path, capsys):
    p = tmp_path / "case.toml"
    p.write_text(CASE.format(shank="59.3 mm").split("[target.resistance]")[0])
    rc = main(["optimize", str(p), "--out", str(tmp_path / "o"), "--vary", "projectile.crh=1:4"])
    assert rc == 2 and "error: --objective" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_unreachable_scheduler(case_file, tmp_path, capsys):
    rc = main(["optimize", str(case_file), "--out", str(tmp_path / "o"), "--vary", "projectile.crh=1:4",
               "--scheduler", "tcp://127.0.0.1:9", "--no-progress"])
    assert rc == 2 and "error: --scheduler" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_deep_drag_of_a_cone_and_the_exact_rod_depth(tmp_path, monkeypatch):
    # a cone's deep drag over its half angle, and an ogive's exact-rod depth: the optimum is the
    # best design the search evaluated, and a sharper cone has the smaller Bbar (the BEM's deep
    # limit decreases with the half angle; the grid spans 15-40 deg, far apart against the
    # coarse table's error)
    from semianalytic.case import load_case
    from semianalytic.optimize.case import build_problem
    from semianalytic.optimize.evaluate import optimise

    monkeypatch.setenv("SEMIANALYTIC_CACHE_DIR", str(tmp_path / "cache"))
    p = tmp_path / "cone.toml"
    p.write_text(CASE.format(shank="59.3 mm").replace('nose = "ogive"\ncrh = 3.0', 'nose = "cone"\nhalf_angle = "20 deg"'))
    problem = build_problem(load_case(p), ["projectile.half_angle=15 deg:40 deg"], "deep_drag", ["caliber"])
    res = optimise(problem, popsize=2, maxiter=1, confirm=0, classic_noses=False)
    ok = [r for r in res["history"] if r["status"] == "ok" and r["phase"] in ("search", "start")]
    by_angle = sorted((r["x"][0], r["objective"]) for r in ok if "x" in r)
    assert by_angle[0][1] < by_angle[-1][1]
    q = tmp_path / "ogive.toml"
    q.write_text(CASE.format(shank="59.3 mm"))
    problem = build_problem(load_case(q), ["projectile.crh=2:4"], "depth", ["length"], depth_model="exact-rod")
    res = optimise(problem, popsize=2, maxiter=1, confirm=0, classic_noses=False)
    assert res["optimum"]["status"] == "ok" and len(res["optimum"]["depths_m"]) == 2
    assert all(math.isclose(r["length_m"], res["fixed_length_m"], rel_tol=1e-12)
               for r in res["history"] if r["status"] == "ok" and r["phase"] != "classic")
