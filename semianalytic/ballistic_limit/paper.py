"""The paper's own arithmetic behind Tables 2-4 of Part IV, as errata items 25-27 explain it,
beside the consistent (corrected) computation.

Table 2 (errata 25): V(1) with HM = HV/sin(68 deg) except the three soft-Al rows (HM = HV); the
column headed R(3) holds R(3) for 6112 and both AMG5 rows and R(2) = R(3) delta_H for the
others.  Table 3 (errata 26-27): three rules for the areal mass P (m/(pi d^2/4), rho_p L_p,
and values that cannot be derived for the 30.1 g and 2.3 g cores); the P2 row used the
4.8 g / 26 mm core.  Table 4: eq. (9) with P = rho_p L_p; the "3:1" composite is SiC with an
AMG5 back at 3:1 by areal density.
"""

from __future__ import annotations

import math
from dataclasses import replace

from semianalytic.ballistic_limit.empirical import (
    PAPER_CONSTANTS,
    EmpiricalConstants,
    areal_mass,
    areal_mass_cylinder,
    critical_areal_density,
    critical_areal_density_composite,
)
from semianalytic.ballistic_limit.shots import (
    AREAL_MASS_RULES,
    empirical_limits,
    fit_sample,
    is_fittable,
    projectile_areal_mass,
    theoretical_limits,
)
from semianalytic.ballistic_limit.tables import Table2Row, Table3Row, Table4Cell

__all__ = [
    "table2_paper",
    "table2_from_yield",
    "implied_modulus",
    "table3_paper",
    "table3_consistent",
    "implied_areal_mass",
    "fit_samples",
    "table4_paper",
    "TABLE4_COMPOSITE_BACK_HVDELTA",
    "TABLE4_COMPOSITE_SHARES",
    "P3_SOFT_PROJECTILE_HVDELTA",
]

GPa = 1e9
# Table 4's "3:1" composite (errata 27): AMG5 back, (HV delta_H) = 0.8 x 0.93 GPa, 3:1 by areal density.
TABLE4_COMPOSITE_BACK_HVDELTA = 0.8 * 0.93 * GPa
TABLE4_COMPOSITE_SHARES = (3.0, 1.0)
# Errata 27: SiC + P3, V(3) = 606 m/s uses the soft-steel (HV delta_H)_p = 1.8 x 0.93 GPa for the back plate.
P3_SOFT_PROJECTILE_HVDELTA = 1.8 * 0.93 * GPa
CORE_4_8G_26MM = 0.026  # m, L_p of the 4.8 g core (errata 27, row P2)


def table2_paper(row: Table2Row) -> tuple[float, float, float]:
    """V(1), V(2), V(3) of a Table 2 row by eq. (5) as the paper computed them (errata 25):
    R(1) with the row's hardness rule, R(3) read from the printed column per ``column_holds``."""
    v = theoretical_limits(row.shot, row.hardness_in_R1)
    return v["V_R1_m_s"], v["V_R2_m_s"], v["V_R3_m_s"]


def table2_from_yield(row: Table2Row) -> tuple[float, float, float]:
    """V(1), V(2), V(3) computed consistently: HM = HV/sin(68 deg) for every row and R(3) from
    the printed Y = sigma_0.2 with the assumed (handbook, not printed) E, eq. (6)."""
    shot = replace(row.shot, resistance_R3=None, youngs_modulus=row.E_assumed)
    v = theoretical_limits(shot, "meyer")
    return v["V_R1_m_s"], v["V_R2_m_s"], v["V_R3_m_s"]


def implied_modulus(row: Table2Row) -> tuple[float, float]:
    """E [Pa] that makes eq. (6) with the printed Y reproduce the printed column, reading it as
    R(3) and as R(2) = R(3) delta_H: E = (3Y/2) exp(R/Y - 2/3)."""
    Y = row.shot.yield_stress
    as_R3 = 1.5 * Y * math.exp(row.R_column / Y - 2.0 / 3.0)
    as_R2 = 1.5 * Y * math.exp(row.R_column / row.shot.target_delta_H / Y - 2.0 / 3.0)
    return as_R3, as_R2


def _paper_areal_mass(row: Table3Row) -> float | None:
    s = row.shot
    if row.paper_rule == "mass-per-area":
        return areal_mass(s.projectile_mass, s.projectile_diameter)
    if row.paper_rule == "cylinder":
        return areal_mass_cylinder(s.projectile_density, s.projectile_length)
    if row.paper_rule == "core-4.8g-26mm":
        return areal_mass_cylinder(s.projectile_density, CORE_4_8G_26MM)
    return None  # not derivable from the printed inputs


def table3_paper(row: Table3Row, constants: EmpiricalConstants = PAPER_CONSTANTS):
    """V by eqs. (7), (8), (9) with the areal mass the paper used for this row (errata 26-27);
    ``None`` where that value cannot be derived from the printed inputs."""
    P = _paper_areal_mass(row)
    if P is None:
        return None
    v = empirical_limits(row.shot, constants, P=P)
    return v["V_eq7_m_s"], v["V_eq8_m_s"], v["V_eq9_m_s"]


def table3_consistent(row: Table3Row, constants: EmpiricalConstants = PAPER_CONSTANTS):
    """V by eqs. (7)-(9) with P = m_p/(pi d_p^2/4) for every row (errata 26)."""
    v = empirical_limits(row.shot, constants, rule="mass-per-area")
    return v["V_eq7_m_s"], v["V_eq8_m_s"], v["V_eq9_m_s"]


def implied_areal_mass(row: Table3Row, constants: EmpiricalConstants = PAPER_CONSTANTS):
    """The areal mass P [kg/m^2] each printed V of a single-plate row implies, from eqs. (7),
    (8), (9) solved for P: (P_7, P_8, P_9).  Consistent rows give three equal values."""
    s = row.shot
    rh = s.target_density * s.thickness
    V7, V8, V9 = row.printed
    return (constants.C1 * rh / V7**2,
            constants.C2 * rh * s.HVdelta_t / V8**2,
            constants.C3 * rh * s.HVdelta_t / s.HVdelta_p / V9**2)


def fit_samples(rows, rule: str = "paper-implied", constants: EmpiricalConstants = PAPER_CONSTANTS):
    """:class:`FitSample` for every single-plate row with a measured V_cr (no "<"/">").

    ``rule``: ``paper-implied`` (P the paper used, back-computed from its printed eq. (7) value:
    how its constants were obtained), ``mass-per-area`` (errata 26) or ``cylinder``.
    """
    out = []
    for row in rows:
        s = row.shot
        if not is_fittable(s):
            continue
        if rule == "paper-implied":
            P = implied_areal_mass(row, constants)[0]
        elif rule in AREAL_MASS_RULES:
            P = projectile_areal_mass(s, rule)
        else:
            raise ValueError(f"unknown areal-mass rule {rule!r}")
        out.append(fit_sample(s, P))
    return out


def table4_paper(cell: Table4Cell, C3: float = PAPER_CONSTANTS.C3):
    """(rho h)_cr [kg/m^2], h_cr [m] and, for SiC, the 3:1 composite (rho h)_cr of a Table 4 cell:
    eq. (9) with P = rho_p L_p and the printed (HV delta_H)_p."""
    P = areal_mass_cylinder(cell.rho_p, cell.L_p)
    HVd_t = cell.HV_t * cell.delta_t
    rhoh = float(critical_areal_density(cell.V, P, HVd_t, cell.HVdelta_p, C3))
    shares = TABLE4_COMPOSITE_SHARES
    comp = float(critical_areal_density_composite(
        cell.V, P, [(HVd_t, shares[0]), (TABLE4_COMPOSITE_BACK_HVDELTA, shares[1])], cell.HVdelta_p, C3))
    return rhoh, rhoh / cell.rho_t, comp
