"""Every printed V_cr of Part IV Tables 2 and 3 and every cell of Table 4, recomputed.

The reference is the paper's printed number (independent of this code).  Rows that errata
items 25-27 show to be inconsistent are known deviations: for them the test checks the
errata's explanation instead, and that the row really does miss (so the mark cannot go stale).

Tolerances (stated once, not tuned per row):
- Table 2, 1.5 % in V: errata 25 finds all 27 values "within about 1 %" once the R column is
  read correctly; the paper evidently carried digits it did not print.  Every wrong reading
  misses by far more (R(2)/R(3) swapped: 4-9 %; HM vs HV in R(1): 3.7-4.9 %).
- Table 3, 2 % in V: the same 4.8 g / 26 mm core implies areal masses from 207 to 210 kg/m^2
  in different rows (a 1.5 % spread in the paper's own arithmetic, 2-3.5 % above
  rho_p L_p = 202.8), i.e. up to 1.8 % in V; any other P rule misses by 15-40 %.
- Table 4, 1 % + half a unit of the printed last digit (0.05), plus the half-unit rounding of
  the printed rho_t for h: (HV delta_H)_t is printed to 2-3 digits (0.6 %) and C3 to 3 (0.3 %).
"""

from dataclasses import replace

import pytest

from semianalytic.ballistic_limit.empirical import composite_vcr, fit_constants, vcr_eq9
from semianalytic.ballistic_limit.paper import (
    P3_SOFT_PROJECTILE_HVDELTA,
    fit_samples,
    implied_areal_mass,
    implied_modulus,
    table2_paper,
    table3_paper,
    table4_paper,
)
from semianalytic.ballistic_limit.shots import empirical_limits, theoretical_limits
from semianalytic.ballistic_limit.tables import load_table2, load_table3, load_table4
from semianalytic.ballistic_limit.theory import resistance_part4

TOL2, TOL3, TOL4 = 0.015, 0.02, 0.01
GPa = 1e9
T2 = {r.material: r for r in load_table2()}
T3 = {r.id: r for r in load_table3()}
T4 = load_table4()


def rel(a, b):
    return abs(a / b - 1)


# ------------------------------------------------------------------------------- Table 2


@pytest.mark.parametrize("name", list(T2))
def test_table2_row_reproduces(name):
    row = T2[name]
    for k, (calc, printed) in enumerate(zip(table2_paper(row), row.printed), start=1):
        assert rel(calc, printed) < TOL2, f"{name} V({k}): {calc:.1f} vs printed {printed}"


def test_table2_other_readings_miss():
    """The errata-25 reading is the one that works: the literal headings miss."""
    r = T2["8112"]
    literal_R3 = theoretical_limits(replace(r.shot, resistance_R3=r.R_column), "meyer")
    assert rel(literal_R3["V_R3_m_s"], r.printed[2]) > 0.04
    soft = T2["6112"]
    assert rel(theoretical_limits(soft.shot, "meyer")["V_R1_m_s"], soft.printed[0]) > 0.03


def test_table2_known_deviation_steel45_column():
    """Errata 25: Steel 45's column is Steel 40's R(3) (Y = 0.4 GPa) times delta_H, not eq. (6)
    with its own Y = 0.5 GPa (E = 200 GPa, as the Steel 40 column implies)."""
    s45, s40 = T2["Steel 45"], T2["Steel 40"]
    R3_from_column = s45.R_column / s45.shot.target_delta_H
    assert R3_from_column == pytest.approx(s40.R_column / s40.shot.target_delta_H, rel=1e-3)
    assert R3_from_column == pytest.approx(resistance_part4(0.4 * GPa, 200 * GPa), rel=1e-3)
    assert rel(R3_from_column, resistance_part4(0.5 * GPa, 200 * GPa)) > 0.1


def test_table2_known_deviation_ti_column():
    """New finding: the Ti-alloy column (2.849 GPa) cannot come from eq. (6) with Y = 1.0 GPa and
    a titanium modulus: read as R(2) it implies E = 22 GPa, as R(3) E = 13 GPa (Ti: ~110 GPa).
    The steel rows, for comparison, imply 200-211 GPa read as R(2)."""
    as_R3, as_R2 = implied_modulus(T2["Ti-alloy"])
    assert as_R2 < 30 * GPa and as_R3 < 30 * GPa
    for steel in ("Steel 40", "High hardness steel"):
        assert 190 * GPa < implied_modulus(T2[steel])[1] < 215 * GPa


# ------------------------------------------------------------------------------- Table 3

DERIVABLE = [k for k, r in T3.items() if r.paper_rule != "not-derivable"]
NOT_DERIVABLE = [k for k, r in T3.items() if r.paper_rule == "not-derivable"]
KNOWN = {("SiC+P3", 2)}  # errata 27: V(9) of SiC + P3 uses the soft-steel (HV delta)_p for the back


@pytest.mark.parametrize("rid", DERIVABLE)
def test_table3_row_reproduces(rid):
    row = T3[rid]
    calc = table3_paper(row)
    for k, (c, printed) in enumerate(zip(calc, row.printed)):
        if (rid, k) in KNOWN:
            continue
        assert rel(c, printed) < TOL3, f"{rid} eq. ({7 + k}): {c:.1f} vs printed {printed}"


def test_table3_known_deviation_sic_p3():
    row = T3["SiC+P3"]
    assert rel(table3_paper(row)[2], row.printed[2]) > TOL3
    cer, back = row.shot.layers
    P = 7800 * 0.026
    v = composite_vcr(vcr_eq9(cer.density, cer.thickness, P, cer.HVdelta, row.shot.HVdelta_p),
                      vcr_eq9(back.density, back.thickness, P, back.HVdelta, P3_SOFT_PROJECTILE_HVDELTA))
    assert rel(v, row.printed[2]) < TOL3


def test_table3_known_deviation_sic_6mm_repeats_8mm():
    """Errata 27: the SiC 6 mm row prints the 8 mm row's numbers (its own recomputed values
    happen to lie within 1 % of them)."""
    assert T3["SiC-6mm"].printed == T3["SiC-8mm"].printed
    assert table3_paper(T3["SiC-6mm"]) != pytest.approx(table3_paper(T3["SiC-8mm"]), rel=0.01)


@pytest.mark.parametrize("rid", NOT_DERIVABLE)
def test_table3_known_deviation_not_derivable(rid):
    """Errata 26: the 30.1 g and 2.3 g core rows use an areal mass that neither
    m/(pi d^2/4) nor rho_p L_p gives; the three printed laws agree on one value of P."""
    row = T3[rid]
    for rule in ("mass-per-area", "cylinder"):
        v = empirical_limits(row.shot, rule=rule)
        assert rel(v["V_eq7_m_s"], row.printed[0]) > 0.1, rule
    P7, P8, P9 = implied_areal_mass(row)
    # three printed 3-digit values: each P to ~0.3 %, so they agree to 1 %
    assert P8 == pytest.approx(P7, rel=0.01) and P9 == pytest.approx(P7, rel=0.01)
    expected = 323.0 if row.shot.projectile_mass == pytest.approx(30.1e-3) else 121.0
    assert P7 == pytest.approx(expected, rel=0.01)


def test_table3_p2_used_the_48g_core():
    """Errata 27: P2 as listed (2.3 g / 12.5 mm) misses; with the 4.8 g / 26 mm core it reproduces
    (checked in test_table3_row_reproduces)."""
    row = T3["P2"]
    for rule in ("mass-per-area", "cylinder"):
        assert rel(empirical_limits(row.shot, rule=rule)["V_eq7_m_s"], row.printed[0]) > 0.3


def test_refit_reproduces_paper_constants():
    """Errata 26: arithmetic means over the 12 single-target rows with a measured V_cr, each with
    the areal mass the paper used, give C1 = 1.52e6, C2 = 0.79e6 (per GPa), C3 = 1.69e6
    (half a unit of the printed last digit)."""
    samples = fit_samples(T3.values(), "paper-implied")
    assert len(samples) == 12
    c = fit_constants(samples, "mean").constants
    assert c.C1 == pytest.approx(1.52e6, abs=0.005e6)
    assert c.C2_per_GPa == pytest.approx(0.79e6, abs=0.005e6)
    assert c.C3 == pytest.approx(1.69e6, abs=0.005e6)


# ------------------------------------------------------------------------------- Table 4


def _half_unit(text: str) -> float:
    return 0.5 * 10 ** -(len(text.split(".")[1]) if "." in text else 0)


@pytest.mark.parametrize("block", ["soft-26", "hard-26", "hard-51.6"])
def test_table4_cells(block):
    checked = 0
    for cell in (c for c in T4 if c.block == block):
        rhoh, h, comp = table4_paper(cell)
        rho_round = _half_unit(cell.rho_t_text) / float(cell.rho_t_text)
        # g/cm^2 and mm as printed
        assert abs(rhoh / 10 - float(cell.rhoh_text)) <= TOL4 * float(cell.rhoh_text) + _half_unit(cell.rhoh_text), cell
        h_tol = (TOL4 + rho_round) * float(cell.h_text) + _half_unit(cell.h_text)
        if cell.note:  # known deviation: Steel 40, soft projectile, 700 m/s (errata 27: 6.8, not 7.6)
            assert abs(h * 1e3 - float(cell.h_text)) > h_tol
            assert h * 1e3 == pytest.approx(6.8, abs=0.05)
        else:
            assert abs(h * 1e3 - float(cell.h_text)) <= h_tol, cell
        if cell.composite_text:
            c = float(cell.composite_text)
            assert abs(comp / 10 - c) <= TOL4 * c + _half_unit(cell.composite_text), cell
            checked += 1
        checked += 2
    assert checked == {"soft-26": 60, "hard-26": 62, "hard-51.6": 62}[block]
