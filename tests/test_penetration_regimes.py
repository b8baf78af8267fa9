"""Regimes (issue 17, issue 12 item 4): the eroding rod against an independent time integration
and an exact solution, the predicted regimes against the recorded responses of the bundled
Piekutowski et al. (1999) shots, the eroding depths against the measured ones, the JSON keys,
warnings and bad input of ``penetrate``.
"""

import json
import math
from pathlib import Path

import numpy as np
import pytest
from case_blocks import TARGET_6061_T651
from tate_reference import tate_penetration_ode as tate_penetration

from semianalytic.cli import main
from semianalytic.penetration import regime as rg

CASES = Path(__file__).resolve().parents[1] / "cases"
ROD = dict(length=0.0711, nose_length=0.0118, diameter=7.11e-3)


@pytest.mark.parametrize("Y_p, R_t, rho_p", [(1.64e9, 1.45e9, 7830.0), (1.0e9, 1.45e9, 7830.0), (2.48e9, 1.2e9, 7890.0),
                                             (1.0e9, 2.0e9, 2710.0)])
def test_eroding_depth_against_time_integration(Y_p, R_t, rho_p):
    """The quadrature in v against the time integration of tests/tate_reference.py (DOP853 in time, rtol 1e-11), off any
    grid, Y_p above and below R_t and equal densities: both converge, so 1e-7 relative is a
    loose bound on two methods that agree to ~1e-10."""
    U = np.array([317.0, 733.0, 1411.0, 2333.0, 2987.0])
    m = 0.0204
    r = rg.eroding_depth(U, **ROD, density=rho_p, target_density=2710.0, target_resistance=R_t, rod_strength=Y_p, mass=m)
    L0 = m / (rho_p * math.pi * ROD["diameter"] ** 2 / 4)
    for u, P, Lr in zip(U, r.depth, r.residual_length):
        ref = tate_penetration(L0, rho_p, Y_p, 2710.0, R_t, u, rtol=1e-11)
        assert P == pytest.approx(ref.depth, rel=1e-7, abs=1e-12)
        assert Lr == pytest.approx(ref.residual_length, rel=1e-7, abs=1e-12)


def test_eroding_depth_hydrodynamic_exact():
    """Y_p = R_t: u = c v, c = sqrt(rho_p)/(sqrt(rho_p) + sqrt(rho_t)) exactly, so dP = -c/(1-c) dL,
    L_r = L exp(-rho_p (1-c) U^2/(2 Y_p)) and P = sqrt(rho_p/rho_t) (L - L_r) (-> the hydrodynamic
    limit L sqrt(rho_p/rho_t)); the quadrature should reach ~1e-10."""
    U = np.array([500.0, 1700.0, 4100.0])
    rp, rt, Y = 7830.0, 2710.0, 1.3e9
    r = rg.eroding_depth(U, **ROD, density=rp, target_density=rt, target_resistance=Y, rod_strength=Y)
    c = math.sqrt(rp) / (math.sqrt(rp) + math.sqrt(rt))
    Lr = ROD["length"] * np.exp(-rp * (1 - c) * U**2 / (2 * Y))
    assert np.allclose(r.residual_length, Lr, rtol=1e-8, atol=1e-15)
    assert np.allclose(r.depth, math.sqrt(rp / rt) * (ROD["length"] - Lr), rtol=1e-8)


def test_erosion_onset_leaves_the_nose_length():
    """At U_e the time-integrated rod keeps exactly its nose length (the definition of U_e);
    the spline inversion is accurate to ~1e-8, 1e-6 allows for the ODE tolerance."""
    kw = dict(**ROD, density=7830.0, target_density=2710.0, target_resistance=1.4535e9, rod_strength=1.64e9, mass=0.02044)
    Ue = rg.erosion_onset_velocity(1000.0, **kw)
    L0 = rg.eroding_rod_length(ROD["length"], ROD["nose_length"], ROD["diameter"], 7830.0, 0.02044)
    ref = tate_penetration(L0, 7830.0, 1.64e9, 2710.0, 1.4535e9, Ue, rtol=1e-11)
    assert ref.residual_length == pytest.approx(ROD["nose_length"], rel=1e-6)
    assert rg.erosion_onset_velocity(2000.0, **kw) == 2000.0  # never below the yield onset
    assert rg.classify_regimes([900.0, 1500.0, 2500.0], 1000.0, Ue) == ["rigid", "deforming", "eroding"]


def test_eroding_bad_input():
    with pytest.raises(Exception) as e:
        rg.eroding_depth([1000.0], length=0.01, nose_length=0.0118, diameter=7.11e-3, density=7830.0,
                         target_density=2710.0, target_resistance=1e9, rod_strength=1e9)
    assert "projectile.length" in str(e.value)
    with pytest.raises(Exception) as e:
        rg.eroding_depth([1000.0], **ROD, density=7830.0, target_density=2710.0, target_resistance=-1e9, rod_strength=1e9)
    assert "eroding_resistance" in str(e.value)


# ---------------------------------------------------------------------------------------------
# the bundled data: every shot with its recorded response


@pytest.fixture(scope="module")
def validations():
    from semianalytic.cache import coefficients_for_case
    from semianalytic.case import load_case
    from semianalytic.penetration.regime_setup import regime_validation

    out = {}
    for mat in ("var4340", "aermet100"):
        case = load_case(CASES / f"piekutowski1999_{mat}_regimes.toml")
        coef = coefficients_for_case(case, "bem", None)[0]
        out[mat] = regime_validation(case, coef, velocities=np.linspace(500.0, 3000.0, 26), loo=(mat == "var4340"),
                                     rule="nose_length")
    return out


def test_regime_labels_against_recorded_responses(validations):
    """VAR 4340 (U_sC within 10 % of its observed transition): no rigid shot called eroding, no
    eroded shot called rigid, every eroded shot called eroding and at least 70 % of the 20 shots
    right (today 15: the four rods that turned round are predicted eroding, their depths are
    eroding-like). AerMet 100: eq. (33) with the assumed Y_p = 2.48 GPa puts U_sC far above the
    observed transition (documented shortfall), so only 'every rigid shot predicted rigid' is
    required; the counts are pinned so a change in either direction is seen."""
    c = validations["var4340"]["confusion"]
    assert c["rigid"]["eroding"] == 0 and c["eroding"]["rigid"] == 0
    assert c["eroding"]["eroding"] == 6
    agree = sum(c[k][k] for k in c)
    assert agree / 20 >= 0.70
    a = validations["aermet100"]["confusion"]
    assert a["rigid"] == {"rigid": 7, "deforming": 0, "eroding": 0}
    assert sum(sum(v.values()) for v in a.values()) == 14


def test_transition_velocity_target(validations):
    """Issue 17 target: U_sC between the last rigid (1237 m/s) and first non-rigid (1365 m/s)
    VAR 4340 shot or within 10 % of it (met: -5.8 %)."""
    v = validations["var4340"]
    assert v["recorded"]["last_rigid_m_s"] == 1237.0 and v["recorded"]["first_non_rigid_m_s"] == 1365.0
    # the raw predictions against the recorded shots (not the code's own verdicts)
    U_y = v["prediction"]["transition_velocity_m_s"]
    assert 0.9 * 1237.0 <= U_y <= 1.1 * 1365.0
    # the predicted depth drop (U_e) falls where the measured depth falls most: 277 mm at 1493 m/s -> 105 mm at 1585 m/s
    assert (v["recorded"]["depth_drop_below_m_s"], v["recorded"]["depth_drop_above_m_s"]) == (1493.0, 1585.0)
    assert 1493.0 <= v["prediction"]["erosion_velocity_m_s"] <= 1585.0


def test_eroding_depths_against_measured(validations):
    """Eroded VAR 4340 shots: Alekseevskii-Tate with the case defaults (Y_p = 1.64 GPa, R_t of
    eq. (16)) within the issue's 15 % mean |error| (today 11.0 %), and leave-one-out with (R_t,
    Y_p) fitted on the other eroded shots (today 4.2 %); every shot within 25 % (the scatter of
    repeated shots at 2.2 km/s is 4 %, the model's flat trend misses the 3 km/s shots by ~20 %)."""
    v = validations["var4340"]
    err = v["errors"]["eroding"]
    assert err["n"] == 6 and err["mean_abs"] <= 0.15 and err["max_abs"] <= 0.25
    fit = v["eroding_fit"]
    assert fit["loo_mean_abs"] <= 0.15
    assert all(abs(r["error"]) <= 0.25 for r in fit["loo"])


def test_rigid_shots_keep_their_accuracy(validations):
    """The regime-aware depth of the recorded-rigid VAR 4340 shots is the exact-rod elastic
    projectile's where predicted rigid: mean |error| 6.6 % as in the rigid-only validation (the
    one shot predicted deforming keeps the Part I depth as the upper bound)."""
    err = validations["var4340"]["errors"]["rigid"]
    assert err["n"] == 7 and err["mean_abs"] <= 0.075


# ---------------------------------------------------------------------------------------------
# penetrate through the CLI


def _run(capsys, *argv):
    code = main(["penetrate", *map(str, argv)])
    out = capsys.readouterr()
    return code, out.out, out.err


CASE = """
title = "regimes cli test"
[projectile]
nose = "{nose}"
{nose_keys}
diameter = "7.11 mm"
shank_length = "59.3 mm"
density = "7830 kg/m^3"
youngs_modulus = "210 GPa"
poisson_ratio = 0.29
yield_stress = "1.64 GPa"
{extra}
""" + TARGET_6061_T651 + """{res_extra}
[impact]
striking_velocities = ["733 m/s", "1411 m/s", "2333 m/s", "2987 m/s"]
"""


def _case(tmp_path, nose="ogive", nose_keys="crh = 3.0", extra="", res_extra=""):
    p = tmp_path / "case.toml"
    p.write_text(CASE.format(nose=nose, nose_keys=nose_keys, extra=extra, res_extra=res_extra))
    return p


@pytest.mark.parametrize("nose, keys", [("ogive", "crh = 3.0"), ("sphere", "")])
def test_cli_json_keys_and_warnings(tmp_path, capsys, nose, keys):
    """Old and new JSON keys, regimes in velocity order, depth_m from the model that holds, valid
    per model, one warning per model outside its validity naming it and the reason."""
    code, out, err = _run(capsys, _case(tmp_path, nose, keys), "--json", "--coefficients", "paper",
                          "--regime-rule", "nose_length")
    assert code == 0, err
    res = json.loads(out)
    from semianalytic.commands.penetrate.cli import JSON_KEYS

    for key in JSON_KEYS:
        assert key in res
    n = 4
    assert len(res["regime"]) == len(res["depth_m"]) == len(res["depth_eroding_m"]) == n
    order = {"rigid": 0, "deforming": 1, "eroding": 2}
    assert [order[r] for r in res["regime"]] == sorted(order[r] for r in res["regime"])
    Uc, Ue = res["transition_velocity_m_s"], res["erosion_velocity_m_s"]
    assert Uc == pytest.approx(res["critical_velocity_m_s"][0])
    U = res["striking_velocity_m_s"]
    assert [r == "rigid" for r in res["regime"]] == [u < Uc for u in U]
    assert [r == "eroding" for r in res["regime"]] == [u >= Ue for u in U]
    assert res["regime"][-1] == "eroding"  # 2987 m/s erodes both noses
    for i, r in enumerate(res["regime"]):
        expect = res["depth_eroding_m"][i] if r == "eroding" else res["depth_elastic_exact_rod_m"][i]
        assert res["depth_m"][i] == expect
    for model in ("rigid", "quasi_rigid", "elastic", "elastic_exact_rod", "forrestal", "chen_li", "eroding"):
        assert len(res["valid"][model]) == n and all(isinstance(b, bool) for b in res["valid"][model])
    assert res["valid"]["rigid"] == [r == "rigid" for r in res["regime"]]
    assert res["valid"]["eroding"] == [r == "eroding" for r in res["regime"]]
    assert "warning: rigid projectile (eq. (11)): depth outside the model's validity" in err
    assert "eqs. (33)/(36)" in err and "eroding rod (Alekseevskii-Tate)" in err
    assert "note: projectile.dynamic_yield_stress not given" in err
    assert "note: target.resistance.eroding_resistance not given" in err


def test_cli_eroding_keys_used(tmp_path, capsys):
    """The case keys set the eroding rod: the depth equals the model's at those strengths, no note."""
    p = _case(tmp_path, extra='dynamic_yield_stress = "2.0 GPa"', res_extra='eroding_resistance = "1.2 GPa"')
    code, out, err = _run(capsys, p, "--json", "--coefficients", "paper")
    assert code == 0, err
    res = json.loads(out)
    assert "not given" not in err
    assert res["eroding_inputs"]["rod_strength_Pa"] == 2.0e9
    assert res["eroding_inputs"]["target_resistance_Pa"] == 1.2e9
    L0 = res["eroding_inputs"]["rod_length_m"]
    ref = tate_penetration(L0, 7830.0, 2.0e9, 2710.0, 1.2e9, 2987.0, rtol=1e-11)
    assert res["depth_eroding_m"][-1] == pytest.approx(ref.depth, rel=1e-7)


@pytest.mark.parametrize("extra, res_extra, field", [
    ('dynamic_yield_stress = "-1 GPa"', "", "projectile.dynamic_yield_stress"),
    ('dynamic_yield_stress = "0 GPa"', "", "projectile.dynamic_yield_stress"),
    ("", 'eroding_resistance = "0 MPa"', "target.resistance.eroding_resistance"),
    ("", 'eroding_resistance = "-3 MPa"', "target.resistance.eroding_resistance"),
    ('dynamic_yield_stress = "2 kg"', "", "projectile.dynamic_yield_stress"),
])
def test_cli_bad_strengths(tmp_path, capsys, extra, res_extra, field):
    code, out, err = _run(capsys, _case(tmp_path, extra=extra, res_extra=res_extra), "--json", "--coefficients", "paper")
    assert code == 2 and out == ""
    assert field in err and "Traceback" not in err


def test_cli_rod_shorter_than_nose(tmp_path, capsys):
    text = CASE.format(nose="ogive", nose_keys="crh = 3.0", extra="", res_extra="").replace('shank_length = "59.3 mm"', 'length = "10 mm"')
    p = tmp_path / "short.toml"
    p.write_text(text)
    code, out, err = _run(capsys, p, "--json", "--coefficients", "paper")
    assert code == 2 and "projectile.length" in err


def test_cli_regimes_case_json(capsys):
    """penetrate --json on the bundled regimes case: the rigid-model statistics use only the shots
    recorded rigid (7 VAR 4340 shots); the confusion table's recorded side matches the data file's
    responses and its rigid row the printed U_sC."""
    code, out, err = _run(capsys, CASES / "piekutowski1999_var4340_regimes.toml", "--json", "--regime-rule", "nose_length")
    assert code == 0, err
    res = json.loads(out)
    assert res["validation"]["statistics"]["rigid"]["n"] == 7
    conf = res["validation"]["regimes"]["confusion"]
    # recorded side, counted from the data file itself (responses mapped as the report states)
    import csv

    mapped = {"rigid": "rigid", "curved": "deforming", "exited": "deforming", "turned_around": "deforming",
              "broken": "deforming", "eroded": "eroding", "broken_eroding": "eroding"}
    rows = [r for r in csv.reader(line for line in open(CASES / "piekutowski1999_ogive_6061T6511.csv")
                                  if not line.startswith("#"))]
    head = rows[0]
    body = [r for r in rows[1:] if r and r[head.index("material")] == "VAR4340"]
    recorded = [mapped[r[-1]] for r in body]
    for reg in ("rigid", "deforming", "eroding"):
        assert sum(conf[reg].values()) == recorded.count(reg), reg
    # rigid shots below the printed U_sC are predicted rigid, the others not
    U_sC = res["transition_velocity_m_s"]
    v = [float(r[head.index("Vs_m_s")]) for r in body]
    assert conf["rigid"]["rigid"] == sum(1 for reg, u in zip(recorded, v) if reg == "rigid" and u < U_sC)
    assert res["regime"] == ["rigid", "rigid", "deforming", "eroding", "eroding", "eroding"]  # 0.5 ... 3 km/s


@pytest.mark.slow  # the whole report (numerics, timings, leave-one-out): ~20 s; the pieces are tested above
def test_cli_regimes_report(tmp_path, capsys):
    """penetrate --report on the regimes case writes validation_regimes.md with the full-range
    figure, the confusion table and the per-regime error table (paper coefficients)."""
    code, out, err = _run(capsys, CASES / "piekutowski1999_var4340_regimes.toml", "--coefficients", "paper",
                          "--report", tmp_path)
    assert code == 0, err
    text = (tmp_path / "validation_regimes.md").read_text()
    for part in ("Regime confusion table", "Per recorded regime", "leave-one-out", "validation_regimes_depth_velocity_VAR4340.png"):
        assert part in text
    assert (tmp_path / "validation_regimes_depth_velocity_VAR4340.png").stat().st_size > 10000


@pytest.mark.parametrize("nose, keys", [("ogive", "crh = 3.0"), ("sphere", "")])
def test_regime_rule_meyer_by_hand(tmp_path, capsys, nose, keys):
    """--regime-rule meyer (the previous default): rigid below
    U_y = sqrt(2 (H_M - R_t) / rho_t) (Tate 1967's tip pressure against the rod's static Meyer
    hardness H_M = HV x 9.80665 MPa / sin 68 deg), the depth Part I's below the breakup
    U_b = sqrt(2 (1.15 H_M - R_t) / rho_t) and the Alekseevskii-Tate rod's above, eroding from
    U_e with 3 x the dynamic ultimate strength of Pavlina & Van Tyne (2008).  Every velocity is
    recomputed here by hand from the printed R_t, Y_p and the case's density (independent of the
    code's path); HV from Y_p through Pavlina & Van Tyne's eq. (4) inverted."""
    code, out, err = _run(capsys, _case(tmp_path, nose, keys), "--json", "--coefficients", "paper", "--regime-rule", "meyer")
    assert code == 0, err
    res = json.loads(out)
    rho_t = 2710.0
    Y, R = res["yield_stress_Pa"], res["resistance_Pa"]
    HV = (Y / 1.5e6 + 90.7) / 2.876
    H_M = HV * 9.80665e6 / math.sin(math.radians(68.0))
    U_y = math.sqrt(2.0 * (H_M - R) / rho_t)
    U_b = math.sqrt(2.0 * (1.15 * H_M - R) / rho_t)
    U_e = math.sqrt(2.0 * (3.0 * 1.5e6 * (3.734 * HV - 99.8) - R) / rho_t)
    assert res["regime_rule"] == "meyer" and res["breakup_factor"] == 1.15
    assert res["transition_velocity_m_s"] == pytest.approx(U_y, rel=1e-12)
    assert res["breakup_velocity_m_s"] == pytest.approx(min(U_b, U_e), rel=1e-12)
    assert res["erosion_velocity_m_s"] == pytest.approx(U_e, rel=1e-12)
    U = res["striking_velocity_m_s"]
    assert [r == "rigid" for r in res["regime"]] == [u < U_y for u in U]
    assert [r == "eroding" for r in res["regime"]] == [u >= U_e for u in U]
    for i, u in enumerate(U):
        expect = res["depth_elastic_exact_rod_m"][i] if u < min(U_b, U_e) else res["depth_eroding_m"][i]
        assert res["depth_m"][i] == expect
    assert all(res["valid"]["regime_aware"])
    assert "Tate 1967" in err and "Meyer hardness" in err


@pytest.mark.parametrize("nose, keys, bbar", [("ogive", "crh = 3.0", 0.11), ("sphere", "", 0.58)])
def test_default_regime_rule_is_the_nose_load(tmp_path, capsys, nose, keys, bbar):
    """The default labels (chosen by transfer, reports/validation_regimes.md): the nose's own load
    rho_t Bbar U^2 / 2 (Part I, the paper's Bbar of the nose: 0.11 ogive, 0.58 sphere) reaches
    kappa (S - Cbar R_t) at S = H_M (onset), b H_M (breakup), e H_M (erosion), kappa, b, e the stated
    defaults; the depth Forrestal's below the breakup, the Alekseevskii-Tate rod's (Y_p = the static
    ultimate strength, R_t of Tate 1986) above.  Recomputed by hand from the printed Y_p, R_t, Bbar and
    the case's target (Y = 400 MPa, E = 68.9 GPa); the sphere's transitions come earlier."""
    from semianalytic.penetration.regime_setup import NOSE_LOAD_DEFAULTS as D

    code, out, err = _run(capsys, _case(tmp_path, nose, keys), "--json", "--coefficients", "paper")
    assert code == 0, err
    res = json.loads(out)
    rho_t = 2710.0
    Y, R = res["yield_stress_Pa"], res["resistance_Pa"]
    assert res["deep_B_bar"] == pytest.approx(bbar, rel=1e-12) and res["deep_C_bar"] == pytest.approx(1.0, abs=1e-12)
    HV = (Y / 1.5e6 + 90.7) / 2.876
    H_M = HV * 9.80665e6 / math.sin(math.radians(68.0))

    def U(S):
        return math.sqrt(2.0 * D["kappa"] * (S - R) / (rho_t * bbar))

    U_y, U_b, U_e = U(H_M), U(D["breakup_factor"] * H_M), U(D["erosion_factor"] * H_M)
    assert res["regime_rule"] == "nose_load"
    assert res["transition_velocity_m_s"] == pytest.approx(U_y, rel=1e-12)
    assert res["breakup_velocity_m_s"] == pytest.approx(U_b, rel=1e-12)
    assert res["erosion_velocity_m_s"] == pytest.approx(U_e, rel=1e-12)
    assert res["eroding_inputs"]["rod_strength_Pa"] == pytest.approx((3.734 * HV - 99.8) * 1e6, rel=1e-12)
    assert res["eroding_inputs"]["target_resistance_Pa"] == pytest.approx(0.4e9 * (2 / 3 + math.log(0.57 * 68.9 / 0.4)), rel=1e-12)
    V = res["striking_velocity_m_s"]
    assert [r == "rigid" for r in res["regime"]] == [u < U_y for u in V]
    assert [r == "eroding" for r in res["regime"]] == [u >= U_e for u in V]
    for i, u in enumerate(V):
        expect = res["depth_forrestal_m"][i] if u < U_b else res["depth_eroding_m"][i]
        assert res["depth_m"][i] == expect
    if nose == "sphere":  # a blunter nose: every transition earlier than the ogive's (sqrt(0.11/0.58) = 0.44 x)
        assert U_y < 0.5 * math.sqrt(2.0 * D["kappa"] * (H_M - R) / (rho_t * 0.11))


@pytest.mark.parametrize("nose, keys", [("ogive", "crh = 3.0")])
def test_regime_rule_tate_tabor_by_hand(tmp_path, capsys, nose, keys):
    """--regime-rule tate_tabor (the previous default): rigid below U_y = sqrt(2 (3 Y_p - R_t) /
    rho_t) (Tabor's constrained dynamic yield stress), the eroding rod's depth beyond U_y."""
    code, out, err = _run(capsys, _case(tmp_path, nose, keys), "--json", "--coefficients", "paper",
                          "--regime-rule", "tate_tabor")
    assert code == 0, err
    res = json.loads(out)
    Y, R = res["yield_stress_Pa"], res["resistance_Pa"]
    U_y = math.sqrt(2.0 * (3.0 * Y - R) / 2710.0)
    assert res["regime_rule"] == "tate_tabor"
    assert res["transition_velocity_m_s"] == pytest.approx(U_y, rel=1e-12)
    for i, r in enumerate(res["regime"]):
        expect = res["depth_elastic_exact_rod_m"][i] if r == "rigid" else res["depth_eroding_m"][i]
        assert res["depth_m"][i] == expect
