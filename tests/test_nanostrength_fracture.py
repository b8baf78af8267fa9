"""Part III fracture quantities, eqs. (15)-(16) and Table 3.

References: Table 3 as printed (eq. (16) with the Delta Phi printed after it), and for eq. (15)
the identity int sigma du = Delta Phi of the reference-spacing measure.
"""

import math

import pytest

from semianalytic.nanostrength import data
from semianalytic.nanostrength.crystal import paper_crystal
from semianalytic.nanostrength.fracture import fracture, fracture_toughness, surface_energy_eq16
from semianalytic.nanostrength.interplanar import calibrate


@pytest.mark.parametrize("name", data.MATERIALS)
def test_table3_within_two_percent(name):
    # The tolerance: 2 %.  Measured: largest SiC Y_1c II at -1.8 % (the printed value
    # needs Delta Phi = 0.871e-3 instead of the quoted 0.855e-3); all others within 0.6 %.
    c, t3 = paper_crystal(name), data.TABLE3[name]
    ft = fracture(c, None, "tension", "eq16", "printed")
    fc = fracture(c, None, "compression", "eq16", "printed")
    assert ft.Y1c == pytest.approx(t3.Y_t, rel=0.02)
    assert fc.Y1c == pytest.approx(t3.Y_c, rel=0.02)
    assert ft.K1c / 1e6 == pytest.approx(t3.K_t, rel=0.02)
    assert fc.K1c / 1e6 == pytest.approx(t3.K_c, rel=0.02)


@pytest.mark.parametrize("name", data.MATERIALS)
def test_table3_K_follows_from_its_Y(name):
    # K_1c = sqrt(Y_1c E) applied to the printed Y columns reproduces the printed K columns to
    # 0.1 % (their 3-5 printed digits): the relation and E of Table 2 are what the paper used.
    t3, E = data.TABLE3[name], data.TABLE2[name].E2 * 1e9
    assert fracture_toughness(t3.Y_t, E) / 1e6 == pytest.approx(t3.K_t, rel=1e-3)
    assert fracture_toughness(t3.Y_c, E) / 1e6 == pytest.approx(t3.K_c, rel=1e-3)


def test_eq16_with_the_printed_factor():
    # Diamond, tension: gamma = 0.22195e-2 / 0.1456 * 7.78605e2 N/m = 11.869 N/m, by hand from the
    # printed numbers; our SI route uses CODATA Ry/bohr^2 (0.02 % lower), hence rel 5e-4.
    dphi = 0.22195e-2 * data.RY_PER_BOHR2
    assert surface_energy_eq16(dphi, 0.1456) == pytest.approx(0.22195e-2 / 0.1456 * 7.78605e2, rel=5e-4)


def test_eq15_is_the_energy_change_and_eq16_divides_it_by_e():
    # With the reference measure int_{d0}^{dmax} sigma du = Phi(dmax) - Phi(d0) exactly, so
    # eq. (16) with the law's Delta Phi is eq. (15) / e**: the factor the report flags.
    c = paper_crystal("SiC")
    law = calibrate(c, "cutoff", "reference")
    for side, e in (("tension", c.e_t), ("compression", c.e_c)):
        f15 = fracture(c, law, side, "eq15")
        f16 = fracture(c, law, side, "eq16", "law")
        assert f15.gamma == pytest.approx(abs(f15.delta_phi), rel=1e-9)
        assert f16.gamma == pytest.approx(f15.gamma / e, rel=1e-9)
        assert f15.K1c == pytest.approx(math.sqrt(2 * f15.gamma * c.E), rel=1e-12)


def test_bad_fracture_requests():
    c = paper_crystal("C")
    with pytest.raises(ValueError):
        fracture(c, None, "shear")
    with pytest.raises(ValueError):
        fracture(c, None, "tension", "eq15")  # eq. (15) needs the law
    with pytest.raises(ValueError):
        surface_energy_eq16(1.0, 0.0)
