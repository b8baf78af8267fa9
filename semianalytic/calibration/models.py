"""Depth of penetration of every depth model as a function of the target resistance R_t.

The calibration infers target properties; each depth model sees them only through the
target density rho_t (fixed) and the resistance R_t (Part I, eqs. (16)-(19)).  For a set of
shots (mass m_i, striking velocity U_i) this module gives the depth D_i(R_t) of each model
at any number of R_t values, and a Chebyshev surrogate in ln R_t that is built once per
(model, shot set) and then evaluated for thousands of posterior samples in microseconds.

Models (the names of :data:`MODELS`):

* ``rigid``: Part I, eq. (11), u(0) = U_s.  In w = u^2 the equation is linear,
  (m + rho A) dw/dP = -(rho B w + 2 C R_t), so w = e^{-F(P)} (U^2 - R_t G_1(P)) with F and
  G_1 = G/R_t independent of R_t: the final depth solves G_1(P_f) = U^2/R_t, i.e.
  P_f(U; R_t) = P_f(U sqrt(R_0/R_t); R_0).  One integration per mass serves every R_t
  (:func:`rigid_depths`), exactly.
* ``quasi_rigid``: the same from the start velocity U_0 of eq. (26), whose axial stress
  sigma_0 = alpha U_0^2 + beta has beta proportional to R_t (exact, vectorised in R_t).
* ``elastic`` (paper's W2, eqs. (29), (30')) and ``elastic_exact_rod`` (exact-rod energy,
  errata item 5): :func:`semianalytic.penetration.curve.penetration_curve` at the surrogate's
  nodes (the energy depends on the stop time, so no scaling holds); per-shot masses by
  polynomial interpolation between Chebyshev nodes in m.
* ``eroding``: the Alekseevskii-Tate eroding rod (:mod:`semianalytic.penetration.regime`) as a
  function of its two strengths theta = (R_t, Y_p) (either may be fixed): no surrogate, the
  closed-form I(v) and a fixed Gauss rule evaluate every draw and shot at once
  (:class:`ErodingDepths`; the depth is proportional to the rod length L_0 of each shot's mass).
* ``forrestal``: Forrestal's cavity-expansion formula with the cavity law's shape (A, B, C)
  and its yield stress set so that its static term A Y equals R_t; ``chen_li``: Chen & Li
  (2002) with the static resistance R_t and B = 3/2 (as in :mod:`.penetration.validation`).

Pure: SI floats and numpy arrays; no case, units or reports.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import chebyshev as cheb

from semianalytic.penetration import peers
from semianalytic.penetration.curve import PenetrationSetup, penetration_curve
from semianalytic.penetration.elastic import quasi_rigid_start, start_force_coefficients
from semianalytic.penetration.motion import depth_profile

__all__ = ["MODELS", "PHYSICALLY_CONSISTENT", "ShotSet", "DepthModelInputs", "model_depths",
           "rigid_depths", "DepthSurrogate", "build_surrogate", "ThetaColumn", "ErodingDepths"]

# the keys of semianalytic.penetration.validation.MODEL_LABELS (its labels are used by the report;
# that module reads CSV files, so a pure model does not import it)
from semianalytic.calibration.names import MODELS, PHYSICALLY_CONSISTENT  # noqa: E402,F401


@dataclass(frozen=True)
class ShotSet:
    """Shots as arrays (SI): striking velocity U [m/s], mass m [kg], measured depth [m] (NaN
    where a shot is only predicted), ids."""

    velocity: np.ndarray
    mass: np.ndarray
    depth: np.ndarray
    ids: tuple[str, ...]

    def __len__(self) -> int:
        return len(self.velocity)

    def subset(self, index) -> ShotSet:
        idx = np.atleast_1d(np.arange(len(self))[index])
        return ShotSet(self.velocity[idx], self.mass[idx], self.depth[idx], tuple(self.ids[i] for i in idx))


@dataclass(frozen=True)
class DepthModelInputs:
    """Everything but R_t and the shot: a PenetrationSetup (coefficients, rho_t, rod, ...),
    the nose factors (N_1, N_2) and the cavity law's shape (A, B, C) for Forrestal."""

    setup: PenetrationSetup
    nose_factors: tuple[float, float]
    cavity_shape: tuple[float, float, float]


def rigid_depths(inputs: DepthModelInputs, R, shots: ShotSet, quasi: bool = False) -> np.ndarray:
    """Final depth [m] of Part I, eq. (11), (n_R, n_shots), exactly for every R_t (module
    docstring); ``quasi``: from the start velocity of eq. (26) instead of U_s."""
    R = np.atleast_1d(np.asarray(R, float))
    s = inputs.setup
    out = np.empty((len(R), len(shots)))
    R0 = float(R.min())
    for m in np.unique(shots.mass):
        cols = np.flatnonzero(shots.mass == m)
        U = shots.velocity[cols][None, :]
        if quasi:
            alpha, beta0 = start_force_coefficients(s.coefficients, m, s.target_density, R0)
            beta = beta0 * (R / R0)[:, None]  # beta = f C R_t (linear in R_t)
            U, _ = quasi_rigid_start(U, s.rod.c0, s.rod.youngs_modulus, alpha, beta)
        U_eq = np.broadcast_to(U * np.sqrt(R0 / R)[:, None], (len(R), len(cols)))  # G_1(P_f) = U^2/R_t
        prof = depth_profile(s.coefficients, float(m), s.target_density, R0, float(max(U_eq.max(), 1e-9)))
        out[:, cols] = prof.final_depth(np.minimum(U_eq, prof.U_max))
    return out


def _elastic_depths(inputs: DepthModelInputs, R, shots: ShotSet) -> dict[str, np.ndarray]:
    """Both elastic models (n_R, n_shots) by penetration_curve at every R_t, with the masses
    interpolated between Chebyshev nodes in m (linear below a 1 % mass range, else
    quadratic: the depth is smooth in m, and the interpolation error is below 1e-5, against
    the exact-rod model's own steps of ~3e-3, see :class:`DepthSurrogate`)."""
    R = np.atleast_1d(np.asarray(R, float))
    m_lo, m_hi = float(shots.mass.min()), float(shots.mass.max())
    if m_hi - m_lo <= 1e-9 * m_hi:
        m_nodes = np.array([m_lo])
    else:
        k = 2 if m_hi - m_lo < 1e-2 * m_hi else 3
        m_nodes = 0.5 * (m_lo + m_hi) + 0.5 * (m_hi - m_lo) * np.cos(np.pi * (np.arange(k) + 0.5) / k)
    Uu, inv = np.unique(shots.velocity, return_inverse=True)
    out = {key: np.empty((len(R), len(shots))) for key in ("elastic", "elastic_exact_rod")}
    # Lagrange weights of every shot's mass on the nodes
    L = np.ones((len(shots), len(m_nodes)))
    for j, mj in enumerate(m_nodes):
        for k_, mk in enumerate(m_nodes):
            if k_ != j:
                L[:, j] *= (shots.mass - mk) / (mj - mk)
    for a, Ra in enumerate(R):
        vals = {key: np.empty((len(m_nodes), len(Uu))) for key in out}
        for j, mj in enumerate(m_nodes):
            setup = dataclasses.replace(inputs.setup, resistance_pa=float(Ra), mass=float(mj))
            res = penetration_curve(setup, Uu)
            vals["elastic"][j] = res["depth_elastic_m"]
            vals["elastic_exact_rod"][j] = res["depth_elastic_exact_rod_m"]
        for key in out:
            out[key][a] = np.einsum("ij,ji->i", L, vals[key][:, inv])
    return out


def _peer_depths(inputs: DepthModelInputs, R, shots: ShotSet, model: str) -> np.ndarray:
    s = inputs.setup
    d = float(s.coefficients.diameter)
    N1, N2 = inputs.nose_factors
    cA, cB, cC = inputs.cavity_shape
    R = np.atleast_1d(np.asarray(R, float))
    out = np.empty((len(R), len(shots)))
    for a, Ra in enumerate(R):
        for i in range(len(shots)):
            m, U = float(shots.mass[i]), shots.velocity[i : i + 1]
            if model == "forrestal":
                law = peers.CavityLaw(Ra / cA, cA, cB, cC)  # static term A Y = R_t
                out[a, i] = np.atleast_1d(peers.forrestal_depth(m, d, s.target_density, law, U, N1, N2))[0]
            else:
                out[a, i] = np.atleast_1d(peers.chen_li_depth(m, d, s.target_density, float(Ra), 1.5, N2, U))[0]
    return out


def model_depths(inputs: DepthModelInputs, models, R, shots: ShotSet) -> dict[str, np.ndarray]:
    """Depth [m] of each model in ``models`` at every R_t [Pa] for every shot: {model: (n_R, n_shots)}
    (Part I, eq. (11), with eqs. (26), (29)/(30') for the elastic models; the peers' laws)."""
    out: dict[str, np.ndarray] = {}
    for model in models:
        if model == "rigid":
            out[model] = rigid_depths(inputs, R, shots)
        elif model == "quasi_rigid":
            out[model] = rigid_depths(inputs, R, shots, quasi=True)
        elif model in ("elastic", "elastic_exact_rod"):
            if model not in out:
                out.update({k: v for k, v in _elastic_depths(inputs, R, shots).items() if k in models})
        elif model in ("forrestal", "chen_li"):
            out[model] = _peer_depths(inputs, R, shots, model)
        else:
            raise ValueError(f"unknown model {model!r}")
    return out


@dataclass(frozen=True)
class DepthSurrogate:
    """ln D_i(R_t) of one model for a shot set as a Chebyshev series in x = ln R_t on
    [ln R_lo, ln R_hi]: ``coef`` (n_nodes, n_shots).  ``log_depth(R)`` -> (n_R, n_shots);
    outside the interval NaN (the caller treats it as zero probability)."""

    model: str
    R_lo: float
    R_hi: float
    coef: np.ndarray

    def log_depth(self, R) -> np.ndarray:
        R = np.atleast_1d(np.asarray(R, float))
        with np.errstate(invalid="ignore", divide="ignore"):
            x = (2.0 * np.log(R) - math.log(self.R_lo) - math.log(self.R_hi)) / (math.log(self.R_hi) - math.log(self.R_lo))
        inside = (x >= -1.0 - 1e-12) & (x <= 1.0 + 1e-12)
        x = np.where(inside, x, 0.0)[:, None]
        # Clenshaw recurrence of sum_k c_k T_k(x), all shots at once
        b1 = b2 = 0.0
        for c in self.coef[:0:-1]:
            b1, b2 = c[None, :] + 2.0 * x * b1 - b2, b1
        out = self.coef[0][None, :] + x * b1 - b2
        out[~inside] = np.nan
        return out

    def log_depth_theta(self, theta, resistance) -> np.ndarray:
        """ln D (n, n_shots) at parameter draws theta (n, p) through R_t = resistance(theta)
        (NaN where R_t is not finite or outside the surrogate's range)."""
        R = np.asarray(resistance(theta), float)
        ok = np.isfinite(R)
        out = self.log_depth(np.where(ok, R, self.R_lo))
        out[~ok] = np.nan
        return out

    def subset(self, keep) -> DepthSurrogate:
        """The surrogate of the shots ``keep`` (column indices)."""
        return dataclasses.replace(self, coef=self.coef[:, keep])


def chebyshev_nodes(lo: float, hi: float, n: int) -> np.ndarray:
    """n Chebyshev points of the first kind, log-spaced on [lo, hi] (ascending)."""
    x = np.cos(np.pi * (np.arange(n)[::-1] + 0.5) / n)
    return np.exp(0.5 * (math.log(lo) + math.log(hi)) + 0.5 * (math.log(hi) - math.log(lo)) * x) * 1.0


def build_surrogate(inputs: DepthModelInputs, models, shots: ShotSet, R_lo: float, R_hi: float,
                    n_nodes: int = 16) -> dict[str, DepthSurrogate]:
    """A :class:`DepthSurrogate` per model on [R_lo, R_hi] from the depths at ``n_nodes``
    Chebyshev nodes in ln R_t (interpolation, so exact at the nodes; the tests check it
    off the nodes against the direct evaluation)."""
    if not (0 < R_lo < R_hi):
        raise ValueError("need 0 < R_lo < R_hi")
    nodes = chebyshev_nodes(R_lo, R_hi, n_nodes)
    x = (2.0 * np.log(nodes) - math.log(R_lo) - math.log(R_hi)) / (math.log(R_hi) - math.log(R_lo))
    depths = model_depths(inputs, models, nodes, shots)
    out = {}
    for model in models:
        D = depths[model]
        with np.errstate(divide="ignore"):
            y = np.log(np.maximum(D, 1e-300))
        coef = cheb.chebfit(x, y, n_nodes - 1)
        out[model] = DepthSurrogate(model, float(R_lo), float(R_hi), np.atleast_2d(coef.reshape(n_nodes, -1)))
    return out


@dataclass(frozen=True)
class ThetaColumn:
    """theta -> one calibrated parameter (column ``index``) or, when it is not calibrated
    (index None), its fixed value: the R_t or Y_p of the eroding rod per draw."""

    index: int | None
    fixed: float

    def __call__(self, theta) -> np.ndarray:
        theta = np.atleast_2d(np.asarray(theta, float))
        return theta[:, self.index].copy() if self.index is not None else np.full(len(theta), self.fixed)


@dataclass(frozen=True)
class ErodingDepths:
    """ln depth of the Alekseevskii-Tate eroding rod (penetration.regime, eq. of the module
    docstring there) for a shot set, at parameter draws theta: R_t = ``resistance(theta)``,
    Y_p = ``strength(theta)`` (each a :class:`ThetaColumn`); ``rod_length`` L_0 per shot (the
    cylinder of the shot's mass).  Depth 0 (the target does not yield, Y_p < R_t and U_s <= v_e)
    is floored at 1e-12 m, so its ln is finite and far below any measured depth."""

    velocity: np.ndarray
    rod_length: np.ndarray
    density: float
    target_density: float
    resistance: ThetaColumn
    strength: ThetaColumn
    model: str = "eroding"

    def log_depth_theta(self, theta, resistance=None) -> np.ndarray:
        from semianalytic.penetration.regime import eroding_depth_per_length

        R = self.resistance(theta)[:, None]
        Y = self.strength(theta)[:, None]
        ok = np.isfinite(R) & np.isfinite(Y) & (R > 0) & (Y > 0)
        d, _, _ = eroding_depth_per_length(self.velocity[None, :], density=self.density,
                                           target_density=self.target_density,
                                           target_resistance=np.where(ok, R, 1e9), rod_strength=np.where(ok, Y, 1e9))
        out = np.log(np.maximum(d * self.rod_length[None, :], 1e-12))
        return np.where(ok, out, np.nan)

    def subset(self, keep) -> ErodingDepths:
        keep = np.atleast_1d(keep)
        return dataclasses.replace(self, velocity=self.velocity[keep], rod_length=self.rod_length[keep])
