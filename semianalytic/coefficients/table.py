"""Tables of A(P), B(P), C(P) from first contact to deep penetration (Part I, eqs. (12)-(15), Fig. 8).

The table samples depths densely while the nose enters (A ~ P^3 and C ~ P^2 at first
contact) and geometrically beyond it, up to hundreds of nose lengths.  Between samples the
coefficients are interpolated with monotone cubic Hermite splines (C^1, as the adaptive
integrator of the equation of motion needs); beyond the last sample they approach the
deep-penetration limit like 1/P (errata item 2b: the free-surface image keeps A decaying
like 1/P and B_body rising well past the nose length), the limit being extrapolated from
the tail of the table by a least-squares fit in 1/P.
"""

from __future__ import annotations

import bisect
import json
import math
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.interpolate import PchipInterpolator

from semianalytic.bem.panels import LayoutOptions
from semianalytic.coefficients import READINGS
from semianalytic.coefficients.depth import DepthCoefficients, coefficients_at_depth
from semianalytic.geometry import Nose

TABLE_VERSION = 4  # bump when the numerics change, to invalidate caches


def default_depths(nose: Nose, n_depths: int = 60, max_depth_nose_lengths: float = 300.0) -> np.ndarray:
    """Depths from first contact to ``max_depth_nose_lengths`` nose lengths.

    Half of them while the nose enters (geometric from 1% of L_h, then linear, stopping
    short of L_h where the layout changes topology), half beyond, geometric.  A flat nose
    (L_h = 0) uses the radius as its length scale.
    """
    Lh = nose.length
    scale = Lh if Lh > 0.05 * nose.radius else nose.radius
    P_max = max_depth_nose_lengths * scale
    if Lh > 0.05 * nose.radius:
        n_in = n_depths // 2
        n_geo = n_in // 3
        entry = np.concatenate(
            [np.geomspace(0.01, 0.2, n_geo, endpoint=False), np.linspace(0.2, 0.985, n_in - n_geo)]
        ) * Lh
        deep = np.geomspace(1.015 * Lh, P_max, n_depths - n_in)
        return np.concatenate([entry, deep])
    return np.geomspace(0.01 * scale + Lh, P_max, n_depths)


def deep_limit(depth: np.ndarray, values: np.ndarray) -> float:
    """Limit as P -> infinity from a least-squares fit X = X_inf + a/P + b/P^2 over the
    deepest decade of the table (at least the last four depths)."""
    tail = max(4, int(np.sum(depth >= 0.1 * depth[-1])))
    P = depth[-tail:]
    X = values[-tail:]
    M = np.column_stack([np.ones_like(P), 1.0 / P, 1.0 / P**2])
    coef, *_ = np.linalg.lstsq(M, X, rcond=None)
    return float(coef[0])


@dataclass(frozen=True, eq=False)
class CoefficientTable:
    """A(P) [m^3], B(P) [m^2] in three readings, C(P) [m^2] and phi at the tip [m].

    Call ``A(P)``, ``B(P)``, ``C(P)`` with floats or arrays (P >= 0, SI); ``reading``
    selects the B of errata item 2a (default ``body``).
    """

    nose_kind: str
    diameter: float
    nose_length: float
    depth: np.ndarray
    values: dict  # name -> array over depth: A, B_body, B_literal, B_bernoulli, C, phi_tip, dA_dP
    limits: dict  # name -> deep-penetration limit
    unknowns: np.ndarray
    nodes: tuple = field(repr=False)  # per depth: dict of surface arrays (see DepthCoefficients)
    options: dict = field(default_factory=dict)
    reading: str = "body"

    def __post_init__(self):
        if self.reading not in READINGS:
            raise ValueError(f"reading must be one of {READINGS}")
        splines = {}
        P = np.concatenate([[0.0], self.depth])
        for name, vals in self.values.items():
            if name in ("dA_dP", "dphi_tip_dP"):
                continue
            splines[name] = PchipInterpolator(P, np.concatenate([[0.0], vals]), extrapolate=False)
        object.__setattr__(self, "_splines", splines)
        # scalar fast path (the equation of motion calls A, B, C with one depth at a time)
        object.__setattr__(self, "_breaks", P.tolist())
        object.__setattr__(self, "_coef", {k: sp.c.T.tolist() for k, sp in splines.items()})

    # --- evaluation -----------------------------------------------------------------

    def _eval(self, name: str, P):
        if isinstance(P, float) and 0.0 <= P <= self._breaks[-1]:
            i = min(max(bisect.bisect_right(self._breaks, P) - 1, 0), len(self._breaks) - 2)
            c3, c2, c1, c0 = self._coef[name][i]
            h = P - self._breaks[i]
            return ((c3 * h + c2) * h + c1) * h + c0
        P = np.asarray(P, dtype=float)
        if np.any(P < 0) or not np.all(np.isfinite(P)):
            raise ValueError("depth P must be finite and >= 0")
        out = np.empty_like(P)
        last = self.depth[-1]
        inside = P <= last
        out[inside] = self._splines[name](P[inside])
        if np.any(~inside):
            inf = self.limits[name]
            out[~inside] = inf + (self.values[name][-1] - inf) * last / P[~inside]
        return out[()]

    def A(self, P):
        """Added-mass volume A(P) = integral phi n_x dS [m^3] (Part I, eq. (12))."""
        return self._eval("A", P)

    def B(self, P, reading: str | None = None):
        """Drag area B(P) [m^2] in the given reading (Part I, eq. (12); errata item 2a)."""
        reading = reading or self.reading
        if reading not in READINGS:
            raise ValueError(f"reading must be one of {READINGS}; got {reading!r}")
        return self._eval(f"B_{reading}", P)

    def C(self, P):
        """Contact area C(P) = integral n_x dS [m^2] (Part I, eq. (12))."""
        return self._eval("C", P)

    def phi_tip(self, P):
        """phi at the nose tip [m] (Fig. 6)."""
        return self._eval("phi_tip", P)

    def dA_dP(self, P):
        """dA/dP [m^2]: the derivative of the interpolant (equals B_bernoulli)."""
        P = np.asarray(P, dtype=float)
        out = np.empty_like(P)
        inside = P <= self.depth[-1]
        out[inside] = self._splines["A"].derivative()(P[inside])
        last, inf = self.depth[-1], self.limits["A"]
        out[~inside] = -(self.values["A"][-1] - inf) * last / P[~inside] ** 2
        return out[()]

    def with_reading(self, reading: str) -> "CoefficientTable":
        """The same table with another default B reading."""
        return replace(self, reading=reading)

    def deep_limit(self, reading: str | None = None) -> tuple[float, float, float]:
        """(A_inf, B_inf, C_inf) as P -> infinity."""
        reading = reading or self.reading
        return self.limits["A"], self.limits[f"B_{reading}"], self.limits["C"]

    # --- normalised (Part I, after eq. (34); errata item 2) --------------------------

    @property
    def area(self) -> float:
        return math.pi * self.diameter**2 / 4

    def A_bar(self, P):
        """Abar = 4A/(pi d^2), a length [m]."""
        return self.A(P) / self.area

    def B_bar(self, P, reading: str | None = None):
        """Bbar = 4B/(pi d^2) (dimensionless)."""
        return self.B(P, reading) / self.area

    def C_bar(self, P):
        """Cbar = 4C/(pi d^2) (dimensionless)."""
        return self.C(P) / self.area

    # --- contact pressure and region (Part I, eqs. (9), (13), (15)) ------------------

    def _nearest(self, P: float) -> dict:
        k = int(np.argmin(np.abs(self.depth - P)))
        return self.nodes[k]

    def pressure_profile(self, P: float, rho: float, u: float, du_dt: float, R_t: float, reading: str | None = None):
        """Contact pressure p_c of Part I, eq. (9) at the surface nodes (tabulated depth nearest P).

        p_c = rho phi du/dt + (|grad phi|^2 + 2 phi'_P) rho u^2/2 + R_t; in the ``bernoulli``
        reading the sign of |grad phi|^2 is corrected (errata item 2a).  Returns (x, p_c):
        target-frame abscissae of the nodes (0 <= x <= P) and pressures [Pa].
        """
        reading = reading or self.reading
        n = self._nearest(P)
        if reading == "body":
            q = n["grad2"] + 2 * n["dphi_dP_body"]
        elif reading == "literal":
            q = n["grad2"] + 2 * n["dphi_dP_literal"]
        else:
            q = -n["grad2"] + 2 * n["dphi_dP_literal"]
        return n["x"], rho * n["phi"] * du_dt + q * rho * u * u / 2 + R_t

    def contact_intervals(self, P: float, rho: float, u: float, du_dt: float, R_t: float, reading: str | None = None):
        """Separated intervals [(x0, x1), ...] of the nose, where p_c <= 0 (eq. (15)); [] if none."""
        n = self._nearest(P)
        x, p = self.pressure_profile(P, rho, u, du_dt, R_t, reading)
        on_nose = n["nx"] > 1e-12
        sep = (p <= 0) & on_nose
        out = []
        k = 0
        while k < len(sep):
            if sep[k]:
                j = k
                while j + 1 < len(sep) and sep[j + 1]:
                    j += 1
                out.append((float(min(x[k], x[j])), float(max(x[k], x[j]))))
                k = j + 1
            else:
                k += 1
        return out

    # --- persistence ------------------------------------------------------------------

    def to_npz_bytes(self) -> bytes:
        """The table as the bytes of an ``.npz`` archive (persisted by :mod:`semianalytic.cache`)."""
        import io

        keys = list(self.nodes[0])
        counts = np.array([len(n["x"]) for n in self.nodes])
        buf = io.BytesIO()
        np.savez(
            buf,
            meta=json.dumps(
                {"nose_kind": self.nose_kind, "diameter": self.diameter, "nose_length": self.nose_length,
                 "limits": self.limits, "options": self.options, "version": TABLE_VERSION, "node_keys": keys}
            ),
            depth=self.depth,
            unknowns=self.unknowns,
            counts=counts,
            **{f"v_{k}": v for k, v in self.values.items()},
            **{f"n_{k}": np.concatenate([n[k] for n in self.nodes]) for k in keys},
        )
        return buf.getvalue()

    @classmethod
    def from_npz(cls, source) -> "CoefficientTable":
        """The table from an ``.npz`` archive (a path or a binary file object)."""
        with np.load(source, allow_pickle=False) as z:
            meta = json.loads(str(z["meta"]))
            if meta.get("version") != TABLE_VERSION:
                raise ValueError("coefficient table cache has another version")
            counts = z["counts"]
            bounds = np.concatenate([[0], np.cumsum(counts)])
            node_arrays = {k: z[f"n_{k}"] for k in meta["node_keys"]}
            nodes = tuple({k: v[a:b] for k, v in node_arrays.items()} for a, b in zip(bounds[:-1], bounds[1:]))
            values = {k[2:]: z[k] for k in z.files if k.startswith("v_")}
            return cls(meta["nose_kind"], meta["diameter"], meta["nose_length"], z["depth"], values,
                       meta["limits"], z["unknowns"], nodes, meta["options"])


def coefficients_at(nose: Nose, depths, order: int = 8, refinement: float = 1.0, levels: int = 12) -> dict:
    """A, B (three readings), C, phi_tip, dA/dP at the given depths (arrays, SI)."""
    opts = LayoutOptions(order, refinement, levels)
    rows = [coefficients_at_depth(nose, float(P), opts) for P in np.atleast_1d(depths)]
    return {
        "depth": np.array([r.depth for r in rows]),
        "A": np.array([r.A for r in rows]),
        "B_body": np.array([r.B_body for r in rows]),
        "B_literal": np.array([r.B_literal for r in rows]),
        "B_bernoulli": np.array([r.B_bernoulli for r in rows]),
        "C": np.array([r.C for r in rows]),
        "phi_tip": np.array([r.phi_tip for r in rows]),
        "dA_dP": np.array([r.dA_dP for r in rows]),
        "unknowns": np.array([r.unknowns for r in rows]),
    }


def coefficient_table(
    nose: Nose,
    *,
    order: int = 8,
    refinement: float = 0.3,
    levels: int = 6,
    n_depths: int = 60,
    max_depth_nose_lengths: float = 300.0,
    depths=None,
    progress: bool = False,
) -> CoefficientTable:
    """Tabulate A, B, C of a nose from first contact to deep penetration (Fig. 8)."""
    depths = np.asarray(default_depths(nose, n_depths, max_depth_nose_lengths) if depths is None else depths, float)
    opts = LayoutOptions(order, refinement, levels)
    it = depths
    if progress:
        from tqdm import tqdm

        it = tqdm(depths, desc="BEM depths", unit="depth", leave=False)
    rows: list[DepthCoefficients] = [coefficients_at_depth(nose, float(P), opts) for P in it]
    names = ("A", "B_body", "B_literal", "B_bernoulli", "C", "phi_tip", "dA_dP", "dphi_tip_dP")
    values = {k: np.array([getattr(r, k) for r in rows]) for k in names}
    limits = {k: deep_limit(depths, values[k]) for k in names if k not in ("dA_dP", "dphi_tip_dP")}
    if depths[-1] > nose.length:
        limits["C"] = math.pi * nose.radius**2  # exact once the nose is in
    return CoefficientTable(
        nose_kind=nose.kind,
        diameter=nose.diameter,
        nose_length=nose.length,
        depth=depths,
        values=values,
        limits=limits,
        unknowns=np.array([r.unknowns for r in rows]),
        nodes=tuple(r.nodes for r in rows),
        options={"order": order, "refinement": refinement, "levels": levels},
    )
