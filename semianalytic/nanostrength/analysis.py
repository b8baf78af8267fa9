"""Theoretical strength of a nanobar/nanoplate mesolayer and the studies of Part III, section 2.

The strength of mesolayer i follows from eq. (29) applied to the bulk curve scaled by
Phi_i/Phi_0 (eqs. (26)-(28)); :func:`theoretical_strength` does exactly that with the
calibrated law, so sigma_1 and sigma_2 both scale with the factor and e* stays put.
A *study* evaluates a grid (crystals x basis x l x m = n x i), optionally beside the values
printed in Tables 4 and 5.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np

from semianalytic.nanostrength import data, mesolayer
from semianalytic.nanostrength.crystal import Crystal
from semianalytic.nanostrength.fracture import SIDES, FractureResult, fracture
from semianalytic.nanostrength.interplanar import Law, Strength, calibrate


@dataclass(frozen=True)
class Geometry:
    """A mesolayer in a nanoparticle.  basis: 'parallelogram' | 'rectangle' | 'none' (plate,
    unbounded in x, y); l: atomic planes along [111] (None: unbounded, an infinite bar);
    m = n: basis size in lattice vectors (None for 'none'); i: mesolayer index 1..j."""

    basis: str
    l: int | None
    m: int | None
    n: int | None
    i: int | None

    def factor(self, odd_surface_ratio: float) -> float:
        """Phi_i / Phi_0, Part III, eqs. (21), (24)-(28)."""
        return mesolayer.strength_factor(i=self.i, l=self.l, m=self.m, n=self.n, basis=self.basis,
                                         odd_surface_ratio=odd_surface_ratio)

    def to_json(self) -> dict:
        return {"basis": self.basis, "l_planes": self.l, "m": self.m, "n": self.n, "i_mesolayer": self.i}


def theoretical_strength(law: Law, geometry: Geometry, odd_surface_ratio: float) -> tuple[float, Strength]:
    """(Phi_i/Phi_0, peaks of eq. (29) for the mesolayer curve (Phi_i/Phi_0) Phi(d)); Part III,
    eqs. (26)-(29)."""
    f = geometry.factor(odd_surface_ratio)
    return f, law.scaled(f).strength()


# --------------------------------------------------------------------------------------
# printed values of Tables 4 and 5


def printed_value(compare: str | None, material: str, g: Geometry) -> tuple[float, float] | None:
    """(sigma_1, sigma_2) [GPa] printed for this geometry, if the table has it.

    table4: rectangle / parallelogram with l = 100, m = n = 25, i = 2; the third column
    (parallelogram, m = n = 2500, 30 <= i <= 570) with any l (printed 120, the text says 1200).
    table5: SiC, m = n in the printed sizes, either basis (l and i are not printed).
    """
    if compare == "table4" and material in data.TABLE4:
        if g.basis in ("rectangle", "parallelogram") and g.l == 100 and g.m == g.n == 25 and g.i == 2:
            return data.table4_printed(material, g.basis)
        if g.basis == "parallelogram" and g.m == g.n == 2500 and g.i is not None and 30 <= g.i <= 570:
            return data.table4_printed(material, "plate")
    if compare == "table5" and material == "SiC" and g.basis in data.TABLE5 and g.m == g.n and g.m in data.TABLE5_SIZES:
        return data.table5_printed(g.basis, g.m)
    return None


@dataclass(frozen=True)
class StrengthRow:
    material: str
    geometry: Geometry
    factor: float
    strength: Strength
    printed: tuple[float, float] | None

    def differences(self) -> tuple[float, float] | None:
        """(computed - printed)/printed for sigma_1 and sigma_2."""
        if self.printed is None:
            return None
        s1, s2 = self.printed
        return (self.strength.sigma_c / 1e9 - s1) / s1, (self.strength.sigma_t / 1e9 - s2) / s2

    def to_json(self) -> dict:
        out = {
            "material": self.material,
            **self.geometry.to_json(),
            "phi_ratio": self.factor,
            "sigma1_compression_GPa": _num(self.strength.sigma_c / 1e9),
            "sigma2_tension_GPa": _num(self.strength.sigma_t / 1e9),
            "e_compression": _num(self.strength.e_c),
            "e_tension": _num(self.strength.e_t),
        }
        if self.printed is not None:
            d1, d2 = self.differences()
            out.update({"printed_sigma1_GPa": self.printed[0], "printed_sigma2_GPa": self.printed[1],
                        "rel_diff_sigma1": _num(d1), "rel_diff_sigma2": _num(d2)})
        return out


def _num(x: float):
    return None if x is None or not math.isfinite(x) else float(x)


@dataclass(frozen=True)
class StudySpec:
    """A grid of geometries; ``i`` entries may be 'all' (every mesolayer) or 'centre'."""

    name: str
    title: str
    materials: tuple[str, ...]
    basis: tuple[str, ...]
    l: tuple[int | None, ...]
    mn: tuple[int | None, ...]
    i: tuple[int | str, ...] | str
    compare: str | None = None
    plot: str | None = None

    def geometries(self) -> list[Geometry]:
        out = []
        for basis, l, mn in itertools.product(self.basis, self.l, self.mn):
            if l is None:
                idx: list[int | None] = [None]
            elif self.i == "all":
                idx = list(range(1, mesolayer.mesolayer_count(l) + 1))
            else:
                idx = [mesolayer.centre_index(l) if k == "centre" else int(k) for k in self.i]
            for i in idx:
                out.append(Geometry(basis, l, mn, mn, i))
        return out


@dataclass
class StudyResult:
    spec: StudySpec
    rows: list[StrengthRow] = field(default_factory=list)

    def to_json(self) -> dict:
        return {"name": self.spec.name, "title": self.spec.title, "compare": self.spec.compare,
                "rows": [r.to_json() for r in self.rows]}


def run_study(spec: StudySpec, laws: dict[str, Law], odd_surface_ratio: float) -> StudyResult:
    """Evaluate every geometry of ``spec`` for every crystal (laws by crystal name)."""
    res = StudyResult(spec)
    for name in spec.materials:
        for g in spec.geometries():
            f, s = theoretical_strength(laws[name], g, odd_surface_ratio)
            res.rows.append(StrengthRow(name, g, f, s, printed_value(spec.compare, name, g)))
    return res


# --------------------------------------------------------------------------------------
# Table 5: which l and i?


@dataclass(frozen=True)
class Table5Fit:
    l: int
    i: int
    factor_rectangle_25: float
    median_rel: float
    max_rel_inliers: float
    outliers: int


def infer_table5(bulk_c: float = data.TABLE2["SiC"].sigma1, bulk_t: float = data.TABLE2["SiC"].sigma2,
                 l_values=range(2, 201), odd_surface_ratio: float = mesolayer.DEFAULT_ODD_SURFACE_RATIO,
                 outlier: float = 1e-3, top: int = 5) -> list[Table5Fit]:
    """Scan (l, i) for the mesolayer that best reproduces all 28 entries of Table 5 with the
    SiC bulk strengths [GPa] (errata item 21: Table 5 does not state l and i).  Entries off by
    more than ``outlier`` (relative) are counted, not fitted.  Best first (fewest outliers,
    then smallest median residual); mirror images i <-> j + 1 - i are listed once."""
    # eq. (26): Phi_i*/Phi_0 = (basis factor) x (plate factor of eq. (21)); the 28 entries differ
    # only in the basis factor, so compute it once per entry and the plate factor once per (l, i).
    basis_f, printed, bulk = [], [], []
    for basis in ("parallelogram", "rectangle"):
        for k, size in enumerate(data.TABLE5_SIZES):
            s = mesolayer.basis_factor(size, size, basis)
            basis_f += [s, s]
            printed += [data.TABLE5[basis]["sigma1"][k], data.TABLE5[basis]["sigma2"][k]]
            bulk += [bulk_c, bulk_t]
    basis_f, printed, bulk = np.array(basis_f), np.array(printed), np.array(bulk)
    rect25 = mesolayer.basis_factor(25, 25, "rectangle")
    fits = []
    for l in l_values:
        j, phi1, phi2 = mesolayer.surface_energies(l, -1.0, odd_surface_ratio)
        for i in range(1, j + 1):
            if l % 2 == 0 and i > j + 1 - i:
                continue
            plate = mesolayer.plate_energy(i, j, -1.0, phi1, phi2) / -1.0
            rel = np.abs(bulk * basis_f * plate / printed - 1)
            inl = rel[rel <= outlier]
            fits.append(Table5Fit(l, i, rect25 * plate, float(np.median(rel)),
                                  float(inl.max()) if inl.size else math.inf, int((rel > outlier).sum())))
    fits.sort(key=lambda f: (f.outliers, f.median_rel))
    return fits[:top]


# --------------------------------------------------------------------------------------
# per-crystal bulk quantities


@dataclass(frozen=True)
class CrystalResult:
    crystal: Crystal
    law: Law
    uber: Law
    bulk: Strength
    uber_bulk: Strength
    fracture: dict[str, FractureResult]  # keys "<form>/<source>/<side>"

    def to_json(self) -> dict:
        c, law, b = self.crystal, self.law, self.bulk
        out = {
            "phi0_J_per_m2": c.phi0,
            "phi0_Ry_per_bohr2": c.phi0 / data.RY_PER_BOHR2,
            "d0_m": c.d0,
            "law": law_parameters(law),
            "law_E_GPa": law.youngs_modulus / 1e9,
            "law_sigma1_compression_GPa": _num(b.sigma_c / 1e9),
            "law_e_compression": _num(b.e_c),
            "law_sigma2_tension_GPa": _num(b.sigma_t / 1e9),
            "law_e_tension": _num(b.e_t),
            "table2_sigma1_GPa": c.sigma_c / 1e9, "table2_e_compression": c.e_c,
            "table2_sigma2_GPa": c.sigma_t / 1e9, "table2_e_tension": c.e_t, "table2_E_GPa": c.E / 1e9,
            "uber": law_parameters(self.uber),
            "uber_sigma2_tension_GPa": _num(self.uber_bulk.sigma_t / 1e9),
            "uber_e_tension": _num(self.uber_bulk.e_t),
            "uber_sigma1_compression_GPa": _num(self.uber_bulk.sigma_c / 1e9),
            "fracture": {},
        }
        for key, fr in self.fracture.items():
            out["fracture"][key] = {
                "delta_phi_J_per_m2": fr.delta_phi, "critical_strain": fr.critical_strain,
                "gamma_J_per_m2": fr.gamma, "Y1c_J_per_m2": fr.Y1c, "K1c_MPa_sqrt_m": fr.K1c / 1e6,
            }
        return out


def law_parameters(law: Law) -> dict:
    """The law's constants, JSON-ready (SI units in the keys)."""
    out = {"name": type(law).__name__, "stress_measure": law.measure, "d0_m": law.d0, "phi0_J_per_m2": law.phi0}
    if hasattr(law, "k"):
        out.update({"k": law.k, "alpha_t": law.alpha_t, "p_t": law.p_t, "alpha_c": law.alpha_c, "p_c": law.p_c})
    else:
        out.update({"phi_b_J_per_m2": law.phi_b, "l_m": law.l})
    return out


FRACTURE_VARIANTS = (("eq16", "printed"), ("eq16", "law"), ("eq15", "law"))


def analyse_crystal(crystal: Crystal, law_name: str = "cutoff", measure: str = "current") -> CrystalResult:
    """Calibrate the laws and compute the fracture quantities of Table 3 in every variant that
    the crystal's data allow."""
    law = calibrate(crystal, law_name, measure)
    uber = calibrate(crystal, "uber", measure)
    frac = {}
    for form, source in FRACTURE_VARIANTS:
        if source == "printed" and (crystal.dphi_t is None or crystal.dphi_c is None):
            continue
        for side in SIDES:
            try:
                frac[f"{form}/{source}/{side}"] = fracture(crystal, law, side, form, source)
            except ValueError:  # e.g. the uber law has no compressive peak
                continue
    return CrystalResult(crystal, law, uber, law.strength(), uber.strength(), frac)


# --------------------------------------------------------------------------------------
# the whole analysis of a case


@dataclass
class Analysis:
    """Everything the ``nanostrength`` command computes for a case."""

    options: dict
    crystals: dict[str, CrystalResult]
    studies: list[StudyResult]
    table5_fits: list[Table5Fit] | None

    def to_json(self) -> dict:
        out = {
            "options": self.options,
            "units": {"Ry_per_bohr2_J_per_m2": data.RY_PER_BOHR2, "eq16_factor_printed_N_per_m": data.EQ16_FACTOR,
                      "bohr_m": data.BOHR},
            "crystals": {name: r.to_json() for name, r in self.crystals.items()},
            "studies": [s.to_json() for s in self.studies],
        }
        if self.table5_fits is not None:
            out["table5_inferred"] = [{k: (_num(v) if isinstance(v, float) else v) for k, v in f.__dict__.items()}
                                      for f in self.table5_fits]
        return out


def analyse(crystals: list[Crystal], studies: list[StudySpec], *, law: str = "cutoff", measure: str = "current",
            odd_surface_ratio: float = mesolayer.DEFAULT_ODD_SURFACE_RATIO) -> Analysis:
    """Calibrate every crystal's law, compute Table 2-3 quantities and run the studies."""
    results = {c.name: analyse_crystal(c, law, measure) for c in crystals}
    laws = {name: r.law for name, r in results.items()}
    study_results = [run_study(s, laws, odd_surface_ratio) for s in studies]
    fits = None
    if any(s.compare == "table5" for s in studies):
        fits = infer_table5(odd_surface_ratio=odd_surface_ratio)
    options = {"law": law, "stress_measure": measure, "odd_surface_ratio": odd_surface_ratio}
    return Analysis(options, results, study_results, fits)
