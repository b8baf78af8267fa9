"""Plasticity characteristic delta_H from an indentation test (Part IV, section 5, eqs. (10)-(14)).

delta_H = eps_p / eps_t = 1 - eps_e / eps_t (10), the share of plastic strain in the total
strain under a pyramidal indenter, with

    eps_e = HM (1 - nu_1 - 2 nu_1^2) / E_1                          (11)
    eps_p = -ln(sin gamma_2)                                         (12)
    cot(gamma_2) = cot(gamma_1) - 1.77 HM / E_ef                     (13)
    1/E_ef = (1 - nu_1^2)/E_1 + (1 - nu_2^2)/E_2                     (14)

(1: specimen, 2: indenter; gamma_1 the indenter's face-to-axis angle, 68 deg for Vickers).
HM is the Meyer hardness; from a Vickers number HM = HV / sin(68 deg) (errata item 25).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from semianalytic.ballistic_limit.theory import VICKERS_HALF_ANGLE, meyer_hardness

__all__ = [
    "Indenter",
    "VICKERS_DIAMOND",
    "effective_modulus",
    "elastic_strain",
    "indentation_angle",
    "plastic_strain",
    "plasticity_characteristic",
    "plasticity_from_vickers",
]


@dataclass(frozen=True)
class Indenter:
    """A pyramidal indenter: face-to-axis angle gamma_1 [rad], Young's modulus E_2 [Pa] and
    Poisson ratio nu_2 (Part IV, eqs. (13)-(14))."""

    name: str
    half_angle: float
    youngs_modulus: float
    poisson_ratio: float

    def __post_init__(self):
        if not 0.0 < self.half_angle < math.pi / 2:
            raise ValueError(f"indenter half_angle must lie in (0, pi/2) rad; got {self.half_angle!r}")
        if not self.youngs_modulus > 0:
            raise ValueError(f"indenter youngs_modulus must be positive; got {self.youngs_modulus!r}")
        if not -1.0 < self.poisson_ratio < 0.5:
            raise ValueError(f"indenter poisson_ratio must lie in (-1, 0.5); got {self.poisson_ratio!r}")


# Diamond Vickers pyramid: 136 deg between opposite faces; E = 1140 GPa, nu = 0.07 are the
# values commonly used for diamond indenters (Oliver & Pharr, J. Mater. Res. 7 (1992) 1564).
VICKERS_DIAMOND = Indenter("Vickers diamond", VICKERS_HALF_ANGLE, 1140e9, 0.07)


def effective_modulus(E1, nu1, E2, nu2):
    """E_ef of the specimen-indenter pair: 1/E_ef = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 (eq. (14))."""
    return 1.0 / ((1.0 - nu1**2) / E1 + (1.0 - nu2**2) / E2)


def elastic_strain(HM, E1, nu1):
    """eps_e = HM (1 - nu1 - 2 nu1^2) / E1 (Part IV, eq. (11))."""
    return HM * (1.0 - nu1 - 2.0 * nu1**2) / E1


def indentation_angle(HM, E_ef, gamma_1):
    """gamma_2 from cot(gamma_2) = cot(gamma_1) - 1.77 HM / E_ef (Part IV, eq. (13)) [rad]."""
    cot2 = 1.0 / np.tan(gamma_1) - 1.77 * np.asarray(HM, dtype=float) / E_ef
    return (np.pi / 2 - np.arctan(cot2))[()]


def plastic_strain(gamma_2):
    """eps_p = -ln(sin gamma_2) (Part IV, eq. (12))."""
    return (-np.log(np.sin(gamma_2)))[()]


def plasticity_characteristic(HM, E1, nu1, indenter: Indenter = VICKERS_DIAMOND):
    """delta_H = 1 - eps_e / (eps_p + eps_e) (Part IV, eq. (10)) for a specimen of Meyer
    hardness HM, modulus E1 and Poisson ratio nu1 [Pa], indented by ``indenter``."""
    E_ef = effective_modulus(E1, nu1, indenter.youngs_modulus, indenter.poisson_ratio)
    eps_e = elastic_strain(HM, E1, nu1)
    eps_p = plastic_strain(indentation_angle(HM, E_ef, indenter.half_angle))
    return (1.0 - eps_e / (eps_p + eps_e))[()]


def plasticity_from_vickers(HV, E1, nu1, indenter: Indenter = VICKERS_DIAMOND):
    """delta_H from a Vickers hardness HV [Pa], with HM = HV / sin(68 deg) (errata 25)."""
    return plasticity_characteristic(meyer_hardness(HV), E1, nu1, indenter)
