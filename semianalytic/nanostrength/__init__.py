"""Part III: theoretical strength of diamond-like crystals and the size effect in nanoparticles.

Public API (SI units):

* :mod:`.data` -- the paper's Tables 1-5 and atomic units (Ry/bohr^2 = 778.43 J/m^2).
* :class:`Crystal`, :func:`paper_crystal` -- inputs of one crystal (Tables 1-2).
* :func:`calibrate` (``"cutoff"`` | ``"uber"``), :class:`CutoffLaw`, :class:`UberLaw` -- the bulk
  interplanar law Phi(d) and the stress of eq. (14): ``law.stress(e)``, ``law.strength()``,
  ``law.energy(d)``, ``law.scaled(f)``.
* :func:`fracture`, :func:`surface_energy_eq15`, :func:`surface_energy_eq16`,
  :func:`fracture_toughness` -- eqs. (15)-(16), Table 3.
* :mod:`.mesolayer` -- eqs. (17)-(28): :func:`plate_energy`, :func:`basis_factor`,
  :func:`strength_factor`, :func:`profile`.
* :func:`theoretical_strength`, :func:`analyse` -- eq. (29) for a mesolayer, whole studies.
"""

from semianalytic.nanostrength.analysis import Analysis, Geometry, StudySpec, analyse, theoretical_strength
from semianalytic.nanostrength.crystal import Crystal, paper_crystal
from semianalytic.nanostrength.fracture import (
    fracture,
    fracture_toughness,
    surface_energy_eq15,
    surface_energy_eq16,
)
from semianalytic.nanostrength.interplanar import CalibrationError, CutoffLaw, Strength, UberLaw, calibrate
from semianalytic.nanostrength.mesolayer import basis_factor, plate_energy, profile, strength_factor

__all__ = [
    "Analysis", "Geometry", "StudySpec", "analyse", "theoretical_strength",
    "Crystal", "paper_crystal",
    "fracture", "fracture_toughness", "surface_energy_eq15", "surface_energy_eq16",
    "CalibrationError", "CutoffLaw", "Strength", "UberLaw", "calibrate",
    "basis_factor", "plate_energy", "profile", "strength_factor",
]
