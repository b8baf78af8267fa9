"""Monte Carlo on arrays (issue 14) against the case-by-case path on the same samples, for every
resistance model the penetration sweep offers; engine selection.

With constant drag coefficients eq. (11) has the closed-form final depth
P = (m + rho A)/(rho B) ln(1 + rho B U^2 / (2 C R_t)), written out here independently.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from case_blocks import COARSE_TABLES

from semianalytic.coefficients import ConstantCoefficients
from semianalytic.sweep.engine import choose_engine, run_sweep
from semianalytic.sweep.kernels import PenetrationKernel
from semianalytic.sweep.spec import build_spec

D = 7.11e-3
COEF = ConstantCoefficients.from_normalised(1.0e-3, 0.11, 1.0, D)
CASE = """
[projectile]
nose = "ogive"
crh = 3.0
diameter = "7.11 mm"
shank_length = "59.3 mm"
density = "7830 kg/m^3"
youngs_modulus = "210 GPa"
poisson_ratio = 0.29
yield_stress = "1.5 GPa"
[target]
density = "2710 kg/m^3"
[target.resistance]
{resistance}
[impact]
striking_velocities = ["0.8 km/s", "1.4 km/s"]
"""
MODELS = {
    "elastic-plastic": ('model = "elastic-plastic"\nyield_stress = "400 MPa"\nyoungs_modulus = "68.9 GPa"\npoisson_ratio = 0.33',
                        "target.resistance.yield_stress=normal(400 MPa, 30 MPa)"),
    "brittle": ('model = "brittle"\ncompressive_strength = "150 MPa"\ntensile_strength = "15 MPa"\n'
                'youngs_modulus = "60 GPa"\npoisson_ratio = 0.2\nalpha = 0.8',
                "target.resistance.compressive_strength=uniform(120 MPa, 180 MPa)"),
    "hardening": ('model = "hardening"\nyield_stress = "400 MPa"\nyoungs_modulus = "68.9 GPa"\nhardening_exponent = 0.1',
                  "target.resistance.yield_stress=normal(400 MPa, 30 MPa)"),
    "limestone": ('model = "limestone"', "target.resistance.psi=normal(607 MPa, 40 MPa)"),
    "part4": ('model = "part4"\nyield_stress = "400 MPa"\nyoungs_modulus = "68.9 GPa"',
              "target.resistance.youngs_modulus=uniform(60 GPa, 75 GPa)"),
    "constant": ('model = "constant"\nvalue = "1.2 GPa"', "target.resistance.value=lognormal(1.2 GPa, 0.1)"),
    # Part II (no closed form): R_t on a Chebyshev grid of the strength, checked against direct solves
    "cavity": ('model = "cavity"\nyoungs_modulus = "373.14 GPa"\npoisson_ratio = 0.232\ntensile_strength = "0.262 GPa"\n'
               'compressive_strength = "2.62 GPa"',
               "target.resistance.compressive_strength=uniform(2.5 GPa, 2.75 GPa)"),
}


def _run(case_file, spec, out, vectorised):
    k = PenetrationKernel(coefficients=COEF, vectorised=vectorised)
    s = run_sweep(case_file, spec, out, scheduler="inline", progress=False, kernel=k, batch_size=25)
    return s, pd.read_csv(out / "results.csv").sort_values("case_id").reset_index(drop=True)


@pytest.mark.parametrize("model", list(MODELS))
def test_arrays_equal_the_case_by_case_path(tmp_path, monkeypatch, model):
    calls = []
    original = PenetrationKernel.evaluate_arrays
    monkeypatch.setattr(PenetrationKernel, "evaluate_arrays", lambda self, *a: calls.append(1) or original(self, *a))
    res, sample = MODELS[model]
    p = tmp_path / "case.toml"
    p.write_text(CASE.format(resistance=res))
    spec = build_spec([], [sample, "target.density=uniform(2650 kg/m^3, 2770 kg/m^3)",
                           "projectile.density=normal(7830 kg/m^3, 80 kg/m^3)"], 30, 3)
    s_vec, vec = _run(p, spec, tmp_path / "vec", True)
    n_array_batches = len(calls)
    s_ref, ref = _run(p, spec, tmp_path / "ref", False)
    assert n_array_batches == len(calls) >= 2  # the array path ran (and the reference did not use it)
    assert s_vec.n_ok == s_ref.n_ok == s_vec.n_cases == 2 * 30  # every sample valid, two velocities each
    assert list(vec.columns) == list(ref.columns)
    # same R_t (the same closed form per sample); depth: two integrations of eq. (11) agreeing
    # to ~1e-12, the ratio interpolation of penetration/batch.py adds < 1e-10
    np.testing.assert_allclose(vec.depth_rigid_m, ref.depth_rigid_m, rtol=1e-9)
    np.testing.assert_allclose(vec.critical_velocity_m_s, ref.critical_velocity_m_s, rtol=1e-12)
    assert (vec.yields == ref.yields).all()


def test_sampled_density_with_a_fixed_mass_equals_the_case_by_case_path(tmp_path):
    """A case that fixes the mass and samples the density: the density still sets c_0 of
    eq. (33) in every sample (the array path once kept the case's density for U_sC)."""
    p = tmp_path / "case.toml"
    p.write_text(CASE.format(resistance=MODELS["elastic-plastic"][0]).replace(
        'density = "7830 kg/m^3"\n', 'density = "7830 kg/m^3"\nmass = "20.4 g"\n', 1))
    spec = build_spec([], ["projectile.density=uniform(4000 kg/m^3, 16000 kg/m^3)"], 12, 5)
    _, vec = _run(p, spec, tmp_path / "vec", True)
    _, ref = _run(p, spec, tmp_path / "ref", False)
    assert ref.critical_velocity_m_s.std() > 1.0  # the reference does vary with the density
    np.testing.assert_allclose(vec.critical_velocity_m_s, ref.critical_velocity_m_s, rtol=1e-12)
    np.testing.assert_allclose(vec.depth_rigid_m, ref.depth_rigid_m, rtol=1e-9)  # the mass is the case's


def test_arrays_against_the_closed_form(tmp_path):
    p = tmp_path / "case.toml"
    p.write_text(CASE.format(resistance=MODELS["elastic-plastic"][0]))
    spec = build_spec([], ["target.resistance.yield_stress=normal(400 MPa, 30 MPa)",
                           "target.density=uniform(2650 kg/m^3, 2770 kg/m^3)", "projectile.mass=normal(20 g, 1 g)"], 40, 5)
    _, df = _run(p, spec, tmp_path / "vec", True)
    Y, rho, m = df["target.resistance.yield_stress_Pa"], df["target.density_kg_m3"], df["projectile.mass_kg"]
    U = df["impact.striking_velocity_m_s"]
    R = 2.0 / 3.0 * Y * (1.0 + np.log(68.9e9 / (3.0 * Y * (1.0 - 0.33))))  # Part I eq. (16)
    P = (m + rho * COEF.A_m3) / (rho * COEF.B_m2) * np.log1p(rho * COEF.B_m2 * U**2 / (2.0 * COEF.C_m2 * R))
    np.testing.assert_allclose(df.depth_rigid_m, P, rtol=1e-9)  # spectral integration: round-off level


def test_invalid_samples_reported_like_the_case_by_case_path(tmp_path):
    # a normal yield stress crossing zero: the batch's corners are invalid, the samples go case by case
    p = tmp_path / "case.toml"
    p.write_text(CASE.format(resistance=MODELS["elastic-plastic"][0]))
    # built directly: the command line refuses such a sample of a positive quantity (issue 27)
    from semianalytic.sweep.spec import Sampler, SweepSpec

    spec = SweepSpec(samplers=(Sampler("target.resistance.yield_stress", "normal", (100e6, 120e6), "Pa"),), n_samples=40,
                     seed=2)
    s_vec, vec = _run(p, spec, tmp_path / "vec", True)
    s_ref, ref = _run(p, spec, tmp_path / "ref", False)
    assert s_vec.n_invalid == s_ref.n_invalid > 0
    assert (vec.status == ref.status).all()


def test_engine_choice():
    # cheap cases on one table: inline (a local cluster costs seconds to start)
    assert choose_engine(None, n_cases=100_000, n_geometries=1, seconds_per_case=1e-5) == "inline"
    # a geometry sweep: one BEM table per design, seconds each
    assert choose_engine(None, n_cases=64, n_geometries=64) == "local"
    assert choose_engine(None, n_cases=64, n_geometries=64, workers=1) == "inline"
    assert choose_engine("tcp://10.0.0.1:8786", 10, 1) == "tcp://10.0.0.1:8786"
    assert choose_engine("local", 10, 1) == "local"


def test_cheap_sweep_runs_inline_without_a_scheduler(tmp_path):
    p = tmp_path / "case.toml"
    p.write_text(CASE.format(resistance=MODELS["elastic-plastic"][0]))
    s = run_sweep(p, build_spec(["impact.striking_velocity=400:1400:100 m/s"]), tmp_path / "o", progress=False,
                  kernel=PenetrationKernel(coefficients=COEF))
    assert s.scheduler == "inline" and s.n_ok == 11


@pytest.mark.parametrize("model", ["elastic-plastic", "brittle", "hardening", "limestone", "part4", "constant", "cavity"])
def test_interpolated_resistance_equals_the_closed_form_per_sample(model, monkeypatch):
    # R_t on a Chebyshev grid over the samples' box, interpolated, against the model's closed form
    # evaluated sample by sample (smooth in the fields: interpolation error ~1e-13, checked to 1e-10)
    from semianalytic.cavity import BrittleMaterial
    from semianalytic.penetration import resistance as res
    from semianalytic.sweep.kernels import _pressures, resistance_per_sample

    base, fields = {
        "elastic-plastic": (res.ElasticPlastic(400e6, 68.9e9, 0.33), {"yield_stress": (300e6, 500e6), "poisson_ratio": (0.3, 0.36)}),
        "brittle": (res.Brittle(150e6, 15e6, 60e9, 0.2, 0.8), {"compressive_strength": (120e6, 180e6)}),
        "hardening": (res.Hardening(400e6, 68.9e9, 0.1), {"yield_stress": (300e6, 500e6), "hardening_exponent": (0.05, 0.2)}),
        "limestone": (res.Limestone(), {"psi": (500e6, 700e6)}),
        "part4": (res.Part4(400e6, 68.9e9), {"youngs_modulus": (60e9, 75e9)}),
        "constant": (res.Constant(1.2e9), {"value": (1.0e9, 1.4e9)}),
        "cavity": (res.Cavity(BrittleMaterial(373.14e9, 0.232, 0.262e9, 2.62e9)), {"compressive_strength": (2.5e9, 2.75e9)}),
    }[model]
    rng = np.random.default_rng(4)
    n = 200 if model == "cavity" else 2000  # a Part II solve per sample for the reference
    samples = {f: rng.uniform(lo, hi, n) for f, (lo, hi) in fields.items()}
    import semianalytic.sweep.kernels as kernels

    sizes = []
    monkeypatch.setattr(kernels, "_pressures", lambda b, cols, d: sizes.append(len(next(iter(cols.values())))) or _pressures(b, cols, d))
    R, msg = resistance_per_sample(base, samples, D)
    assert max(sizes, default=0) < n  # closed form on arrays, or the grid and three probes: not every sample
    exact, _ = _pressures(base, {f: v.tolist() for f, v in samples.items()}, D)
    assert (msg == "").all()
    np.testing.assert_allclose(R, exact, rtol=1e-10)


def test_geometry_batches_hold_one_table_each():
    # a geometry sweep on workers: every batch holds the cases of one nose (its task builds that table)
    from semianalytic.sweep.engine import _geometry_batches

    spec = build_spec(["projectile.crh=1,2,3,4", "impact.striking_velocity=400:1600:100 m/s"])
    k = PenetrationKernel()
    ids = np.arange(spec.n_cases, dtype=np.int64)
    batches = _geometry_batches(spec, k, ids, {}, size=5)
    crh = spec.values(ids)["projectile.crh"]
    assert sorted(np.concatenate(batches).tolist()) == ids.tolist()  # every case once
    assert all(len(set(crh[b].tolist())) == 1 and len(b) <= 5 for b in batches)
    assert len(batches) == 4 * 3  # 13 velocities per nose in batches of at most 5


def test_worker_moves_into_its_own_session():
    # own_session (run in every LocalCluster worker): setsid, so the kernel's autogroup scheduler
    # gives the worker its own CPU share; a child of this process starts in this process's session
    import os
    import subprocess
    import sys

    code = "import os; from semianalytic.sweep.engine import own_session; print(os.getsid(0), own_session(), os.getpid())"
    before, after, pid = map(int, subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                                                 check=True).stdout.split())
    assert before == os.getsid(0) and after == pid != before


# the case above with coarse BEM tables (order 4, 16 depths to 30 nose lengths): about 0.5 s per design
GEOMETRY_CASE = CASE.format(resistance=MODELS["elastic-plastic"][0]) + """
""" + COARSE_TABLES


def test_geometry_sweep_on_a_local_cluster_equals_inline(tmp_path):
    # coarse BEM tables (the check is of the engine: same tables, same rows); the inline run builds
    # the tables, the cluster's tasks load them from the same disk cache (one table per task)
    p = tmp_path / "case.toml"
    p.write_text(GEOMETRY_CASE)
    spec = build_spec(["projectile.crh=1.5,2.5,3.5"])
    cache = str(tmp_path / "cache")
    s_in = run_sweep(p, spec, tmp_path / "in", scheduler="inline", progress=False, kernel=PenetrationKernel(cache_dir=cache))
    s_lc = run_sweep(p, spec, tmp_path / "lc", scheduler="local", workers=2, progress=False,
                     kernel=PenetrationKernel(cache_dir=cache))
    assert s_lc.scheduler == "local" and s_lc.workers == 2 and s_in.n_ok == s_lc.n_ok == 6
    a, b = (pd.read_csv(tmp_path / d / "results.csv").sort_values("case_id").reset_index(drop=True) for d in ("in", "lc"))
    pd.testing.assert_frame_equal(a, b)  # same tables and the same arithmetic: identical rows


def test_sweep_with_an_unreachable_scheduler_exits_2_and_writes_nothing(tmp_path, capsys):
    from semianalytic.cli import main

    p = tmp_path / "case.toml"
    p.write_text(CASE.format(resistance=MODELS["elastic-plastic"][0]))
    out = tmp_path / "o"
    rc = main(["sweep", str(p), "--out", str(out), "--scheduler", "tcp://127.0.0.1:9",
               "--vary", "impact.striking_velocity=400:800:200 m/s", "--no-progress"])
    err = capsys.readouterr().err
    assert rc == 2 and err.startswith("error: --scheduler"), err
    assert not out.exists()
