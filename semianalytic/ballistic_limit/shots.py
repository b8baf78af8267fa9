"""A shot (target plate + projectile) and the ballistic limits Part IV predicts for it.

:class:`Shot` holds what a row of Tables 2-3 (or a case file) gives, in SI units; every field
a law does not need may be ``None``.  :func:`theoretical_limits` evaluates eq. (5) with R(1),
R(2), R(3); :func:`empirical_limits` evaluates eqs. (7)-(9), summing squares over the layers
of a composite target (V_comp^2 = V_cer^2 + V_back^2).
"""

from __future__ import annotations

from dataclasses import dataclass

from semianalytic.ballistic_limit.empirical import (
    PAPER_CONSTANTS,
    EmpiricalConstants,
    FitSample,
    areal_mass,
    areal_mass_cylinder,
    composite_vcr,
    critical_areal_density,
    vcr_eq7,
    vcr_eq8,
    vcr_eq9,
)
from semianalytic.ballistic_limit.theory import ballistic_limit, resistance_part4, resistance_R1

__all__ = ["Layer", "Shot", "AREAL_MASS_RULES", "HARDNESS_RULES", "projectile_areal_mass",
           "theoretical_limits", "empirical_limits", "critical_values", "is_fittable", "fit_sample"]

AREAL_MASS_RULES = ("mass-per-area", "cylinder")
HARDNESS_RULES = ("meyer", "vickers")
PAPER_PROJECTILE_DENSITY = 7800.0  # kg/m^3, "accepted as 7.8 g/cm^3" (Part IV, Table 3)


@dataclass(frozen=True)
class Layer:
    """One plate of a layered target: density [kg/m^3], thickness [m], HV [Pa], delta_H [-]."""

    name: str
    density: float
    thickness: float
    hardness: float
    delta_H: float

    @property
    def HVdelta(self) -> float:
        return self.hardness * self.delta_H


@dataclass(frozen=True)
class Shot:
    """A plate target and a projectile (SI units; ``None`` where not known).

    Target: ``target_density`` rho_t, ``thickness`` h_t, ``target_hardness`` HV_t,
    ``target_delta_H``, ``yield_stress`` Y and ``youngs_modulus`` E (for R(3), eq. (6)), or
    ``resistance_R3`` given directly; ``layers`` for a composite target.
    Projectile: ``projectile_density`` rho_p, ``projectile_length`` L_p,
    ``projectile_diameter`` d_p, ``projectile_mass`` m_p, ``projectile_hardness`` HV_p,
    ``projectile_delta_H``.  ``measured`` V_cr [m/s] with ``measured_qualifier`` ("" or "<", ">").
    """

    name: str
    projectile_length: float
    projectile_density: float = PAPER_PROJECTILE_DENSITY
    target_density: float | None = None
    thickness: float | None = None
    target_hardness: float | None = None
    target_delta_H: float | None = None
    yield_stress: float | None = None
    youngs_modulus: float | None = None
    resistance_R3: float | None = None
    projectile_diameter: float | None = None
    projectile_mass: float | None = None
    projectile_hardness: float | None = None
    projectile_delta_H: float | None = None
    measured: float | None = None
    measured_qualifier: str = ""
    layers: tuple[Layer, ...] = ()

    @property
    def is_composite(self) -> bool:
        return bool(self.layers)

    @property
    def HVdelta_t(self) -> float | None:
        if self.target_hardness is None or self.target_delta_H is None:
            return None
        return self.target_hardness * self.target_delta_H

    @property
    def HVdelta_p(self) -> float | None:
        if self.projectile_hardness is None or self.projectile_delta_H is None:
            return None
        return self.projectile_hardness * self.projectile_delta_H

    def target_layers(self) -> tuple[Layer, ...]:
        """The plates of the target: ``layers``, or the single plate described by the target fields."""
        if self.layers:
            return self.layers
        if None in (self.target_density, self.thickness, self.target_hardness, self.target_delta_H):
            return ()
        return (Layer(self.name, self.target_density, self.thickness, self.target_hardness, self.target_delta_H),)


def projectile_areal_mass(shot: Shot, rule: str = "mass-per-area") -> float | None:
    """P [kg/m^2] by ``rule``: ``mass-per-area`` m_p/(pi d_p^2/4) (errata 26) or ``cylinder``
    rho_p L_p (the form behind (7')-(9')).  ``None`` if the shot lacks the inputs."""
    if rule == "mass-per-area":
        if shot.projectile_mass is None or shot.projectile_diameter is None:
            return None
        return areal_mass(shot.projectile_mass, shot.projectile_diameter)
    if rule == "cylinder":
        return areal_mass_cylinder(shot.projectile_density, shot.projectile_length)
    raise ValueError(f"areal-mass rule must be one of {AREAL_MASS_RULES}; got {rule!r}")


def theoretical_limits(shot: Shot, hardness: str = "meyer") -> dict[str, float]:
    """Rigid-projectile ballistic limits of Part IV, eq. (5) for a single plate.

    Keys (present when the inputs allow): ``R1_Pa``/``V_R1_m_s`` with R(1) = HM delta_H
    (``hardness``: HM = HV/sin 68 deg or HV), ``R3_Pa``/``V_R3_m_s`` with R(3) of eq. (6) (or
    the given ``resistance_R3``), ``R2_Pa``/``V_R2_m_s`` with R(2) = R(3) delta_H.
    """
    out: dict[str, float] = {}
    if shot.is_composite or shot.target_density is None or shot.thickness is None:
        return out

    def V(R):
        return float(ballistic_limit(shot.thickness, R, shot.target_density, shot.projectile_density,
                                     shot.projectile_length))

    if shot.target_hardness is not None and shot.target_delta_H is not None:
        R1 = float(resistance_R1(shot.target_hardness, shot.target_delta_H, hardness))
        out.update(R1_Pa=R1, V_R1_m_s=V(R1))
    R3 = shot.resistance_R3
    if R3 is None and shot.yield_stress is not None and shot.youngs_modulus is not None:
        R3 = float(resistance_part4(shot.yield_stress, shot.youngs_modulus))
    if R3 is not None:
        if shot.target_delta_H is not None:
            R2 = R3 * shot.target_delta_H
            out.update(R2_Pa=R2, V_R2_m_s=V(R2))
        out.update(R3_Pa=R3, V_R3_m_s=V(R3))
    return out


def empirical_limits(shot: Shot, constants: EmpiricalConstants = PAPER_CONSTANTS,
                     rule: str = "mass-per-area", P: float | None = None) -> dict[str, float]:
    """Empirical ballistic limits of Part IV, eqs. (7)-(9): keys ``P_kg_m2``, ``V_eq7_m_s``,
    ``V_eq8_m_s``, ``V_eq9_m_s`` (those the inputs allow).  For a composite target each layer
    is evaluated with the same projectile and V_comp = sqrt(sum V_i^2).  ``P`` overrides the
    areal mass given by ``rule``.
    """
    P = projectile_areal_mass(shot, rule) if P is None else P
    layers = shot.target_layers()
    if P is None or not layers:
        return {}
    out: dict[str, float] = {"P_kg_m2": P}
    out["V_eq7_m_s"] = composite_vcr(*[vcr_eq7(l.density, l.thickness, P, constants.C1) for l in layers])
    out["V_eq8_m_s"] = composite_vcr(*[vcr_eq8(l.density, l.thickness, P, l.HVdelta, constants.C2) for l in layers])
    if shot.HVdelta_p is not None:
        out["V_eq9_m_s"] = composite_vcr(
            *[vcr_eq9(l.density, l.thickness, P, l.HVdelta, shot.HVdelta_p, constants.C3) for l in layers])
    return out


def critical_values(shot: Shot, velocity: float, constants: EmpiricalConstants = PAPER_CONSTANTS,
                    rule: str = "cylinder") -> dict[str, float]:
    """Critical areal density and thickness of the shot's (single-plate) target material against
    its projectile at ``velocity`` (Part IV, section 4, Table 4; eq. (9) solved for rho_t h_t).
    Table 4 takes P = rho_p L_p (``rule='cylinder'``)."""
    P = projectile_areal_mass(shot, rule)
    if P is None or shot.is_composite or shot.HVdelta_t is None or shot.HVdelta_p is None:
        return {}
    rho_h = float(critical_areal_density(velocity, P, shot.HVdelta_t, shot.HVdelta_p, constants.C3))
    out = {"V_p_m_s": velocity, "rhoh_cr_kg_m2": rho_h}
    if shot.target_density:
        out["h_cr_m"] = rho_h / shot.target_density
    return out


def is_fittable(shot: Shot) -> bool:
    """A single-plate shot with an exactly measured V_cr (no "<"/">"): usable to refit C1-C3."""
    return not shot.is_composite and shot.measured is not None and not shot.measured_qualifier


def fit_sample(shot: Shot, P: float | None) -> FitSample:
    """The :class:`FitSample` of a fittable shot with projectile areal mass ``P`` [kg/m^2];
    raises ``InputError`` naming the shot if an input of eqs. (7)-(9) is missing."""
    from semianalytic.errors import InputError

    missing = [n for n, v in (("P", P), ("rho_t", shot.target_density), ("h_t", shot.thickness),
                              ("(HV delta_H)_t", shot.HVdelta_t), ("(HV delta_H)_p", shot.HVdelta_p)) if v is None]
    if missing:
        raise InputError(shot.name, f"cannot be fitted: missing {', '.join(missing)}")
    return FitSample(shot.name, shot.target_density, shot.thickness, P, shot.HVdelta_t, shot.HVdelta_p, shot.measured)
