"""``calibrate --model eroding`` (issue 17 item 3) and ``penetrate --posterior`` in every regime.

Checked against what the code under test does not produce: the closed-form I(v) against a
numerical quadrature of its integrand, the vectorised depth over draws against the time
integration of Alekseevskii-Tate (tests/tate_reference.py), and the calibrated predictions
against the measured depths of the eroded VAR 4340 shots of Piekutowski et al. (1999) (the
issue's leave-one-out target), through the command line; bad input exits 2 naming the field.
"""

import json
import math
from pathlib import Path

import numpy as np
import pytest
from case_blocks import copy_case

from semianalytic.cli import main

ROOT = Path(__file__).resolve().parents[1]
CASES = ROOT / "cases"
ERODING_CASE = "piekutowski1999_var4340_eroding.toml"
CSV = "piekutowski1999_ogive_6061T6511.csv"
# the six eroded VAR 4340 shots (Piekutowski et al. 1999, Table 1): U_s [m/s], P [mm]
ERODED = {"4-1832": (1977, 123), "4-1809": (2166, 124), "8-0113": (2193, 126), "4-1833": (2204, 121),
          "8-0112": (2570, 144), "8-0104": (2988, 147)}


def _run(capsys, *argv):
    code = main([*map(str, argv)])
    out = capsys.readouterr()
    return code, out.out, out.err


def _copy(tmp_path, name=ERODING_CASE, edit=None):
    return copy_case(tmp_path, name, edit, CSV)


@pytest.mark.parametrize("Y_p, R_t, rho_p", [(8.5e9, 5.6e9, 7830.0), (1.2e9, 3.0e9, 7830.0), (2.0e9, 2.0e9, 2710.0)])
def test_tate_integral_closed_form_against_quadrature(Y_p, R_t, rho_p):
    """I(v) = int_{v_e}^v (w - u(w)) dw in closed form against scipy's adaptive quadrature of the
    integrand (u from peers.tate_interface_velocity); quad reaches ~1e-12, so 1e-9 relative."""
    from scipy.integrate import quad

    from semianalytic.penetration import regime as rg
    from semianalytic.penetration.peers import tate_interface_velocity

    v_e = rg._erosion_end(rho_p, Y_p, 2710.0, R_t)
    for v in (v_e + 1.0, 1733.0 + v_e, 4011.0):
        ref = quad(lambda w: w - tate_interface_velocity(w, rho_p, Y_p, 2710.0, R_t), v_e, v, epsabs=0, epsrel=1e-12)[0]
        assert float(rg.tate_integral(v, v_e, rho_p, Y_p, 2710.0, R_t)) == pytest.approx(ref, rel=1e-9, abs=1e-9)


def test_eroding_depths_over_draws_against_time_integration():
    """ErodingDepths (every draw and shot at once) against the time integration of tests/tate_reference.py (DOP853 in
    time, rtol 1e-11) at draws on both sides of Y_p = R_t and with one parameter held fixed:
    two converged methods, 1e-7 relative."""
    from tate_reference import tate_penetration_ode as tate_penetration

    from semianalytic.calibration.models import ErodingDepths, ThetaColumn

    U = np.array([1977.0, 2570.0, 2988.0])
    L0 = np.array([0.0655, 0.0656, 0.0654])
    theta = np.array([[5.6e9, 8.5e9], [1.9e9, 1.2e9], [1.4e9, 1.64e9]])
    both = ErodingDepths(U, L0, 7830.0, 2710.0, ThetaColumn(0, math.nan), ThetaColumn(1, math.nan))
    one = ErodingDepths(U, L0, 7830.0, 2710.0, ThetaColumn(0, math.nan), ThetaColumn(None, 1.64e9))
    got, got_one = np.exp(both.log_depth_theta(theta)), np.exp(one.log_depth_theta(theta[:, :1]))
    for k, (R, Y) in enumerate(theta):
        for i in range(len(U)):
            assert got[k, i] == pytest.approx(tate_penetration(L0[i], 7830.0, Y, 2710.0, R, U[i], rtol=1e-11).depth, rel=1e-7)
            assert got_one[k, i] == pytest.approx(tate_penetration(L0[i], 7830.0, 1.64e9, 2710.0, R, U[i], rtol=1e-11).depth,
                                                  rel=1e-7)
    assert np.exp(both.subset([2]).log_depth_theta(theta))[:, 0] == pytest.approx(got[:, 2], rel=1e-14)


@pytest.fixture(scope="module")
def eroding_calibration(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("ero")
    case = _copy(tmp)
    out = tmp / "out"
    # 1500 steps (the shipped posterior takes the case's 6000): enough for the predictions checked here
    code = main(["calibrate", str(case), "--out", str(out), "--cross-validate", "--quiet", "--steps", "1500"])
    assert code == 0
    return tmp, out


def test_eroding_posterior_file(eroding_calibration):
    """The posterior file: format version 2, the eroding model with its one calibrated parameter
    (issue 22: R_t keeps its published relation, the two-parameter posterior was a ridge), only
    the shots recorded eroded (the six of Table 1), the record penetrate checks and the sampler's
    diagnostics (4 ensembles, arviz R-hat <= 1.01 and ESS >= 400 per parameter)."""
    _, out = eroding_calibration
    post = json.loads((out / "posterior.json").read_text())
    assert post["version"] == 2 and list(post["models"]) == ["eroding"]
    keys = ["projectile.dynamic_yield_stress"]
    assert [p["key"] for p in post["parameters"]] == keys and post["models"]["eroding"]["parameters"] == keys
    shots = {s["id"]: (s["velocity_m_s"], round(s["depth_m"] * 1e3, 9)) for s in post["data"]["shots"]}
    assert shots == {k: (float(u), float(p)) for k, (u, p) in ERODED.items()}
    ero = post["models"]["eroding"]["eroding"]
    # R_t held at the Part I value (eq. (16), Y = 400 MPa: 1453.5 MPa, printed in validation_regimes.md)
    assert ero["projectile_density_kg_m3"] == 7830.0
    assert ero["fixed"] == {"target.resistance.eroding_resistance": pytest.approx(1453.5e6, rel=1e-3)}
    d = post["models"]["eroding"]["diagnostics"]
    assert 0.2 < d["acceptance_fraction"] < 0.9 and d["effective_sample_size"] > 200
    assert set(d["r_hat"]) == {*keys, "sigma"} and d["chains"] == 64
    # the shipped posterior (the case's 6000 steps) meets issue 22's sampler targets
    shipped = json.loads((ROOT / "reports" / "calibration_piekutowski1999_eroding" / "posterior.json").read_text())
    d = shipped["models"]["eroding"]["diagnostics"]
    assert max(d["r_hat"].values()) <= 1.01 and not d["warnings"]
    assert min(min(d["ess_bulk"].values()), min(d["ess_tail"].values())) >= 400


def test_issue17_target_leave_one_out_against_the_measured_depths(eroding_calibration):
    """Issue 17: the eroding model calibrated on the eroded VAR 4340 shots predicts each held-out
    shot's measured depth with a mean |error| of the median of at most 15 % (the issue's target;
    measured 7 %, reports/calibration_piekutowski1999_eroding/).  Each shot within 20 %: Tate's
    depth flattens with U_s while the measured one still rises (147 mm at 2988 m/s is predicted
    from five shots at or below 2570 m/s), the known limit of the model; the repeated shots at
    2.2 km/s scatter by 4 %.  The 90 % intervals must cover at least 5 of the 6 held-out shots
    (90 % of 6 is 5.4; one miss is within the sampling of so few shots)."""
    _, out = eroding_calibration
    cv = json.loads((out / "cross_validation.json").read_text())
    st = cv["loo"]["eroding"]["statistics"]
    sh = cv["loo"]["eroding"]["shots"]
    assert st["n"] == 6 and sorted(sh["id"]) == sorted(ERODED)
    measured = np.array([ERODED[i][1] / 1e3 for i in sh["id"]])
    err = (np.array(sh["0.5"]) - measured) / measured  # recomputed from the measured depths of the paper's table
    assert np.mean(np.abs(err)) == pytest.approx(st["mean_abs_error"], rel=1e-9)
    assert np.mean(np.abs(err)) <= 0.15
    assert np.all(np.abs(err) <= 0.20)
    inside = (np.array(sh["0.05"]) <= measured) & (measured <= np.array(sh["0.95"]))
    assert inside.sum() >= 5
    text = (out / "report.md").read_text()
    assert "Issue 17 target" in text and f"{100 * st['mean_abs_error']:.1f} %" in text


def test_penetrate_two_posteriors_every_regime_against_the_shots(eroding_calibration, tmp_path, capsys):
    """penetrate --posterior RIGID --posterior ERODING at the velocities of the recorded rigid and
    eroded VAR 4340 shots (a velocity list the implementation did not choose): the
    regime-aware intervals take the exact-rod model below the erosion onset and the eroding rod
    above it, and their 90 % intervals hold the measured depths of at least 6 of the 7 rigid and
    5 of the 6 eroded shots (in-sample for both posteriors; the case's single mass 20.44 g
    instead of each shot's 20.38-20.43 g moves a depth by <0.3 %)."""
    tmp, out = eroding_calibration
    rigid_case = _copy(tmp_path, "piekutowski1999_var4340.toml")
    code, _, err = _run(capsys, "calibrate", rigid_case, "--out", tmp_path / "rigid", "--model", "elastic_exact_rod",
                        "--quiet", "--steps", "400")
    assert code == 0, err
    rigid_shots = {"1-0415": (569, 58), "4-1805": (570, 55), "4-1806": (679, 72), "4-1796": (821, 102),
                   "4-1797": (966, 140), "1-0412": (1147, 190), "4-1798": (1237, 224)}
    shots = [*rigid_shots.values(), *ERODED.values()]
    vel = ", ".join(f'"{u} m/s"' for u, _ in shots)
    case = _copy(tmp_path, "piekutowski1999_var4340_regimes.toml",
                 edit=lambda t: t.replace('striking_velocities = ["0.5 km/s", "1.0 km/s", "1.5 km/s", "2.0 km/s", '
                                          '"2.5 km/s", "3.0 km/s"]', f"striking_velocities = [{vel}]"))
    code, stdout, err = _run(capsys, "penetrate", case, "--json", "--posterior", tmp_path / "rigid" / "posterior.json",
                             "--posterior", out / "posterior.json")
    assert code == 0, err
    res = json.loads(stdout)
    q = res["depth_quantiles_m"]
    assert set(q) == {"elastic_exact_rod", "eroding", "regime_aware"}
    assert res["posterior_regime_aware"] == {"regime": res["regime"], "rigid_model": "elastic_exact_rod",
                                             "eroding_model": "eroding"}
    n_rigid = len(rigid_shots)
    assert res["regime"][n_rigid:] == ["eroding"] * len(ERODED)
    for i, reg in enumerate(res["regime"]):
        src = q["elastic_exact_rod"] if reg == "rigid" else q["eroding"]  # the default rule's depth model
        assert all(q["regime_aware"][p][i] == src[p][i] for p in ("0.05", "0.5", "0.95"))
    P = np.array([p for _, p in shots]) / 1e3
    inside = (np.array(q["regime_aware"]["0.05"]) <= P) & (P <= np.array(q["regime_aware"]["0.95"]))
    assert inside[:n_rigid].sum() >= 6 and inside[n_rigid:].sum() >= 5
    # the depth drop is in the intervals: the eroded shots' median is below the rigid model's at 1147 m/s
    assert max(q["regime_aware"]["0.5"][n_rigid:]) < q["regime_aware"]["0.5"][n_rigid - 2]
    # one file holding a model twice is refused; the old format (version 1) is still read
    code, _, err = _run(capsys, "penetrate", case, "--json", "--posterior", out / "posterior.json",
                        "--posterior", out / "posterior.json")
    assert code == 2 and err.startswith("error: --posterior") and "two posterior files" in err
    old = json.loads((tmp_path / "rigid" / "posterior.json").read_text())
    old["version"] = 1
    for m in old["models"].values():
        m.pop("parameters")
    (tmp_path / "v1.json").write_text(json.dumps(old))
    code, stdout, err = _run(capsys, "penetrate", case, "--json", "--posterior", tmp_path / "v1.json")
    assert code == 0, err
    assert json.loads(stdout)["depth_quantiles_m"]["elastic_exact_rod"] == q["elastic_exact_rod"]


def test_penetrate_refuses_eroding_posterior_of_another_projectile_or_target(eroding_calibration, tmp_path, capsys):
    _, out = eroding_calibration
    post = out / "posterior.json"
    for old, new, field in (('density = "7830 kg/m^3"', 'density = "7890 kg/m^3"', "projectile.density"),
                            ('[target]\ndensity = "2710 kg/m^3"', '[target]\ndensity = "2800 kg/m^3"', "target.density")):
        case = _copy(tmp_path, "piekutowski1999_var4340_regimes.toml", edit=lambda t: t.replace(old, new))  # noqa: B023
        code, stdout, err = _run(capsys, "penetrate", case, "--posterior", post, "--json")
        assert code == 2 and err.startswith(f"error: {field}") and err.count("\n") == 1, (field, err)
        assert stdout == ""
    obj = json.loads(post.read_text())
    bad = tmp_path / "bad.json"
    case = _copy(tmp_path, "piekutowski1999_var4340_regimes.toml")
    for mutate, field in ((lambda o: o.update(version=1), "models.eroding"),
                          (lambda o: o.update(version=3), "--posterior.version"),
                          (lambda o: o["models"]["eroding"].pop("eroding"), "models.eroding"),
                          (lambda o: o["models"]["eroding"]["samples"].update(
                              {"projectile.dynamic_yield_stress": [-1.0] * len(o["models"]["eroding"]["samples"]["sigma"])}),
                           "models.eroding.samples")):
        o = json.loads(json.dumps(obj))
        mutate(o)
        bad.write_text(json.dumps(o))
        code, _, err = _run(capsys, "penetrate", case, "--posterior", bad, "--json")
        assert code == 2 and err.startswith(f"error: {field}"), (field, err)


@pytest.mark.parametrize("edit,argv,field", [
    (lambda t: t.replace('response_column = "regime"\n', ""), [], "data.response_column"),
    (None, ["--model", "eroding", "--model", "rigid"], "--model"),
    (None, ["--parameter", "target.resistance.yield_stress"], "--parameter"),
    (None, ["--diagnose"], "--diagnose"),
    (lambda t: t.replace('"lognormal(1700 MPa, 0.35)"', '"lognormal(1700 m/s, 0.35)"'), [],
     "calibration.prior.projectile.dynamic_yield_stress"),
    (lambda t: t.replace('select = { material = ["VAR4340"] }', 'select = { material = ["VAR4340"], regime = ["rigid"] }'),
     [], "data.file"),
])
def test_calibrate_eroding_bad_input(tmp_path, capsys, edit, argv, field):
    """No response column (the eroded shots are not known), mixed model kinds, a parameter of the
    other kind, a prior with the wrong unit, no eroded shot selected: exit 2, one line, nothing written."""
    case = _copy(tmp_path, edit=edit)
    out = tmp_path / "out"
    code, _, err = _run(capsys, "calibrate", case, "--out", out, "--quiet", "--steps", "50", *argv)
    assert code == 2 and err.startswith(f"error: {field}") and err.count("\n") == 1, err
    assert not out.exists()


def test_rigid_parameter_of_the_eroding_rod_is_refused(tmp_path, capsys):
    """--parameter projectile.dynamic_yield_stress with the rigid-shot models: exit 2 naming --parameter."""
    case = _copy(tmp_path, "piekutowski1999_var4340.toml")
    code, _, err = _run(capsys, "calibrate", case, "--out", tmp_path / "o", "--model", "rigid", "--coefficients", "paper",
                        "--parameter", "projectile.dynamic_yield_stress", "--quiet")
    assert code == 2 and err.startswith("error: --parameter") and "--model eroding" in err
