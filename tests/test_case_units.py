"""Case-file layer: unit parsing and one-line errors naming the field.

Checked against pint-independent facts (1 mm = 1e-3 m, 1 MPa = 1e6 Pa, 1 km/s = 1000 m/s).
"""

import math

import pytest

from semianalytic.case import parse_case
from semianalytic.errors import InputError
from semianalytic.units import parse_quantity


@pytest.mark.parametrize(
    "text, kind, si",
    [
        ("7.11 mm", "length", 7.11e-3),
        ("400 MPa", "pressure", 4e8),
        ("1.0 km/s", "velocity", 1000.0),
        ("7830 kg/m^3", "density", 7830.0),
        ("2.7 g/cm^3", "density", 2700.0),
        ("30 deg", "angle", math.pi / 6),
    ],
)
def test_parse_quantity_to_si(text, kind, si):
    assert parse_quantity(text, kind, "f") == pytest.approx(si, rel=1e-12)


@pytest.mark.parametrize("bad", ["7.11", 7.11, "7.11 kg", "abc", "", True])
def test_bad_length_names_the_field(bad):
    with pytest.raises(InputError) as err:
        parse_quantity(bad, "length", "projectile.diameter")
    assert err.value.field == "projectile.diameter"
    assert "length" in err.value.message


FIG5 = {
    "projectile": {"nose": "ogive", "crh": 3.0, "diameter": "7.11 mm", "shank_length": "59.3 mm", "density": "7830 kg/m^3"},
    "target": {"density": "2710 kg/m^3"},
}


def test_fig5_case_parses():
    case = parse_case(FIG5)
    assert case.projectile.diameter == pytest.approx(7.11e-3)
    assert case.target.density == 2710.0


@pytest.mark.parametrize(
    "patch, field",
    [
        ({"projectile": {**FIG5["projectile"], "diameter": "-1 mm"}}, "projectile.diameter"),
        ({"projectile": {**FIG5["projectile"], "diameter": "7 kg"}}, "projectile.diameter"),
        ({"projectile": {**FIG5["projectile"], "colour": "red"}}, "projectile.colour"),
        ({"projectile": {**FIG5["projectile"], "poisson_ratio": 0.5}}, "projectile.poisson_ratio"),
        ({"projectile": {**FIG5["projectile"], "nose": "banana"}}, "projectile.nose"),
        ({"target": {}}, "target.density"),
        ({"wibble": {}}, "wibble"),
    ],
)
def test_bad_case_names_field(patch, field):
    with pytest.raises(InputError) as err:
        parse_case({**FIG5, **patch})
    assert err.value.field == field
    assert "\n" not in str(err.value)
