"""Penetration sweeps: velocity-by-material grids on a dask LocalCluster and inline.

With constant drag coefficients (the stand-in of Part IV eqs. (2)-(3)), eq. (11) has the
closed-form final depth  P = (m + rho A)/(rho B) ln(1 + rho B U^2 / (2 C R_t)),  and R_t of
eq. (16) is a closed form too; both are written out here, independent of the code under
test.  One test runs on a real two-worker LocalCluster.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from case_blocks import TARGET_6061_T651

from semianalytic.coefficients import ConstantCoefficients
from semianalytic.sweep.engine import run_sweep
from semianalytic.sweep.kernels import PenetrationKernel
from semianalytic.sweep.spec import build_spec

D = 7.11e-3
COEF = ConstantCoefficients.from_normalised(1.0e-3, 0.11, 1.0, D)  # the paper's quoted ogive values
CASE = """
title = "ogive into aluminium, sweep test"
[projectile]
nose = "ogive"
crh = 3.0
diameter = "7.11 mm"
shank_length = "59.3 mm"
mass = "20.9 g"
youngs_modulus = "210 GPa"
poisson_ratio = 0.29
yield_stress = "1.5 GPa"
""" + TARGET_6061_T651 + """[impact]
striking_velocities = ["1 km/s"]
"""


def _closed_form(U, Y, E=68.9e9, nu=0.33, rho=2710.0, m=20.9e-3):
    R = 2.0 / 3.0 * Y * (1.0 + np.log(E / (3.0 * Y * (1.0 - nu))))  # Part I eq. (16)
    return (m + rho * COEF.A_m3) / (rho * COEF.B_m2) * np.log1p(rho * COEF.B_m2 * U**2 / (2.0 * COEF.C_m2 * R))


@pytest.fixture()
def case_file(tmp_path):
    p = tmp_path / "case.toml"
    p.write_text(CASE)
    return p


def _check(df):
    assert (df.status == "ok").all(), df[df.status != "ok"].message.head()
    Y = df["target.resistance.yield_stress_Pa"].to_numpy() if "target.resistance.yield_stress_Pa" in df else 400e6
    ref = _closed_form(df["impact.striking_velocity_m_s"].to_numpy(), Y)
    # the ODE in P is integrated to rtol 1e-12; 1e-8 leaves room for the unit round trip and the root find
    np.testing.assert_allclose(df.depth_rigid_m.to_numpy(), ref, rtol=1e-8)


def test_velocity_by_material_inline(case_file, tmp_path):
    spec = build_spec(["target.resistance.yield_stress=300:500:50 MPa", "impact.striking_velocity=500:1500:250 m/s"])
    kernel = PenetrationKernel(coefficients=COEF)
    s = run_sweep(case_file, spec, tmp_path / "sw", scheduler="inline", progress=False, kernel=kernel, batch_size=7)
    assert s.n_ok == 25
    _check(pd.read_csv(tmp_path / "sw" / "results.csv"))


def test_velocity_by_material_on_an_existing_dask_cluster(case_file, tmp_path):
    # --scheduler ADDRESS: a cluster started elsewhere (here: by the test), two worker processes
    from dask.distributed import LocalCluster

    spec = build_spec(["target.resistance.yield_stress=300:500:50 MPa", "impact.striking_velocity=400:1600:100 m/s"])
    kernel = PenetrationKernel(coefficients=COEF)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        s = run_sweep(case_file, spec, tmp_path / "sw", scheduler=cluster.scheduler_address, progress=False,
                      kernel=kernel, batch_size=13)
    assert s.scheduler == cluster.scheduler_address and s.workers == 2
    assert s.n_ok == 5 * 13
    df = pd.read_csv(tmp_path / "sw" / "results.csv")
    assert sorted(df.case_id) == list(range(65))
    _check(df)
    # U_sC depends on the material only; yields <=> U_s >= U_sC
    assert (df.yields == (df["impact.striking_velocity_m_s"] >= df.critical_velocity_m_s)).all()


def test_full_mode_adds_the_elastic_projectile(case_file, tmp_path):
    spec = build_spec(["impact.striking_velocity=600:1400:400 m/s"])
    s = run_sweep(case_file, spec, tmp_path / "sw", scheduler="inline", progress=False,
                  kernel=PenetrationKernel(coefficients=COEF, full=True))
    df = pd.read_csv(tmp_path / "sw" / "results.csv")
    assert s.n_ok == 3
    _check(df)
    # the elastic projectile never penetrates deeper than the rigid one (Part I eq. (30))
    assert (df.depth_elastic_m <= df.depth_rigid_m * (1 + 1e-12)).all()
    assert (df.depth_quasi_rigid_m <= df.depth_rigid_m * (1 + 1e-12)).all()


def test_case_velocities_become_an_axis_and_bad_draws_are_rows(case_file, tmp_path):
    # without a velocity axis the case's own velocity is used; Monte-Carlo draws that make
    # an invalid case (nu >= 0.5) are reported as invalid rows and the sweep goes on
    spec = build_spec([], ["target.resistance.poisson_ratio=uniform(0.3, 0.7)"], 40, seed=5)
    s = run_sweep(case_file, spec, tmp_path / "sw", scheduler="inline", progress=False,
                  kernel=PenetrationKernel(coefficients=COEF))
    df = pd.read_csv(tmp_path / "sw" / "results.csv")
    nu = df["target.resistance.poisson_ratio"]
    assert ((df.status == "invalid") == (nu >= 0.5)).all()
    bad = df[df.status == "invalid"].message
    assert bad.str.startswith("target.resistance").all() and bad.str.contains("poisson_ratio").all()
    assert (df["impact.striking_velocity_m_s"] == 1000.0).all()
    assert s.n_ok + s.n_invalid == 40 and s.n_ok > 0 and s.n_invalid > 0


def test_invalid_grid_value_is_bad_input(case_file, tmp_path):
    from semianalytic.errors import InputError

    spec = build_spec(["target.resistance.yield_stress=400 MPa,40 GPa"])  # E < 3 Y (1 - nu) for eq. (16)
    with pytest.raises(InputError) as err:
        run_sweep(case_file, spec, tmp_path / "sw", scheduler="inline", progress=False,
                  kernel=PenetrationKernel(coefficients=COEF))
    assert err.value.field.startswith("target.resistance")
    assert not (tmp_path / "sw").exists()
