"""Empirical ballistic-limit laws of Part IV, section 3, eqs. (7)-(9), and their constants.

    V_cr^2 = C1 rho_t h_t / P                                    (7)
    V_cr^2 = C2 rho_t h_t / P (HV delta_H)_t                     (8)
    V_cr^2 = C3 rho_t h_t / P (HV delta_H)_t / (HV delta_H)_p    (9)

P is the projectile's areal mass m_p / (pi d_p^2 / 4) in kg/m^2, not a pressure (errata 26);
for a cylinder P = rho_p L_p and rho_t h_t / P is the alpha of eq. (5'), giving (7')-(9').

Units (SI inside): C1, C3 in m^2/s^2; C2 in m^3/kg, i.e. (m/s)^2 per Pa of (HV delta_H)_t.
The paper's C2 = 0.79e6 is in (m/s)^2/GPa (= 7.9e-4 m^3/kg), not "m/kg" (errata 26).

Composite targets: V_comp^2 = V_cer^2 + V_back^2 (section 3).  Critical areal density and
thickness for a projectile and a striking velocity (section 4, Table 4): eq. (9) solved for
rho_t h_t.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

__all__ = [
    "EmpiricalConstants",
    "PAPER_CONSTANTS",
    "GPA",
    "areal_mass",
    "areal_mass_cylinder",
    "vcr_eq7",
    "vcr_eq8",
    "vcr_eq9",
    "composite_vcr",
    "critical_areal_density",
    "critical_thickness",
    "critical_areal_density_composite",
    "FitSample",
    "FitResult",
    "fit_constants",
    "FIT_METHODS",
]

GPA = 1e9


@dataclass(frozen=True)
class EmpiricalConstants:
    """C1 [m^2/s^2], C2 [m^3/kg = (m/s)^2/Pa], C3 [m^2/s^2] of eqs. (7)-(9)."""

    C1: float
    C2: float
    C3: float

    @property
    def C2_per_GPa(self) -> float:
        """C2 in (m/s)^2/GPa, the unit in which the paper quotes 0.79e6 (errata 26)."""
        return self.C2 * GPA

    def to_json(self) -> dict:
        return {"C1_m2_per_s2": self.C1, "C2_m3_per_kg": self.C2,
                "C2_m2_per_s2_per_GPa": self.C2_per_GPa, "C3_m2_per_s2": self.C3}


# Part IV, section 3: C1 = 1.52e6 m^2/s^2, C2 = 0.79e6 (m/s)^2/GPa, C3 = 1.69e6 m^2/s^2.
PAPER_CONSTANTS = EmpiricalConstants(C1=1.52e6, C2=0.79e6 / GPA, C3=1.69e6)


def areal_mass(m_p, d_p):
    """P = m_p / (pi d_p^2 / 4) [kg/m^2], the projectile's areal mass (Part IV after eq. (9),
    errata item 26)."""
    return m_p / (math.pi * d_p**2 / 4.0)


def areal_mass_cylinder(rho_p, L_p):
    """P = rho_p L_p [kg/m^2]: the areal mass of a cylinder, as used to write (7')-(9')."""
    return rho_p * L_p


def vcr_eq7(rho_t, h_t, P, C1=PAPER_CONSTANTS.C1):
    """V_cr = sqrt(C1 rho_t h_t / P) (Part IV, eq. (7)) [m/s]."""
    return np.sqrt(C1 * rho_t * h_t / P)[()]


def vcr_eq8(rho_t, h_t, P, HVdelta_t, C2=PAPER_CONSTANTS.C2):
    """V_cr = sqrt(C2 rho_t h_t / P (HV delta_H)_t) (Part IV, eq. (8)); (HV delta_H)_t in Pa."""
    return np.sqrt(C2 * rho_t * h_t / P * HVdelta_t)[()]


def vcr_eq9(rho_t, h_t, P, HVdelta_t, HVdelta_p, C3=PAPER_CONSTANTS.C3):
    """V_cr = sqrt(C3 rho_t h_t / P (HV delta_H)_t / (HV delta_H)_p) (Part IV, eq. (9))."""
    return np.sqrt(C3 * rho_t * h_t / P * HVdelta_t / HVdelta_p)[()]


def composite_vcr(*layer_limits):
    """V_comp = sqrt(sum V_i^2) for a layered target, e.g. ceramic + back plate
    (Part IV, section 3: V_comp^2 = V_cer^2 + V_back^2)."""
    return float(np.sqrt(np.sum(np.square(layer_limits))))


def critical_areal_density(V, P, HVdelta_t, HVdelta_p, C3=PAPER_CONSTANTS.C3):
    """(rho_t h_t)_cr = V^2 P (HV delta_H)_p / (C3 (HV delta_H)_t) [kg/m^2]: eq. (9) solved for
    the areal density that stops a projectile of areal mass P striking at V (Table 4)."""
    return np.asarray(V, dtype=float) ** 2 * P * HVdelta_p / (C3 * HVdelta_t)


def critical_thickness(V, P, HVdelta_t, HVdelta_p, rho_t, C3=PAPER_CONSTANTS.C3):
    """h_t,cr = (rho_t h_t)_cr / rho_t [m] (Part IV, Table 4)."""
    return critical_areal_density(V, P, HVdelta_t, HVdelta_p, C3) / rho_t


def critical_areal_density_composite(V, P, layers: Sequence[tuple[float, float]], HVdelta_p,
                                     C3=PAPER_CONSTANTS.C3):
    """Total critical areal density of a layered target whose layers share it in fixed ratios.

    ``layers`` = [((HV delta_H)_i, share_i), ...] with the shares of the total areal density
    (normalised here).  From V^2 = sum_i V_i^2 and eq. (9) for each layer:
    (rho h)_total = V^2 P (HV delta_H)_p / (C3 sum_i share_i (HV delta_H)_i).
    Table 4's "3:1" composite is SiC and an AMG5 back at 3:1 by areal density (errata 27).
    """
    shares = np.array([s for _, s in layers], dtype=float)
    hard = np.array([h for h, _ in layers], dtype=float)
    if np.any(shares < 0) or not shares.sum() > 0:
        raise ValueError("layer shares must be non-negative and not all zero")
    mean_hard = float(np.dot(shares, hard) / shares.sum())
    return np.asarray(V, dtype=float) ** 2 * P * HVdelta_p / (C3 * mean_hard)


# ------------------------------------------------------------------------------------ fitting


@dataclass(frozen=True)
class FitSample:
    """One measured shot for refitting: target rho_t [kg/m^3], h_t [m], projectile areal mass
    P [kg/m^2], (HV delta_H)_t and (HV delta_H)_p [Pa], measured V_cr [m/s]."""

    name: str
    rho_t: float
    h_t: float
    P: float
    HVdelta_t: float
    HVdelta_p: float
    V: float


@dataclass(frozen=True)
class FitResult:
    """Refitted constants, the method and per-law errors of V_cr over the samples
    (relative, (V_fit - V_meas) / V_meas)."""

    constants: EmpiricalConstants
    method: str
    n: int
    rms_error: tuple[float, float, float]
    max_error: tuple[float, float, float]
    residuals: tuple[tuple[str, float, float, float], ...]

    def to_json(self) -> dict:
        return {
            "method": self.method,
            "n": self.n,
            **self.constants.to_json(),
            "rms_relative_error_V": {"eq7": self.rms_error[0], "eq8": self.rms_error[1], "eq9": self.rms_error[2]},
            "max_relative_error_V": {"eq7": self.max_error[0], "eq8": self.max_error[1], "eq9": self.max_error[2]},
            "rows": [{"name": n, "error_eq7": a, "error_eq8": b, "error_eq9": c} for n, a, b, c in self.residuals],
        }


FIT_METHODS = ("mean", "least-squares")


def fit_constants(samples: Iterable[FitSample], method: str = "mean") -> FitResult:
    """Refit C1, C2, C3 of eqs. (7)-(9) from measured shots.

    Each law reads V^2 = C x with x_1 = rho_t h_t/P, x_2 = x_1 (HV delta)_t,
    x_3 = x_2 / (HV delta)_p.  ``mean``: C = arithmetic mean of V_i^2 / x_i (the paper's rule,
    "determination of average arithmetic value"); ``least-squares``: C minimising
    sum (V_i^2 - C x_i)^2, i.e. C = sum x_i V_i^2 / sum x_i^2.
    """
    samples = list(samples)
    if method not in FIT_METHODS:
        raise ValueError(f"method must be one of {FIT_METHODS}; got {method!r}")
    if not samples:
        raise ValueError("no samples with a measured V_cr to fit")
    x1 = np.array([s.rho_t * s.h_t / s.P for s in samples])
    x2 = x1 * np.array([s.HVdelta_t for s in samples])
    x3 = x2 / np.array([s.HVdelta_p for s in samples])
    y = np.array([s.V for s in samples]) ** 2
    consts = []
    for x in (x1, x2, x3):
        consts.append(float(np.mean(y / x)) if method == "mean" else float(np.dot(x, y) / np.dot(x, x)))
    errs = [np.sqrt(c * x / y) - 1.0 for c, x in zip(consts, (x1, x2, x3))]
    return FitResult(
        constants=EmpiricalConstants(*consts),
        method=method,
        n=len(samples),
        rms_error=tuple(float(np.sqrt(np.mean(e**2))) for e in errs),
        max_error=tuple(float(e[np.argmax(np.abs(e))]) for e in errs),
        residuals=tuple((s.name, float(errs[0][i]), float(errs[1][i]), float(errs[2][i])) for i, s in enumerate(samples)),
    )
