"""Published thin-plate models of perforation and the choice of the failure mode.

Every function is a pure function of SI values and names its source.  They serve two purposes:
the closed forms are the independent hand computations the tests check the integrated model
(Part I, eq. (11) through the plate, :mod:`semianalytic.perforation.model`) against, and
:func:`failure_mode` chooses the mechanism the integrated model uses.

Models
------
* Cylindrical cavity expansion (ductile hole enlargement, pointed noses): the quasi-static
  radial stress to open a cylindrical cavity from zero radius in an incompressible
  elastic-perfectly plastic (von Mises, plane strain) solid,
  sigma_s = (Y / sqrt 3) [1 + ln(E / (sqrt 3 Y))]  (Bishop, Hill & Mott 1945, Proc. Phys. Soc.
  57:147, the cylindrical cavity with shear yield k = Y/sqrt 3 and G = E/3), used for the plate
  material displaced radially by the nose in thin plates by Forrestal, Rosenberg, Luk & Bless
  (1987), J. Appl. Mech. 54:230-232 (conical noses), Forrestal, Luk & Brar (1990), Mech. Mater.
  10:97-105 (ogival noses) and Piekutowski, Forrestal, Poormon & Warren (1996), Int. J. Impact
  Eng. 18:877-887 (ogive rods through 6061-T651 plates).  The work of opening the hole of radius
  a through the thickness H at the stress sigma_s is W = pi a^2 H sigma_s (the quasi-static
  term of those papers' energy balance), so V_bl = sqrt(2 W / m) and V_r = sqrt(V_s^2 - V_bl^2)
  (:func:`hole_enlargement_limit`, :func:`energy_residual`).
* Shear plugging (blunt noses): Recht & Ipson (1963), J. Appl. Mech. 30:384-390: the plug of mass
  m_p = rho pi d^2 H / 4 is accelerated inelastically (momentum) and pushed out against the shear
  force pi d tau (H - x): W = pi d tau H^2 / 2, V_bl = sqrt(2 W (m + m_p)) / m and
  V_r = m / (m + m_p) sqrt(V_s^2 - V_bl^2) (their eq. for the residual velocity of a plugging
  perforation) (:func:`plugging_limit`, :func:`recht_ipson_residual`); plug onset inside a plate by
  the criterion of Chen & Li (2003), Int. J. Impact Eng. 28:743-759 (the nose force reaches the
  ligament's shear capacity pi d (H - P) tau, tau = Y / sqrt 3).
* Petalling (thin plates, conical and ogival noses): Thomson (1955), J. Appl. Phys. 26:80-82,
  the quasi-static work of bending the plate material out of the way, W = (pi / 2) a^2 H Y
  (:func:`petalling_work`), the lower of the thin-plate works.
* Lambert & Jonas (1976), BRL-R-1852: V_r = a (V_s^p - V_bl^p)^(1/p) (model.lambert_jonas).

Failure mode (:func:`failure_mode`)
-----------------------------------
* a blunt nose (flat, or a meplat of at least half the diameter): shear plugging (Recht & Ipson
  1963; the mode Borvik, Langseth, Hopperstad & Malo 2002, Int. J. Impact Eng. 27:19-35 report for
  blunt noses in 12 mm Weldox 460 E);
* otherwise ductile hole enlargement (the mode of conical and ogival noses in ductile plates,
  Forrestal et al. 1987, 1990; Borvik et al. 2002 for conical noses), and
* petalling where the plate is thin against the nose: H < a (this project's own threshold, "ours":
  Backman & Goldsmith 1978, Int. J. Eng. Sci. 16:1-99, report petalling for thin plates struck
  by conical and ogival noses without a number).
The integrated model keeps eq. (11) for every mode; the mode sets the resistance near the back face
(``back_face``) and whether the plug criterion is active.

Where Part I's spherical cavity holds (:func:`spherical_zone_fits`)
------------------------------------------------------------------
Part I's resistance (eqs. (16)-(19)) is the spherical cavity-expansion pressure, whose plastic zone
reaches c = (2E/(3Y))^(1/3) a (Hill 1950, ch. V).  A plate thinner than c has no spherical plastic
zone anywhere: there the cylindrical cavity expansion (plate material displaced radially) takes
over, and the output says so (``thin_plate``).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "FAILURE_MODES",
    "cylindrical_cavity_stress",
    "energy_residual",
    "failure_mode",
    "hole_enlargement_limit",
    "hole_enlargement_work",
    "is_blunt",
    "petalling_work",
    "plugging_limit",
    "plugging_work",
    "recht_ipson_residual",
    "spherical_plastic_radius",
    "spherical_zone_fits",
]

FAILURE_MODES = ("shear plugging", "ductile hole enlargement", "petalling")


def cylindrical_cavity_stress(yield_stress: float, youngs_modulus: float) -> float:
    """sigma_s = (Y / sqrt 3) [1 + ln(E / (sqrt 3 Y))] [Pa]: the quasi-static radial stress of a
    cylindrical cavity opened from zero radius in an incompressible elastic-perfectly plastic solid
    (Bishop, Hill & Mott 1945; the thin-plate stress of Forrestal, Rosenberg, Luk & Bless 1987)."""
    Y, E = float(yield_stress), float(youngs_modulus)
    if not (Y > 0 and E > math.sqrt(3.0) * Y):
        raise ValueError("the cylindrical cavity needs 0 < sqrt(3) Y < E")
    return von_mises_shear_strength(Y) * (1.0 + math.log(E / (math.sqrt(3.0) * Y)))


def hole_enlargement_work(radius: float, thickness: float, stress: float) -> float:
    """W = pi a^2 H sigma_s [J]: the work to open a hole of radius a through H at the radial stress
    sigma_s (the quasi-static term of Forrestal et al. 1987, 1990)."""
    return math.pi * radius * radius * thickness * stress


def hole_enlargement_limit(mass: float, radius: float, thickness: float, stress: float) -> float:
    """V_bl = sqrt(2 pi a^2 H sigma_s / m) [m/s] (energy balance, Forrestal et al. 1987)."""
    return math.sqrt(2.0 * hole_enlargement_work(radius, thickness, stress) / mass)


def energy_residual(Vs, V_bl: float):
    """V_r = sqrt(V_s^2 - V_bl^2) for V_s > V_bl, else 0 (the energy balance of a rigid projectile
    that loses a fixed work; Lambert & Jonas with a = 1, p = 2)."""
    Vs = np.asarray(Vs, float)
    return np.sqrt(np.maximum(Vs * Vs - V_bl * V_bl, 0.0))[()]


def von_mises_shear_strength(yield_stress: float) -> float:
    """tau = Y / sqrt 3 [Pa]: the shear yield stress of a von Mises material of tensile yield Y
    (the plug's shear strength where the case gives none)."""
    return float(yield_stress) / math.sqrt(3.0)


def plugging_work(diameter: float, thickness: float, shear_strength: float) -> float:
    """W = pi d tau H^2 / 2 [J]: pushing a plug of diameter d out of H against the shear force
    pi d tau (H - x) (Recht & Ipson 1963)."""
    return 0.5 * math.pi * diameter * shear_strength * thickness * thickness


def plugging_limit(mass: float, diameter: float, thickness: float, shear_strength: float, density: float) -> float:
    """V_bl = sqrt(2 W (m + m_p)) / m [m/s] of Recht & Ipson (1963): the plug m_p = rho pi d^2 H / 4
    takes momentum inelastically, then the shear work W = pi d tau H^2 / 2."""
    m_p = density * math.pi * diameter * diameter / 4.0 * thickness
    return math.sqrt(2.0 * plugging_work(diameter, thickness, shear_strength) * (mass + m_p)) / mass


def recht_ipson_residual(Vs, V_bl: float, mass: float, plug_mass: float):
    """V_r = m / (m + m_p) sqrt(V_s^2 - V_bl^2) (Recht & Ipson 1963, plugging)."""
    return mass / (mass + plug_mass) * energy_residual(Vs, V_bl)


def petalling_work(radius: float, thickness: float, yield_stress: float) -> float:
    """W = (pi / 2) a^2 H Y [J]: the quasi-static work of petalling of Thomson (1955)."""
    return 0.5 * math.pi * radius * radius * thickness * yield_stress


def spherical_plastic_radius(radius: float, yield_stress: float, youngs_modulus: float) -> float:
    """c = (2E / (3Y))^(1/3) a [m]: the plastic-zone radius of a spherical cavity of radius a
    opened from zero in an incompressible elastic-perfectly plastic solid (Hill 1950, ch. V)."""
    return (2.0 * youngs_modulus / (3.0 * yield_stress)) ** (1.0 / 3.0) * radius


def spherical_zone_fits(thickness: float, radius: float, yield_stress: float, youngs_modulus: float) -> bool:
    """True where the spherical plastic zone of Part I's resistance fits inside the plate, H >= c."""
    return thickness >= spherical_plastic_radius(radius, yield_stress, youngs_modulus)


def is_blunt(nose) -> bool:
    """A flat nose, or one whose flat tip (meplat) is at least half the diameter."""
    if getattr(nose, "kind", None) == "flat":
        return True
    params = getattr(nose, "parameters", None) or {}
    meplat = params.get("meplat_diameter", 0.0) or 0.0
    return meplat >= 0.5 * float(nose.diameter)


def failure_mode(nose, thickness: float) -> tuple[str, str]:
    """(mode, reason) of a rigid nose through a ductile plate of thickness H (module docstring)."""
    d = float(nose.diameter)
    if is_blunt(nose):
        why = ("blunt nose (flat, or a meplat >= d/2): shear plugging, Recht & Ipson 1963 with the "
               "onset criterion of Chen & Li 2003")
        return "shear plugging", why
    if thickness < 0.5 * d:
        why = (f"pointed nose and H = {thickness * 1e3:.4g} mm < d/2 = {0.5 * d * 1e3:.4g} mm (threshold ours; "
               "petalling of thin plates: Backman & Goldsmith 1978; work: Thomson 1955)")
        return "petalling", why
    why = ("pointed nose: ductile hole enlargement by cylindrical cavity expansion "
           "(Forrestal, Rosenberg, Luk & Bless 1987; Forrestal, Luk & Brar 1990)")
    return "ductile hole enlargement", why
