"""Issue 22: projectile strength from its hardness, published transition criteria, the regime
mixture of ``penetrate --posterior`` and the leave-one-material-out transfer on Piekutowski et
al. (1999).

Checked against what the code under test does not produce: the numbers printed in ASTM E140 and
in Pavlina & Van Tyne (2008) (hand arithmetic), the tensile yield stresses printed by Piekutowski
et al. beside each steel's hardness, the recorded responses and depths of the data file (read
here with the csv module), iid draws of known effective sample size, and the exact grid
posterior against emcee (a second method).
"""

import csv
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from case_blocks import copy_case

from semianalytic.cli import main

ROOT = Path(__file__).resolve().parents[1]
CASES = ROOT / "cases"
CSV = "piekutowski1999_ogive_6061T6511.csv"
VAR = "piekutowski1999_var4340_hardness_regimes.toml"
AER = "piekutowski1999_aermet100_hardness_regimes.toml"
RESPONSE_REGIME = {"rigid": "rigid", "curved": "deforming", "exited": "deforming", "turned_around": "deforming",
                   "broken": "deforming", "eroded": "eroding", "broken_eroding": "eroding"}


def _rows():
    with (CASES / CSV).open() as fh:
        return list(csv.DictReader(line for line in fh if not line.startswith("#")))


def _run(capsys, *argv):
    code = main([*map(str, argv)])
    out = capsys.readouterr()
    return code, out.out, out.err


def _copy(tmp_path, name, edit=None):
    return copy_case(tmp_path, name, edit, CSV)


# --- hardness -> strength -----------------------------------------------------------------


def test_hardness_conversion_against_the_published_tables():
    """ASTM E140 Table 1 rows (38 HRC = 372 HV, 53 HRC = 560 HV) and Pavlina & Van Tyne (2008),
    eq. (4) by hand: 2.876 x 372 - 90.7 = 979.17 MPa; eq. (5): 3.734 x 560 - 99.8 = 1991.24 MPa.
    Against the experiment: Piekutowski et al. print tensile yields of 1140 MPa (VAR 4340, Rc 38)
    and 1720 MPa (AerMet 100, Rc 53); the conversion is within 20 % of both (the 2-sigma scatter
    of Pavlina & Van Tyne's fit is about 200 MPa, 15-20 % at these strengths)."""
    from semianalytic.penetration import hardness as H

    assert H.vickers_from_rockwell_c(38) == 372 and H.vickers_from_rockwell_c(53) == 560
    assert H.vickers_from_rockwell_c(38.5) == pytest.approx(377.0)  # halfway between 372 and 382
    assert H.yield_stress_from_hardness(38) == pytest.approx(979.172e6, rel=1e-12)
    assert H.ultimate_strength_from_vickers(560) == pytest.approx(1991.24e6, rel=1e-12)
    for hrc, printed in ((38, 1140e6), (53, 1720e6)):
        assert abs(H.yield_stress_from_hardness(hrc) / printed - 1) < 0.20
    assert H.parse_hardness("39.5 HRC") == 39.5 and H.parse_hardness("Rc 53") == 53


def test_case_hardness_gives_the_yield_stress(tmp_path):
    """[projectile] hardness = '38 HRC', dynamic_factor = 1.2 -> yield_stress = 1.2 x 979.172 MPa;
    without dynamic_factor the stated default (1.5) applies."""
    from semianalytic.case import load_case
    from semianalytic.penetration.hardness import DEFAULT_DYNAMIC_FACTOR

    case = load_case(_copy(tmp_path, VAR, lambda t: t.replace("dynamic_factor = 1.5", "dynamic_factor = 1.2")))
    assert case.projectile.yield_stress == pytest.approx(1.2 * 979.172e6, rel=1e-9)
    case = load_case(_copy(tmp_path, VAR, lambda t: t.replace("dynamic_factor = 1.5", "# no dynamic factor")))
    assert DEFAULT_DYNAMIC_FACTOR == 1.5 and case.projectile.yield_stress == pytest.approx(1.5 * 979.172e6, rel=1e-9)


@pytest.mark.parametrize("edit, field", [
    (lambda t: t.replace('hardness = "38 HRC"', 'hardness = "38 HRC"\nyield_stress = "1.6 GPa"'), "projectile.hardness"),
    (lambda t: t.replace('hardness = "38 HRC"', 'hardness = "75 HRC"'), "projectile.hardness"),
    (lambda t: t.replace('hardness = "38 HRC"', 'hardness = "12 HRC"'), "projectile.hardness"),
    (lambda t: t.replace('hardness = "38 HRC"', 'hardness = "38 HB"'), "projectile.hardness"),
    (lambda t: t.replace("dynamic_factor = 1.5", "dynamic_factor = 0.8"), "projectile.dynamic_factor"),
    (lambda t: t.replace('hardness = "38 HRC"   # nominal; each shot its own (hardness_column)', 'yield_stress = "1.6 GPa"'),
     "projectile.dynamic_factor"),
])
def test_bad_hardness_input_exits_2_naming_the_key(tmp_path, capsys, edit, field):
    case = _copy(tmp_path, VAR, edit)
    code, _, err = _run(capsys, "penetrate", case, "--coefficients", "paper")
    assert code == 2 and err.startswith(f"error: {field}:"), err
    assert "Traceback" not in err


# --- criteria against the recorded transitions ----------------------------------------------


def _recorded_onsets():
    """Per steel of the data file: (material, mean HRC of its shots, last rigid and first deformed
    striking velocity [m/s])."""
    rows = _rows()
    for mat in ("VAR4340", "AerMet100"):
        mine = sorted((float(r["Vs_m_s"]), r["regime"]) for r in rows if r["material"] == mat)
        hrc = np.mean([float(r["hardness_Rc"]) for r in rows if r["material"] == mat])
        yield mat, hrc, max(v for v, g in mine if g == "rigid"), min(v for v, g in mine if g != "rigid")


def test_tip_criterion_places_both_onsets_between_the_recorded_shots():
    """Tate's pressure against the tip's constrained strength (C = 3, Tabor) with ONE dynamic
    factor: for f = 1.28 the rigid -> deforming velocity of each steel lies between its last
    rigid and its first deformed shot in the data file (VAR 4340: 1237 / 1365 m/s; AerMet 100:
    1786 / 1816 m/s), from the shots' mean hardness.  Part I's U_sC (eqs. (33)/(36)) with one
    Y_p = f sigma_y cannot do this for both steels (it needs f >= 1.7 for VAR 4340, and then puts
    AerMet 100's onset above 2.5 km/s): checked too."""
    from semianalytic.penetration import hardness as H
    from semianalytic.penetration import regime as rg

    R_t = 1453.55e6  # Part I, eq. (16), Y = 400 MPa, E = 68.9 GPa, nu = 0.33 (the cases' target)
    for mat, hrc, last_rigid, first_def in _recorded_onsets():
        U = rg.tate_erosion_velocity(1.28 * H.yield_stress_from_hardness(hrc), R_t, 2710.0, rg.TABOR_CONSTRAINT)
        assert last_rigid < U < first_def, (mat, U)
    # independent closed form of the criterion: (1/2) rho U^2 + R_t = C Y at U
    U = rg.tate_erosion_velocity(2.0e9, R_t, 2710.0, 3.0)
    assert 0.5 * 2710.0 * U**2 + R_t == pytest.approx(6.0e9, rel=1e-12)
    assert rg.tate_erosion_velocity(1.0e9, R_t, 2710.0) == 0.0  # Y_p < R_t: erodes at any velocity


def test_meyer_onset_without_a_fitted_constant_against_the_recorded_transitions():
    """The default onset: Tate's tip pressure (1/2) rho_t U^2 + R_t against the rod's static Meyer
    hardness, no fitted constant.  The Meyer hardness by hand from the Vickers pyramid's geometry
    (136 deg between faces: contact area d^2 / (2 sin 68 deg), projected area d^2 / 2), and the onset
    of each steel from its shots' mean hardness within 1 % of the interval between its last rigid
    and its first deformed shot (VAR 4340: 1237 / 1365 m/s; AerMet 100: 1786 / 1816 m/s; the
    measured onset: 1362 and 1825 m/s, 0.5 % above AerMet 100's first deformed shot)."""
    from semianalytic.penetration import hardness as H
    from semianalytic.penetration import regime as rg

    d = 1e-4  # any indent diagonal: H_M / HV = contact area / projected area
    contact, projected = d**2 / (2 * math.sin(math.radians(68.0))), d**2 / 2
    # H_M = F / projected area, HV = F / contact area (in kgf/mm^2): H_M = HV x contact / projected
    assert H.meyer_hardness_from_vickers(372.0) == pytest.approx(372.0 * 9.80665e6 * contact / projected, rel=1e-12)
    assert H.meyer_hardness_from_vickers(372.0) == pytest.approx(372.0 * 9.80665e6 * 1.07853, rel=1e-5)
    R_t = 1453.55e6  # Part I, eq. (16), as above
    for mat, hrc, last_rigid, first_def in _recorded_onsets():
        U = rg.tate_erosion_velocity(H.meyer_hardness_from_vickers(H.vickers_from_rockwell_c(hrc)), R_t, 2710.0)
        assert 0.99 * last_rigid < U < 1.01 * first_def, (mat, U)


def test_tate_1986_resistance_by_hand():
    """Tate (1986): R_t = Y (2/3 + ln(0.57 E / Y)); Y = 276 MPa, E = 68.9 GPa: 0.57 x 68900 / 276
    = 142.29, ln = 4.9579, R_t = 276 x 5.6246 = 1552.4 MPa."""
    from semianalytic.penetration.regime import tate_resistance

    assert tate_resistance(276e6, 68.9e9) == pytest.approx(1552.4e6, rel=2e-4)


# --- sampler diagnostics ---------------------------------------------------------------------


def test_chain_diagnostics_against_iid_and_disagreeing_chains():
    """arviz's R-hat and ESS: 4 chains of iid N(0, 1) draws have R-hat ~ 1 and an ESS near the
    number of draws (4000; within 25 %: the ESS estimate's own scatter at this size is ~5 %); two
    chains centred 1 apart give R-hat far above 1.01 and a warning naming the parameter."""
    from semianalytic.calibration.sampler import chain_diagnostics

    rng = np.random.default_rng(3)
    d = chain_diagnostics(rng.standard_normal((4, 1000, 1)), ("theta",))
    p = d["parameters"]["theta"]
    assert p["r_hat"] < 1.01 and 3000 < p["ess_bulk"] < 5000 and not d["warnings"]
    bad = rng.standard_normal((4, 500, 1)) + np.array([0, 0, 1, 1])[:, None, None]
    d = chain_diagnostics(bad, ("dynamic_factor",))
    assert d["parameters"]["dynamic_factor"]["r_hat"] > 1.1
    assert any(w.startswith("dynamic_factor: R-hat") for w in d["warnings"])
    short = rng.standard_normal((4, 50, 1))  # 200 draws: ESS < 400
    assert any("effective sample size" in w for w in chain_diagnostics(short, ("sigma",))["warnings"])


# --- transfer (fast: API on the default model set) ------------------------------------------


@pytest.fixture(scope="module")
def groups():
    from semianalytic.cache import coefficients_for_case
    from semianalytic.calibration import regimes as R
    from semianalytic.case import load_case

    out = []
    for name in (VAR, AER):
        case = load_case(CASES / name)
        out.append(R.regime_shots(case, coefficients_for_case(case, "bem", None)[0]))
    return out


@pytest.fixture(scope="module")
def study(groups):
    from semianalytic.calibration import regimes as R

    return R.transfer_study(groups, (R.DEFAULT_OPTIONS,), n_draws=600)


def _recorded(mat):
    return {r["shot"]: (RESPONSE_REGIME[r["regime"]], float(r["P_mm"]) / 1e3 if r["P_mm"] else math.nan)
            for r in _rows() if r["material"] == mat}


def test_transfer_between_materials_against_the_data_file(study):
    """Leave one material out with the default model set: each steel predicted from the fit on the
    other; the figures are recomputed here from the predicted labels and quantiles against the
    data file's recorded responses and depths.  Measured (reports/validation_regimes.md, 1000
    draws): labels right 32 of 34 (the misses: VAR 4340's first curved shot at 1365 m/s and one
    AerMet 100 shot at its onset), rigid mean |error| 4 %, 90 % coverage of the rigid shots 93 %.
    Asserted: at least 32 of 34 labels (the 600 draws here are seeded), rigid mean |error| <= 15 % and
    rigid coverage in 80-95 % (the issue's targets, met), every eroded shot labelled eroding, the
    eroded shots' median below the measured depth on average (the eroding rod with Y_p < R_t stays
    below the hydrodynamic limit, 111 mm, while the shots lie at 121-172 mm: the eroding regime's
    shortfall, 30 %, asserted <= 35 % so that a worse eroding model fails here)."""
    shots = [s for t in study["options"][0]["transfer"] for s in t["shots"]]
    rec = {**_recorded("VAR4340"), **_recorded("AerMet100")}
    assert sorted(s["shot"] for s in shots) == sorted(rec)
    right = sum(s["predicted"] == rec[s["shot"]][0] for s in shots)
    assert right >= 32

    def err(reg):
        return [s["q50_m"] / rec[s["shot"]][1] - 1 for s in shots if rec[s["shot"]][0] == reg and math.isfinite(rec[s["shot"]][1])]

    assert np.mean(np.abs(err("rigid"))) <= 0.15
    assert np.mean(np.abs(err("eroding"))) <= 0.35 and np.mean(err("eroding")) < 0
    cov = [s["q05_m"] <= rec[s["shot"]][1] <= s["q95_m"] for s in shots
           if rec[s["shot"]][0] == "rigid" and math.isfinite(rec[s["shot"]][1])]
    assert 0.80 <= np.mean(cov) <= 0.95, np.mean(cov)
    assert all(s["predicted"] == "eroding" for s in shots if rec[s["shot"]][0] == "eroding")
    for s in shots:  # probabilities sum to 1
        assert sum(s["regime_probability"].values()) == pytest.approx(1.0, abs=1e-12)


@pytest.mark.xfail(strict=True, reason="issue 36 targets missed by transfer: deforming-band median error 18 % (> 15 %), eroding "
                                       "30 % (> 15 %: the eroding rod with Tate's R_t and the static strength, whose depth "
                                       "rises with velocity as required, stays below the hydrodynamic limit the eroded shots "
                                       "exceed), deforming and eroding 90 % coverage 100 % (> 95 %) "
                                       "(reports/validation_regimes.md)")
def test_issue22_targets(study):
    sm = study["options"][0]["summary"]
    assert sm["label_right"] >= 0.9 * sm["labelled"]
    for k in ("rigid", "deforming", "eroding"):
        assert sm[k]["mean_abs_error"] <= 0.15 and 0.80 <= sm[k]["coverage_90"] <= 0.95


# --- penetrate --posterior with a regimes posterior -----------------------------------------


def _regimes_posterior(tmp_path, case_path, **over):
    from semianalytic.calibration import regimes as R
    from semianalytic.case import load_case

    rng = np.random.default_rng(1)
    n = 400
    obj = {"format": R.REGIMES_FORMAT, "version": R.REGIMES_VERSION, "model": "regimes",
           "options": R.DEFAULT_OPTIONS.as_dict(), "signature": R.geometry_signature(load_case(case_path)),
           "velocity_range_m_s": [569.0, 2988.0],
           "samples": {"nose_load_factor": (0.101 + 0.006 * rng.standard_normal(n)).tolist(),
                       "sigma": np.full(n, 0.045).tolist(), "sigma_deformed": np.full(n, 0.33).tolist(),
                       "tau": np.full(n, 0.03).tolist(),
                       "breakup_factor": (1.29 + 0.05 * rng.standard_normal(n)).tolist(),
                       "erosion_factor": (1.70 + 0.08 * rng.standard_normal(n)).tolist()}}
    obj.update(over)
    p = tmp_path / "posterior.json"
    p.write_text(json.dumps(obj))
    return p


def _no_data(text):
    return text[: text.index("[data]")].replace(
        'striking_velocities = ["0.5 km/s", "1.0 km/s", "1.5 km/s", "2.0 km/s", "2.5 km/s", "3.0 km/s"]',
        'striking_velocities = ["1.0 km/s", "1.3 km/s", "1.6 km/s", "2.0 km/s", "2.6 km/s", "4.0 km/s"]')


def test_penetrate_regime_probability_and_mixture(tmp_path):
    """Through the command line: regime_probability per velocity sums to 1; at 1.0 km/s (all
    VAR 4340 shots rigid up to 1237 m/s in the data) rigid is near certain, at 2.6 km/s (shots
    eroded) eroding is; near the recorded onset (1.3 km/s) rigid and deforming are both possible;
    near the transitions (1.3 km/s, 1.6 km/s: 277 mm recorded at 1493 m/s, 105 mm at 1585 m/s)
    the interval spans both depths, far wider (relative) than at 1.0 km/s; 4 km/s is outside the calibrated
    range: null and a warning on stderr.  The old keys stay."""
    case = _copy(tmp_path, VAR, _no_data)
    post = _regimes_posterior(tmp_path, case)
    res = subprocess.run([sys.executable, "-m", "semianalytic", "penetrate", str(case), "--posterior", str(post),
                          "--json", "--coefficients", "paper"], capture_output=True, text=True, cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    out = json.loads(res.stdout)
    p = out["regime_probability"]
    for k in range(5):
        assert p["rigid"][k] + p["deforming"][k] + p["eroding"][k] == pytest.approx(1.0, abs=1e-9)
    assert p["rigid"][0] > 0.99 and p["eroding"][4] > 0.95
    assert 0.05 < p["rigid"][1] < 0.95
    q = out["depth_quantiles_m"]["regime_aware"]
    width = [(q["0.95"][k] - q["0.05"][k]) / q["0.5"][k] for k in range(5)]
    k = 1 if width[1] > width[2] else 2  # the transition velocity with the widest interval
    assert width[k] > 2 * width[0]
    # it spans the eroding rod's depth (105-142 mm recorded above the drop) and the deep rigid one
    # (224 mm recorded at 1237 m/s)
    assert q["0.05"][k] < 0.130 and q["0.95"][k] > 0.220
    assert q["0.5"][5] is None and p["rigid"][5] is None and out["regime_model_holds"][5] is False
    assert "no model holds at U_s = 4000 m/s" in res.stderr
    for key in ("regime", "depth_m", "valid", "depth_eroding_m"):
        assert key in out


def test_penetrate_accepts_a_regimes_posterior_of_another_target(tmp_path, capsys):
    """Issue 36 item 5: a posterior's rod parameters apply to any target (R_t recomputed from the
    case): another target is accepted with a note naming what differs, and the transfer widens."""
    case = _copy(tmp_path, VAR, _no_data)
    sig_case = _copy(tmp_path / "..", VAR, lambda t: _no_data(t).replace('yield_stress = "400 MPa"', 'yield_stress = "300 MPa"'))
    post = _regimes_posterior(tmp_path, sig_case)
    code, out, err = _run(capsys, "penetrate", case, "--json", "--posterior", post, "--coefficients", "paper")
    assert code == 0, err
    assert str(post) in err and "another target" in err and "target_yield_stress" in err
    assert json.loads(out)["posterior_transfer"]["transfer"] is True


def test_penetrate_transfers_a_regimes_posterior_to_another_nose(tmp_path, capsys):
    """The regime model's parameters belong to the rod steel and the target: a posterior fitted on
    the 3-CRH ogive applies to another nose (the transfer the model is chosen for), with a note."""
    case = _copy(tmp_path, VAR, _no_data)
    sig_case = _copy(tmp_path / "..", VAR, lambda t: _no_data(t).replace("crh = 3.0", "crh = 2.0"))
    post = _regimes_posterior(tmp_path, sig_case)
    code, out, err = _run(capsys, "penetrate", case, "--json", "--posterior", post, "--coefficients", "paper")
    assert code == 0, err
    assert "crh = 2.0" in err and "transfer" in err
    probs = json.loads(out)["regime_probability"]
    total = [sum(v) for v in zip(*(probs[k] for k in ("rigid", "deforming", "eroding"))) if None not in v]
    assert total and all(abs(t - 1.0) < 1e-12 for t in total)


# --- the shipped posterior: emcee against the exact grid (slow) ------------------------------


@pytest.mark.slow
def test_emcee_against_the_grid_posterior_and_diagnostics(groups):
    """The 4-ensemble emcee posterior of the nose-load factor, b and e against the exact grid posterior
    (a second method)."""
    from semianalytic.calibration import regimes as R

    s = R.sample_regimes(groups[0], R.DEFAULT_OPTIONS, steps=2000, burn=700)
    g = R.grid_posterior(groups[0], R.DEFAULT_OPTIONS)
    # kappa: the grid is 5 % apart in ln kappa (2.5 % half-cell); b and e 0.067 and 0.1 apart
    assert np.median(s["f"]) == pytest.approx(g["f_quantiles"][0.5], rel=0.04)
    assert set(s["diagnostics"]["parameters"]) == set(R.parameter_names(R.DEFAULT_OPTIONS))
    assert abs(np.median(s["b"]) - g["b_quantiles"][0.5]) < 0.05
    assert abs(np.median(s["e"]) - g["e_quantiles"][0.5]) < 0.08


def test_calibrate_regimes_transfer_through_the_cli(tmp_path, capsys):
    """calibrate --model regimes --cross-validate --transfer (the other material) --quick: the
    transfer table printed and written, recomputed here from transfer.json's shots against the
    data file's responses."""
    var, aer = _copy(tmp_path, VAR), _copy(tmp_path, AER)
    out = tmp_path / "out"
    code, stdout, _ = _run(capsys, "calibrate", var, "--model", "regimes", "--cross-validate", "--transfer", aer,
                           "--quick", "--steps", "300", "--out", out)
    assert code == 0
    tr = json.loads((out / "transfer.json").read_text())
    rec = {**_recorded("VAR4340"), **_recorded("AerMet100")}
    shots = [s for t in tr["options"][0]["transfer"] for s in t["shots"]]
    right = sum(s["predicted"] == rec[s["shot"]][0] for s in shots)
    assert f"regime label right {right}/34" in stdout and right >= 31
    for reg, tol in (("rigid", 0.15), ("eroding", 0.35)):  # the issue's 15 %: met for the rigid shots (4 %); eroding 30 %
        e = [abs(s["q50_m"] / rec[s["shot"]][1] - 1) for s in shots if rec[s["shot"]][0] == reg and math.isfinite(rec[s["shot"]][1])]
        assert np.mean(e) <= tol, (reg, np.mean(e))
    assert (out / "depth_velocity_VAR4340.png").stat().st_size > 10000
    assert (out / "depth_velocity_AerMet100.csv").read_text().count("\n") == 68  # 2 header lines + 66 velocities


def test_shipped_regimes_posterior_is_healthy():
    """Issue 22, item 5: the shipped posterior (reports/calibration_piekutowski1999_regimes) of 4
    independent ensembles has R-hat <= 1.01 and bulk and tail ESS >= 400 for every parameter, no
    sampler warning, and its constants lie inside their priors, away from the edges: kappa in
    loguniform(0.02, 3), b and e in uniform(1, 3)."""
    from semianalytic.calibration import regimes as R

    post = json.loads((ROOT / "reports" / "calibration_piekutowski1999_regimes" / "posterior.json").read_text())
    d = post["diagnostics"]
    assert d["ensembles"] == 4 and set(d["parameters"]) == set(R.parameter_names(R.DEFAULT_OPTIONS))
    assert post["options"] == R.DEFAULT_OPTIONS.as_dict()
    assert not d["warnings"]
    for p in d["parameters"].values():
        assert p["r_hat"] <= 1.01 and min(p["ess_bulk"], p["ess_tail"]) >= 400
    k = post["summary"]["nose_load_factor"]
    assert 0.03 < k["q05"] < k["q95"] < 2.5 and not post["at_prior_edge"]["nose_load_factor"]
    for name in ("breakup_factor", "erosion_factor"):
        b = post["summary"][name]
        assert 1.02 < b["q05"] < b["q95"] < 2.9 and not post["at_prior_edge"][name]


def test_rigid_depth_options_against_the_rigid_shots(groups):
    """The two depths of a rod that keeps its nose, at the rigid shots of the data file: Part I and
    Forrestal's cavity-expansion peer with the authors' constants (the default, chosen by transfer).  Measured: mean |error| Part I 7 % (VAR 4340) and 10 % (AerMet 100),
    Forrestal 3 % and 5 %; asserted: each within 12 % and Forrestal's the smaller on both steels
    (Piekutowski et al. 1999 show their model within about 5-10 % of these shots, their Fig. 5)."""  # noqa: E501
    from semianalytic.calibration import regimes as R

    for g in groups:
        rig = (g.recorded == 0) & np.isfinite(g.depth)
        errs = {}
        for rd in R.RIGID_DEPTHS:
            out = R.model_outcome([0.1], g, R.Options(rigid_depth=rd), [1.2], [1.6])
            errs[rd] = float(np.mean(np.abs(out.depth[0][rig] / g.depth[rig] - 1)))
        assert max(errs.values()) < 0.12 and errs["forrestal"] < errs["part1"], (g.group, errs)
    assert R.DEFAULT_OPTIONS.rigid_depth == "forrestal"  # chosen by transfer (a candidate, not a comparison)
