"""Projectile strength from its hardness: Rockwell C -> Vickers -> yield stress.

Two published steps, no fitted constant of this project:

1. Rockwell C hardness HRC -> Vickers hardness HV: ASTM E140-12b (reapproved 2019), "Standard
   Hardness Conversion Tables for Metals", Table 1 (non-austenitic steels), the HRC 20-68 rows
   (:data:`E140_HRC_HV`); linear interpolation between integer rows.  Outside 20-68 HRC the
   table gives no value and the conversion refuses (``InputError``).
2. Vickers hardness -> static (quasi-static tensile) yield stress: Pavlina & Van Tyne (2008),
   "Correlation of yield strength and tensile strength with hardness for steels",
   J. Mater. Eng. Perform. 17:888-893, eq. (4):  sigma_y = -90.7 + 2.876 HV  [MPa]
   (fitted on 150 non-austenitic steels, HV 106-692; standard error about 100 MPa); and eq. (5)
   for the ultimate tensile strength, sigma_uts = -99.8 + 3.734 HV [MPa].

The dynamic yield stress of the projectile is ``dynamic_factor`` times this static value
(:func:`dynamic_yield_stress`); the factor is an input, stated with its source in the case
(its default is chosen by transfer in reports/validation_regimes.md).

Check (independent of the code): the data of Piekutowski et al. (1999) give VAR 4340 at Rc 38
with a tensile yield of 1140 MPa and AerMet 100 at Rc 53 with 1720 MPa; this conversion gives
979 and 1520 MPa (-14 % and -12 %, inside the 2-sigma scatter of Pavlina & Van Tyne's fit).
"""

from __future__ import annotations

import math

import numpy as np

from semianalytic.ballistic_limit.theory import VICKERS_HALF_ANGLE  # the one home of the 68-degree constant
from semianalytic.ballistic_limit.theory import meyer_hardness as meyer_from_vickers_number  # HM = HV / sin 68 deg
from semianalytic.errors import InputError

__all__ = ["E140_HRC_HV", "HRC_RANGE", "DEFAULT_DYNAMIC_FACTOR", "vickers_from_rockwell_c", "yield_stress_from_vickers",
           "yield_stress_from_hardness", "ultimate_strength_from_vickers", "vickers_from_yield_stress", "meyer_hardness_from_vickers", "meyer_from_vickers_number",  # noqa: E501
           "VICKERS_HALF_ANGLE", "dynamic_yield_stress", "parse_hardness"]

# ASTM E140, Table 1: HRC -> HV (non-austenitic steels), HRC 20..68
E140_HRC_HV = (
    (20, 238), (21, 243), (22, 248), (23, 254), (24, 260), (25, 266), (26, 272), (27, 279), (28, 286),
    (29, 294), (30, 302), (31, 310), (32, 318), (33, 327), (34, 336), (35, 345), (36, 354), (37, 363),
    (38, 372), (39, 382), (40, 392), (41, 402), (42, 412), (43, 423), (44, 434), (45, 446), (46, 458),
    (47, 471), (48, 484), (49, 498), (50, 513), (51, 528), (52, 544), (53, 560), (54, 577), (55, 595),
    (56, 613), (57, 633), (58, 653), (59, 674), (60, 697), (61, 720), (62, 746), (63, 772), (64, 800),
    (65, 832), (66, 865), (67, 900), (68, 940),
)
HRC_RANGE = (20.0, 68.0)
# dynamic / static yield stress when [projectile] dynamic_factor is not given: the posterior medians of
# the regime model's dynamic factor on Piekutowski et al. (1999) are 1.40 (AerMet 100) and 1.53 (VAR 4340),
# each transferring to the other steel (reports/validation_regimes.md)
DEFAULT_DYNAMIC_FACTOR = 1.5
_HRC = np.array([r[0] for r in E140_HRC_HV], float)
_HV = np.array([r[1] for r in E140_HRC_HV], float)


def vickers_from_rockwell_c(hrc, field: str = "projectile.hardness"):
    """HV from HRC by ASTM E140, Table 1 (module docstring), linear between rows; vectorised.
    Raises InputError naming ``field`` outside 20-68 HRC (the table's range)."""
    h = np.asarray(hrc, float)
    if np.any(~np.isfinite(h)) or np.any(h < HRC_RANGE[0]) or np.any(h > HRC_RANGE[1]):
        bad = h[~(np.isfinite(h) & (h >= HRC_RANGE[0]) & (h <= HRC_RANGE[1]))].ravel()[0]
        raise InputError(field, f"{bad:g} HRC is outside the range of the hardness conversion (ASTM E140, Table 1: "
                                f"{HRC_RANGE[0]:g}-{HRC_RANGE[1]:g} HRC)")
    return np.interp(h, _HRC, _HV)[()]


def yield_stress_from_vickers(hv):
    """Static yield stress [Pa] from HV: Pavlina & Van Tyne (2008), J. Mater. Eng. Perform.
    17:888, eq. (4), sigma_y = -90.7 + 2.876 HV [MPa]."""
    return (-90.7 + 2.876 * np.asarray(hv, float))[()] * 1e6


def vickers_from_yield_stress(sigma_y):
    """HV from the static yield stress [Pa]: Pavlina & Van Tyne (2008), eq. (4) inverted,
    HV = (sigma_y [MPa] + 90.7) / 2.876 (the inverse of :func:`yield_stress_from_vickers`)."""
    return ((np.asarray(sigma_y, float) / 1e6 + 90.7) / 2.876)[()]


def ultimate_strength_from_vickers(hv):
    """Static ultimate tensile strength [Pa] from HV: Pavlina & Van Tyne (2008), J. Mater. Eng.
    Perform. 17:888, eq. (5), sigma_uts = -99.8 + 3.734 HV [MPa]."""
    return (-99.8 + 3.734 * np.asarray(hv, float))[()] * 1e6


VICKERS_MEYER_RATIO = math.sin(VICKERS_HALF_ANGLE)
"""HV / Meyer hardness of the Vickers pyramid (136 deg between faces, d the indent's diagonal):
HV = F / (contact surface, d^2 / (2 sin 68 deg)), Meyer hardness = F / (projected area, d^2 / 2),
so H_M = HV / sin 68 deg = 1.0785 HV (Tabor 1951, The Hardness of Metals, ch. 1 and 6; ISO 6507-1 for the definition of HV)."""
KGF_MM2 = 9.80665e6  # 1 kgf/mm^2 in Pa (HV is stated in kgf/mm^2)


def meyer_hardness_from_vickers(hv):
    """Meyer hardness [Pa] (the mean contact pressure over the projected area at which a steel
    indents plastically) from HV: H_M = HV x 9.80665 MPa / sin 68 deg (:data:`VICKERS_MEYER_RATIO`,
    Tabor 1951).  Tabor's point is that this pressure, about 3 times the flow stress, is itself the
    resistance of the surface to plastic indentation, so no strength conversion enters."""
    return (np.asarray(meyer_from_vickers_number(hv), float) * KGF_MM2)[()]


def yield_stress_from_hardness(hrc, field: str = "projectile.hardness"):
    """Static yield stress [Pa] of a steel of Rockwell C hardness ``hrc`` (ASTM E140 Table 1,
    then Pavlina & Van Tyne 2008, eq. (4)); vectorised."""
    return yield_stress_from_vickers(vickers_from_rockwell_c(hrc, field))


def dynamic_yield_stress(hrc, dynamic_factor: float, field: str = "projectile.hardness"):
    """Y_p = dynamic_factor x static yield stress from the hardness [Pa]."""
    if not (math.isfinite(dynamic_factor) and dynamic_factor >= 1.0):
        raise InputError("projectile.dynamic_factor", f"must be >= 1 (the dynamic yield stress is not below the "
                                                      f"static one); got {dynamic_factor!r}")
    return dynamic_factor * yield_stress_from_hardness(hrc, field)


def parse_hardness(text, field: str = "projectile.hardness") -> float:
    """'39.5 HRC' (or 'HRC 39.5', 'Rc 39.5', '39.5 Rc') -> 39.5.  Raises InputError naming
    ``field`` for anything else (only the Rockwell C scale is converted)."""
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        raise InputError(field, f"give the scale with the number, e.g. '{text} HRC'")
    s = str(text).strip().replace("_", " ")
    parts = s.split()
    units = {"hrc", "rc"}
    num = None
    if len(parts) == 2 and parts[1].lower() in units:
        num = parts[0]
    elif len(parts) == 2 and parts[0].lower() in units:
        num = parts[1]
    try:
        value = float(num) if num is not None else math.nan
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise InputError(field, f"expected a Rockwell C hardness such as '39.5 HRC'; got {text!r}")
    vickers_from_rockwell_c(value, field)  # range check
    return value
