"""Issue 23 item 6: ``sweep`` over ``target.thickness`` with the plate outputs, and ``optimize``
with the plate objectives (``ballistic_limit``, ``residual_velocity``).

Checked against the ``perforate`` command on the same case (its own driver of the model: the
curve, the bisection and its error estimate), and against physics the sweep does not impose:
a thicker plate has the higher ballistic limit, and a striking velocity perforates exactly when
it is above the ballistic limit (two different computations: the curve and the bisection).
The plate's coefficients are the half-space stand-in (``[perforation] coefficients =
"half-space"``) on coarse tables, so that no plate table (minutes of BEM) is built.
"""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parent.parent
DEMO = ROOT / "cases" / "perforation_ogive_6061T651.toml"
COARSE = """
[bem]
order = 4
refinement = 0.2
[coefficients]
depths = 16
max_depth_nose_lengths = 30.0
"""


@pytest.fixture()
def plate_case(tmp_path, monkeypatch):
    monkeypatch.setenv("SEMIANALYTIC_CACHE_DIR", str(tmp_path / "cache"))
    text = DEMO.read_text().replace("[perforation]\n", '[perforation]\ncoefficients = "half-space"\n', 1)
    p = tmp_path / "plate.toml"
    p.write_text(text + COARSE)
    return p


def _perforate(case: Path) -> dict:
    import contextlib
    import io

    from semianalytic.cli import main

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(["perforate", str(case), "--json"]) == 0
    return json.loads(out.getvalue())


def test_sweep_over_the_thickness(plate_case, tmp_path):
    from semianalytic.cli import main

    out = tmp_path / "sw"
    rc = main(["sweep", str(plate_case), "--out", str(out), "--vary", "target.thickness=12 mm,26.3 mm",
               "--vary", "impact.striking_velocity=300 m/s,900 m/s", "--scheduler", "inline", "--no-progress"])
    assert rc == 0
    df = pd.read_csv(out / "results.csv")
    assert (df.status == "ok").all(), df.message.tolist()
    bl = df.groupby("target.thickness_m").ballistic_limit_m_s.first()
    assert bl.iloc[0] < bl.iloc[1]  # the thicker plate stops faster projectiles
    for _, r in df.iterrows():  # perforated exactly above the ballistic limit (curve against bisection)
        if abs(r["impact.striking_velocity_m_s"] - r.ballistic_limit_m_s) > r.ballistic_limit_error_m_s:
            assert bool(r.perforated) == (r["impact.striking_velocity_m_s"] > r.ballistic_limit_m_s), r.to_dict()
    # the 26.3 mm row against the perforate command on the same case: the same V_bl within its estimate
    ref = _perforate(plate_case)
    thick = df[df["target.thickness_m"] == df["target.thickness_m"].max()]
    assert abs(thick.ballistic_limit_m_s.iloc[0] - ref["ballistic_limit_m_s"]) <= ref["ballistic_limit_error_m_s"] + 1e-9
    for U, Vr in zip(ref["striking_velocity_m_s"], ref["residual_velocity_m_s"]):
        rows = thick[thick["impact.striking_velocity_m_s"] == U]
        if len(rows):
            assert rows.residual_velocity_m_s.iloc[0] == pytest.approx(Vr, rel=1e-9, abs=1e-9)


@pytest.mark.parametrize("objective", ["ballistic_limit", "residual_velocity"])
def test_optimize_a_plate_objective(plate_case, tmp_path, objective):
    from semianalytic.cli import main

    out = tmp_path / "opt"
    rc = main(["optimize", str(plate_case), "--out", str(out), "--vary", "projectile.crh=1.5:4.5",
               "--objective", objective, "--constraint", "mass", "--coarse", "3", "--maxfev", "2", "--confirm", "0",
               "--scheduler", "inline", "--no-progress"] + (["--striking-velocity", "800 m/s"]
                                                             if objective == "residual_velocity" else []))
    assert rc == 0
    res = json.loads((out / "optimum.json").read_text())
    crh = res["optimum"]["x"][0]
    # the optimum's design through the perforate command: the same V_bl (or V_r at 800 m/s)
    text = plate_case.read_text().replace("crh = 3.0", f"crh = {crh!r}")
    text = text.replace('shank_length = "71.1 mm"', f'shank_length = "{res["optimum"]["shank_length_m"]!r} m"')
    q = tmp_path / "optimum.toml"
    q.write_text(text)
    ref = _perforate(q)
    if objective == "ballistic_limit":
        assert abs(res["optimum"]["objective"] - ref["ballistic_limit_m_s"]) <= ref["ballistic_limit_error_m_s"] + 1e-9
    else:  # 800 m/s is one of the case's striking velocities
        Vr = ref["residual_velocity_m_s"][ref["striking_velocity_m_s"].index(800.0)]
        assert res["optimum"]["residual_velocities_m_s"][0] == pytest.approx(Vr, rel=1e-9)


def test_plate_objectives_refuse_nonsense(plate_case, tmp_path):
    """Issue 37: a 2 m plate that nothing perforates inside the model's range: every design is
    infeasible (never a number) and optimize exits 2 with the reason; residual_velocity at 50 m/s,
    below every design's V_bl (the demo plate: ~330 m/s): every design stops, exit 2."""
    import contextlib
    import io

    from semianalytic.cli import main

    thick = tmp_path / "thick.toml"
    thick.write_text(plate_case.read_text().replace('thickness = "26.3 mm"', 'thickness = "2 m"'))
    for case, objective, extra in ((thick, "ballistic_limit", []),
                                   (plate_case, "residual_velocity", ["--striking-velocity", "50 m/s"])):
        err = io.StringIO()
        with contextlib.redirect_stderr(err):
            rc = main(["optimize", str(case), "--out", str(tmp_path / objective), "--vary", "projectile.crh=1.5:4.5",
                       "--objective", objective, "--constraint", "mass", "--coarse", "3", "--maxfev", "2", "--confirm", "0",
                       "--scheduler", "inline", "--no-progress", *extra])
        assert rc == 2, err.getvalue()
        assert "infeasible" in err.getvalue() and ("model's range" in err.getvalue() or "stops" in err.getvalue())
