"""``run``: a case in, results.json + report.md + report.html + PNG + VTK out.

The numbers in results.json are checked against closed forms written out here, independent
of the code under test: with ``[run] coefficients = "paper"`` the drag coefficients are the
paper's constants, and eq. (11) then has the closed-form final depth
P = (m + rho A)/(rho B) ln(1 + rho B U^2/(2 C R_t)) (Part IV eqs. (2)-(3), errata 22-24);
R_t is eq. (16) and U_sC eq. (33).  The velocity-field VTK is checked in test_vtk_export.py.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from case_blocks import TARGET_6061_T651

from semianalytic.cli import main

CASE = """
title = "run test: Fig. 5 ogive into 6061-T651 with the paper's constants"
reproduces = "test"
[projectile]
nose = "ogive"
crh = 3.0
diameter = "7.11 mm"
shank_length = "59.3 mm"
density = "7830 kg/m^3"
youngs_modulus = "210 GPa"
poisson_ratio = 0.29
yield_stress = "1.64 GPa"
""" + TARGET_6061_T651 + """[impact]
striking_velocities = ["0.6 km/s", "1.0 km/s"]
[run]
analyses = ["penetration", "critical_velocity", "velocity_field"]
coefficients = "paper"
field_depths = ["30 mm"]
field_grid = [9, 5]
field_segments = 6
vtk_dir = "fields/vtk"
"""

D, RHO, Y, E, NU = 7.11e-3, 2710.0, 400e6, 68.9e9, 0.33
AREA = math.pi * D * D / 4
A, B, C = 1.0e-3 * AREA, 0.11 * AREA, 1.0 * AREA  # the paper's ogive Abar [m], Bbar, Cbar


def _mass():
    R = D / 2
    s = 3.0 * D
    L_h = math.sqrt(2 * s * R - R * R)
    # tangent-ogive volume: revolve r(x) = sqrt(s^2 - x^2) - (s - R), x in [0, L_h] (numerically, fine grid)
    x = np.linspace(0.0, L_h, 200001)
    r = np.sqrt(s * s - x * x) - (s - R)
    v_nose = math.pi * np.trapezoid(r * r, x)
    return 7830.0 * (v_nose + math.pi * R * R * 59.3e-3)


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    d = tmp_path_factory.mktemp("run")
    case = d / "case.toml"
    case.write_text(CASE)
    out = d / "out"
    assert main(["run", str(case), "--out", str(out)]) == 0
    return case, out


def test_files(report):
    _, out = report
    for name in ("results.json", "report.md", "report.html"):
        assert (out / name).is_file()
    res = json.loads((out / "results.json").read_text())
    for rel in res["figures"]:
        data = (out / rel).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 5000
    html = (out / "report.html").read_text()
    md = (out / "report.md").read_text()
    for rel in res["figures"]:
        assert rel in html and rel in md
    vtus = sorted(p.relative_to(out).as_posix() for p in out.rglob("*.vtu"))
    assert vtus and all(v.startswith("fields/vtk/") for v in vtus)
    assert not list(out.parent.glob(".out.*"))  # no staging folder left


def test_depths_against_the_closed_form(report):
    _, out = report
    pen = json.loads((out / "results.json").read_text())["analyses"]["penetration"]
    m = _mass()
    R_t = 2.0 / 3.0 * Y * (1.0 + math.log(E / (3.0 * Y * (1.0 - NU))))  # Part I eq. (16)
    assert pen["resistance_Pa"] == pytest.approx(R_t, rel=1e-12)
    assert pen["mass_kg"] == pytest.approx(m, rel=1e-6)  # trapezoid volume of the ogive to ~1e-9
    U = np.array(pen["striking_velocity_m_s"])
    P = (m + RHO * A) / (RHO * B) * np.log1p(RHO * B * U**2 / (2 * C * R_t))
    # report ODEs at rtol 1e-9; 1e-6 leaves room for the mass (1e-9) and the event location
    np.testing.assert_allclose(pen["depth_rigid_m"], P, rtol=1e-6)
    # the elastic projectiles stop earlier than the rigid one (eqs. (26), (30'))
    assert all(e < r for e, r in zip(pen["depth_elastic_m"], pen["depth_rigid_m"]))


def test_critical_velocity_against_eq_33(report):
    _, out = report
    crit = json.loads((out / "results.json").read_text())["analyses"]["critical_velocity"]
    m = _mass()
    R_t = 2.0 / 3.0 * Y * (1.0 + math.log(E / (3.0 * Y * (1.0 - NU))))
    Yp, Ep, rho_p = 1.64e9, 210e9, 7830.0
    c0 = math.sqrt(Ep / rho_p)
    U_sC = Yp * c0 / Ep + math.sqrt(math.pi * D * D / (2 * RHO * B) * ((1 + RHO * A / m) * Yp - 4 * C / (math.pi * D * D) * R_t))
    # the buckling factor is 1 here (buckling = "none"); same closed form -> round-off only
    assert crit["critical_velocity_m_s"] == pytest.approx(U_sC, rel=1e-9)


def test_existing_folder_and_force(report, capsys):
    case, out = report
    before = (out / "results.json").read_text()
    assert main(["run", str(case), "--out", str(out), "--no-render"]) == 2
    assert capsys.readouterr().err.startswith("error: --out")
    assert (out / "results.json").read_text() == before
    (out / "stale.txt").write_text("old")  # a file the tool did not write: --force refuses (issue 27)
    assert main(["run", str(case), "--out", str(out), "--no-render", "--only", "critical_velocity", "--force"]) == 2
    assert "'stale.txt'" in capsys.readouterr().err and (out / "stale.txt").read_text() == "old"
    (out / "stale.txt").unlink()
    assert main(["run", str(case), "--out", str(out), "--no-render", "--only", "critical_velocity", "--force"]) == 0
    assert "critical_velocity" in json.loads((out / "results.json").read_text())["analyses"]


def test_body_case_added_mass(tmp_path):
    # [body] sphere: the BEM added-mass coefficient against the exact 1/2
    case = Path(__file__).resolve().parent.parent / "cases" / "body_sphere.toml"
    out = tmp_path / "out"
    assert main(["run", str(case), "--out", str(out), "--no-render"]) == 0
    am = json.loads((out / "results.json").read_text())["analyses"]["added_mass"]
    assert am["added_mass_coefficient"] == pytest.approx(0.5, rel=1e-8)  # the BEM reaches ~1e-12 on a sphere
