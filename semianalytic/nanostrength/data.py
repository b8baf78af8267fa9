"""The numbers Part III prints, and the atomic units they are written in.

Source of every constant below: the seed paper, Part III ("Investigation of deformation
process at high-speed loadings of ceramic materials with diamond-like structure ..."),
Tables 1-5 and the text after eq. (16).  The same values are kept as documented data files
``cases/part3_table{1..5}.csv`` and ``cases/part3_deformation_energy.csv`` (a test checks that the
files and these constants agree; the code never reads /work/shared).

Units (inferred; the paper only says "atomic units"):

* lengths a_0, c_0 are in bohr (a_0 = 4.7969 bohr = 2.538 angstrom is the hexagonal a of
  diamond, a_cubic / sqrt(2) = 2.522 angstrom);
* the interlayer energy Phi is an energy per unit area in rydberg / bohr^2: the factor
  7.78605e2 N/m of eq. (16) is Ry / bohr^2 = 778.43 J/m^2 to 0.02 %, and with it eq. (16)
  turns the quoted Delta Phi values into Table 3's gamma = Y_1c / 2;
* the column "-Phi_0 * 10^-2" of Table 1 lists -Phi_0 in units of 10^-2 Ry/bohr^2
  (Phi_0 = -0.25998e-2 Ry/bohr^2 = -2.02 J/m^2 for diamond): only this reading is consistent
  with Table 2 (E d_0 / |Phi_0| ~ 86 for all four crystals) and with Delta Phi < |Phi_0|.

Inside the package everything is SI: Phi in J/m^2, lengths in m, stresses in Pa.
"""

from __future__ import annotations

from dataclasses import dataclass

# --- atomic units (CODATA 2018) ---------------------------------------------------------
BOHR = 5.29177210903e-11  # m
RYDBERG = 2.1798723611035e-18  # J
RY_PER_BOHR2 = RYDBERG / BOHR**2  # J/m^2 (= 778.43 N/m)
RY_PER_BOHR3 = RYDBERG / BOHR**3  # Pa (= 14.71 TPa)
#: the factor printed in Part III, eq. (16), in N/m; Ry/bohr^2 to 0.02 %
EQ16_FACTOR = 7.78605e2

MATERIALS = ("C", "BN", "SiC", "AlN")
GPa = 1e9


@dataclass(frozen=True)
class Table1Row:
    """Part III, Table 1: -Phi_0 [1e-2 Ry/bohr^2], a_0, c_0 (calculated) and a_0*, c_0*
    (experimental) [bohr]."""

    minus_phi0_e2: float
    a0: float
    c0: float
    a0_exp: float
    c0_exp: float

    @property
    def phi0(self) -> float:
        """Phi_0 [J/m^2] (negative: bound)."""
        return -self.minus_phi0_e2 * 1e-2 * RY_PER_BOHR2

    @property
    def d0(self) -> float:
        """d_0 = c_0 / 4 [m]: spacing of the weakest pair of {111} planes (Part III, text after eq. 13)."""
        return self.c0 / 4 * BOHR


@dataclass(frozen=True)
class Table2Row:
    """Part III, Table 2: compression sigma_1^max [GPa], -e*_111, E_1 [GPa];
    tension sigma_2^max [GPa], e**_111, E_2 [GPa]."""

    sigma1: float
    e1: float
    E1: float
    sigma2: float
    e2: float
    E2: float


@dataclass(frozen=True)
class Table3Row:
    """Part III, Table 3: Y_1c [N/m] and K_1c [MPa m^1/2] in tension (I) and compression (II)."""

    Y_t: float
    Y_c: float
    K_t: float
    K_c: float


TABLE1: dict[str, Table1Row] = {
    "C": Table1Row(0.25998, 4.7969, 12.007, 4.76, 11.86),
    "BN": Table1Row(0.22528, 4.8423, 12.144, 4.89, 12.0),
    "SiC": Table1Row(0.23109, 5.735, 14.372, 5.817, 14.23),
    "AlN": Table1Row(0.13385, 5.808, 14.549, 5.85, 14.58),
}

TABLE2: dict[str, Table2Row] = {
    "C": Table2Row(204.4, 0.0975, 1100, 139.07, 0.1456, 1100),
    "BN": Table2Row(175.4, 0.0978, 970, 119.24, 0.1458, 970),
    "SiC": Table2Row(147.56, 0.0998, 750, 103.12, 0.1459, 750),
    "AlN": Table2Row(88.26, 0.098, 450, 59.05, 0.1460, 450),
}

#: Delta Phi = Phi(d_max) - Phi(d_0) quoted after eq. (16), in Ry/bohr^2: (tension, compression)
DEFORMATION_ENERGY: dict[str, tuple[float, float]] = {
    "C": (0.22195e-2, 0.8081e-3),
    "BN": (0.193595e-2, 0.698e-3),
    "SiC": (0.189e-2, 0.855e-3),
    "AlN": (0.113032e-2, 0.44764e-3),
}

TABLE3: dict[str, Table3Row] = {
    "C": Table3Row(23.6728, 12.839, 5.1067, 3.76075),
    "BN": Table3Row(20.6484, 11.0914, 4.479, 3.2832),
    "SiC": Table3Row(20.1584, 13.5858, 3.89, 3.194),
    "AlN": Table3Row(12.056, 7.113, 2.33, 1.79),
}
#: experimental K_1c quoted beside Table 3 [MPa m^1/2]: (low, high, reference)
TABLE3_EXPERIMENT = {"C": (3.4, 8.0, "[14]"), "BN": (3.0, 4.0, "[15]")}

# Table 4: (sigma_1, sigma_2) [GPa] per material and column.  Column keys give the inputs
# as printed in the header; the study that recomputes it states what it assumed.
TABLE4_COLUMNS = {
    "rectangle": "nanobar, rectangle basis, l = 100, m = n = 25, i = 2",
    "parallelogram": "nanobar, parallelogram basis, l = 100, m = n (= 25, not printed), i = 2",
    "plate": "nanobar/plate, parallelogram basis, l = 120 (printed; 1200 in the text), m = n = 2500, 30 <= i <= 570",
}
TABLE4: dict[str, dict[str, tuple[float, float]]] = {
    "C": {"rectangle": (236.709, 161.048), "parallelogram": (235.768, 160.4), "plate": (204.4, 139.07)},
    "BN": {"rectangle": (203.14, 138.087), "parallelogram": (202.3, 137.5), "plate": (175.4, 119.24)},
    "SiC": {"rectangle": (170.88, 119.42), "parallelogram": (170.203, 118.94), "plate": (147.56, 103.12)},
    "AlN": {"rectangle": (102.208, 63.385), "parallelogram": (101.802, 68.113), "plate": (88.26, 59.05)},
}

# Table 5: SiC nanobar, sigma_1 and sigma_2 [GPa] against m = n, form I (parallelogram)
# and II (rectangle).  l and i are not printed (errata item 21).
TABLE5_SIZES = (25, 50, 100, 150, 200, 300, 500)
TABLE5: dict[str, dict[str, tuple[float, ...]]] = {
    "parallelogram": {
        "sigma1": (180.023, 179.845, 178.709, 178.323, 178.129, 177.934, 177.777),
        "sigma2": (127.207, 125.68, 124.89, 124.62, 124.486, 124.349, 124.24),
    },
    "rectangle": {
        "sigma1": (182.749, 180.027, 178.75, 178.34, 178.14, 177.939, 177.777),
        "sigma2": (127.715, 125.80, 124.92, 124.63, 124.49, 124.353, 124.24),
    },
}


def table4_printed(material: str, column: str) -> tuple[float, float]:
    """Printed (sigma_1, sigma_2) of Table 4 [GPa]."""
    return TABLE4[material][column]


def table5_printed(basis: str, size: int) -> tuple[float, float]:
    """Printed (sigma_1, sigma_2) of Table 5 [GPa] for SiC, basis form and m = n."""
    k = TABLE5_SIZES.index(size)
    return TABLE5[basis]["sigma1"][k], TABLE5[basis]["sigma2"][k]
