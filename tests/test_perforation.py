"""Perforation (issue 23): the ``perforate`` command's keys and exit codes, the thick-plate
identity with ``penetrate``, the ballistic limit against an independent time integration, the
back-face factor against Hill's finite-sphere integral, the Lambert-Jonas fit, bad inputs."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
DEMO = ROOT / "cases" / "perforation_ogive_6061T651.toml"


def _cli(*args, cwd=ROOT):
    env = {**os.environ, "MPLBACKEND": "Agg"}
    return subprocess.run([sys.executable, "-m", "semianalytic", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, env=env, timeout=300)


class _Result:
    def __init__(self, returncode, stdout, stderr):
        self.returncode, self.stdout, self.stderr = returncode, stdout, stderr


def _main(*args):
    """The command in-process (the dispatcher's exit status and streams; no interpreter start-up)."""
    import contextlib
    import io

    from semianalytic.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        rc = main([str(a) for a in args])
    return _Result(rc, out.getvalue(), err.getvalue())


def _case(tmp_path, text: str, name="case.toml") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def _demo_text(fast: bool = True, **replace) -> str:
    """The demo case; ``fast``: with the half-space stand-in coefficients ([perforation]
    coefficients = "half-space"), so that no plate table (minutes of BEM solves) is built: the
    tests of the dynamics, the CLI and bad input do not depend on which table it is."""
    text = DEMO.read_text()
    if fast:
        text = text.replace("[perforation]\n", '[perforation]\ncoefficients = "half-space"\n', 1)
    for old, new in replace.items():
        text = text.replace(old, new)
    return text


# --------------------------------------------------------------------------------------
# the command


def test_perforate_json_keys_and_curve(tmp_path):
    r = _cli("perforate", _case(tmp_path, _demo_text()), "--json")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    n = len(out["striking_velocity_m_s"])
    for key in ("perforated", "residual_velocity_m_s", "depth_m", "exit_time_s"):
        assert len(out[key]) == n, key
    for key in ("ballistic_limit_m_s", "ballistic_limit_error_m_s", "lambert_jonas", "part4_v_cr_m_s"):
        assert key in out, key
    assert set(out["lambert_jonas"]) == {"a", "p", "V_bl_m_s"}
    assert "eq5_R3" in out["part4_v_cr_m_s"]  # Y and E of the target give R(3) of Part IV eq. (6)
    V_bl = out["ballistic_limit_m_s"]
    for U, perf, Vr, P, t in zip(out["striking_velocity_m_s"], out["perforated"], out["residual_velocity_m_s"],
                                 out["depth_m"], out["exit_time_s"]):
        # stops below the limit (V_r = 0, a depth inside the plate), perforates above (V_r < V_s, an exit time)
        assert perf == (U > V_bl)
        if perf:
            assert 0 < Vr < U and t > 0 and P is None
        else:
            assert Vr == 0 and 0 < P < out["thickness_m"] + 0.0119 and t is None
    # the reproducibility target (0.5 m/s) is met by the estimate the command states
    assert out["ballistic_limit_error_m_s"] <= 0.5
    # eq. (11) is linear in w = u^2: V_r^2 = exp(-F(P_exit)) (V_s^2 - V_bl^2) exactly, the Lambert-Jonas
    # form with p = 2, so the fit of the computed points must find p = 2 and the bisection's V_bl
    # (to the fit's convergence, 1e-4 relative, and the bisection's error)
    assert out["lambert_jonas"]["p"] == pytest.approx(2.0, rel=1e-4)
    assert out["lambert_jonas"]["V_bl_m_s"] == pytest.approx(V_bl, abs=1e-4 * V_bl + out["ballistic_limit_error_m_s"])


@pytest.mark.parametrize("edit, field", [
    ({'thickness = "26.3 mm"': 'thickness = "0 mm"'}, "target.thickness"),
    ({'thickness = "26.3 mm"': 'thickness = "-3 mm"'}, "target.thickness"),
    ({'thickness = "26.3 mm"\n': '[[target.layers]]\nthickness = "10 mm"\n[[target.layers]]\ngap = "-2 mm"\nthickness = "5 mm"\n'},
     "target.layers.1.gap"),
    ({'thickness = "26.3 mm"\n': '[[target.layers]]\nthickness = "10 mm"\n[[target.layers]]\ngap = "2 mm"\n'},
     "target.layers.1.gap"),
    ({'back_face = "auto"': 'back_face = "round"'}, "perforation.back_face"),
])
def test_bad_input_exit_2_naming_the_key(tmp_path, edit, field):
    r = _main("perforate", _case(tmp_path, _demo_text(**edit)), "--json")
    assert r.returncode == 2, r.stderr
    assert r.stderr.startswith(f"error: {field}:"), r.stderr
    assert "Traceback" not in r.stderr and len(r.stderr.strip().splitlines()) == 1
    if "-2 mm" in str(edit):
        assert "overlapping" in r.stderr
    if 'gap = "2 mm"\n' in str(edit):
        assert "without a following layer" in r.stderr


def test_no_perforation_when_a_ballistic_limit_is_asked(tmp_path):
    """Issue 37: no listed velocity perforates, and the command finds V_bl itself (exit 0), the same as
    with the demo's velocities (the search does not depend on the listed velocities: 0.1 m/s)."""
    text = _demo_text(**{'striking_velocities = [': 'striking_velocities = ["100 m/s", "150 m/s"] #'})
    r = _main("perforate", _case(tmp_path, text), "--json")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert not any(out["perforated"]) and out["ballistic_limit_bound"] == "exact"
    full = json.loads(_main("perforate", _case(tmp_path, _demo_text()), "--json").stdout)
    assert out["ballistic_limit_m_s"] == pytest.approx(full["ballistic_limit_m_s"], abs=0.1)
    ok = _main("perforate", _case(tmp_path, text), "--json", "--no-ballistic-limit")
    assert ok.returncode == 0 and json.loads(ok.stdout)["ballistic_limit_m_s"] is None


def test_older_cases_keep_their_meaning():
    from semianalytic.case import load_case

    case = load_case(ROOT / "cases" / "fig15a_ogive_6061T651.toml")
    assert case.target.thickness is None and case.target.layers is None


# --------------------------------------------------------------------------------------
# the model


@pytest.fixture(scope="module")
def demo_setup(tmp_path_factory):
    from semianalytic.case import load_case
    from semianalytic.commands.perforate.evaluate import perforation_setup

    case = load_case(_case(tmp_path_factory.mktemp("demo"), _demo_text()))
    return case, perforation_setup(case)


def test_ballistic_limit_against_time_integration(demo_setup):
    """The bisection (eq. (11) in P) against an independent integration of eq. (11) in time
    (solve_motion, DOP853, rtol 1e-10): 0.5 m/s below the limit the rod stops inside, 0.5 m/s
    above it leaves the plate (the issue's reproducibility target)."""
    from semianalytic.penetration.motion import solve_motion
    from semianalytic.perforation.model import ballistic_limit

    _, s = demo_setup
    bl = ballistic_limit(s.coefficients, s.mass, 400.0, tolerance=0.05)
    assert bl.error <= 0.5
    Pe = s.coefficients.exit_depth
    below = solve_motion(s.coefficients, s.mass, 1.0, 1.0, bl.value - 0.5)
    above = solve_motion(s.coefficients, s.mass, 1.0, 1.0, bl.value + 0.5)
    assert below.final_depth < Pe < above.final_depth


def test_ballistic_limit_bracket_without_the_limit_raises(demo_setup):
    """A ``lower`` bracket that already perforates holds no change of sign: the bisection says so
    instead of returning the bracket's end as the limit."""
    from semianalytic.perforation.model import ballistic_limit

    _, s = demo_setup
    V = ballistic_limit(s.coefficients, s.mass, 400.0, tolerance=0.05).value
    with pytest.raises(RuntimeError, match="no change"):
        ballistic_limit(s.coefficients, s.mass, V + 20.0, lower=V + 10.0, tolerance=0.05)


def test_residual_velocity_and_exit_time_against_time_integration(demo_setup):
    """V_r and the exit time of the P-form against the time integration's dense output at the
    exit depth; 1e-5 relative covers the dense output's interpolation (rtol 1e-10 steps)."""
    from semianalytic.penetration.motion import solve_motion
    from semianalytic.perforation.model import perforation_curve

    _, s = demo_setup
    U = 600.0
    cur = perforation_curve(s.coefficients, s.mass, [U])
    mo = solve_motion(s.coefficients, s.mass, 1.0, 1.0, U)
    t = np.linspace(0.0, mo.penetration_time, 200001)
    P, u = mo.at(t)
    Pe = s.coefficients.exit_depth
    t_exit = float(np.interp(Pe, P, t))
    assert cur.exit_time[0] == pytest.approx(t_exit, rel=1e-5)
    assert cur.residual_velocity[0] == pytest.approx(float(np.interp(Pe, P, u)), rel=1e-5)


@pytest.mark.parametrize("back_face", ["constant", pytest.param("finite-sphere", marks=pytest.mark.slow)])
def test_thick_plate_gives_the_penetrate_depth(tmp_path, back_face):
    """H = 20 rod lengths (1658 mm): the stopping depths equal the half-space depths of
    ``penetrate`` (rigid) within its depth error estimate.  The finite-sphere back face lowers the
    resistance by (c/b)^3 / (1 + ln(2E/3Y)) even 1.6 m away (about 2e-7): that physical change,
    bounded by P times that fraction, is added to the tolerance."""
    H = 20 * 0.0829
    text = _demo_text(**{'thickness = "26.3 mm"': f'thickness = "{H * 1e3:.1f} mm"',
                         'back_face = "auto"': f'back_face = "{back_face}"'})
    path = _case(tmp_path, text)
    perf = _cli("perforate", path, "--json", "--no-ballistic-limit")
    pen = _cli("penetrate", path, "--json")
    assert perf.returncode == 0 and pen.returncode == 0, perf.stderr + pen.stderr
    assert "more than this rod can ever reach" in perf.stderr  # said, and computed anyway
    a, b = json.loads(perf.stdout), json.loads(pen.stdout)
    P1 = np.array(a["depth_m"], float)
    P0 = np.array(b["depth_rigid_m"])
    err = np.array(b["depth_error_estimate_m"]["rigid"])
    if back_face == "finite-sphere":
        q = (2 * 68.9e9 / (3 * 400e6)) ** (1 / 3)
        c = q * 0.00711 / 2
        err = err + P0 * (c / (H - P0.max())) ** 3 / (1 + 3 * math.log(q))
    assert not any(a["perforated"])
    assert np.all(np.abs(P1 - P0) <= err), (P1 - P0, err)


def test_back_face_factor_against_hill_integral():
    """Hill's finite sphere: p(b) = int_a^b 2 (sigma_theta - sigma_r)/r dr with the stress
    difference Y in the plastic zone (r < c) and Y (c/r)^3 in the elastic shell, computed here by
    quadrature, divided by the same integral to infinity; against back_face_factor to 1e-10."""
    from scipy.integrate import quad

    from semianalytic.perforation.model import back_face_factor

    a, q = 1.0, 4.0
    c = q * a

    def p(b):
        plastic = quad(lambda r: 2.0 / r, a, min(b, c))[0]
        elastic = quad(lambda r: 2.0 * (c / r) ** 3 / r, c, b)[0] if b > c else 0.0
        return plastic + elastic

    p_inf = quad(lambda r: 2.0 / r, a, c)[0] + quad(lambda r: 2.0 * (c / r) ** 3 / r, c, np.inf)[0]
    for b in (1.0, 1.5, 3.0, 4.0, 6.0, 40.0):
        assert back_face_factor(b, a, q) == pytest.approx(p(b) / p_inf, abs=1e-10)
    assert back_face_factor(0.5, a, q) == 0.0


def test_lambert_jonas_fit_recovers_known_parameters():
    """Synthetic V_r from known (a, p, V_bl) are fitted back to 1e-4."""
    from semianalytic.perforation.model import lambert_jonas, lambert_jonas_fit

    Vs = np.linspace(200.0, 1200.0, 30)
    Vr = lambert_jonas(Vs, 0.9, 2.4, 430.0)
    fit = lambert_jonas_fit(Vs, Vr)
    assert fit["a"] == pytest.approx(0.9, rel=1e-4)
    assert fit["p"] == pytest.approx(2.4, rel=1e-4)
    assert fit["V_bl_m_s"] == pytest.approx(430.0, rel=1e-4)


def test_layered_target_runs_and_a_gap_changes_nothing_but_time(tmp_path):
    """Two layers with an air gap: the projectile flies the gap freely, so V_r equals that of the
    same layers touching (each layer sees its own plate coefficients); the exit time grows by
    about gap / V_mid (checked loosely: it must grow)."""
    base = '[[target.layers]]\nthickness = "8 mm"\n[[target.layers]]\n{gap}thickness = "8 mm"\n'
    outs = []
    for gap in ("", 'gap = "200 mm"\n'):
        text = _demo_text(**{'thickness = "26.3 mm"\n': base.format(gap=gap)})
        r = _main("perforate", _case(tmp_path, text), "--json", "--no-ballistic-limit")
        assert r.returncode == 0, r.stderr
        outs.append(json.loads(r.stdout))
    touching, apart = outs
    assert len(apart["layers"]) == 2 and apart["layers"][1]["front_m"] == pytest.approx(0.208)
    # apart: no overlap of the nose with both layers; touching: the stand-in sums both layers'
    # coefficients while the nose spans the joint, so the two differ a little; 2 % bounds it here
    for Vt, Va in zip(touching["residual_velocity_m_s"], apart["residual_velocity_m_s"]):
        assert Va == pytest.approx(Vt, rel=0.02, abs=1.0)
    i = len(apart["exit_time_s"]) - 1
    assert apart["exit_time_s"][i] > touching["exit_time_s"][i]


def test_flat_nose_plug_against_recht_ipson_closed_form(tmp_path):
    """A flat nose on a 3 mm plate: the braking force C R_t exceeds the ligament's shear capacity
    pi d H tau at first contact (d R_t / 4 > H tau), so the plug forms at the impact face and the
    Recht-Ipson balance (momentum, then the shear work pi d tau H^2 / 2) gives V_r in closed form:
    V_r^2 = (m V_s / (m + m_p))^2 - pi d tau H^2 / (m + m_p).  The model forms the plug at the first
    grid point (H/800) after eq. (11) has braked it there: 0.2 % covers that."""
    text = (ROOT / "cases" / "flat_nose.toml").read_text().replace("[target]\n", '[target]\nthickness = "3 mm"\n', 1)
    text += '\n[perforation]\ncoefficients = "half-space"\n'  # a flat nose: C is the full area from first contact either way
    r = _cli("perforate", _case(tmp_path, text), "--json")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["failure"] == "plug" and out["plug_layer"] == [0, 0]
    m, d, H, tau = out["mass_kg"], 7.11e-3, 3e-3, 400e6 / math.sqrt(3)
    mp = 2710 * math.pi * d * d / 4 * H
    for Vs, Vr in zip(out["striking_velocity_m_s"], out["residual_velocity_m_s"]):
        expect = math.sqrt((m * Vs / (m + mp)) ** 2 - math.pi * d * tau * H * H / (m + mp))
        assert Vr == pytest.approx(expect, rel=2e-3)
    # the ballistic limit: v0 just enough for the shear work
    V_bl = (m + mp) / m * math.sqrt(math.pi * d * tau * H * H / (m + mp))
    assert out["ballistic_limit_m_s"] == pytest.approx(V_bl, rel=2e-2)


def test_run_gains_a_perforation_section(tmp_path):
    """`run --only perforation`: the section, the V_r figure and its data as CSV (the CSV's
    computed rows are the command's curve; the limit rows its ballistic limit and Part IV's V_cr)."""
    out = tmp_path / "out"
    r = _cli("run", _case(tmp_path, _demo_text()), "--out", out, "--only", "perforation")
    assert r.returncode == 0, r.stderr
    text = (out / "report.md").read_text()
    assert "## Perforation" in text and "perforation_residual_velocity.png" in text
    rows = (out / "figures" / "perforation_residual_velocity.csv").read_text().splitlines()
    assert rows[0] == "kind,name,Vs_m_s,Vr_m_s"
    kinds = {row.split(",")[0] for row in rows[1:]}
    assert kinds == {"computed", "limit"}
    assert any(row.startswith("limit,part4_eq5_R3,") for row in rows)


@pytest.mark.slow
def test_thick_plate_with_the_plate_table_gives_the_penetrate_depth(tmp_path):
    """The same identity on the plate BEM table (H = 20 rod lengths: a 311-knot table, 2 to
    16 min of BEM solves on a loaded machine, then cached).  The plate is not the half-space: the
    image of the monopole lowers A by C^2 ln 2 / (2 pi H) (and B on the nose by C C' ln 2 / (pi H);
    semianalytic.coefficients.plate), which changes the stopping depth by at most
    P rho C^2 ln 2 / (pi H m) relative to the half-space (the effective mass m + rho A and the
    drag rho B, each at most that fraction).  Measured: 6e-7 relative, the bound 2.3e-5."""
    H = 20 * 0.0829
    text = _demo_text(fast=False, **{'thickness = "26.3 mm"': f'thickness = "{H * 1e3:.1f} mm"',
                                     'back_face = "auto"': 'back_face = "constant"'})
    path = _case(tmp_path, text)
    perf = _cli("perforate", path, "--json", "--no-ballistic-limit")
    pen = _cli("penetrate", path, "--json")
    assert perf.returncode == 0 and pen.returncode == 0, perf.stderr + pen.stderr
    a, b = json.loads(perf.stdout), json.loads(pen.stdout)
    assert "plate BEM table" in a["coefficients"]
    P1, P0 = np.array(a["depth_m"], float), np.array(b["depth_rigid_m"])
    C, rho, m = math.pi * 0.00711**2 / 4, 2710.0, a["mass_kg"]
    allow = np.array(b["depth_error_estimate_m"]["rigid"]) + P0 * rho * C * C * math.log(2) / (math.pi * H * m)
    assert np.all(np.abs(P1 - P0) <= allow), (P1 - P0, allow)


def test_part4_table3_shots_beside_the_ballistic_limit_command():
    """The Table 3 comparison: Part IV's values per shot are those of the `ballistic-limit`
    command on the same case (reused, not recomputed), and the shots the assumed nose cannot fit
    are named, not dropped silently."""
    case = ROOT / "cases" / "perforation_part4_table3.toml"
    r = _main("perforate", case, "--json", "--no-ballistic-limit")
    assert r.returncode == 0, r.stderr
    st = json.loads(r.stdout)["shot_table"]
    bl = _main("ballistic-limit", case, "--json")
    assert bl.returncode == 0, bl.stderr
    part4 = {row["name"]: row for row in json.loads(bl.stdout)["rows"]}
    used = [row for row in st["rows"] if "model_V_m_s" in row]
    assert len(used) == st["statistics"]["model_V_m_s"]["n"] >= 5
    for row in used:
        assert row["eq5_R1"] == pytest.approx(part4[row["name"]]["V_R1_m_s"], rel=1e-12)
        assert row["measured_V_m_s"] == part4[row["name"]]["measured_V_m_s"]
        assert 0 < row["model_V_m_s"] < 5000
    # issue 37: the short cores (12-12.5 mm) are not skipped: their assumed ogive is shortened to fit
    short = [row for row in used if row["assumed_crh"] < 3.0]
    assert {row["name"] for row in short} == {"AMG5-9mm", "P1-2.3g", "P2"}
    assert all(row["assumed_crh"] <= 0.25 + (0.9 * 12.5 / 7.62) ** 2 + 1e-9 for row in short)  # L_h <= 0.9 L
