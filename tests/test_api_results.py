"""The Python face as a notebook uses it: every command's result is a frozen object that
pandas turns into a frame in one call, its arrays are NumPy arrays, its JSON is what the
command prints; validity notices are Python warnings; quantities are SI floats or unit strings.

References independent of the wrapper: the command's own JSON (``--json`` in a subprocess, the
other door), numbers written by hand (the ogive's nose length sqrt(2 s R - R^2), the requested
velocities), and the stderr lines of the command for the warnings.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from semianalytic import api
from semianalytic.errors import InputError, ValidityWarning

ROOT = Path(__file__).resolve().parent.parent
VAR4340 = ROOT / "cases" / "piekutowski1999_var4340.toml"


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("SEMIANALYTIC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "api-cache"))


def _cli_json(*args, cwd=ROOT):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.run([sys.executable, "-m", "semianalytic", *args], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return json.loads(proc.stdout), proc.stderr


def test_penetrate_result_is_tidy_and_is_the_command_json():
    case = api.load_case(VAR4340)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ValidityWarning)
        r = api.penetrate(case)
    cli, _ = _cli_json("penetrate", str(VAR4340), "--json")
    U = cli["striking_velocity_m_s"]
    frame = pd.DataFrame(r.to_frame())
    assert len(frame) == len(U)  # one row per striking velocity
    np.testing.assert_allclose(frame["striking_velocity_m_s"], U, rtol=0)
    np.testing.assert_allclose(frame["depth_rigid_m"], cli["depth_rigid_m"], rtol=1e-9)
    assert all(c.split(".")[0].endswith("_m") for c in frame.columns if c.startswith("depth"))  # units in the names
    assert isinstance(r["depth_m"], np.ndarray) and r["depth_m"].dtype == float
    assert r["depth_rigid_m"] == pytest.approx(cli["depth_rigid_m"], rel=1e-9)  # the old mapping access
    d = r.to_dict()
    assert json.loads(json.dumps(d)) == d  # strict JSON
    assert set(cli) == set(d) and d["coefficients"] == cli["coefficients"]
    assert d["regime"] == cli["regime"] and d["valid"] == cli["valid"]
    with pytest.raises((TypeError, AttributeError)):
        r.data = {}  # frozen
    with pytest.raises(TypeError):
        r.data["depth_m"] = []  # read-only


def test_every_result_makes_a_frame(tmp_path):
    """pandas.DataFrame from every API result in one call (``to_frame``), rows as documented."""
    frames = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ValidityWarning)
        case = api.load_case(VAR4340)
        frames["penetrate"] = (api.penetrate(case, [600.0, 900.0]), 2)
        frames["coefficients_at"] = (api.coefficients_at(case, ["5 mm", 0.02, 0.1]), 3)
        frames["predict_with_posterior"] = (api.predict_with_posterior(
            case, ROOT / "reports/calibration_piekutowski1999/posterior.json", [600.0, 900.0]), 2)
        frames["perforate"] = (api.perforate(api.load_case(ROOT / "cases/perforation_ogive_6061T651_constant.toml"),
                                             ["400 m/s", 800.0], ballistic=False), 2)
        bl = api.load_case(ROOT / "cases/part4_table3.toml")
        frames["ballistic_limit"] = (api.ballistic_limit(bl), len(api.ballistic_limit(bl).data["rows"]))
        frames["cavity"] = (api.cavity(api.load_case(ROOT / "cases/cavity_ad995.toml")), 1)
        nano = api.nanostrength(api.load_case(ROOT / "cases/part3_nanostrength.toml"))
        frames["nanostrength"] = (nano, sum(len(s["rows"]) for s in nano.data["studies"]))
        sw = api.sweep(ROOT / "cases/cavity_ad995.toml", tmp_path / "sw", ["material.poisson_ratio=0.2:0.22:0.01"],
                       quiet=True)
        frames["sweep"] = (sw, 3)
    for name, (result, rows) in frames.items():
        frame = result.to_frame()
        assert isinstance(frame, pd.DataFrame), name
        assert len(frame) == rows, (name, len(frame), rows)
        json.dumps(result.to_dict())  # the JSON the command prints
    q = frames["predict_with_posterior"][0]["depth_quantiles_m"]
    model = next(iter(q))
    assert sorted(q[model]) == [0.05, 0.25, 0.5, 0.75, 0.95]  # float quantile levels
    assert q[model][0.05] is q[model]["0.05"] or np.array_equal(q[model][0.05], q[model]["0.05"])
    assert np.all(q[model][0.05] <= q[model][0.95])


def test_optimize_and_fem_verify_in_the_api(tmp_path):
    """optimize: the typed call gives the optimum the command writes; fem_check.api.verify: the
    payload of ``fem_check verify --json`` (FEM against BEM within the command's own 5e-3)."""
    from fem_check.api import verify

    case = tmp_path / "case.toml"
    opts = dict(constraint=["mass"], coarse=3, confirm=0, maxfev=4, quiet=True)
    case.write_text("""
title = "optimize test"
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
model = "constant"
value = "1.2 GPa"
[impact]
striking_velocities = ["600 m/s"]
""")
    r = api.optimize(case, ["projectile.crh=1:5"], "depth", **opts)
    assert 1.0 <= r["optimum"]["x"][0] <= 5.0
    assert len(r.to_frame()) == 1
    v = verify(ROOT / "cases/fig5_ogive.toml", [2.0], h=0.1, quick=True, quiet=True)
    assert v["kind"] == "halfspace" and v["max_rel_diff"] < 5e-3
    with pytest.raises(InputError, match="^h:"):
        verify(ROOT / "cases/fig5_ogive.toml", [2.0], h=0.0)


def test_validity_warnings_are_python_warnings():
    """Every ``warning:`` line ``penetrate`` prints on stderr comes as a ValidityWarning, and the
    class filters them (ignore, error)."""
    case = api.load_case(VAR4340)
    U = [600.0, 2500.0]
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        api.penetrate(case, U)
    got = [str(w.message) for w in seen if issubclass(w.category, ValidityWarning)]
    _, err = _cli_json("penetrate", str(VAR4340), "--json")
    # the CLI at the case's velocities; the API at 600 and 2500 m/s: both warn on the rigid model
    # beyond the yield velocity and on the eroding rod below its onset
    assert any("rigid projectile (eq. (11))" in g and "2500" in g for g in got), got
    assert any("eroding rod" in g and "600" in g for g in got), got
    assert "warning:" in err
    with warnings.catch_warnings():
        warnings.simplefilter("error", ValidityWarning)
        with pytest.raises(ValidityWarning):
            api.depth(case, 2500.0, model="rigid")
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        api.depth(case, 600.0, model="rigid")  # inside the rigid model's validity: no notice about it
    assert not [w for w in seen if "rigid projectile" in str(w.message)]


def test_long_velocity_lists_are_summarised():
    case = api.load_case(VAR4340)
    U = np.linspace(300.0, 1400.0, 1000)
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        api.penetrate(case, U, source="paper")
    eroding = [str(w.message) for w in seen if "eroding rod" in str(w.message)]
    assert eroding and all(len(m) < 400 for m in eroding), [len(m) for m in eroding]
    assert "1000 values, 300 to 1400" in eroding[0]


def test_quantities_as_floats_or_unit_strings():
    case = api.load_case(VAR4340)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ValidityWarning)
        assert api.depth(case, "0.8 km/s") == api.depth(case, 800.0)
        assert np.array_equal(api.depth(case, ["800 m/s", 900.0]), api.depth(case, [800.0, 900.0]))
    for bad, field in (("800 m", "velocity"), ("fast", "velocity"), ([800.0, "x"], "velocity[1]")):
        with pytest.raises(InputError) as e:
            api.depth(case, bad)
        assert str(e.value).startswith(field + ":") and "\n" not in str(e.value)


def test_case_offers_its_derived_geometry():
    case = api.load_case(ROOT / "cases/fig5_ogive.toml")
    g = case.geometry
    d, psi = 7.11e-3, 3.0
    R, s = d / 2, psi * d
    L_h = math.sqrt(2 * s * R - R * R)  # tangent ogive: by hand
    assert g.nose_length_m == pytest.approx(L_h, rel=1e-12)
    assert g.length_m == pytest.approx(L_h + case.projectile.shank, rel=1e-12)
    assert g.length_over_diameter == pytest.approx(g.length_m / d, rel=1e-12)
    if g.mass_kg is not None and case.projectile.density:
        assert g.mass_kg == pytest.approx(case.projectile.density * g.volume_m3, rel=1e-12)
    assert api.geometry(case) == g
