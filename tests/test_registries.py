"""Registries (issue 39 item 4): a resistance model and an output format are each added in one
place, and that one registration reaches every list the user sees.

Independent checks: a registered model's depth equals the built-in ``constant`` model's at the
same R_t (the depth of eq. (11) depends on R_t alone); the JSON of ``--json`` keeps the bytes of
the release before the registry (the key order recorded below and Python's ``json.dumps``
layout); the CSV on stdout equals the ``--csv FILE`` the command wrote before the registry.
"""

from __future__ import annotations

import json
import sys
import textwrap
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import pytest

import semianalytic.case  # noqa: F401 (the case schema exists before a test registers a model)
from semianalytic.cli import main

ROOT = Path(__file__).resolve().parents[1]
CAVITY = ROOT / "cases" / "cavity_ad995.toml"
FIG15A = ROOT / "cases" / "fig15a_ogive_6061T651.toml"

# the keys of `cavity cases/cavity_ad995.toml --json`, in order, as printed before the registry
CAVITY_KEYS = ["case", "sigma_star_Pa", "cavity_pressure_Pa", "C", "theta_star", "theta_c", "e_r", "e_phi", "e_c",
               "gamma_c", "v_star", "c_over_b", "a_over_b", "e_k", "e_ks", "theta_k", "alpha", "method", "iterations",
               "contraction", "e_k_exact_balance", "e_k_true_strain", "warnings"]


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


# -- resistance models ----------------------------------------------------------------------


@dataclass(frozen=True)
class Scaled:
    """A test model: R_t = factor * yield_stress [Pa]."""

    yield_stress: float
    factor: float
    name = "scaled"
    equation = "R_t = factor Y (test)"

    def pressure(self, diameter=None):
        return self.factor * self.yield_stress


@pytest.fixture
def scaled_model():
    from semianalytic.sections.penetration import (
        ResistanceInput,
        register_resistance,
        unregister_resistance,
    )
    from semianalytic.units import Pressure

    @register_resistance(calibrate="yield_stress")
    class ScaledInput(ResistanceInput):
        model: Literal["scaled"]
        yield_stress: Pressure
        factor: float

        def build(self):
            return Scaled(self.yield_stress, self.factor)

    yield ScaledInput
    unregister_resistance("scaled")


def _case(tmp_path, name, resistance):
    text = FIG15A.read_text().split("[target.resistance]")[0] + "[target.resistance]\n" + textwrap.dedent(resistance) + \
        '\n[impact]\nstriking_velocities = ["0.5 km/s", "1.0 km/s"]\n'
    path = tmp_path / name
    path.write_text(text)
    return path


def test_a_registered_resistance_model_is_a_case_model(tmp_path, capsys, scaled_model):
    """One registration: the case schema accepts it, penetrate runs it, calibrate knows its default
    parameter, and its depths are the constant model's at the same R_t (4 x 100 MPa)."""
    from semianalytic.case import load_case
    from semianalytic.penetration.resistance import resistance_from_case
    from semianalytic.sections.calibration import default_parameter

    mine = _case(tmp_path, "scaled.toml", 'model = "scaled"\nyield_stress = "100 MPa"\nfactor = 4.0\n')
    same = _case(tmp_path, "constant.toml", 'model = "constant"\nvalue = "400 MPa"\n')
    model = resistance_from_case(load_case(mine))
    assert model == Scaled(100e6, 4.0) and model.pressure() == 400e6
    assert default_parameter(model) == "target.resistance.yield_stress"
    depths = []
    for path in (mine, same):
        code, out, err = run(capsys, "penetrate", path, "--coefficients", "paper", "--json")
        assert code == 0, err
        depths.append(json.loads(out)["depth_rigid_m"])
    assert depths[0] == depths[1]  # the same R_t: the same eq. (11), to the last bit


def test_a_misspelt_model_lists_the_registered_one(tmp_path, capsys, scaled_model):
    path = _case(tmp_path, "typo.toml", 'model = "scalde"\nyield_stress = "100 MPa"\nfactor = 4.0\n')
    code, out, err = run(capsys, "penetrate", path, "--coefficients", "paper")
    assert code == 2 and out == ""
    line, = err.strip().splitlines()
    assert line.startswith("error: target.resistance.model:") and "'scaled'" in line and "did you mean 'scaled'" in line
    for name in ("elastic-plastic", "constant", "cavity"):
        assert name in line


def test_an_unregistered_model_is_refused_again(tmp_path, capsys, scaled_model):
    from semianalytic.sections.penetration import MODELS, unregister_resistance

    path = _case(tmp_path, "scaled.toml", 'model = "scaled"\nyield_stress = "100 MPa"\nfactor = 4.0\n')
    unregister_resistance("scaled")
    try:
        assert "scaled" not in MODELS
        code, _out, err = run(capsys, "penetrate", path, "--coefficients", "paper")
        assert code == 2 and "target.resistance.model" in err and "'scaled'" in err
    finally:
        from semianalytic.sections.penetration import register_resistance

        register_resistance(scaled_model)  # the fixture removes it again


def test_one_file_in_resistances_adds_a_model(tmp_path, monkeypatch, capsys):
    """The folder semianalytic/sections/resistances: one module there is one more model."""
    import semianalytic.sections.resistances as folder
    from semianalytic.sections.penetration import MODELS, unregister_resistance

    extra = tmp_path / "plugins"
    extra.mkdir()
    (extra / "halved.py").write_text(textwrap.dedent('''
        from dataclasses import dataclass
        from typing import Literal

        from semianalytic.sections.penetration import ResistanceInput, register_resistance
        from semianalytic.units import Pressure


        @dataclass(frozen=True)
        class Halved:
            value: float
            name = "halved"
            equation = "R_t = value / 2 (test)"

            def pressure(self, diameter=None):
                return 0.5 * self.value


        @register_resistance(calibrate="value")
        class HalvedInput(ResistanceInput):
            model: Literal["halved"]
            value: Pressure

            def build(self):
                return Halved(self.value)
    '''))
    monkeypatch.setattr(folder, "__path__", [*folder.__path__, str(extra)])
    try:
        assert "halved" in folder.load_all()
        assert "halved" in MODELS
        path = _case(tmp_path, "halved.toml", 'model = "halved"\nvalue = "800 MPa"\n')
        code, out, err = run(capsys, "penetrate", path, "--coefficients", "paper", "--json")
        assert code == 0, err
        assert json.loads(out)["resistance_Pa"] == 400e6
    finally:
        unregister_resistance("halved")
        sys.modules.pop("semianalytic.sections.resistances.halved", None)


# -- output formats -------------------------------------------------------------------------


@pytest.fixture
def keys_format():
    from semianalytic.report.formats import FORMATS, register_format

    @register_format("keys", needs="data", help="the top-level keys, one a line")
    def write_keys(output, stream):
        stream.write("".join(f"{k}\n" for k in output.data))

    yield write_keys
    del FORMATS["keys"]


def test_json_bytes_are_kept(capsys):
    code, out, err = run(capsys, "cavity", CAVITY, "--json")
    assert code == 0, err
    data = json.loads(out)
    assert list(data) == CAVITY_KEYS
    assert out == json.dumps(data, indent=2, allow_nan=False) + "\n"  # layout and float repr of before
    code, same, err = run(capsys, "cavity", CAVITY, "--format", "json")
    assert code == 0 and same == out


def test_a_registered_format_works_on_a_command(capsys, keys_format):
    code, out, err = run(capsys, "cavity", CAVITY, "--format", "keys")
    assert code == 0, err
    assert out.splitlines() == CAVITY_KEYS


def test_an_unknown_format_names_the_flag_and_the_choices(capsys):
    code, out, err = run(capsys, "cavity", CAVITY, "--format", "keys")
    assert code == 2 and out == ""
    assert err.strip() == "error: --format: must be one of json, text; got 'keys'"


def test_csv_only_where_there_are_rows(capsys):
    code, _, err = run(capsys, "cavity", CAVITY, "--format", "csv")
    assert code == 2 and err.strip() == "error: --format: must be one of json, text; got 'csv'"
    code, _out, err = run(capsys, "ballistic-limit", ROOT / "cases" / "part4_table3.toml", "--format", "csv")
    assert code == 2 and "--format" in err


def test_json_and_a_different_format_is_refused(capsys):
    code, _out, err = run(capsys, "cavity", CAVITY, "--json", "--format", "text")
    assert code == 2 and err.strip().startswith("error: --format:")


def test_penetrate_csv_on_stdout_is_the_csv_file(tmp_path, capsys):
    target = tmp_path / "d.csv"
    code, out, err = run(capsys, "penetrate", FIG15A, "--coefficients", "paper", "--format", "csv", "--csv", target)
    assert code == 0, err
    assert out == target.read_text()  # nothing else on stdout (no "csv: FILE" line)
    header, *rows = out.splitlines()
    assert header.startswith("case,striking_velocity [m/s],model,depth [m]")
    velocities = {r.split(",")[1] for r in rows}
    assert len(velocities) == 13  # the case's 13 striking velocities


def test_text_is_the_default(capsys):
    code, text, _err = run(capsys, "cavity", CAVITY)
    code2, same, _err2 = run(capsys, "cavity", CAVITY, "--format", "text")
    assert code == code2 == 0 and text == same and text.startswith("AD995")


def test_the_tate_model_of_the_worked_example(tmp_path, capsys):
    """docs/extending.md's model, shipped as semianalytic/sections/resistances/tate.py: R_t
    against a hand computation of Tate (1986) at Y_t = 400 MPa, E_t = 68.9 GPa:
    400e6 (2/3 + ln(0.57 * 172.25)) = 2101.3979 MPa (to 1e-9: the digits carried by hand)."""
    path = _case(tmp_path, "tate.toml", 'model = "tate"\nyield_stress = "400 MPa"\nyoungs_modulus = "68.9 GPa"\n')
    code, out, err = run(capsys, "penetrate", path, "--coefficients", "paper", "--json")
    assert code == 0, err
    assert json.loads(out)["resistance_Pa"] == pytest.approx(2101.397863e6, rel=1e-9)
    bad = _case(tmp_path, "bad.toml", 'model = "tate"\nyield_stress = "400 MPa"\nyoungs_modulus = "300 MPa"\n')
    code, out, err = run(capsys, "penetrate", bad, "--coefficients", "paper")
    assert code == 2 and err.startswith("error: target.resistance: youngs_modulus: Tate's R_t needs E_t > Y_t"), err


def _blocks():
    import re

    return re.findall(r"```python\n(.*?)```", (ROOT / "docs" / "extending.md").read_text(encoding="utf-8"), re.DOTALL)


def test_the_worked_examples_of_the_docs_are_the_code(capsys):
    """docs/extending.md shows the shipped tate.py (every line of its block is in the file, the
    comments aside) and its format example runs as shown."""
    model, fmt, use, report = _blocks()
    shipped = (ROOT / "semianalytic" / "sections" / "resistances" / "tate.py").read_text(encoding="utf-8")
    for line in model.splitlines():
        assert line.split("  #")[0].rstrip() in shipped, line
    from semianalytic.report.formats import FORMATS

    try:
        exec(compile(fmt, "extending.md", "exec"), {})  # noqa: S102 (the page's own example)
        code, out, err = run(capsys, "cavity", CAVITY, "--format", "keys")
        assert code == 0 and out.splitlines() == CAVITY_KEYS, err
    finally:
        FORMATS.pop("keys", None)
    assert '"--format", "keys"' in use
    from semianalytic.report.report_formats import REPORT_FORMATS

    try:
        exec(compile(report, "extending.md", "exec"), {})  # noqa: S102 (the page's own example)
        assert REPORT_FORMATS["plain"].render("**a**", lambda rel: None) == "a"
    finally:
        REPORT_FORMATS.pop("plain", None)


# -- report formats -------------------------------------------------------------------------


@pytest.fixture
def plain_report_format():
    from semianalytic.report.report_formats import (
        REPORT_FORMATS,
        register_report_format,
    )

    @register_report_format("plain", suffix=".txt")
    def plain(markdown, images):
        return markdown.replace("**", "")

    yield plain
    del REPORT_FORMATS["plain"]


def test_a_registered_report_format_is_written_beside_every_report(tmp_path, plain_report_format):
    """write_beside (every per-package --report) writes each registered format; the HTML page is
    the one html_beside wrote before the registry, byte for byte."""
    from semianalytic.report.html import html_beside
    from semianalytic.report.report_formats import targets_beside, write_beside

    md = tmp_path / "r.md"
    md.write_text("# Title\n\nSome **bold** text.\n\n![fig](f.png)\n")
    (tmp_path / "f.png").write_bytes(b"\x89PNG\r\n\x1a\nnot really")
    assert targets_beside(md) == [tmp_path / "r.html", tmp_path / "r.txt"]
    write_beside(md)
    assert (tmp_path / "r.txt").read_text() == "# Title\n\nSome bold text.\n\n![fig](f.png)\n"
    html = (tmp_path / "r.html").read_bytes()
    html_beside(md)
    assert (tmp_path / "r.html").read_bytes() == html


def test_a_registered_report_format_through_a_command(tmp_path, capsys, plain_report_format):
    code, _, err = run(capsys, "nanostrength", ROOT / "cases" / "part3_table3.toml", "--report", tmp_path)
    assert code == 0, err
    assert (tmp_path / "part3_table3.txt").read_text() == (tmp_path / "part3_table3.md").read_text().replace("**", "")


# -- nose kinds -----------------------------------------------------------------------------


def test_a_nose_kind_registered_before_the_case_layer_is_a_case_nose(tmp_path):
    """register_nose in geometry's registry (before semianalytic.case is imported) is accepted by
    [projectile] nose; the nose it builds is the ogive of crh 1 (the same segments), and a key the
    kind does not list is refused naming the kinds that use it."""
    import os
    import subprocess

    case = tmp_path / "c.toml"
    case.write_text(FIG15A.read_text().replace('nose = "ogive"\ncrh = 3.0', 'nose = "one_caliber"'))
    code = textwrap.dedent(f'''
        import semianalytic.geometry as g

        @g.register_nose("one_caliber")
        def build(sec):
            return g.ogive_nose(sec.diameter, 1.0)

        from semianalytic.case import load_case
        from semianalytic.errors import InputError
        c = load_case({str(case)!r})
        nose = g.nose_from_section(c.projectile)
        # a tangent ogive's length: L_h = d sqrt(psi - 1/4) (geometry of the tangent arc)
        assert abs(nose.length - 7.11e-3 * 0.75 ** 0.5) <= 1e-12 * nose.length, nose.length
        try:
            load_case({str(case)!r}.replace("c.toml", "bad.toml"))
        except InputError as exc:
            print(exc.field, exc.message)
    ''')
    (tmp_path / "bad.toml").write_text(case.read_text().replace('nose = "one_caliber"', 'nose = "one_caliber"\ncrh = 2.0'))
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120, check=False)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.startswith("projectile.crh has no use for the 'one_caliber' nose (only for: ogive)"), proc.stdout


def test_the_schema_choices_are_the_registered_noses():
    import typing

    from semianalytic.case import ProjectileSection
    from semianalytic.geometry import NOSE_KINDS

    assert list(typing.get_args(ProjectileSection.model_fields["nose"].annotation)) == list(NOSE_KINDS)
    assert list(NOSE_KINDS) == ["ogive", "sphere", "cone", "flat", "table", "power", "spline"]
