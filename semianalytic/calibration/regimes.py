"""The whole-range regime model, its posterior and its transfer between projectile materials.

Model (per shot i of striking velocity U_i, mass m_i, Rockwell C hardness H_i; calibrated: the
dynamic factor f, with ``deforming = "two_stage"`` (the default) the breakup factor b, the
discrepancy sigma and the transition scatter tau):

* projectile dynamic yield stress Y_p,i = f sigma_y(H_i) (ASTM E140 + Pavlina & Van Tyne 2008,
  :mod:`semianalytic.penetration.hardness`);
* rigid -> deforming at U_y,i by the criterion ``onset`` (:data:`.regime.ONSET_CRITERIA`: Tate's
  (1967) tip pressure against the rod's static Meyer hardness H_M(H_i), the default, with no fitted
  constant; against Tabor's (1951) constrained yield stress 3 Y_p,i; or U_sC(Y_p,i) of Part I,
  eqs. (33)/(36), shot's mass);
* deforming -> eroding at U_e,i by the criterion ``erosion`` (:data:`.regime.EROSION_CRITERIA`:
  the same tip pressure against 3 f sigma_u(H_i), the default, Tate's flat-rod criterion, or
  this project's nose-length rule);
* depth: Part I (elastic projectile, exact-rod W2) when rigid; the Alekseevskii-Tate rod with
  R_t from ``resistance`` (:data:`.regime.RESISTANCE_RELATIONS`: Part I eq. (16) or Tate 1986) and
  the rod strength ``rod_strength`` (Y_p,i or, the default, f sigma_u(H_i)) when eroding; in the
  deforming band the model ``deforming`` (:data:`.regime.DEFORMING_MODELS`; default ``two_stage``:
  the Part I depth of a bent rod that keeps its nose until the tip pressure reaches b H_M, the
  eroding rod's beyond -- this project's own, with b fitted);
* ln P_i = ln D_i(f) + eps_i, eps_i ~ N(0, sigma^2); and the recorded response of each shot
  matches the predicted regime with probability 1 - epsilon (:data:`LABEL_ERROR`).

Nothing but f is fitted: R_t and Y_p follow from the materials' published properties.  Priors
(physical ranges): f ~ Uniform(1, 3): at least the static strength (the definition of a
dynamic factor) and at most three times it (split-Hopkinson data of high-strength steels at
1e3-1e4 /s give 1.1-1.5 over the quasi-static yield, e.g. Johnson & Cook 1985 for 4340; the
factor also absorbs the conversion's scatter, 1-sigma about 10 % (Pavlina & Van Tyne 2008), and
Part I's Appendix infers 1.44 x the tensile yield of VAR 4340 from its U_sC, i.e. 1.68 x the
hardness value); sigma ~ HalfNormal(0.3) (a 30 % scatter of depth at one standard deviation).

Posterior: exact on a grid of f (:func:`grid_posterior`, used by the transfer study: fast and
deterministic) and sampled by emcee in 4 independent ensembles with arviz's rank-normalised
split R-hat and bulk/tail effective sample sizes (each walker a chain) (:func:`sample_regimes`, the shipped
posterior; the grid is its check).

Transfer (:func:`transfer_study`): leave-one-group-out by projectile material: f fitted on one
material's shots, every shot of the other predicted (regime probability, regime-aware median and
90 % interval of the mixture over the posterior).  :func:`regime_shots` reads a case's shots
(the case glue); the rest works on SI arrays.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from semianalytic.penetration import regime as rg
from semianalytic.penetration.nose_load import NOSE_LOADS, transition_velocity
from semianalytic.penetration.regime_setup import case_nose_loads

__all__ = ["RegimeShots", "Options", "DEFAULT_OPTIONS", "OPTION_SETS", "F_PRIOR", "SIGMA_PRIOR_SCALE",
           "model_outcome", "grid_posterior", "predict", "transfer_scores", "sample_regimes"]

F_PRIOR = (1.0, 3.0)
SIGMA_PRIOR_SCALE = 0.3
_F_GRID = np.linspace(F_PRIOR[0], F_PRIOR[1], 401)  # 0.005 apart: finer than any posterior width found
_SIGMA_GRID = np.exp(np.linspace(np.log(0.02), np.log(1.0), 30))
_Y_TABLE = np.exp(np.linspace(np.log(3e8), np.log(1.2e10), 321))  # Y_p knots of the U_e table


@dataclass(frozen=True)
class Options:
    """One model set: rigid -> deforming criterion, deforming -> eroding criterion, the R_t
    relation and the Y_p reading of the eroding rod, and the depth model of the deforming band
    (:mod:`semianalytic.penetration.regime`)."""

    onset: str = "nose_meyer"
    erosion: str = "nose_meyer"
    resistance: str = "tate1986"
    rod_strength: str = "static_ultimate"
    deforming: str = "two_stage"
    discrepancy: str = "per_regime"
    rigid_depth: str = "forrestal"
    nose_load: str = "part1"
    deformed_depth: str = "forrestal"

    def label(self) -> str:
        return (f"onset={self.onset}, erosion={self.erosion}, load={self.nose_load}, R_t={self.resistance}, "
                f"Y_p={self.rod_strength}, deforming={self.deforming}, sigma={self.discrepancy}, "
                f"rigid={self.rigid_depth}, bent={self.deformed_depth}")

    def as_dict(self) -> dict:
        return {"onset": self.onset, "erosion": self.erosion, "resistance": self.resistance,
                "rod_strength": self.rod_strength, "deforming": self.deforming, "discrepancy": self.discrepancy,
                "rigid_depth": self.rigid_depth, "nose_load": self.nose_load, "deformed_depth": self.deformed_depth}

    @classmethod
    def from_dict(cls, d: dict) -> Options:
        """Options from a posterior's ``options`` (a version-1 posterior lacks the nose-load keys: its
        model set had no nose load and the Part I depth for a bent rod)."""
        d = dict(d)
        d.setdefault("nose_load", "tip")
        d.setdefault("deformed_depth", d.get("rigid_depth", "part1"))
        return cls(**d)

    def check(self, field: str = "--option") -> Options:
        """InputError naming the key and the allowed values if a choice does not exist."""
        from semianalytic.errors import InputError

        for k, vals in OPTION_VALUES.items():
            v = getattr(self, k)
            if v not in vals:
                raise InputError(f"{field} {k}" if field.startswith("--") else f"{field}.{k}",
                                 f"unknown value {v!r}; allowed: {', '.join(vals)}")
        return self


RIGID_DEPTHS = ("part1", "forrestal")
"""The depth of a rod that keeps its nose (rigid, and bent in the deforming band): ``part1`` (Part I,
the elastic projectile with the exact-rod W2) or ``forrestal`` (Forrestal et al.'s cavity-expansion
model, the peer of ``penetrate``, with the data authors' target constants where ``[data]`` gives them)."""

DISCREPANCIES = ("shared", "per_regime")
"""The depth discrepancy sigma: one for every state (``shared``), or one for the rigid state and one
for the deformed states (``per_regime``: the Part I model of a rigid rod is checked to 5-10 % on
rigid shots, a deforming or eroding rod is not; one sigma for both widens the rigid intervals by
the misfit of the others)."""
NEW_ROD_STRENGTHS = ("static_ultimate", "static_yield")
OPTION_VALUES = {"onset": rg.ONSET_CRITERIA, "erosion": rg.EROSION_CRITERIA, "resistance": rg.RESISTANCE_RELATIONS,
                 "rod_strength": rg.ROD_STRENGTHS, "deforming": rg.DEFORMING_MODELS, "discrepancy": DISCREPANCIES,
                 "rigid_depth": RIGID_DEPTHS, "nose_load": NOSE_LOADS, "deformed_depth": RIGID_DEPTHS}
"""Every choice of a model set and its allowed values (the case file's ``[regimes]`` keys and
``calibrate --option KEY=VALUE``)."""


def uses_nose_load(opt) -> bool:
    """Whether the model set's transitions are the nose-load criteria (first parameter kappa, with
    the erosion factor e) rather than the legacy criteria (first parameter the dynamic factor f)."""
    return opt.onset == "nose_meyer"


def combination_error(opt) -> str | None:
    """Why a model set cannot be evaluated (None if it can): the nose-load onset and erosion go
    together (kappa is not a dynamic factor), the legacy rod strengths and ``breakup`` need the
    legacy dynamic factor."""
    nl = uses_nose_load(opt)
    if nl != (opt.erosion == "nose_meyer"):
        return "onset = 'nose_meyer' and erosion = 'nose_meyer' go together (their kappa is not a dynamic factor)"
    if nl and opt.rod_strength not in NEW_ROD_STRENGTHS:
        return (f"rod_strength = {opt.rod_strength!r} multiplies the legacy dynamic factor; with the nose-load "
                f"criteria use {' or '.join(NEW_ROD_STRENGTHS)}")
    if nl and opt.deforming == "breakup":
        return "deforming = 'breakup' is the legacy tip-UTS breakup; with the nose-load criteria use two_stage"
    return None


def _one_at_a_time() -> tuple:
    """The default and every alternative that changes one of its choices, plus the published Part I
    onset (eqs. (33)/(36), its own factor) and the earlier default (Tate tip against the Meyer
    hardness, one dynamic factor for the transitions and the eroding rod); the full product is not run."""
    import dataclasses

    base = Options()
    out = [base]
    for name, values in OPTION_VALUES.items():
        for v in values:
            if v == getattr(base, name):
                continue
            o = dataclasses.replace(base, **{name: v})
            if combination_error(o) is None:
                out.append(o)
    out.append(dataclasses.replace(base, onset="part1_usc", erosion="tate_tip_uts"))
    out.append(Options(onset="meyer_tip", erosion="tate_tip_uts", resistance="part1", rod_strength="ultimate",
                       deforming="two_stage", discrepancy="shared", rigid_depth="part1", nose_load="tip",
                       deformed_depth="part1"))
    return tuple(out)


OPTION_SETS = _one_at_a_time()
DEFAULT_OPTIONS = Options()  # chosen by transfer_study (reports/validation_regimes.md)


@dataclass(frozen=True)
class RegimeShots:
    """Shots of one projectile material (SI arrays): ids, velocity, mass, depth (NaN: none),
    recorded regime (0/1/2, -1: none), static yield stress from the hardness, Part I depth,
    U_sC as a function of Y_p (``critical``: callable (Y (n,), shot index) -> U_sC), the eroding
    rod's length per shot and the shared inputs."""

    group: str
    ids: tuple[str, ...]
    velocity: np.ndarray
    mass: np.ndarray
    depth: np.ndarray
    recorded: np.ndarray
    responses: tuple
    static_yield: np.ndarray
    static_ultimate: np.ndarray
    meyer_hardness: np.ndarray
    part1_depth: np.ndarray
    forrestal_depth: np.ndarray
    critical: object
    rod_length: np.ndarray
    length: float
    nose_length: float
    diameter: float
    density: float
    target_density: float
    resistance: dict  # {relation: R_t [Pa]}
    nose_loads: dict | None = None  # {kind: NoseLoad} of this nose and target (penetration/nose_load.py)

    def __len__(self) -> int:
        return len(self.velocity)


def _erosion_table(shots: RegimeShots, opt: Options):
    """U_e(Y_p) of the nose-length rule (this project's own) on :data:`_Y_TABLE` for the group's
    mean rod (U_y is applied per shot)."""
    R = shots.resistance[opt.resistance]
    m = float(np.mean(shots.mass))
    return np.array([rg.erosion_onset_velocity(0.0, length=shots.length, nose_length=shots.nose_length,
                                               diameter=shots.diameter, density=shots.density,
                                               target_density=shots.target_density, target_resistance=R,
                                               rod_strength=float(Y), mass=m) for Y in _Y_TABLE])


_TABLES: dict = {}


_EROSION_CACHE: dict = {}


def _stated_eroding_depth(shots: RegimeShots, opt: Options) -> np.ndarray:
    """The Alekseevskii-Tate depth [m] per shot with the eroding rod's own stated strength
    (``static_ultimate`` / ``static_yield`` x :data:`.regime.ROD_FLOW_FACTOR`): no fitted constant,
    computed once per shots and model set."""
    key = (id(shots), opt.resistance, opt.rod_strength)
    hit = _EROSION_CACHE.get(key)
    if hit is not None and hit[0] is shots:
        return hit[1]
    static = shots.static_ultimate if opt.rod_strength == "static_ultimate" else shots.static_yield
    per_len, _, _ = rg.eroding_depth_per_length(shots.velocity, density=shots.density, target_density=shots.target_density,
                                                 target_resistance=shots.resistance[opt.resistance],
                                                 rod_strength=rg.ROD_FLOW_FACTOR * static)
    depth = per_len * shots.rod_length
    _EROSION_CACHE[key] = (shots, depth)
    return depth


def model_outcome(f, shots: RegimeShots, opt: Options, b=None, e=None):
    """(regime code (n_f, n), depth [m] (n_f, n), U_y (n_f, n), U_e (n_f, n)) for first parameters
    ``f`` (module docstring: the nose-load factor kappa of ``onset = "nose_meyer"``, else the
    legacy dynamic factor) and, with ``deforming = "two_stage"``, breakup factors ``b`` and, with
    ``erosion = "nose_meyer"``, erosion factors ``e`` (one per f)."""
    why = combination_error(opt)
    if why is not None:
        raise ValueError(why)
    f = np.atleast_1d(np.asarray(f, float))
    rho_t = shots.target_density
    R = shots.resistance[opt.resistance]
    R1 = shots.resistance["part1"]  # the legacy onset criteria are about the rigid nose: Part I's R_t
    n = len(shots)
    if uses_nose_load(opt):
        if e is None:
            raise ValueError("erosion = 'nose_meyer' needs erosion factors e")
        if shots.nose_loads is None:
            raise ValueError("these shots carry no nose loads (regime_shots / shots_at compute them)")
        L = shots.nose_loads[opt.nose_load]
        kap = f[:, None]
        H = shots.meyer_hardness[None, :]
        Uy = np.broadcast_to(transition_velocity(kap, H, L.static, L.linear, L.quadratic), (len(f), n))
        ee = np.broadcast_to(np.atleast_1d(np.asarray(e, float)), f.shape)[:, None]
        Ue = np.maximum(Uy, transition_velocity(kap, ee * H, L.static, L.linear, L.quadratic))
        eroding = np.broadcast_to(_stated_eroding_depth(shots, opt)[None, :], (len(f), n))
        if opt.deforming == "two_stage":
            if b is None:
                raise ValueError("deforming = 'two_stage' needs breakup factors b")
            bb = np.broadcast_to(np.atleast_1d(np.asarray(b, float)), f.shape)[:, None]
            Ux = np.clip(transition_velocity(kap, bb * H, L.static, L.linear, L.quadratic), Uy, Ue)
        elif opt.deforming == "part1_upper":
            Ux = Ue
        elif opt.deforming == "eroding":
            Ux = Uy
        else:
            raise ValueError(f"unknown deforming-band model {opt.deforming!r}")
    else:
        Y = f[:, None] * shots.static_yield[None, :]
        Yu = f[:, None] * shots.static_ultimate[None, :]
        fu, inv = np.unique(f, return_inverse=True)  # what depends on f only is computed once per f (b repeats f)
        inv = inv.ravel()
        if opt.onset == "part1_usc":
            Uy = shots.critical(fu[:, None] * shots.static_yield[None, :])[inv]
        elif opt.onset == "tate_tip":
            Uy = rg.tate_erosion_velocity(Y, R1, rho_t, rg.TABOR_CONSTRAINT)
        elif opt.onset == "meyer_tip":  # no fitted constant: the static Meyer hardness itself
            Uy = np.broadcast_to(rg.tate_erosion_velocity(shots.meyer_hardness, R1, rho_t), Y.shape)
        else:
            raise ValueError(f"unknown onset criterion {opt.onset!r}")
        Yrod = {"yield": Y, "ultimate": Yu}.get(opt.rod_strength)
        if opt.erosion == "tate":
            Ue = rg.tate_erosion_velocity(Yrod if Yrod is not None else Yu, R, rho_t)
        elif opt.erosion == "tate_tip_uts":
            Ue = rg.tate_erosion_velocity(Yu, R1, rho_t, rg.TABOR_CONSTRAINT)
        elif opt.erosion == "nose_length":
            key = (id(shots), opt.resistance)
            if key not in _TABLES:
                _TABLES[key] = (shots, _erosion_table(shots, opt))
            Ue = np.interp(np.log(Yrod if Yrod is not None else Yu), np.log(_Y_TABLE), _TABLES[key][1])
        else:
            raise ValueError(f"unknown erosion criterion {opt.erosion!r}")
        Ue = np.maximum(Uy, Ue)
        if Yrod is None:  # the eroding rod's own stated strength
            eroding = np.broadcast_to(_stated_eroding_depth(shots, opt)[None, :], Uy.shape)
        else:
            Yrod_u = fu[:, None] * (shots.static_yield if opt.rod_strength == "yield" else shots.static_ultimate)[None, :]
            per_len, _, _ = rg.eroding_depth_per_length(shots.velocity[None, :], density=shots.density,
                                                         target_density=rho_t, target_resistance=R, rod_strength=Yrod_u)
            eroding = per_len[inv] * shots.rod_length[None, :]
        if opt.deforming == "part1_upper":
            Ux = Ue
        elif opt.deforming == "eroding":
            Ux = Uy
        elif opt.deforming == "breakup":  # Part I below the tip-UTS velocity, eroding above
            Ux = np.clip(rg.tate_erosion_velocity(Yu, R1, rho_t, rg.TABOR_CONSTRAINT), Uy, Ue)
        elif opt.deforming == "two_stage":  # Part I below the breakup pressure b H_M, eroding above
            if b is None:
                raise ValueError("deforming = 'two_stage' needs breakup factors b")
            bb = np.broadcast_to(np.atleast_1d(np.asarray(b, float)), f.shape)
            Ux = rg.breakup_velocity(bb[:, None], shots.meyer_hardness[None, :], R1, rho_t, Uy, Ue)
        else:
            raise ValueError(f"unknown deforming-band model {opt.deforming!r}")
    code = rg.regime_codes(shots.velocity[None, :], Uy, Ue)
    pick = {"forrestal": shots.forrestal_depth, "part1": shots.part1_depth}
    rigid = np.broadcast_to(pick[opt.rigid_depth][None, :], code.shape)
    bent = np.broadcast_to(pick[opt.deformed_depth][None, :], code.shape)
    U = shots.velocity[None, :]
    depth = np.where(U >= Ux, eroding, np.where(U >= Uy, bent, rigid))
    return Thresholds(code, depth, Uy, Ue, Ux, rigid, eroding, bent)


@dataclass(frozen=True)
class Thresholds:
    """Outcome of :func:`model_outcome` (arrays (n_f, n)): regime code and depth at the nominal
    transitions, the transition velocities U_y (rigid -> deforming), U_e (-> eroding) and U_x
    (where the depth becomes the eroding rod's: U_y, the tip-UTS velocity or U_e by the deforming
    model), and the two depths."""

    code: np.ndarray
    depth: np.ndarray
    Uy: np.ndarray
    Ue: np.ndarray
    Ux: np.ndarray
    part1: np.ndarray
    eroding: np.ndarray
    bent: np.ndarray | None = None  # the depth of a deformed rod that keeps its nose (None: part1)

    def __post_init__(self):
        if self.bent is None:
            object.__setattr__(self, "bent", self.part1)

    def __iter__(self):  # (code, depth, U_y, U_e)
        return iter((self.code, self.depth, self.Uy, self.Ue))


def state_probabilities(U, out: Thresholds, tau):
    """Transition scatter: every transition velocity of a shot is scaled by exp(tau z), z ~ N(0, 1)
    (one z per shot: the order of the transitions is kept).  Returns the probabilities (n_f, n)
    of the four states (rigid, deforming with the Part I depth, deforming with the eroding depth,
    eroding): U e^{-tau z} >= T  <=>  z <= ln(U/T)/tau."""
    from scipy.special import ndtr

    t = np.asarray(tau, float).reshape(-1, 1)
    U = np.asarray(U, float)[None, :]

    def above(T):
        with np.errstate(divide="ignore", invalid="ignore"):
            a = np.where(np.isfinite(T), np.log(U / T) / t, -np.inf)
        return ndtr(a)

    py, pe, px = above(out.Uy), above(out.Ue), above(out.Ux)  # U_y <= U_x <= U_e
    p_rigid = 1.0 - py
    p_def_p1 = np.clip(py - px, 0.0, 1.0)
    p_def_er = np.clip(px - pe, 0.0, 1.0)
    return p_rigid, p_def_p1, p_def_er, pe


LABEL_ERROR = 0.05
"""epsilon: the probability that a shot's recorded response is not the regime the model predicts
for it at the true parameters (spread evenly over the two other regimes).  The recorded
response enters the likelihood with it, P(recorded | predicted) = 1 - epsilon or epsilon/2, so
that the transitions are placed by what the experimenters saw and not only by the depths."""


TAU_PRIOR_SCALE = 0.1
_TAU_GRID = np.exp(np.linspace(np.log(0.003), np.log(0.4), 24))


def _state_weights(shots: RegimeShots, out: Thresholds, tau) -> list:
    """Per state (rigid; deforming, Part I depth; deforming, eroding depth; eroding) the probability
    of the state (:func:`state_probabilities`, transition scatter ``tau`` per row) times the
    probability of the recorded response given the state (right with 1 - epsilon, :data:`LABEL_ERROR`)."""
    rec = shots.recorded[None, :]
    probs = state_probabilities(shots.velocity, out, tau)
    return [p * np.where(rec < 0, 1.0, np.where(rec == lab, 1.0 - LABEL_ERROR, 0.5 * LABEL_ERROR))
            for p, lab in zip(probs, (0, 1, 1, 2))]


def _loglik_from_weights(shots: RegimeShots, out: Thresholds, w: list, sig_r, sig_d):
    """ln p(depths, responses) per row from the state weights ``w`` (:func:`_state_weights`): each
    measured depth log-normal about its state's depth (Part I for the first two states, the
    eroding rod for the last two), sigma ``sig_r`` in the rigid state and ``sig_d`` in the others
    (scalars or (rows, 1)); a shot without a depth contributes its response only."""
    has_d = np.isfinite(shots.depth)
    lnP = np.log(np.where(has_d, shots.depth, 1.0))[None, :]

    def dens(D, sg):
        r = lnP - np.log(D)
        return np.where(has_d[None, :], np.exp(-0.5 * (r / sg) ** 2) / sg, 1.0)

    total = w[0] * dens(out.part1, sig_r) + w[1] * dens(out.bent, sig_d) + (w[2] + w[3]) * dens(out.eroding, sig_d)
    return np.sum(np.log(np.maximum(total, 1e-300)), axis=1)


def _log_likelihood(shots: RegimeShots, out: Thresholds, sigma, tau):
    """ln p(depths, responses | f, sigma, tau) per row (out rows match sigma and tau rows, or
    broadcast): over the four states of :func:`state_probabilities`, each response and depth
    jointly.  ``sigma`` (rows,) is shared by the states; (rows, 2) is (rigid state, deformed states)."""
    sp = _sigma_pair(sigma)
    return _loglik_from_weights(shots, out, _state_weights(shots, out, tau), sp[:, 0:1], sp[:, 1:2])


BREAKUP_PRIOR = (1.0, 3.0)
"""Prior of the breakup factor b of ``deforming = "two_stage"``: uniform(1, 3): the breakup pressure
is not below the onset pressure (the static Meyer hardness, b = 1) and at most the 3 x hardness
pressure that no steel rod of the data survives (the eroding regime starts below it)."""
_B_GRID = np.linspace(1.0, 2.0, 51)  # 0.02 apart; the posterior found lies in 1.05-1.35, far from 2
_F_GRID_2D = np.linspace(F_PRIOR[0], 2.2, 121)  # 0.01 apart on the (f, b) grid; the posteriors found lie in
# 1.2-1.5, and the mass at the grid's upper end is checked (at_prior_edge)


def _uses_breakup(opt: Options) -> bool:
    return opt.deforming == "two_stage"


_SIGMA_GRID_2 = np.exp(np.linspace(np.log(0.02), np.log(1.0), 16))


def _sigma_pair(sigma):
    """sigma as (rows, 2) = (rigid state, deformed states): a (rows,) array is shared by both."""
    s = np.asarray(sigma, float)
    return np.column_stack([s, s]) if s.ndim <= 1 else s


def _grid_loglik(shots: RegimeShots, out: Thresholds, sig_r, sig_d, tau):
    """ln p(data | row, sigma_r[i], sigma_d[j], tau_k) for every grid row: (rows, n_r, n_d, n_tau);
    ``sig_d = None``: one sigma shared by every state (n_d = 1).  The same sum as
    :func:`_log_likelihood`, with the state weights computed once per tau."""
    rows = out.Uy.shape[0]
    shared = sig_d is None
    nd = 1 if shared else len(sig_d)
    lp = np.empty((rows, len(sig_r), nd, len(tau)))
    for k, t in enumerate(tau):
        w = _state_weights(shots, out, np.full(rows, t))
        for i, sr in enumerate(sig_r):
            for j in range(nd):
                lp[:, i, j, k] = _loglik_from_weights(shots, out, w, sr, sr if shared else sig_d[j])
    return lp


KAPPA_PRIOR = (0.02, 3.0)
"""Prior of the nose-load factor kappa (``onset = "nose_meyer"``): log-uniform over 0.02-3: the
fraction of the rod's strength surplus H_M - s_0 its nose's dynamic load reaches at the onset; 1
is Tate's flat tip against the Meyer hardness, the ogive's Part I Bbar (0.11) and Forrestal's N_2
(0.1) put it near 0.1-0.3; the range spans an order of magnitude either way."""
EROSION_PRIOR = (1.0, 3.0)
"""Prior of the erosion factor e: uniform(1, 3): the erosion strength e H_M is not below the onset's
(H_M) and at most 3 x it."""
_K_GRID = np.exp(np.linspace(np.log(KAPPA_PRIOR[0]), np.log(KAPPA_PRIOR[1]), 101))  # 5 % apart (U: 2.5 %)
_B_GRID_N = np.linspace(1.0, 2.0, 16)  # 0.067 apart
_E_GRID_N = np.linspace(1.0, 3.0, 21)  # 0.1 apart
_SIGMA_GRID_N = np.exp(np.linspace(np.log(0.02), np.log(1.0), 14))
_TAU_GRID_N = np.exp(np.linspace(np.log(0.003), np.log(0.4), 12))
_SIGMA_COARSE = np.exp(np.linspace(np.log(0.03), np.log(0.6), 6))
_TAU_COARSE = np.exp(np.linspace(np.log(0.005), np.log(0.3), 5))


def _weighted_quantiles(x, w, probs=(0.05, 0.5, 0.95)) -> dict:
    o = np.argsort(x)
    c = np.cumsum(w[o])
    c /= c[-1]
    return {p: float(np.interp(p, c, x[o])) for p in probs}


def _grid_posterior_nose(shots: RegimeShots, opt: Options) -> dict:
    """The grid posterior of (kappa, b, e, sigma, tau) of the nose-load model sets in two passes: the
    (kappa, b, e) rows whose best likelihood over a coarse (sigma, tau) grid lies within 25 of the
    best row's are kept (the others carry < e^-25 of the mass), then the full (sigma, tau) grid on them."""
    two = opt.deforming == "two_stage"
    bg0 = _B_GRID_N if two else np.array([1.0])
    kg, bg, eg = (a.ravel() for a in np.meshgrid(_K_GRID, bg0, _E_GRID_N, indexing="ij"))
    keep = bg <= eg  # the breakup is not above the erosion (Ux is clipped to [Uy, Ue])
    kg, bg, eg = kg[keep], bg[keep], eg[keep]
    per = opt.discrepancy == "per_regime"
    out = model_outcome(kg, shots, opt, bg if two else None, eg)
    sc = _SIGMA_COARSE[::2] if per else _SIGMA_COARSE
    lp0 = _grid_loglik(shots, out, sc, sc if per else None, _TAU_COARSE)
    best = lp0.reshape(len(kg), -1).max(axis=1)
    sel = best >= best.max() - 25.0
    kg, bg, eg = kg[sel], bg[sel], eg[sel]
    out = model_outcome(kg, shots, opt, bg if two else None, eg)
    sig = _SIGMA_GRID_N[::2] if per else _SIGMA_GRID_N  # (7 x 7 with two sigmas)
    tau = _TAU_GRID_N
    # kappa log-uniform on a grid uniform in ln kappa: flat weights per row
    w, wrow = _grid_weights(_grid_loglik(shots, out, sig, sig if per else None, tau), sig, per, tau)
    q = _weighted_quantiles(kg, wrow)
    dlk = float(np.log(_K_GRID[1] / _K_GRID[0]))
    lo, hi = np.log(KAPPA_PRIOR)
    edge = bool(wrow[np.log(kg) < lo + 0.02 * (hi - lo)].sum() > 0.05 or wrow[np.log(kg) > hi - 0.02 * (hi - lo)].sum() > 0.05)
    res = {"f": kg, "b": bg if two else None, "e": eg, "weights": w, "f_quantiles": q, "at_prior_edge": edge,
           "sigma": sig, "sigma_d": sig if per else None, "tau": tau, "df": dlk, "log_f": True,
           "e_quantiles": _weighted_quantiles(eg, wrow), "rows_kept": int(sel.sum())}
    if two:
        res["b_quantiles"] = _weighted_quantiles(bg, wrow)
        res["b_at_grid_edge"] = bool(wrow[bg >= _B_GRID_N[-2]].sum() > 0.05)
    res["e_at_grid_edge"] = bool(wrow[eg >= _E_GRID_N[-2]].sum() > 0.05)
    return res


def _grid_weights(lp, sig, per: bool, tau):
    """(joint weights, row weights) of a grid log-likelihood ``lp`` (rows, n_sigma_r, n_sigma_d,
    n_tau) with the half-normal priors of sigma and tau; the grids are uniform in ln sigma and ln
    tau, hence + ln sigma + ln tau (the Jacobian)."""
    ls = np.log(sig) - 0.5 * (sig / SIGMA_PRIOR_SCALE) ** 2
    lp = lp + ls[None, :, None, None] + (ls[None, None, :, None] if per else 0.0)
    lp = lp + (np.log(tau) - 0.5 * (tau / TAU_PRIOR_SCALE) ** 2)[None, None, None, :]
    w = np.exp(lp - lp.max())
    w /= w.sum()
    return w, w.sum(axis=(1, 2, 3))


def grid_posterior(shots: RegimeShots, opt: Options) -> dict:
    """Exact posterior of (f, sigma, tau) -- with the breakup factor b for ``deforming = "two_stage"``
    and two sigmas for ``discrepancy = "per_regime"`` -- on a grid (priors of the module docstring):
    the grid rows (f, b), the joint weights (rows, n_sigma_r, n_sigma_d, n_tau), the f marginal and
    its quantiles (and b's).  The nose-load model sets: :func:`_grid_posterior_nose`."""
    if uses_nose_load(opt):
        return _grid_posterior_nose(shots, opt)
    if _uses_breakup(opt):
        fg, bg = (a.ravel() for a in np.meshgrid(_F_GRID_2D, _B_GRID, indexing="ij"))
    else:
        fg, bg = _F_GRID, None
    out = model_outcome(fg, shots, opt, bg)
    per = opt.discrepancy == "per_regime"
    sig = _SIGMA_GRID_2 if per else _SIGMA_GRID
    tau = _TAU_GRID
    w, wrow = _grid_weights(_grid_loglik(shots, out, sig, sig if per else None, tau), sig, per, tau)
    fgrid = _F_GRID_2D if bg is not None else _F_GRID
    wf = wrow.reshape(len(fgrid), -1).sum(axis=1)
    cdf = np.cumsum(wf)
    q = {p: float(np.interp(p, cdf, fgrid)) for p in (0.05, 0.5, 0.95)}
    edge = bool(wf[: len(fgrid) // 50].sum() > 0.05 or wf[-(len(fgrid) // 50):].sum() > 0.05)
    res = {"f": fg, "b": bg, "weights": w, "f_weights": wf, "f_quantiles": q, "at_prior_edge": edge,
           "sigma": sig, "sigma_d": sig if per else None, "tau": tau, "df": float(fgrid[1] - fgrid[0])}
    if bg is not None:
        wb = wrow.reshape(len(fgrid), -1).sum(axis=0)
        cdfb = np.cumsum(wb)
        res["b_quantiles"] = {p: float(np.interp(p, cdfb, _B_GRID)) for p in (0.05, 0.5, 0.95)}
        res["b_at_grid_edge"] = bool(wb[-3:].sum() > 0.05)
    return res


def draws_from_grid(post: dict, n: int = 1000, seed: int = 1):
    """(f, sigma (n, 2): rigid and deformed states, tau, b, e) draws from the grid posterior (cell
    jitter in f, b and e; b and e are None where the model set has none)."""
    rng = np.random.default_rng(seed)
    w = post["weights"].ravel()
    idx = rng.choice(len(w), size=n, p=w)
    i, jr, jd, k = np.unravel_index(idx, post["weights"].shape)
    e = None
    if post.get("log_f"):
        f = np.clip(post["f"][i] * np.exp(post["df"] * (rng.random(n) - 0.5)), *KAPPA_PRIOR)
        e = np.clip(post["e"][i] + (_E_GRID_N[1] - _E_GRID_N[0]) * (rng.random(n) - 0.5), *EROSION_PRIOR)
        db = _B_GRID_N[1] - _B_GRID_N[0]
    else:
        f = np.clip(post["f"][i] + post["df"] * (rng.random(n) - 0.5), F_PRIOR[0], F_PRIOR[1])
        db = _B_GRID[1] - _B_GRID[0]
    b = None
    if post.get("b") is not None:
        b = np.clip(post["b"][i] + db * (rng.random(n) - 0.5), BREAKUP_PRIOR[0], BREAKUP_PRIOR[1])
        if e is not None:
            b = np.minimum(b, e)
    sr = post["sigma"][jr]
    sd = post["sigma_d"][jd] if post.get("sigma_d") is not None else sr
    return f, np.column_stack([sr, sd]), post["tau"][k], b, e


def predict(shots: RegimeShots, opt: Options, f, sigma, tau, probs=(0.05, 0.5, 0.95), seed: int = 2, b=None,
            e=None) -> dict:
    """Posterior predictive at the shots from draws (f, sigma, tau): regime probability (3, n)
    (exact over the transition scatter, averaged over draws), the regime-aware quantiles
    (len(probs), n) of the mixture over draws and states (each draw with one z per shot, a
    log-normal of its state's depth and sigma) and the most probable regime."""
    from semianalytic.calibration.sampler import mixture_quantiles

    out = model_outcome(f, shots, opt, b, e)
    p_r, p_d1, p_d2, p_e = state_probabilities(shots.velocity, out, tau)
    prob = np.stack([p_r.mean(axis=0), (p_d1 + p_d2).mean(axis=0), p_e.mean(axis=0)])
    rng = np.random.default_rng(seed)
    z = rng.standard_normal(out.Uy.shape)
    t = np.asarray(tau, float)[:, None]
    Ueff = shots.velocity[None, :] * np.exp(-t * z)
    depth = np.where(Ueff >= out.Ux, out.eroding, np.where(Ueff >= out.Uy, out.bent, out.part1))
    sp = _sigma_pair(sigma)
    sig_el = np.where(Ueff >= out.Uy, sp[:, 1:2], sp[:, 0:1])  # the rigid state's sigma or the deformed states'
    q = mixture_quantiles(np.log(depth), sig_el, probs)
    return {"regime_probability": prob, "quantiles": q, "probs": tuple(probs), "regime": np.argmax(prob, axis=0),
            "U_y": np.median(out.Uy, axis=0), "U_e": np.median(out.Ue, axis=0), "U_x": np.median(out.Ux, axis=0)}


def transfer_scores(shots: RegimeShots, pred: dict) -> dict:
    """Per recorded regime and overall: label right, mean |error| of the median, 90 % coverage."""
    out = {}
    q05, q50, q95 = pred["quantiles"][0], pred["quantiles"][1], pred["quantiles"][2]
    rec = shots.recorded
    has = rec >= 0
    out["label_right"] = int(np.sum(pred["regime"][has] == rec[has]))
    out["labelled"] = int(has.sum())
    for k, name in enumerate(rg.REGIMES):
        sel = (rec == k) & np.isfinite(shots.depth)
        e = (q50[sel] - shots.depth[sel]) / shots.depth[sel]
        cov = (shots.depth[sel] >= q05[sel]) & (shots.depth[sel] <= q95[sel])
        out[name] = {"n": int(sel.sum()), "mean_abs_error": float(np.mean(np.abs(e))) if sel.any() else math.nan,
                     "coverage_90": float(np.mean(cov)) if sel.any() else math.nan,
                     "covered": int(cov.sum()),
                     "label_right": int(np.sum(pred["regime"][rec == k] == k)), "labelled": int(np.sum(rec == k))}
    return out


def parameter_names(opt: Options) -> tuple:
    """The posterior's parameters of a model set, in the order sampled (and stored in the JSON):
    the nose-load sets have ``nose_load_factor`` (kappa) and ``erosion_factor`` (e), the legacy sets
    ``dynamic_factor`` (f); ``breakup_factor`` (b) with ``deforming = "two_stage"``, ``sigma_deformed``
    with ``discrepancy = "per_regime"``."""
    nl = uses_nose_load(opt)
    return tuple(["nose_load_factor" if nl else "dynamic_factor", "sigma", "tau"]
                 + (["breakup_factor"] if _uses_breakup(opt) else []) + (["erosion_factor"] if nl else [])
                 + (["sigma_deformed"] if opt.discrepancy == "per_regime" else []))


def sample_regimes(shots: RegimeShots, opt: Options, *, chains: int = 4, walkers: int = 8, steps: int = 1500,
                   burn: int = 500, seed: int = 1, max_draws: int = 2000, start_f=(1.05, 2.0)) -> dict:
    """The posterior by emcee: ``chains`` independent ensembles of ``walkers`` walkers each, started
    apart (legacy sets: f uniform over ``start_f``; nose-load sets: from draws of the grid posterior,
    :func:`grid_posterior`, each ensemble its own).  Sampled in (f or ln kappa, ln sigma, ln tau), plus
    the breakup factor b (``deforming = "two_stage"``), the erosion factor e (nose-load sets) and ln
    sigma of the deformed states (``discrepancy = "per_regime"``).  Diagnostics: arviz rank-normalised
    split R-hat and the bulk and tail effective sample sizes per parameter, every walker of every
    ensemble one chain (as arviz.from_emcee reads an ensemble), after ``burn`` steps."""
    import emcee

    from semianalytic.calibration.sampler import MOVES, chain_diagnostics
    from semianalytic.thirdparty import run_mcmc

    rng = np.random.default_rng(seed)
    has_b, per, nl = _uses_breakup(opt), opt.discrepancy == "per_regime", uses_nose_load(opt)
    names = list(parameter_names(opt))
    walkers = max(walkers, 2 * len(names) + 2)  # the differential-evolution moves need more than twice the dimension
    ib = names.index("breakup_factor") if has_b else None
    ie = names.index("erosion_factor") if nl else None
    isd = names.index("sigma_deformed") if per else None
    lk_lo, lk_hi = np.log(KAPPA_PRIOR)

    def log_prob(x):
        x = np.atleast_2d(x)
        f0, ls, lt = x[:, 0], x[:, 1], x[:, 2]
        f = np.exp(f0) if nl else f0
        sg, t = np.exp(ls), np.exp(lt)
        b = x[:, ib] if has_b else None
        e = x[:, ie] if nl else None
        lsd = x[:, isd] if per else ls
        sd = np.exp(lsd)
        out = np.full(len(x), -np.inf)
        ok = (sg < 5.0) & (t < 2.0) & (sd < 5.0)
        ok &= ((f0 >= lk_lo) & (f0 <= lk_hi)) if nl else ((f >= F_PRIOR[0]) & (f <= F_PRIOR[1]))
        if has_b:
            ok &= (b >= BREAKUP_PRIOR[0]) & (b <= BREAKUP_PRIOR[1])
        if nl:
            ok &= (e >= EROSION_PRIOR[0]) & (e <= EROSION_PRIOR[1])
            if has_b:
                ok &= b <= e
        if ok.any():
            th = model_outcome(f[ok], shots, opt, b[ok] if has_b else None, e[ok] if nl else None)
            ll = _log_likelihood(shots, th, np.column_stack([sg[ok], sd[ok]]), t[ok])
            out[ok] = (ll - 0.5 * (sg[ok] / SIGMA_PRIOR_SCALE) ** 2 + ls[ok]
                       - 0.5 * (t[ok] / TAU_PRIOR_SCALE) ** 2 + lt[ok])  # + Jacobians of ln sigma, ln tau
            if per:
                out[ok] += -0.5 * (sd[ok] / SIGMA_PRIOR_SCALE) ** 2 + lsd[ok]
        return out

    grid = grid_posterior(shots, opt) if nl else None
    chains_out = []
    for c in range(chains):
        if nl:
            f, sig, tau, b, e = draws_from_grid(grid, walkers, seed=seed + 17 * c)
            cols = [np.log(f), np.log(sig[:, 0]), np.log(tau)]
            if has_b:
                cols.append(b)
            cols.append(e)
            if per:
                cols.append(np.log(sig[:, 1]))
        else:
            cols = [rng.uniform(*start_f, walkers), np.log(rng.uniform(0.05, 0.4, walkers)),
                    np.log(rng.uniform(0.01, 0.15, walkers))]
            if has_b:
                cols.append(rng.uniform(1.0, 1.5, walkers))
            if per:
                cols.append(np.log(rng.uniform(0.05, 0.4, walkers)))
        p0 = np.column_stack(cols)
        # differential-evolution moves (ter Braak 2006; emcee.moves.DEMove / DESnookerMove): the posterior
        # has steps in f where a transition crosses a shot, which the stretch move crosses slowly
        sampler = emcee.EnsembleSampler(walkers, len(names), log_prob, vectorize=True, moves=MOVES())
        sampler.random_state = np.random.RandomState(seed + 1000 * c).get_state()
        run_mcmc(sampler, p0, steps, progress=False)  # Ctrl-C and SIGTERM between steps (issue 40)
        chains_out.append(sampler.get_chain(discard=burn))  # (steps - burn, walkers, n_par)
    arr = np.concatenate([np.swapaxes(ch, 0, 1) for ch in chains_out])  # (chains x walkers, draws, n_par)
    nat = arr.copy()
    for k, name in enumerate(names):
        if name.startswith("sigma") or name == "tau" or name == "nose_load_factor":
            nat[..., k] = np.exp(arr[..., k])
    diag = chain_diagnostics(nat, tuple(names))
    diag["ensembles"] = chains
    flat = nat.reshape(-1, len(names))
    thin = max(1, int(math.ceil(len(flat) / max_draws)))
    flat = flat[::thin]
    res = {"f": flat[:, 0], "sigma": flat[:, 1], "tau": flat[:, 2], "diagnostics": diag, "chains": chains,
           "walkers": walkers, "steps": steps, "burn": burn, "b": flat[:, ib] if has_b else None,
           "e": flat[:, ie] if nl else None,
           "sigma_deformed": flat[:, isd] if per else None, "names": tuple(names)}
    return res


def _sigmas(sample) -> np.ndarray:
    """(n, 2) sigma of the rigid and the deformed states from a sample (one shared sigma: equal)."""
    sd = sample.get("sigma_deformed")
    return np.column_stack([sample["sigma"], sample["sigma"] if sd is None else sd])


def _tate1986_resistance(case) -> float:
    """R_t of Tate (1986) (:func:`.regime.tate_resistance`) from ``[target.resistance]``'s yield
    stress and Young's modulus; NaN where the resistance model has neither."""
    res = case.target.resistance
    return (rg.tate_resistance(res.yield_stress, res.youngs_modulus)
            if hasattr(res, "youngs_modulus") and hasattr(res, "yield_stress") else math.nan)


def regime_shots(case, coefficients) -> RegimeShots:
    """The shots of a case's ``[data]`` (every recorded response) as :class:`RegimeShots`: each
    shot's mass and hardness (``[data] hardness_column``, else ``[projectile] hardness``), its
    Part I depth (elastic projectile, exact-rod W2) and U_sC(Y_p) (eqs. (33)/(36))."""
    from semianalytic.errors import InputError
    from semianalytic.penetration import critical as crit
    from semianalytic.penetration.curve import PenetrationSetup, penetration_curve
    from semianalytic.penetration.hardness import (
        meyer_hardness_from_vickers,
        parse_hardness,
        ultimate_strength_from_vickers,
        vickers_from_rockwell_c,
        yield_stress_from_vickers,
    )
    from semianalytic.penetration.regime_setup import RESPONSE_REGIME, eroding_inputs
    from semianalytic.penetration.validation import load_shots, peer_depths

    data = case.require("data")
    psec = case.projectile
    if psec.hardness is None:
        raise InputError("projectile.hardness", "missing: the regime model takes the projectile's strength from its "
                                                "hardness (e.g. '38 HRC'; per shot with [data] hardness_column)")
    H0 = parse_hardness(psec.hardness)
    shots = load_shots(case, require_depth=False)
    if not shots:
        raise InputError("data.file", "no shots selected")
    base = PenetrationSetup.from_case(case, coefficients)
    ei = eroding_inputs(case, base)
    tate = _tate1986_resistance(case)
    U, m, P, rec, H, p1, fd, crits = [], [], [], [], [], [], [], []
    col = data.response_column
    for s in shots:
        setup = PenetrationSetup.from_case(case, coefficients, mass=s.mass) if s.mass is not None else base
        U.append(s.velocity)
        m.append(setup.mass)
        P.append(s.depth)
        r = RESPONSE_REGIME.get(s.row.get(col, "").strip()) if col else None
        rec.append(rg.REGIMES.index(r) if r else -1)
        h = s.row.get(data.hardness_column, "") if data.hardness_column else ""
        try:
            H.append(float(h) if str(h).strip() else H0)
        except ValueError:
            raise InputError("data.hardness_column", f"shot {s.id}: {h!r} is not a number (HRC)") from None
        p1.append(float(penetration_curve(setup, [s.velocity])["depth_elastic_exact_rod_m"][0]))
        fd.append(float(peer_depths(case, setup, [s.velocity])["forrestal"][0]))
        crits.append((setup.critical_inputs(), setup.phi))
    if col and not np.any(np.array(rec) >= 0):  # the transitions would be placed by the depths alone, silently
        raise InputError("data.response_column", f"no selected shot has a recorded response in column {col!r} (every "
                                                 f"label is blank); record each shot's response ({', '.join(RESPONSE_REGIME)})")
    vcrit = np.vectorize(lambda Y, j: crit.critical_velocity(float(Y), crits[j][0], crits[j][1]), otypes=[float])
    idx = np.arange(len(shots))

    def critical(Y):
        return vcrit(Y, np.broadcast_to(idx, np.shape(Y)))

    HV = vickers_from_rockwell_c(np.array(H), "data.hardness_column")
    rod = np.array([rg.eroding_rod_length(ei.length, ei.nose_length, ei.diameter, ei.density, mm) for mm in m])
    groups = sorted({str(v) for s in shots for k, v in s.row.items() if k == "material"})
    return RegimeShots(
        group="+".join(groups) or (data.name or "data"), ids=tuple(s.id for s in shots), velocity=np.array(U),
        mass=np.array(m), depth=np.array(P), recorded=np.array(rec), responses=tuple(s.row.get(col, "") if col else "" for s in shots),
        static_yield=np.asarray(yield_stress_from_vickers(HV), float), static_ultimate=np.asarray(ultimate_strength_from_vickers(HV), float),  # noqa: E501
        meyer_hardness=np.asarray(meyer_hardness_from_vickers(HV), float), part1_depth=np.array(p1), forrestal_depth=np.array(fd), critical=critical, rod_length=rod,  # noqa: E501
        length=ei.length, nose_length=ei.nose_length, diameter=ei.diameter, density=ei.density,
        target_density=ei.target_density, resistance={"part1": base.resistance_pa, "tate1986": tate},
        nose_loads=case_nose_loads(case, base))


def transfer_study(pairs, options=OPTION_SETS, n_draws: int = 1000, chosen_among=None) -> dict:
    """Leave-one-group-out over the :class:`RegimeShots` of ``pairs`` (one per material): for
    every option set and every ordered pair (fit, predict) the grid posterior of f on the fit
    group and the scores of the prediction of the other group (:func:`transfer_scores`), plus
    the in-sample scores (fit and predict on the same group) beside them."""
    out = {"options": [], "groups": [s.group for s in pairs]}
    for opt in options:
        rec = {"options": opt.as_dict(), "label": opt.label(), "transfer": [], "in_sample": []}
        posts = {s.group: grid_posterior(s, opt) for s in pairs}
        for fit in pairs:
            f, sig, tau, b, e = draws_from_grid(posts[fit.group], n_draws)
            for tgt in pairs:
                pred = predict(tgt, opt, f, sig, tau, b=b, e=e)
                sc = transfer_scores(tgt, pred)
                sc.update({"fit": fit.group, "predict": tgt.group, "f_quantiles": posts[fit.group]["f_quantiles"],
                           "f_at_prior_edge": posts[fit.group]["at_prior_edge"],
                           "shots": [{"shot": i, "velocity_m_s": float(v), "measured_m": float(d), "response": resp,
                                      "recorded": (rg.REGIMES[r] if r >= 0 else None),
                                      "predicted": rg.REGIMES[int(k)],
                                      "regime_probability": dict(zip(rg.REGIMES, map(float, pred["regime_probability"][:, j]))),
                                      "q05_m": float(pred["quantiles"][0, j]), "q50_m": float(pred["quantiles"][1, j]),
                                      "q95_m": float(pred["quantiles"][2, j])}
                                     for j, (i, v, d, r, k, resp) in enumerate(zip(tgt.ids, tgt.velocity, tgt.depth,
                                                                                     tgt.recorded, pred["regime"],
                                                                                     tgt.responses))]})
                (rec["in_sample"] if fit is tgt else rec["transfer"]).append(sc)
        rec["summary"] = _pool(rec["transfer"])
        rec["summary_in_sample"] = _pool(rec["in_sample"])
        rec["orders_noses"] = orders_noses(opt)
        rec["eroding_rises"] = all(eroding_trend(g, opt, posts[g.group]["f_quantiles"][0.5])["rising"] for g in pairs)
        rec["score"] = _rank(rec)
        out["options"].append(rec)
    candidates = [o for o in out["options"] if not _comparison_only(o["options"]) and o["orders_noses"]
                  and o["eroding_rises"]]
    best = min(candidates or out["options"], key=_rank)
    out["chosen"] = best["options"]
    out["rule"] = ("smallest transfer score = mean over the regimes of the mean |error| of the regime-aware median "
                   "+ the fraction of regime labels wrong (transfer only; in-sample shown beside), among the model "
                   "sets whose transitions follow the nose's load (a blunter nose earlier: orders the noses) and whose "
                   "eroded depth rises with the striking velocity over 1.5-3.5 km/s on both steels' rods")
    for o in out["options"]:
        o["comparison_only"] = _comparison_only(o["options"])
    return out


COMPARISON_ONLY: dict = {}
"""Model sets shown but not candidates (none: Forrestal's depth, with the data authors' constants where
``[data]`` gives them and A Y = R_t, B = 3/2 otherwise, competes with Part I's on transfer)."""


def _comparison_only(options: dict) -> bool:
    return any(options.get(k) == v for (k, v) in COMPARISON_ONLY)


def point_scores(shots: RegimeShots, opt: Options, f: float, b: float | None, e: float | None = None) -> dict:
    """Labels right and mean |error| per recorded regime of the point prediction at one (f, b, e)
    (what ``penetrate`` prints without a posterior: the nominal transitions, no scatter)."""
    out = model_outcome([f], shots, opt, None if b is None else [b], None if e is None else [e])
    code, depth = out.code[0], out.depth[0]
    rec = shots.recorded
    res = {"f": float(f), "b": None if b is None else float(b), "e": None if e is None else float(e), "label_right": int(np.sum(code[rec >= 0] == rec[rec >= 0])),  # noqa: E501
           "labelled": int(np.sum(rec >= 0))}
    for k, name in enumerate(rg.REGIMES):
        sel = (rec == k) & np.isfinite(shots.depth)
        e = np.abs(depth[sel] / shots.depth[sel] - 1.0)
        res[name] = {"n": int(sel.sum()), "mean_abs_error": float(np.mean(e)) if sel.any() else math.nan}
    return res


def default_constants_study(pairs, opt: Options, posts: dict, f0: float, b0: float | None, e0: float | None = None) -> dict:
    """The stated defaults of ``penetrate`` (``f0`` = hardness.DEFAULT_DYNAMIC_FACTOR, ``b0`` =
    regime.DEFAULT_BREAKUP_FACTOR) scored on every group (in-sample: they round the medians fitted on
    all groups) beside each group predicted at the other group's posterior medians (transfer)."""
    rows = []
    for g in pairs:
        other = next(h for h in pairs if h is not g)
        po = posts[other.group]
        bo = po.get("b_quantiles", {}).get(0.5) if b0 is not None else None
        eo = po.get("e_quantiles", {}).get(0.5) if e0 is not None else None
        rows.append({"group": g.group, "fit": other.group,
                     "defaults": point_scores(g, opt, f0, b0, e0),
                     "transfer": point_scores(g, opt, po["f_quantiles"][0.5], bo, eo)})
    return {"f": f0, "b": b0, "e": e0, "rows": rows}


def _pool(scores) -> dict:
    """Transfer scores pooled over the held-out groups."""
    tot = {"label_right": sum(s["label_right"] for s in scores), "labelled": sum(s["labelled"] for s in scores)}
    from scipy.stats import binomtest

    for name in rg.REGIMES:
        n = sum(s[name]["n"] for s in scores)
        err = sum(s[name]["mean_abs_error"] * s[name]["n"] for s in scores if s[name]["n"])
        covered = sum(s[name]["covered"] for s in scores)
        tot[name] = {"n": n, "mean_abs_error": err / n if n else math.nan,
                     "coverage_90": covered / n if n else math.nan, "covered": covered,
                     # two-sided binomial test of the count against calibrated 90 % intervals: with 8-14
                     # shots a calibrated interval misses the 80-95 % band often (14 of 14 has 0.9^14 = 0.23)
                     "coverage_binomial_p": float(binomtest(covered, n, 0.9).pvalue) if n else math.nan,
                     "label_right": sum(s[name]["label_right"] for s in scores),
                     "labelled": sum(s[name]["labelled"] for s in scores)}
    return tot


def _rank(rec):
    """Transfer score (smaller is better): the mean over the regimes of the mean |error| of the
    regime-aware median plus the fraction of regime labels wrong (both targets of the issue, on
    one scale: a 10 % error in every regime weighs as much as 10 % of the labels wrong)."""
    s = rec["summary"]
    errs = [s[k]["mean_abs_error"] for k in rg.REGIMES if s[k]["n"]]
    return (float(np.mean(errs)) if errs else math.inf) + 1.0 - s["label_right"] / max(s["labelled"], 1)


REGIMES_FORMAT = "semianalytic-regimes-posterior"
# draws per prediction of penetrate --posterior (evenly thinned): against 1000 draws the quantiles move by
# a median 0.4 % (at most 5 %) of the 90 % interval over 50 velocities; the CPU time falls by about 1 s
PREDICTION_DRAWS = 400
REGIMES_VERSION = 2
"""2: the nose-load model sets (``nose_load_factor``, ``erosion_factor``; options ``nose_load`` and
``deformed_depth``); a version-1 posterior reads with :meth:`Options.from_dict`."""


NOSE_KEYS = ("nose", "crh", "diameter_m")
"""Signature keys a regimes posterior may differ in (transfer to another nose, with a note); any
other difference (the target) refuses it."""


def geometry_signature(case) -> dict:
    """What a regimes posterior is about, checked against a case: the nose and the target."""
    p, t = case.projectile, case.target
    return {"nose": p.nose, "crh": p.crh, "diameter_m": p.diameter, "target_density_kg_m3": t.density,
            "resistance_model": getattr(t.resistance, "model", None),
            "target_yield_stress_Pa": getattr(t.resistance, "yield_stress", None)}


def posterior_json(case, shots: RegimeShots, opt: Options, sample: dict, n_store: int = 1000) -> dict:
    """The JSON posterior of ``calibrate --model regimes``: options, signature, draws, diagnostics."""
    idx = np.linspace(0, len(sample["f"]) - 1, min(n_store, len(sample["f"]))).astype(int)
    keys = {parameter_names(opt)[0]: "f", "sigma": "sigma", "tau": "tau", "breakup_factor": "b",
            "erosion_factor": "e", "sigma_deformed": "sigma_deformed"}
    present = {name: np.asarray(sample[k]) for name, k in keys.items() if sample.get(k) is not None}
    summ = {name: dict(zip(("q05", "q50", "q95"), map(float, np.percentile(v, [5, 50, 95])))) for name, v in present.items()}
    first = parameter_names(opt)[0]
    priors = {first: (f"loguniform({KAPPA_PRIOR[0]:g}, {KAPPA_PRIOR[1]:g})" if uses_nose_load(opt)
                      else f"uniform({F_PRIOR[0]:g}, {F_PRIOR[1]:g})"),
              "sigma": f"halfnormal({SIGMA_PRIOR_SCALE:g})", "tau": f"halfnormal({TAU_PRIOR_SCALE:g})",
              "label_error": LABEL_ERROR}
    lo, hi = KAPPA_PRIOR if uses_nose_load(opt) else F_PRIOR
    edge = {first: bool(np.mean(sample["f"] < lo * 1.02) > 0.05 or np.mean(sample["f"] > hi * 0.98) > 0.05)}
    if sample.get("e") is not None:
        priors["erosion_factor"] = f"uniform({EROSION_PRIOR[0]:g}, {EROSION_PRIOR[1]:g})"
        edge["erosion_factor"] = bool(np.mean(sample["e"] > EROSION_PRIOR[1] - 0.02) > 0.05)
    if "breakup_factor" in present:
        priors["breakup_factor"] = f"uniform({BREAKUP_PRIOR[0]:g}, {BREAKUP_PRIOR[1]:g})"
        b = present["breakup_factor"]
        edge["breakup_factor"] = bool(np.mean(b < BREAKUP_PRIOR[0] + 0.01) > 0.05 or np.mean(b > BREAKUP_PRIOR[1] - 0.02) > 0.05)
    if "sigma_deformed" in present:
        priors["sigma_deformed"] = f"halfnormal({SIGMA_PRIOR_SCALE:g})"
    return {
        "format": REGIMES_FORMAT, "version": REGIMES_VERSION, "model": "regimes",
        "case": str(case.path) if case.path else case.title, "title": case.title,
        "options": opt.as_dict(), "signature": geometry_signature(case),
        "velocity_range_m_s": [float(np.min(shots.velocity)), float(np.max(shots.velocity))],
        "meyer_hardness_range_Pa": [float(np.min(shots.meyer_hardness)), float(np.max(shots.meyer_hardness))],
        "groups": shots.group, "n_shots": len(shots),
        "priors": priors, "summary": summ, "at_prior_edge": edge,
        "diagnostics": sample["diagnostics"],
        "samples": {name: v[idx].tolist() for name, v in present.items()},
    }


def posterior_parameters(draws: dict, opt: Options, idx) -> dict:
    """The keyword arguments of :func:`predict` from a posterior's draws (``samples`` of the JSON) at
    the indices ``idx``: ``f`` (``nose_load_factor`` of the nose-load model sets, else
    ``dynamic_factor``), ``sigma`` (n, 2), ``tau``, ``b`` (``breakup_factor`` or None), ``e``
    (``erosion_factor`` or None).  The interface ``predict_case`` uses."""
    first = parameter_names(opt)[0]
    sd = draws.get("sigma_deformed")
    sig = np.column_stack([draws["sigma"][idx], (sd if sd is not None else draws["sigma"])[idx]])
    get = (lambda k: np.asarray(draws[k])[idx] if k in draws else None)  # noqa: E731
    return {"f": np.asarray(draws[first])[idx], "sigma": sig, "tau": np.asarray(draws["tau"])[idx],
            "b": get("breakup_factor"), "e": get("erosion_factor")}


def is_regimes_posterior(path) -> bool:
    """Whether ``path`` holds a regimes posterior (False for anything else, read or not)."""
    import json
    from pathlib import Path

    try:
        with Path(path).open("rb") as fh:
            head = fh.read(4096)
        return REGIMES_FORMAT.encode() in head and json.loads(Path(path).read_text()).get("format") == REGIMES_FORMAT
    except (OSError, ValueError):
        return False


DRAW_SUPPORT = {
    "dynamic_factor": (F_PRIOR[0], F_PRIOR[1], "the prior uniform(1, 3)"),
    "nose_load_factor": (KAPPA_PRIOR[0], KAPPA_PRIOR[1], f"the prior loguniform({KAPPA_PRIOR[0]:g}, {KAPPA_PRIOR[1]:g})"),
    "erosion_factor": (EROSION_PRIOR[0], EROSION_PRIOR[1], f"the prior uniform({EROSION_PRIOR[0]:g}, {EROSION_PRIOR[1]:g})"),
    "breakup_factor": (BREAKUP_PRIOR[0], BREAKUP_PRIOR[1], "the prior uniform(1, 3)"),
    "sigma": (0.0, 5.0, "halfnormal(0.3) truncated by the sampler at 5"),
    "sigma_deformed": (0.0, 5.0, "halfnormal(0.3) truncated by the sampler at 5"),
    "tau": (0.0, 2.0, "halfnormal(0.1) truncated by the sampler at 2"),
}
"""Support of each parameter of a regimes posterior (:func:`sample_regimes`: the priors of the module
docstring, with the bounds its log-density enforces); sigma and tau exclude 0."""


def check_draws(path, samples: dict, opt: Options | None = None) -> dict:
    """The draws of a regimes posterior's ``samples`` as arrays, checked: the model set's first
    parameter (``nose_load_factor`` or ``dynamic_factor``, :func:`parameter_names`), sigma and tau
    present; every list non-empty, of JSON numbers, finite, of one length; every draw inside
    :data:`DRAW_SUPPORT`.  InputError (exit 2) naming the file and the parameter otherwise."""
    from semianalytic.errors import InputError

    first = parameter_names(opt)[0] if opt is not None else "dynamic_factor"
    draws, n = {}, None
    for k in (first, "sigma", "tau", *(q for q in DRAW_SUPPORT if q not in (first, "sigma", "tau"))):
        if k not in samples:
            if k in (first, "sigma", "tau"):
                raise InputError(f"samples.{k}", f"{path}: missing (a regimes posterior of this model set holds "
                                                 f"draws of {first}, sigma and tau)")
            continue
        v = samples[k]
        if not isinstance(v, list) or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v):
            raise InputError(f"samples.{k}", f"{path}: expected a list of numbers, one per draw")
        a = np.asarray(v, float)
        if a.size == 0:
            raise InputError(f"samples.{k}", f"{path}: empty: the posterior holds no draw")
        if n is None:
            n = a.size
        elif a.size != n:
            raise InputError(f"samples.{k}", f"{path}: {a.size} draws, samples.{first} has {n} "
                                             "(one value per draw in every list)")
        lo, hi, why = DRAW_SUPPORT[k]
        ok = np.isfinite(a) & (a >= lo) & (a <= hi) & ((a > 0) if lo == 0 else True)
        if not ok.all():
            j = int(np.argmax(~ok))
            raise InputError(f"samples.{k}", f"{path}: draw {j} is {float(a[j]):.6g}, outside the support "
                                             f"{'(' if lo == 0 else '['}{lo:g}, {hi:g}] of {why}")
        draws[k] = a
    for k, v in samples.items():  # any further parameter: numbers, finite, one per draw
        if k in DRAW_SUPPORT:
            continue
        a = np.asarray(v, float) if isinstance(v, list) and all(
            isinstance(x, (int, float)) and not isinstance(x, bool) for x in v) else None
        if a is None or a.size != n or not np.all(np.isfinite(a)):
            raise InputError(f"samples.{k}", f"{path}: expected {n} finite numbers, one per draw")
    return draws


def _check_range(path, rng) -> list:
    from semianalytic.errors import InputError
    from semianalytic.limits import MAX_STRIKING_VELOCITY

    ok = (isinstance(rng, list) and len(rng) == 2 and all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                                           for x in rng))
    if ok:
        lo, hi = map(float, rng)
        ok = math.isfinite(lo) and math.isfinite(hi) and 0 < lo <= hi <= MAX_STRIKING_VELOCITY
    if not ok:
        raise InputError("velocity_range_m_s", f"{path}: expected [lowest, highest] striking velocity of the "
                                               f"calibration shots (0 < lowest <= highest <= "
                                               f"{MAX_STRIKING_VELOCITY:g} m/s); got {rng!r}")
    return [lo, hi]


def load_regimes_file(path) -> tuple[dict, Options, dict]:
    """(the JSON object, its :class:`Options`, the checked draws) of a regimes posterior file: every
    check that needs no case (format version, options and their values, draws by
    :func:`check_draws`, the calibrated velocity range); InputError naming the file otherwise."""
    import dataclasses
    import json
    from pathlib import Path

    from semianalytic.errors import InputError

    try:
        obj = json.loads(Path(path).read_text())
        known = {f.name for f in dataclasses.fields(Options)}
        if not isinstance(obj["options"], dict) or not set(obj["options"]) <= known:
            extra = sorted(set(obj["options"]) - known) if isinstance(obj["options"], dict) else obj["options"]
            raise InputError("options", f"{path}: unknown option(s) {extra!r}; the options are {', '.join(sorted(known))}")
        opt = Options.from_dict(obj["options"])
        samples = obj["samples"]
        if not isinstance(samples, dict):
            raise TypeError("samples is not a JSON object")
        if not isinstance(obj["signature"], dict):
            raise TypeError("signature is not a JSON object")
    except (OSError, ValueError, KeyError, TypeError) as exc:
        if isinstance(exc, InputError):
            raise
        raise InputError("--posterior", f"{path}: not a readable regimes posterior ({exc})") from None
    if obj.get("version") not in (1, REGIMES_VERSION):
        raise InputError("--posterior", f"{path}: version {obj.get('version')!r}, expected {REGIMES_VERSION}")
    for k, vals in OPTION_VALUES.items():
        if getattr(opt, k) not in vals:
            raise InputError(f"options.{k}", f"{path}: unknown value {getattr(opt, k)!r}; one of {', '.join(vals)}")
    draws = check_draws(path, samples, opt)
    for k in parameter_names(opt):
        if k not in draws:
            raise InputError(f"samples.{k}", f"{path}: missing (the model set {opt.label()} needs it)")
    obj["velocity_range_m_s"] = _check_range(path, obj.get("velocity_range_m_s"))
    return obj, opt, draws


def read_regimes_posterior(path, case) -> dict:
    """Read a regimes posterior (:func:`load_regimes_file`) and check it against ``case``: another
    nose or target is a transfer, accepted with a note (:func:`transfer_notes`)."""

    obj, opt, draws = load_regimes_file(path)
    sig = obj["signature"]
    mine = geometry_signature(case)
    other_nose, other_target = [], []
    for k, v in sig.items():
        w = mine.get(k)
        same = (v == w) if not (isinstance(v, float) and isinstance(w, float)) else math.isclose(v, w, rel_tol=1e-9)
        if not same:
            (other_nose if k in NOSE_KEYS else other_target).append(f"{k} = {v!r} (the case: {w!r})")
    notes, reasons = [], []
    if other_nose:
        reasons.append(f"another nose: fitted for {', '.join(other_nose)}")
    if other_target:
        reasons.append(f"another target: fitted for {', '.join(other_target)}")
        notes.append(f"note: posterior {path}: fitted on another target ({', '.join(other_target)}); its rod parameters "
                     "(dynamic factor, breakup factor of the rod steel) are applied to this target, whose resistance "
                     "R_t is recomputed from the case's [target] properties")
    return {"options": opt, "draws": draws, "raw": obj, "notes": notes, "transfer_reasons": reasons}


def shots_at(case, coefficients, U) -> RegimeShots:
    """Prediction points: the case's projectile (nominal hardness and mass) at velocities ``U``."""
    from semianalytic.errors import InputError
    from semianalytic.penetration import critical as crit
    from semianalytic.penetration.curve import PenetrationSetup, penetration_curve
    from semianalytic.penetration.hardness import (
        meyer_hardness_from_vickers,
        parse_hardness,
        ultimate_strength_from_vickers,
        vickers_from_rockwell_c,
        yield_stress_from_vickers,
    )
    from semianalytic.penetration.regime_setup import eroding_inputs
    from semianalytic.penetration.validation import peer_depths

    if case.projectile.hardness is None:
        raise InputError("projectile.hardness", "missing: a regimes posterior takes the projectile's strength from "
                                                "its hardness (e.g. '38 HRC')")
    U = np.asarray(U, float)
    setup = PenetrationSetup.from_case(case, coefficients)
    ei = eroding_inputs(case, setup)
    HV = float(vickers_from_rockwell_c(parse_hardness(case.projectile.hardness)))
    p1 = np.asarray(penetration_curve(setup, U)["depth_elastic_exact_rod_m"], float)
    fd = np.asarray(peer_depths(case, setup, U)["forrestal"], float)
    ci, phi = setup.critical_inputs(), setup.phi
    vcrit = np.vectorize(lambda Y: crit.critical_velocity(float(Y), ci, phi), otypes=[float])
    tate = _tate1986_resistance(case)
    n = len(U)
    return RegimeShots(
        group="prediction", ids=tuple(str(k) for k in range(n)), velocity=U, mass=np.full(n, setup.mass),
        depth=np.full(n, np.nan), recorded=np.full(n, -1), responses=("",) * n, static_yield=np.full(n, float(yield_stress_from_vickers(HV))),  # noqa: E501
        static_ultimate=np.full(n, float(ultimate_strength_from_vickers(HV))),
        meyer_hardness=np.full(n, float(meyer_hardness_from_vickers(HV))), part1_depth=p1, forrestal_depth=fd, critical=vcrit,
        rod_length=np.full(n, rg.eroding_rod_length(ei.length, ei.nose_length, ei.diameter, ei.density, setup.mass)),
        length=ei.length, nose_length=ei.nose_length, diameter=ei.diameter, density=ei.density,
        target_density=ei.target_density, resistance={"part1": setup.resistance_pa, "tate1986": tate},
        nose_loads=case_nose_loads(case, setup))


TRANSFER_DEPTH_SIGMA = 0.068
"""Depth scatter added (in quadrature, ln depth) when a regimes posterior transfers to a nose,
hardness or target outside what it was fitted on: the leave-one-steel-out inflation measured on
the bundled data (reports/calibration_piekutowski1999_regimes/transfer.json, the chosen model
set): the RMS of ln(measured / predicted median) over the 31 shots with a depth is 0.247 when each
steel is predicted from the other's posterior and 0.237 in-sample, and sqrt(0.247^2 - 0.237^2)
= 0.068 (:func:`transfer_depth_inflation` recomputes it; tests/test_posterior_transfer.py checks
the constant against the committed file)."""

RIGID_BELOW_RANGE = 0.99
"""Below the calibrated velocity range a regimes posterior's prediction is given where the rod is
rigid with at least this probability (the rigid model, Part I, holds down to any speed); it says so
in a note."""


def transfer_depth_inflation(transfer: dict) -> float:
    """sqrt(max(0, mean e_T^2 - mean e_I^2)), e = ln(measured / median), over the shots of the
    chosen model set of a transfer study (``transfer.json`` of ``calibrate --model regimes
    --cross-validate``): T the leave-one-group-out predictions, I the in-sample ones."""
    rec = next(o for o in transfer["options"] if o["options"] == transfer["chosen"])

    def ms(scores):
        e = [math.log(s["measured_m"] / s["q50_m"]) for sc in scores for s in sc["shots"]
             if s["measured_m"] is not None and math.isfinite(s["measured_m"]) and s["q50_m"]]
        return float(np.mean(np.square(e)))

    return math.sqrt(max(0.0, ms(rec["transfer"]) - ms(rec["in_sample"])))


def criteria_spread(shots: RegimeShots, opt: Options, f: float, b, e=None) -> dict:
    """The spread of the transition criteria on this rod and nose at one set of constants: the
    standard deviation of ln U_y over the onset criteria and of ln U_e over the erosion criteria,
    the larger of the two as ``tau`` (the transfer uncertainty of the transition velocities).

    Nose-load model sets (``onset = "nose_meyer"``, kappa = ``f``, erosion factor ``e``): the
    criteria are the published nose loads with a geometry (:data:`NOSE_LOADS` but ``tip``: Part I's
    A, B, C of the nose and Forrestal's cavity-expansion nose factors) at the same constants.
    Legacy sets (dynamic factor ``f``): every onset and erosion criterion of :mod:`.regime` but this
    project's own nose-length rule and the nose-load criterion."""
    import dataclasses

    out = {}
    if uses_nose_load(opt):
        variants = [dataclasses.replace(opt, nose_load=L) for L in NOSE_LOADS if L != "tip"]
        pairs = (("onset", "Uy"), ("erosion", "Ue"))
        for name, attr in pairs:
            vals = {}
            for v in variants:
                th = model_outcome([f], shots, v, None if b is None else [b], None if e is None else [e])
                u = float(np.median(getattr(th, attr)[0]))
                if math.isfinite(u) and u > 0:
                    vals[v.nose_load] = u
            out[name] = {"velocities_m_s": vals,
                         "sd_ln": float(np.std(np.log(list(vals.values())))) if len(vals) > 1 else 0.0}
    else:
        for name, crit, attr in (("onset", rg.ONSET_CRITERIA, "Uy"), ("erosion", rg.EROSION_CRITERIA, "Ue")):
            vals = {}
            for c in crit:
                if c in ("nose_length", "nose_meyer"):
                    continue
                th = model_outcome([f], shots, dataclasses.replace(opt, **{name: c}), None if b is None else [b])
                v = float(np.median(getattr(th, attr)[0]))
                if math.isfinite(v) and v > 0:
                    vals[c] = v
            out[name] = {"velocities_m_s": vals,
                         "sd_ln": float(np.std(np.log(list(vals.values())))) if len(vals) > 1 else 0.0}
    out["tau"] = max(out["onset"]["sd_ln"], out["erosion"]["sd_ln"])
    return out


def _hardness_reason(post: dict, shots: RegimeShots):
    rng = post["raw"].get("meyer_hardness_range_Pa")
    if not (isinstance(rng, list) and len(rng) == 2):
        return None
    H = float(shots.meyer_hardness[0])
    lo, hi = map(float, rng)
    if lo <= H <= hi:
        return None
    return (f"another hardness: the rod's Meyer hardness {H / 1e9:.2f} GPa is outside the {lo / 1e9:.2f}-{hi / 1e9:.2f} "
            "GPa of the shots it was fitted on")


def predict_case(case, coefficients, path, U, probs=(0.05, 0.25, 0.5, 0.75, 0.95)) -> dict:
    """``penetrate --posterior`` with a regimes posterior: per velocity ``regime_probability``
    {rigid, deforming, eroding} and the regime-aware quantiles of the mixture.

    Every striking velocity is answered: inside the calibrated range (10 % margin) by the
    mixture; below it, where the rod is rigid with probability >= :data:`RIGID_BELOW_RANGE`, by
    the same mixture (the rigid model) with a note; elsewhere (above the range, or below it where
    the rod may deform) null, with the reason in ``regime_notes`` and on stderr.

    Transfer (issue 36 item 5): applied to another nose, a hardness outside the fitted shots' or
    another target (accepted: the rod parameters are the steel's, R_t is recomputed from the
    case), the transition scatter tau is widened in quadrature by the spread of the published
    criteria on this rod and nose (:func:`criteria_spread`) and the depth scatter sigma by
    :data:`TRANSFER_DEPTH_SIGMA`; ``transfer`` states the reasons and the amounts."""
    post = read_regimes_posterior(path, case)
    shots = shots_at(case, coefficients, U)
    d = post["draws"]
    idx = np.linspace(0, len(d["sigma"]) - 1, min(PREDICTION_DRAWS, len(d["sigma"]))).astype(int)
    opt = post["options"]
    kw = posterior_parameters(d, opt, idx)
    sig, tau, b, e = kw["sigma"], kw["tau"], kw["b"], kw["e"]
    reasons = list(post["transfer_reasons"])
    hard = _hardness_reason(post, shots)
    if hard:
        reasons.append(hard)
    transfer = {"transfer": bool(reasons), "reasons": reasons, "tau_added": 0.0, "sigma_added": 0.0}
    warnings = list(post["notes"])
    if reasons:
        spread = criteria_spread(shots, opt, float(np.median(kw["f"])),
                                 None if b is None else float(np.median(b)), None if e is None else float(np.median(e)))
        transfer.update(tau_added=spread["tau"], sigma_added=TRANSFER_DEPTH_SIGMA, criteria=spread,
                        rule="tau' = sqrt(tau^2 + s_U^2), s_U = the larger SD of ln U_y over the onset criteria and of "
                             "ln U_e over the erosion criteria on this rod and nose (published ones; the nose-length "
                             "rule, ours, left out); sigma' = sqrt(sigma^2 + 0.068^2), the leave-one-steel-out "
                             "inflation of the depth error on the bundled data")
        tau = np.sqrt(tau**2 + spread["tau"] ** 2)
        sig = np.sqrt(sig**2 + TRANSFER_DEPTH_SIGMA**2)
        warnings.append(f"note: posterior {path}: a transfer ({'; '.join(reasons)}): the intervals are widened by a "
                        f"stated rule: transition scatter tau + {spread['tau']:.3f} (spread of the criteria on this rod "
                        f"and nose), depth scatter sigma + {TRANSFER_DEPTH_SIGMA:.3f} (leave-one-steel-out inflation), "
                        "both in quadrature")
    pred = predict(shots, opt, kw["f"], sig, tau, probs, b=b, e=e)
    lo, hi = post["raw"]["velocity_range_m_s"]
    V = shots.velocity
    inside = (V >= 0.9 * lo) & (V <= 1.1 * hi)
    p_rigid = pred["regime_probability"][0]
    below_rigid = (V < 0.9 * lo) & (p_rigid >= RIGID_BELOW_RANGE)
    finite = np.all(np.isfinite(pred["quantiles"]), axis=0) & np.all(np.isfinite(pred["regime_probability"]), axis=0)
    holds = (inside | below_rigid) & finite
    reason = [None] * len(V)
    for i, u in enumerate(V):
        if below_rigid[i] and finite[i]:
            reason[i] = (f"below the calibrated {lo:.0f}-{hi:.0f} m/s: rigid with probability {p_rigid[i]:.3f}, the rigid "
                         "model (Part I) holds there; given as extrapolated")
        elif not inside[i]:
            reason[i] = (f"no model holds: outside the calibrated {lo:.0f}-{hi:.0f} m/s (10 % margin)"
                         + ("" if u > hi else f", and the rod is not surely rigid (P(rigid) = {p_rigid[i]:.3f} < "
                                              f"{RIGID_BELOW_RANGE})"))
        elif not finite[i]:
            reason[i] = "no model holds: the regime model gives no finite depth here"
    q = np.where(holds[None, :], pred["quantiles"], np.nan)
    prob = np.where(holds[None, :], pred["regime_probability"], np.nan)
    if np.any(below_rigid & finite):
        at = ", ".join(f"{u:.0f}" for u in V[below_rigid & finite])
        warnings.append(f"note: posterior {path}: U_s = {at} m/s below the calibrated {lo:.0f}-{hi:.0f} m/s: the rigid "
                        f"prediction is given (P(rigid) >= {RIGID_BELOW_RANGE} there; regime_notes)")
    if not holds.all():
        bad = ", ".join(f"{u:.0f}" for u in V[~holds])
        warnings.append(f"warning: posterior {path}: no model holds at U_s = {bad} m/s: the regime model was "
                        f"calibrated on {lo:.0f}-{hi:.0f} m/s (10 % margin); no depth is given there (null; the reason "
                        "per velocity in regime_notes)")
    z90 = 1.6448536269514722
    t_med = float(np.median(tau))
    return {"quantiles": {f"{p:g}": q[k].tolist() for k, p in enumerate(probs)},
            "regime_probability": {name: prob[k].tolist() for k, name in enumerate(rg.REGIMES)},
            "model_holds": holds.tolist(), "notes": reason, "options": opt.as_dict(), "transfer": transfer,
            "transition_velocities_m_s": {"onset": pred["U_y"].tolist(), "breakup": pred["U_x"].tolist(),
                                          "erosion": pred["U_e"].tolist()},
            "transition_intervals_90_m_s": {k: [[float(v * math.exp(-z90 * t_med)), float(v * math.exp(z90 * t_med))]
                                                for v in pred[key]]
                                            for k, key in (("onset", "U_y"), ("breakup", "U_x"), ("erosion", "U_e"))},
            "warnings": warnings}


# --- transfer across noses without a second nose's shots (issue 36, item 4) -----------------------

ORDERING_NOSES = (
    ("flat", {"nose": "flat"}),
    ("sphere", {"nose": "sphere"}),
    ("cone 30 deg (15 deg half-angle)", {"nose": "cone", "half_angle": "15 deg"}),
    ("ogive 3 CRH", {"nose": "ogive", "crh": 3.0}),
    ("ogive 6 CRH", {"nose": "ogive", "crh": 6.0}),
)
"""The five noses of the ordering check, each on the case's own rod (diameter, shank, steel)."""
_NOSE_KEYS_ALL = ("nose", "crh", "half_angle", "bluntness", "nose_length", "tip_radius", "table")


def nose_variant(case, nose: dict):
    """The case with its ``[projectile]`` nose replaced by ``nose`` (the rest of the rod and the
    target unchanged); ``[data]`` is kept for the cavity constants of the Forrestal load."""
    raw = {k: (dict(v) if isinstance(v, dict) else v) for k, v in case.raw.items()}
    proj = {k: v for k, v in raw["projectile"].items() if k not in _NOSE_KEYS_ALL}
    proj.update(nose)
    raw["projectile"] = proj
    raw.pop("data", None)  # no shots; the cavity law of the original case is passed on (nose_ordering_study)
    return case.with_raw(raw)


def nose_ordering_study(case, coefficients_for, opt: Options, f: float, b: float | None, e: float | None,
                        hardness_hrc: float | None = None, reference_velocity: float = 1000.0) -> dict:
    """Transition velocities per nose of :data:`ORDERING_NOSES` for the case's rod at the constants
    (f, b, e) (the ogive fit), with each nose's load at ``reference_velocity`` (the nose stress
    sigma_n = F / (pi a^2) of the model set's load and, for comparison, of the other loads).
    ``ordered``: the transitions fall strictly as the nose load rises (a blunter nose earlier).
    ``coefficients_for(case)`` gives a case's coefficient table (BEM, cached)."""
    from semianalytic.penetration.curve import PenetrationSetup
    from semianalytic.penetration.hardness import meyer_hardness_from_vickers, parse_hardness, vickers_from_rockwell_c
    from semianalytic.penetration.validation import peer_inputs

    law, _ = peer_inputs(case, PenetrationSetup.from_case(case, coefficients_for(case)))
    H = hardness_hrc if hardness_hrc is not None else parse_hardness(case.projectile.hardness)
    HM = float(meyer_hardness_from_vickers(vickers_from_rockwell_c(H)))
    rows = []
    for label, nose in ORDERING_NOSES:
        c = nose_variant(case, nose)
        setup = PenetrationSetup.from_case(c, coefficients_for(c))
        loads = case_nose_loads(c, setup, law)
        L = loads[opt.nose_load]
        one = RegimeShots(group=label, ids=("0",), velocity=np.array([reference_velocity]), mass=np.array([setup.mass]),  # noqa: F841
                          depth=np.array([np.nan]), recorded=np.array([-1]), responses=("",), static_yield=np.array([np.nan]),
                          static_ultimate=np.array([np.nan]), meyer_hardness=np.array([HM]), part1_depth=np.array([np.nan]),
                          forrestal_depth=np.array([np.nan]), critical=None, rod_length=np.array([np.nan]), length=np.nan,
                          nose_length=np.nan, diameter=np.nan, density=np.nan, target_density=setup.target_density,
                          resistance={"part1": setup.resistance_pa, "tate1986": _tate1986_resistance(c)}, nose_loads=loads)
        if uses_nose_load(opt):
            kap = f
            Uy = float(transition_velocity(kap, HM, L.static, L.linear, L.quadratic))
            Ue = max(Uy, float(transition_velocity(kap, e * HM, L.static, L.linear, L.quadratic)))
            Ub = (float(np.clip(transition_velocity(kap, b * HM, L.static, L.linear, L.quadratic), Uy, Ue))
                  if b is not None else Uy)
        else:
            Uy = Ub = Ue = math.nan
        rows.append({"nose": label, "load_kind": opt.nose_load,
                     "nose_stress_Pa": {k: float(v.stress(reference_velocity)) for k, v in loads.items()},
                     "dynamic_load_Pa": float(L.dynamic(reference_velocity)),
                     "onset_m_s": Uy, "breakup_m_s": Ub, "erosion_m_s": Ue})
    order = sorted(rows, key=lambda r: r["dynamic_load_Pa"])
    ordered = all(a[k] > b_[k] for a, b_ in zip(order, order[1:]) for k in ("onset_m_s", "erosion_m_s")) and all(
        a["dynamic_load_Pa"] < b_["dynamic_load_Pa"] for a, b_ in zip(order, order[1:]))
    return {"hardness_hrc": float(H), "meyer_hardness_Pa": HM, "reference_velocity_m_s": reference_velocity,
            "rows": rows, "ordered": bool(ordered)}


def eroding_trend(shots: RegimeShots, opt: Options, f: float | None = None, U=np.linspace(1500.0, 3500.0, 21)) -> dict:  # noqa: B008
    """The eroding rod's depth over 1.5-3.5 km/s for the group's mean rod: whether it rises with the
    striking velocity (towards the hydrodynamic limit L sqrt(rho_p / rho_t)) and whether Y_p > R_t
    (then it falls towards the limit from above, which the bundled eroded shots contradict)."""
    R = shots.resistance[opt.resistance]
    if opt.rod_strength in NEW_ROD_STRENGTHS:
        static = shots.static_ultimate if opt.rod_strength == "static_ultimate" else shots.static_yield
        Y = rg.ROD_FLOW_FACTOR * float(np.mean(static))
    else:
        Y = float(f if f is not None else 1.5) * float(np.mean(shots.static_ultimate if opt.rod_strength == "ultimate" else shots.static_yield))  # noqa: E501
    per_len, _, _ = rg.eroding_depth_per_length(U, density=shots.density, target_density=shots.target_density,
                                                 target_resistance=R, rod_strength=Y)
    L0 = float(np.mean(shots.rod_length))
    d = per_len * L0
    return {"velocity_m_s": np.asarray(U).tolist(), "depth_m": d.tolist(), "rising": bool(np.all(np.diff(d) > 0)),
            "rod_strength_Pa": Y, "target_resistance_Pa": float(R), "stronger_rod": bool(Y > R),
            "hydrodynamic_limit_m": L0 * math.sqrt(shots.density / shots.target_density)}


def options_for(case=None, overrides=()) -> Options:
    """The model set of a case: :class:`Options` defaults, the case's ``[regimes]`` keys over them,
    then ``overrides`` (``KEY=VALUE`` strings of ``calibrate --option``) over those.  InputError
    naming the key and the allowed values for an unknown key or value, or a combination that does
    not go together."""
    import dataclasses

    from semianalytic.errors import InputError

    d = Options().as_dict()
    sec = case.section("regimes") if case is not None else None
    if sec is not None:
        d.update(sec.choices())
    for item in overrides or ():
        key, sep, val = str(item).partition("=")
        key, val = key.strip(), val.strip()
        if not sep or key not in OPTION_VALUES:
            raise InputError("--option", f"{item!r}: expected KEY=VALUE with KEY one of {', '.join(OPTION_VALUES)}")
        if val not in OPTION_VALUES[key]:
            raise InputError(f"--option {key}", f"unknown value {val!r}; allowed: {', '.join(OPTION_VALUES[key])}")
        d[key] = val
    opt = dataclasses.replace(Options(), **d)
    opt.check("--option" if overrides else "regimes")
    why = combination_error(opt)
    if why is not None:
        raise InputError("--option" if overrides else "regimes", why)
    return opt


def dataclasses_replace(opt: Options, **kw) -> Options:
    import dataclasses

    return dataclasses.replace(opt, **kw)


def orders_noses(opt: Options) -> bool:
    """Whether the model set's transitions depend on the nose through its load, so that a blunter nose
    (larger load) transitions earlier: the nose-load criteria with the ``part1`` or ``forrestal`` load,
    and Part I's U_sC (its Bbar); the tip-pressure criteria give every nose the same velocities
    (checked numerically by :func:`nose_ordering_study`, printed in the report)."""
    if uses_nose_load(opt):
        return opt.nose_load in ("part1", "forrestal")
    return opt.onset == "part1_usc"


SEED_SPHERE = {"velocity_m_s": 1000.0, "length_m": 74.675e-3, "density_kg_m3": 8000.0, "hardness_hrc": (38.0, 39.5),
               "quote": "Part I, Appendix: the spherical-nose projectile of VAR 4340 (L = 74.675 mm, d = 7.11 mm, "
                        "rho_p = 8000 kg/m^3) into 6061-T651; 'From the experiment U_sC ~ 1000 m/s' (the velocity from "
                        "which the rod deforms irreversibly and its motion becomes unstable, the seed's ref. [9])"}
"""The seed's one statement of a spherical-nose transition (Part I, Appendix): a check of the order of
magnitude of the nose effect, not a value to fit.  Hardness: the bundled data's VAR 4340 (38 HRC) and
the 39.5 HRC the issue quotes for that rod (the seed states none)."""


def seed_sphere_statement(case, coefficients_for, opt: Options, f: float, b: float | None, e: float | None) -> dict:
    """The ogive-fitted transitions of the seed's spherical-nose VAR 4340 rod (:data:`SEED_SPHERE`) on the
    case's target, beside the seed's ~1000 m/s, for each hardness of :data:`SEED_SPHERE`."""
    nose_len = 0.5 * case.projectile.diameter
    c = nose_variant(case, {"nose": "sphere"})
    raw = dict(c.raw)
    raw["projectile"] = {**raw["projectile"], "shank_length": f"{(SEED_SPHERE['length_m'] - nose_len) * 1e3:.4f} mm",
                         "density": f"{SEED_SPHERE['density_kg_m3']:g} kg/m^3"}
    c = case.with_raw(raw)
    rows = []
    for H in SEED_SPHERE["hardness_hrc"]:
        res = _one_nose(case, c, coefficients_for, opt, f, b, e, H)
        rows.append({"hardness_hrc": H, **res})
    return {"quote": SEED_SPHERE["quote"], "seed_velocity_m_s": SEED_SPHERE["velocity_m_s"], "rows": rows,
            "options": opt.as_dict()}


def _one_nose(case, c, coefficients_for, opt: Options, f, b, e, H) -> dict:
    """Transitions of the case ``c`` (one nose) at hardness H with the loads of every kind (the
    cavity law of ``case``)."""
    from semianalytic.penetration.curve import PenetrationSetup
    from semianalytic.penetration.hardness import meyer_hardness_from_vickers, vickers_from_rockwell_c
    from semianalytic.penetration.validation import peer_inputs

    law, _ = peer_inputs(case, PenetrationSetup.from_case(case, coefficients_for(case)))
    setup = PenetrationSetup.from_case(c, coefficients_for(c))
    loads = case_nose_loads(c, setup, law)
    HM = float(meyer_hardness_from_vickers(vickers_from_rockwell_c(H)))
    L = loads[opt.nose_load]
    Uy = float(transition_velocity(f, HM, L.static, L.linear, L.quadratic))
    Ue = max(Uy, float(transition_velocity(f, e * HM, L.static, L.linear, L.quadratic)))
    Ub = float(np.clip(transition_velocity(f, b * HM, L.static, L.linear, L.quadratic), Uy, Ue)) if b is not None else Uy
    tip = loads["tip"]
    return {"onset_m_s": Uy, "breakup_m_s": Ub, "erosion_m_s": Ue,
            "tip_onset_m_s": float(transition_velocity(1.0, HM, tip.static, tip.linear, tip.quadratic)),
            "part1_usc_m_s": float(setup.critical_velocity())}
