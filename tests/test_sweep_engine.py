"""Sweep engine: spec parsing, append-as-completed results, resume after an interruption
(in-process and by SIGKILL), Parquet output, bad sweep input.

The Part II cavity model is the kernel here (a closed-form solve of a few ms per case), so
the engine is checked against direct calls of the model, which the engine does not own.
"""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from semianalytic.cavity import BrittleMaterial, solve_cavity
from semianalytic.cli import main
from semianalytic.errors import InputError
from semianalytic.sweep.engine import run_sweep
from semianalytic.sweep.spec import build_spec, parse_sample, parse_vary

ROOT = Path(__file__).resolve().parent.parent
AD995 = ROOT / "cases" / "cavity_ad995.toml"


# -- spec -------------------------------------------------------------------------------


def test_range_is_inclusive_and_in_si():
    a = parse_vary("impact.striking_velocity=0.5 km/s:1.5 km/s:250 m/s")
    assert a.values == pytest.approx([500.0, 750.0, 1000.0, 1250.0, 1500.0], rel=1e-15)
    assert a.unit == "m/s" and a.column == "impact.striking_velocity_m_s"
    b = parse_vary("target.resistance.yield_stress=200:400:100 MPa")  # bare numbers take the unit
    assert b.values == pytest.approx([2e8, 3e8, 4e8]) and b.column == "target.resistance.yield_stress_Pa"
    c = parse_vary("projectile.crh=0.5,3")
    assert c.values == (0.5, 3.0) and c.unit == ""


def test_samples_are_reproducible_from_the_seed():
    s1 = build_spec([], ["material.compressive_strength=normal(2.62 GPa, 0.1 GPa)"], 1000, seed=3)
    s2 = build_spec([], ["material.compressive_strength=normal(2620 MPa, 100 MPa)"], 1000, seed=3)
    d1, d2 = s1.draws(), s2.draws()
    k = "material.compressive_strength"
    np.testing.assert_array_equal(d1[k], d2[k])
    # sample mean within 4 standard errors of the mean given (sd/sqrt(n) = 3.2 MPa)
    assert abs(d1[k].mean() - 2.62e9) < 4 * 0.1e9 / math.sqrt(1000)
    ln = parse_sample("target.density=lognormal(2710 kg/m^3, 0.05)")
    assert ln.params == (2710.0, 0.05)


@pytest.mark.parametrize(
    "vary, field",
    [
        ("impact.striking_velocity=1500:500:10 m/s", "--vary impact.striking_velocity"),
        ("impact.striking_velocity=500:1500:0 m/s", "--vary impact.striking_velocity"),
        ("impact.striking_velocity=500 m/s:1 GPa:1 m/s", "--vary impact.striking_velocity"),
        ("impactvelocity=1,2", "--vary"),
        ("projectile.crh", "--vary"),
    ],
)
def test_bad_vary(vary, field):
    with pytest.raises(InputError) as err:
        parse_vary(vary)
    assert err.value.field == field


def test_bad_sample():
    with pytest.raises(InputError) as err:
        parse_sample("target.density=normal(2710 kg/m^3, -1 kg/m^3)")
    assert err.value.field == "--sample target.density"
    with pytest.raises(InputError):
        parse_sample("target.density=gauss(1, 2)")


# -- runs ------------------------------------------------------------------------------


def _direct(nu: float, Ys: float) -> float:
    m = BrittleMaterial(373.14e9, nu, 0.262e9, Ys, 231.8e9, 0.0)
    return solve_cavity(m, warn=False).cavity_pressure


def test_inline_sweep_matches_direct_calls(tmp_path):
    spec = build_spec(["material.poisson_ratio=0.20:0.26:0.02"], ["material.compressive_strength=uniform(2.5 GPa, 2.7 GPa)"], 3, seed=1)
    s = run_sweep(AD995, spec, tmp_path / "sw", scheduler="inline", progress=False, batch_size=4)
    assert (s.n_cases, s.n_ok) == (12, 12)
    df = pd.read_csv(tmp_path / "sw" / "results.csv")
    assert sorted(df.case_id) == list(range(12))
    for _, row in df.iterrows():
        # the same closed-form model called directly: agreement to round-off of the unit round trip
        assert row.cavity_pressure_Pa == pytest.approx(
            _direct(row["material.poisson_ratio"], row["material.compressive_strength_Pa"]), rel=1e-12)
    man = json.loads((tmp_path / "sw" / "sweep.json").read_text())
    assert man["analysis"] == "cavity" and man["spec"]["n_samples"] == 3
    st = json.loads((tmp_path / "sw" / "statistics.json").read_text())["cavity_pressure_Pa"]
    v = df.cavity_pressure_Pa.to_numpy()
    assert st["n"] == 12 and st["mean"] == pytest.approx(v.mean(), rel=1e-14)
    assert st["std"] == pytest.approx(v.std(ddof=1), rel=1e-12) and st["max"] == v.max()


def test_interrupted_sweep_resumes_without_loss_or_duplicates(tmp_path):
    spec = build_spec(["material.poisson_ratio=0.18:0.27:0.01"], ["material.compressive_strength=normal(2.62 GPa, 0.05 GPa)"], 4, seed=2)
    calls = {"n": 0}

    def interrupt(_):
        calls["n"] += 1
        if calls["n"] == 3:
            raise KeyboardInterrupt

    out = tmp_path / "sw"
    with pytest.raises(KeyboardInterrupt):
        run_sweep(AD995, spec, out, scheduler="inline", progress=False, batch_size=5, on_batch=interrupt)
    assert len(pd.read_csv(out / "results.csv")) == 15  # three batches kept
    with pytest.raises(InputError) as err:  # neither --resume nor --force
        run_sweep(AD995, spec, out, scheduler="inline", progress=False)
    assert err.value.field == "--out"
    s = run_sweep(AD995, spec, out, scheduler="inline", progress=False, resume=True, batch_size=7)
    assert (s.n_skipped, s.n_run) == (15, spec.n_cases - 15)
    df = pd.read_csv(out / "results.csv")
    assert sorted(df.case_id) == list(range(spec.n_cases))  # every case exactly once
    ref = run_sweep(AD995, spec, tmp_path / "ref", scheduler="inline", progress=False)
    assert ref.n_ok == spec.n_cases
    dref = pd.read_csv(tmp_path / "ref" / "results.csv").set_index("case_id").sort_index()
    pd.testing.assert_frame_equal(df.set_index("case_id").sort_index(), dref)
    # a second resume has nothing left to do
    again = run_sweep(AD995, spec, out, scheduler="inline", progress=False, resume=True)
    assert again.n_run == 0


def test_killed_sweep_process_resumes(tmp_path):
    """SIGKILL a running sweep (no clean-up at all), then --resume: nothing written is lost."""
    out = tmp_path / "sw"
    args = [sys.executable, "-m", "semianalytic", "sweep", str(AD995), "--out", str(out), "--scheduler", "inline",
            "--batch-size", "4", "--no-progress", "--vary", "material.poisson_ratio=0.18:0.27:0.001",
            "--sample", "material.compressive_strength=normal(2.62 GPa, 0.05 GPa)", "--samples", "3"]
    proc = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    res = out / "results.csv"
    t0 = time.time()
    try:
        while time.time() - t0 < 90:
            if res.exists() and res.read_bytes().count(b"\n") > 20:
                break
            if proc.poll() is not None:
                break
            time.sleep(0.05)
        killed = proc.poll() is None
        if killed:
            os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    before = pd.read_csv(res) if res.exists() else pd.DataFrame()
    assert len(before) > 0
    rc = main(args[3:] + ["--resume"])
    assert rc == 0
    df = pd.read_csv(res)
    n = 91 * 3
    assert sorted(df.case_id) == list(range(n))
    # the rows written before the kill are kept unchanged
    merged = before.merge(df, on="case_id", suffixes=("_a", "_b"))
    assert len(merged) == len(before)
    assert np.array_equal(merged.cavity_pressure_Pa_a.to_numpy(), merged.cavity_pressure_Pa_b.to_numpy())
    if not killed:
        pytest.skip("the sweep finished before it could be killed (machine too fast); resume checked only")


def test_parquet_results(tmp_path):
    spec = build_spec(["material.poisson_ratio=0.2,0.22,0.24"])
    s = run_sweep(AD995, spec, tmp_path / "pq", fmt="parquet", scheduler="inline", progress=False, batch_size=1)
    assert s.n_ok == 3
    df = pd.read_parquet(tmp_path / "pq" / "results.parquet")
    assert sorted(df.case_id) == [0, 1, 2]
    assert len(list((tmp_path / "pq" / "results.parquet").glob("part-*.parquet"))) == 3


def test_bad_sweep_input_writes_nothing(tmp_path, capsys):
    out = tmp_path / "sw"
    rc = main(["sweep", str(AD995), "--out", str(out), "--scheduler", "inline", "--vary", "material.poisson_ratio=0.3:0.6:0.1"])
    assert rc == 2
    assert capsys.readouterr().err.startswith("error: material.poisson_ratio")
    assert not out.exists()
    rc = main(["sweep", str(AD995), "--out", str(out), "--scheduler", "inline", "--vary", "material.colour=1,2"])
    assert rc == 2
    assert capsys.readouterr().err.startswith("error: material.colour")
    assert not out.exists()
