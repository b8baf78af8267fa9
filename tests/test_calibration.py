"""``calibrate`` and ``penetrate --posterior``: the depth surrogates against direct evaluations
and closed forms, the sampler against a brute-force quadrature of the same posterior, the
predictive quantiles against the closed-form log-normal, the command line (files, keys,
other noses), bad input (exit 2, field named, nothing written)."""

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from case_blocks import TARGET_6061_T651

from semianalytic.calibration.models import MODELS, DepthModelInputs, ShotSet, build_surrogate, model_depths
from semianalytic.calibration.priors import HalfNormal, LogNormal
from semianalytic.calibration.sampler import Problem, ResistanceMap, mixture_quantiles, sample_posterior
from semianalytic.cli import main

ROOT = Path(__file__).resolve().parents[1]
CASES = ROOT / "cases"
D = 7.11e-3
AREA = math.pi * D**2 / 4


def _run(capsys, *argv):
    code = main([*map(str, argv)])
    out = capsys.readouterr()
    return code, out.out, out.err


def _copy_case(tmp_path, name="piekutowski1999_var4340.toml", edit=None, csv_text=None):
    text = (CASES / name).read_text()
    if edit is not None:
        text = edit(text)
    p = tmp_path / name
    p.write_text(text)
    csv = tmp_path / "piekutowski1999_ogive_6061T6511.csv"
    if csv_text is None:
        shutil.copy(CASES / "piekutowski1999_ogive_6061T6511.csv", csv)
    else:
        csv.write_text(csv_text)
    return p


def _paper_inputs(mass=20.4e-3):
    """The ogive with the paper's constant Abar = 1 mm, Bbar = 0.11, Cbar = 1 (closed form)."""
    from semianalytic.coefficients import ConstantCoefficients
    from semianalytic.penetration.curve import PenetrationSetup
    from semianalytic.penetration.peers import ogive_nose_factor
    from semianalytic.penetration.rod import Rod

    coef = ConstantCoefficients.from_normalised(1.0e-3, 0.11, 1.0, D)
    rod = Rod(71.1e-3, D, 210e9, 7830.0)
    setup = PenetrationSetup(coef, mass, 2710.0, 1.4e9, rod, 0.29, 1.64e9)
    N2 = ogive_nose_factor(3.0)
    return DepthModelInputs(setup, (N2, N2), (5.04, 0.983, 0.94))


def _closed_form(m, U, R):
    """Part IV, eq. (3) with errata item 23: P = (m + rho A)/(rho B) ln(1 + rho B U^2/(2 C R))."""
    rho, A, B, C = 2710.0, 1.0e-3 * AREA, 0.11 * AREA, AREA
    return (m + rho * A) / (rho * B) * np.log1p(rho * B * U**2 / (2 * C * R))


SHOTS = ShotSet(np.array([569.0, 821.0, 1147.0, 1237.0]), np.array([20.38e-3, 20.415e-3, 20.41e-3, 20.379e-3]),
                np.array([58e-3, 102e-3, 190e-3, 224e-3]), ("a", "b", "c", "d"))


def test_models_are_the_validation_models():
    from semianalytic.penetration.validation import MODEL_LABELS

    assert MODELS == tuple(MODEL_LABELS)


def test_rigid_depth_is_exact_for_every_resistance():
    """Rigid model vectorised in R_t (the G/R_t scaling of eq. (11)) against the closed form."""
    inp = _paper_inputs()
    R = np.array([0.61e9, 1.03e9, 1.77e9, 3.1e9])  # arbitrary, not nodes of anything
    P = model_depths(inp, ["rigid"], R, SHOTS)["rigid"]
    # spectral quadrature in P + Newton: 1e-10 (as the penetrate closed-form test)
    np.testing.assert_allclose(P, _closed_form(SHOTS.mass[None, :], SHOTS.velocity[None, :], R[:, None]), rtol=1e-10)


def test_surrogates_match_direct_evaluation_off_the_nodes():
    """Each model's Chebyshev surrogate in ln R_t against penetration_curve / the peers at R_t
    values that are not nodes.  Tolerances: 1e-7 for the smooth models (16 nodes over a factor
    4 in R_t; the series converges geometrically); 5e-3 for the exact-rod elastic model, whose
    own depth steps by ~3e-3 as R_t moves its stop between oscillation periods of the rod."""
    import dataclasses

    from semianalytic.penetration import peers
    from semianalytic.penetration.curve import penetration_curve

    inp = _paper_inputs()
    lo, hi = 0.7e9, 2.8e9
    sur = build_surrogate(inp, MODELS, SHOTS, lo, hi, 16)
    for R in (0.83e9, 1.61e9, 2.47e9):
        for i in range(len(SHOTS)):
            setup = dataclasses.replace(inp.setup, resistance_pa=R, mass=float(SHOTS.mass[i]))
            res = penetration_curve(setup, SHOTS.velocity[i : i + 1])
            law = peers.CavityLaw(R / 5.04, 5.04, 0.983, 0.94)
            direct = {
                "rigid": res["depth_rigid_m"][0], "quasi_rigid": res["depth_quasi_rigid_m"][0],
                "elastic": res["depth_elastic_m"][0], "elastic_exact_rod": res["depth_elastic_exact_rod_m"][0],
                "forrestal": float(np.atleast_1d(peers.forrestal_depth(setup.mass, D, 2710.0, law, SHOTS.velocity[i:i + 1],
                                                                     *inp.nose_factors))[0]),
                "chen_li": float(np.atleast_1d(peers.chen_li_depth(setup.mass, D, 2710.0, R, 1.5, inp.nose_factors[1],
                                                                 SHOTS.velocity[i:i + 1]))[0]),
            }
            for m in MODELS:
                got = math.exp(sur[m].log_depth([R])[0, i])
                tol = 5e-3 if m == "elastic_exact_rod" else 1e-7
                assert got == pytest.approx(direct[m], rel=tol), (m, R, i)
    assert np.isnan(sur["rigid"].log_depth([0.5e9])).all()  # outside the range: no extrapolation


def test_tabulated_resistance_map_matches_eq16():
    from semianalytic.penetration.resistance import ElasticPlastic, elastic_plastic_resistance

    rmap = ResistanceMap(ElasticPlastic(400e6, 68.9e9, 0.33), ("yield_stress",), D)
    fast = rmap.tabulated(100e6, 1.5e9)
    Y = np.array([123.4e6, 400e6, 777.7e6, 1.2e9, 2.0e9])  # the last outside the table: direct
    exact = np.array([elastic_plastic_resistance(y, 68.9e9, 0.33) for y in Y])
    np.testing.assert_allclose(fast(Y[:, None]), exact, rtol=1e-7)  # linear in ln-ln, knots 7e-4 apart


def test_mixture_quantiles_closed_form():
    """One log-normal: q_p = exp(mu + sigma z_p); a symmetric two-component mixture: median exp(mean)."""
    from scipy.stats import norm

    mu = np.full((5, 2), [math.log(0.1), math.log(0.3)])
    q = mixture_quantiles(mu, np.full(5, 0.07), (0.05, 0.5, 0.95))
    for k, p in enumerate((0.05, 0.5, 0.95)):
        np.testing.assert_allclose(q[k], np.exp(mu[0] + 0.07 * norm.ppf(p)), rtol=1e-12)
    mu2 = np.array([[-0.1], [0.1]])
    assert mixture_quantiles(mu2, np.array([0.05, 0.05]), (0.5,))[0, 0] == pytest.approx(1.0, abs=1e-12)


def test_sampler_against_quadrature_of_the_same_posterior():
    """emcee's posterior of (R_t, sigma) against a brute-force 2-D quadrature (independent
    method) for the rigid model with constant coefficients.  Tolerance: the Monte-Carlo error
    of a 5 %/95 % quantile from ~1500 effective draws (~1.5 % of the width) plus grid error."""
    from semianalytic.penetration.resistance import Constant

    inp = _paper_inputs()
    rng = np.random.default_rng(3)
    depth = _closed_form(SHOTS.mass, SHOTS.velocity, 1.3e9) * np.exp(0.05 * rng.standard_normal(len(SHOTS)))
    shots = ShotSet(SHOTS.velocity, SHOTS.mass, depth, SHOTS.ids)
    sur = build_surrogate(inp, ["rigid"], shots, 0.4e9, 4e9, 16)["rigid"]
    prior, sprior = LogNormal(1.0e9, 0.5), HalfNormal(0.15)
    problem = Problem(("target.resistance.value",), (prior,), sprior, ResistanceMap(Constant(1e9), ("value",), D), sur, depth)
    post = sample_posterior(problem, walkers=32, steps=2500, burn=500, seed=7)
    lr = np.linspace(math.log(0.5e9), math.log(3.5e9), 801)
    ls = np.linspace(math.log(0.003), math.log(0.6), 801)
    LR, LS = np.meshgrid(lr, ls, indexing="ij")
    R, S = np.exp(LR), np.exp(LS)
    mu = np.log(_closed_form(shots.mass[None, None, :], shots.velocity[None, None, :], R[..., None]))
    ll = np.sum(-0.5 * ((np.log(depth) - mu) / S[..., None]) ** 2 - np.log(S[..., None]), axis=-1)
    lp = ll + prior.logpdf(R) + sprior.logpdf(S) + LR + LS  # densities in (ln R, ln sigma)
    w = np.exp(lp - lp.max())
    for grid, draws in ((lr, np.log(post.resistance)), (ls, np.log(post.sigma))):
        marg = w.sum(axis=1) if grid is lr else w.sum(axis=0)
        cdf = np.cumsum(marg) / marg.sum()
        for p in (0.05, 0.5, 0.95):
            exact = np.interp(p, cdf, grid)
            width = np.interp(0.95, cdf, grid) - np.interp(0.05, cdf, grid)
            assert np.quantile(draws, p) == pytest.approx(exact, abs=0.04 * width), (p, grid is lr)
    assert 0.2 < post.acceptance_fraction < 0.9
    assert post.effective_sample_size > 500


# -------------------------------------------------------------------------------------- CLI


def test_calibrate_cli_files_keys_and_penetrate_posterior_other_noses(tmp_path, capsys):
    """calibrate (paper's constant coefficients: fast) writes posterior.json with the data,
    samples and diagnostics and the reports; penetrate --posterior then predicts the same
    target for other noses and masses."""
    out = tmp_path / "cal"
    case = _copy_case(tmp_path)
    code, stdout, err = _run(capsys, "calibrate", case, "--out", out, "--model", "rigid", "--model", "quasi_rigid",
                             "--model", "forrestal", "--coefficients", "paper", "--quiet")
    assert code == 0, err
    post = json.loads((out / "posterior.json").read_text())
    assert post["format"] == "semianalytic-posterior"
    assert [p["key"] for p in post["parameters"]] == ["target.resistance.yield_stress"]
    assert len(post["data"]["shots"]) == 7
    for m in ("rigid", "quasi_rigid", "forrestal"):
        d = post["models"][m]["diagnostics"]
        assert 0.2 < d["acceptance_fraction"] < 0.9 and d["effective_sample_size"] > 200
        assert set(d["autocorrelation_time"]) == {"target.resistance.yield_stress", "sigma"}
        assert len(post["models"][m]["samples"]["sigma"]) == len(post["models"][m]["samples"]["target.resistance.yield_stress"])
    for f in ("report.md", "report.html", "posterior.png", "predicted_vs_measured.png", "depth_velocity.png"):
        assert (out / f).is_file(), f
    # The same target for a sphere and a cone of another mass and length: quantiles ordered.
    for nose in ('nose = "sphere"', 'nose = "cone"\nhalf_angle = "20 deg"'):
        other = tmp_path / "other.toml"
        other.write_text(f"""
title = "other nose"
[projectile]
{nose}
diameter = "12.7 mm"
shank_length = "80 mm"
density = "7850 kg/m^3"
youngs_modulus = "210 GPa"
poisson_ratio = 0.29
yield_stress = "1.5 GPa"
{TARGET_6061_T651}[impact]
striking_velocities = ["433 m/s", "917 m/s"]
""")
        code, stdout, err = _run(capsys, "penetrate", other, "--posterior", out / "posterior.json", "--json",
                                 "--coefficients", "paper" if "sphere" in nose else "bem")
        assert code == 0, err
        res = json.loads(stdout)
        q = res["depth_quantiles_m"]
        assert set(q) == {"rigid", "quasi_rigid", "forrestal", "regime_aware"}
        # below the erosion onset the regime-aware intervals are the rigid-projectile model's (--part1-model
        # elastic_exact_rod is not in the file: the first Part I model present, said on stderr); eroding
        # velocities get null (no number) without an eroding posterior, also said
        assert res["posterior_regime_aware"]["rigid_model"] == "rigid"
        assert "elastic_exact_rod is not in the posterior" in err
        for i, reg in enumerate(res["regime"]):
            for p in ("0.05", "0.5", "0.95"):
                if reg == "eroding":
                    assert q["regime_aware"][p][i] is None and "no eroding model" in err
                else:
                    assert q["regime_aware"][p][i] == q["rigid"][p][i]
        for m, qq in q.items():
            assert len(qq["0.05"]) == len(qq["0.5"]) == len(qq["0.95"]) == 2
            # null where no model holds (the regime-aware intervals at an eroding velocity, above)
            assert all(a < b < c for a, b, c in zip(qq["0.05"], qq["0.5"], qq["0.95"]) if b is not None), m
        # median near the model at the posterior-median resistance (the mixture of log-normals
        # is nearly symmetric in ln P): 2 %
        Y = post["models"]["rigid"]["summary"]["target.resistance.yield_stress"]["q50"]
        other.write_text(other.read_text().replace('yield_stress = "400 MPa"', f'yield_stress = "{Y / 1e6:.6f} MPa"'))
        code, stdout2, err = _run(capsys, "penetrate", other, "--json", "--coefficients",
                                  "paper" if "sphere" in nose else "bem")
        direct = json.loads(stdout2)["depth_rigid_m"]
        np.testing.assert_allclose(q["rigid"]["0.5"], direct, rtol=0.02)


def test_penetrate_posterior_refuses_other_target_and_bad_files(tmp_path, capsys):
    out = tmp_path / "cal"
    case = _copy_case(tmp_path)
    code, _, err = _run(capsys, "calibrate", case, "--out", out, "--model", "rigid", "--coefficients", "paper",
                        "--quiet", "--steps", "300")
    assert code == 0, err
    post = out / "posterior.json"
    for old, new, field in (('density = "2710 kg/m^3"', 'density = "2800 kg/m^3"', "target.density"),
                            ('youngs_modulus = "68.9 GPa"', 'youngs_modulus = "70 GPa"', "target.resistance.youngs_modulus"),
                            ('model = "elastic-plastic"\nyield_stress = "400 MPa"\nyoungs_modulus = "68.9 GPa"\npoisson_ratio = 0.33',
                             'model = "constant"\nvalue = "1.4 GPa"', "target.resistance.model")):
        other = _copy_case(tmp_path, edit=lambda t: t.replace(old, new))  # noqa: B023
        code, stdout, err = _run(capsys, "penetrate", other, "--posterior", post, "--json", "--coefficients", "paper")
        assert code == 2 and field in err and err.count("\n") == 1, (field, err)
        assert stdout == ""
    obj = json.loads(post.read_text())
    bad = tmp_path / "bad.json"
    for mutate, field in ((lambda o: o.pop("models"), "--posterior"),
                          (lambda o: o["models"]["rigid"]["samples"].update(sigma=[]), "models.rigid.samples.sigma"),
                          (lambda o: o["models"]["rigid"]["samples"].update(sigma=[-1.0] * 3), "models.rigid.samples"),
                          (lambda o: o.update(format="x"), "--posterior.format")):
        o = json.loads(json.dumps(obj))
        mutate(o)
        bad.write_text(json.dumps(o))
        code, _, err = _run(capsys, "penetrate", case, "--posterior", bad, "--json", "--coefficients", "paper")
        assert code == 2 and field in err, (field, err)
    bad.write_text("{not json")
    code, _, err = _run(capsys, "penetrate", case, "--posterior", bad, "--json", "--coefficients", "paper")
    assert code == 2 and "--posterior" in err
    code, _, err = _run(capsys, "penetrate", case, "--posterior", tmp_path / "missing.json", "--coefficients", "paper")
    assert code == 2 and "does not exist" in err


PRIOR = '"target.resistance.yield_stress" = "lognormal(300 MPa, 0.5)"'
CSV_HEAD = "table,shot,material,Vs_m_s,P_mm,mass_g,regime\n"


@pytest.mark.parametrize(
    "edit,csv_text,argv,field",
    [
        (lambda t: t.replace('file = "piekutowski1999_ogive_6061T6511.csv"', 'file = "nope.csv"'), None, [], "data.file"),
        (None, "", [], "data.file"),
        (None, CSV_HEAD.replace("P_mm", "depth") + "1,a,VAR4340,600,60,20.4,rigid\n", [], "data.depth_column"),
        (None, CSV_HEAD + "1,a,VAR4340,600,-60,20.4,rigid\n1,b,VAR4340,700,70,20.4,rigid\n1,c,VAR4340,800,90,20.4,rigid\n",
         [], "data.file"),
        (None, CSV_HEAD + "1,a,VAR4340,0,60,20.4,rigid\n1,b,VAR4340,700,70,20.4,rigid\n1,c,VAR4340,800,90,20.4,rigid\n",
         [], "data.file"),
        (None, CSV_HEAD + "1,a,VAR4340,600,60,0,rigid\n1,b,VAR4340,700,70,20.4,rigid\n1,c,VAR4340,800,90,20.4,rigid\n",
         [], "data.file"),
        (None, CSV_HEAD + "1,a,VAR4340,600,60,20.4,rigid\n1,b,VAR4340,700,70,20.4,rigid\n", [], "data.file"),
        (lambda t: t.replace(PRIOR, PRIOR.replace("MPa,", "MPa")), None, [],
         "calibration.prior.target.resistance.yield_stress"),
        (lambda t: t.replace(PRIOR, PRIOR.replace("MPa", "m/s")), None, [],
         "calibration.prior.target.resistance.yield_stress"),
        (lambda t: t.replace(PRIOR, PRIOR.replace("lognormal(300 MPa, 0.5)", "gamma(2, 3)")), None, [],
         "calibration.prior.target.resistance.yield_stress"),
        (lambda t: t.replace('discrepancy = "halfnormal(0.15)"', 'discrepancy = "halfnormal(-1)"'), None, [],
         "calibration.discrepancy"),
        (lambda t: t.replace(PRIOR, PRIOR.replace("yield_stress", "yield_strength")), None, [],
         "calibration.prior.target.resistance.yield_strength"),
        (None, None, ["--parameter", "target.density"], "--parameter"),
        (None, None, ["--parameter", "target.resistance.shear"], "--parameter"),
    ],
)
def test_calibrate_bad_input(tmp_path, capsys, edit, csv_text, argv, field):
    if edit is not None:
        assert edit((CASES / "piekutowski1999_var4340.toml").read_text()) != (CASES / "piekutowski1999_var4340.toml").read_text()
    if csv_text is not None and csv_text:
        csv_text = "# comment\n" + csv_text
    case = _copy_case(tmp_path, edit=edit, csv_text=csv_text)
    out = tmp_path / "out"
    code, stdout, err = _run(capsys, "calibrate", case, "--out", out, "--model", "rigid", "--coefficients", "paper",
                             "--quiet", *argv)
    assert code == 2, err
    assert err.startswith(f"error: {field}") and err.count("\n") == 1, err
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["piekutowski1999_var4340.toml",
                                                                  "piekutowski1999_ogive_6061T6511.csv"])
