"""Bayesian calibration of target parameters on measured depths, with model discrepancy.

Statistical model (per depth model, shots i = 1..n):

    ln P_i = ln D_i(R_t(theta)) + eps_i,   eps_i ~ N(0, sigma^2) independent,

theta = the calibrated target parameters (SI), R_t(theta) the target resistance of the
case's model (Part I, eqs. (16)-(19)), D_i the model's depth for shot i
(:mod:`.models`), sigma the model-discrepancy scale (a multiplicative log-normal error on
the depth) inferred with theta.  The posterior predictive of a new shot is then the mixture
over posterior draws of log-normals, ln P ~ N(ln D(R_t(theta_s)), sigma_s^2): an interval
for a measurement, not only for the parameter.

Sampling: emcee's affine-invariant ensemble (Goodman & Weare 2010; Foreman-Mackey et al.
2013), vectorised over walkers, in u = ln x for positive quantities (with the Jacobian), the
walkers started in a small ball about the posterior mode (Nelder-Mead).  Diagnostics: the
mean acceptance fraction, the integrated autocorrelation time per dimension
(``get_autocorr_time``) and the effective sample size n_walkers n_kept / max tau.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from scipy import special

from semianalytic.calibration.models import DepthSurrogate

__all__ = ["ResistanceMap", "Problem", "Posterior", "sample_posterior", "chain_diagnostics", "CHAINS", "mixture_quantiles", "log_predictive_density"]  # noqa: E501


@dataclass(frozen=True)
class ResistanceMap:
    """R_t(theta): the target's resistance model (a frozen dataclass of
    :mod:`semianalytic.penetration.resistance`) with the fields ``fields`` replaced by theta."""

    resistance: object
    fields: tuple[str, ...]
    diameter: float

    table: tuple | None = None  # (ln theta knots, ln R_t) of one positive parameter, see tabulated()

    def tabulated(self, lo: float, hi: float, n: int = 4001) -> ResistanceMap:
        """The same map for one positive parameter as linear interpolation of ln R_t in ln theta
        on ``n`` knots over [lo, hi] (outside: the direct evaluation).  The closed forms of
        eqs. (16)-(19) are smooth in ln theta: with knots 1e-3 apart in ln theta the
        interpolation error is below 1e-7 (checked in the tests), and the sampler's
        log-density costs no Python loop over walkers."""
        if len(self.fields) != 1 or not (0 < lo < hi):
            return self
        x = np.linspace(np.log(lo), np.log(hi), n)
        R = self(np.exp(x)[:, None])
        if not np.all(np.isfinite(R)):
            return self
        return dataclasses.replace(self, table=(x, np.log(R)))

    def __call__(self, theta) -> np.ndarray:
        theta = np.atleast_2d(np.asarray(theta, float))
        if self.table is not None:
            x, lnR = self.table
            with np.errstate(divide="ignore", invalid="ignore"):
                lt = np.log(theta[:, 0])
            inside = (lt >= x[0]) & (lt <= x[-1])
            out = np.exp(np.interp(lt, x, lnR))
            if np.all(inside):
                return out
            rest = dataclasses.replace(self, table=None)(theta[~inside])
            out[~inside] = rest
            return out
        out = np.empty(len(theta))
        for k, row in enumerate(theta):
            try:
                model = dataclasses.replace(self.resistance, **dict(zip(self.fields, map(float, row))))
                R = float(model.pressure(self.diameter))
            except (ValueError, ArithmeticError):
                R = math.nan
            out[k] = R if R > 0 else math.nan
        return out


@dataclass(frozen=True)
class Problem:
    """One calibration: priors of theta (SI), the discrepancy prior, R_t(theta), one model's
    depth over the shots (``surrogate``: anything with ``log_depth_theta(theta, resistance)``
    and ``model``, a :class:`DepthSurrogate` or an :class:`ErodingDepths`) and the measured
    depths [m] (same order as the surrogate's columns)."""

    names: tuple[str, ...]
    priors: tuple
    sigma_prior: object
    resistance: ResistanceMap
    surrogate: DepthSurrogate
    depth: np.ndarray

    @property
    def ndim(self) -> int:
        return len(self.names) + 1

    def to_natural(self, u):
        """Unconstrained u (n, ndim) -> (theta (n, p), sigma (n,), log Jacobian (n,))."""
        u = np.atleast_2d(u)
        cols, jac = [], np.zeros(len(u))
        for j, prior in enumerate((*self.priors, self.sigma_prior)):
            if prior.positive:
                cols.append(np.exp(u[:, j]))
                jac += u[:, j]
            else:
                cols.append(u[:, j])
        x = np.column_stack(cols)
        return x[:, :-1], x[:, -1], jac

    def to_unconstrained(self, theta, sigma):
        x = np.column_stack([np.atleast_2d(theta), np.atleast_1d(sigma)])
        pri = (*self.priors, self.sigma_prior)
        return np.column_stack([np.log(x[:, j]) if p.positive else x[:, j] for j, p in enumerate(pri)])

    def log_prob(self, u) -> np.ndarray:
        """Log posterior density in u (vectorised over rows)."""
        theta, sigma, jac = self.to_natural(u)
        lp = jac + self.sigma_prior.logpdf(sigma)
        for j, prior in enumerate(self.priors):
            lp = lp + prior.logpdf(theta[:, j])
        ok = np.isfinite(lp)
        out = np.full(len(lp), -np.inf)
        if not ok.any():
            return out
        mu = self.surrogate.log_depth_theta(theta[ok], self.resistance)  # (n_ok, n_shots), NaN: no valid depth
        s = sigma[ok][:, None]
        z = (np.log(self.depth)[None, :] - mu) / s
        ll = np.sum(-0.5 * z * z - np.log(s) - 0.5 * math.log(2 * math.pi), axis=1)
        ll = np.where(np.isfinite(ll), ll, -np.inf)
        out[ok] = lp[ok] + ll
        return out


@dataclass(frozen=True)
class Posterior:
    """Posterior draws (thinned, flattened): theta (n, p) SI, R_t (n,) [Pa], sigma (n,);
    and the sampler's diagnostics."""

    names: tuple[str, ...]
    theta: np.ndarray
    resistance: np.ndarray
    sigma: np.ndarray
    acceptance_fraction: float
    autocorrelation_time: tuple[float, ...]
    effective_sample_size: float
    n_walkers: int
    n_steps: int
    n_burn: int
    mode: tuple[float, ...]
    mode_u: tuple[float, ...] = ()
    diagnostics: dict | None = None  # chain_diagnostics: R-hat and ESS per parameter, warnings


def _mode(problem: Problem, rng) -> np.ndarray:
    """The posterior mode in u (Nelder-Mead from the prior medians)."""
    from scipy.optimize import minimize

    pri = (*problem.priors, problem.sigma_prior)
    start = problem.to_unconstrained(np.array([[float(p.ppf(0.5)) for p in problem.priors]]), float(pri[-1].ppf(0.5)))[0]
    best = None
    for trial in range(4):
        x0 = start if trial == 0 else start + 0.3 * rng.standard_normal(len(start))
        f = lambda u: -float(problem.log_prob(u[None, :])[0])  # noqa: E731
        if not math.isfinite(f(x0)):
            continue
        res = minimize(f, x0, method="Nelder-Mead", options={"xatol": 1e-6, "fatol": 1e-8, "maxiter": 4000})
        if best is None or res.fun < best.fun:
            best = res
    if best is None:
        raise ValueError("the posterior is zero at the prior medians: no parameter value reproduces the data")
    return best.x


def sample_posterior(problem: Problem, *, walkers: int = 32, steps: int = 2000, burn: int = 500, seed: int = 1,
                     max_draws: int = 4000, progress: bool = False, start=None) -> Posterior:
    """Sample the posterior of ``problem`` with emcee (see the module docstring).  ``start``:
    a point in u near the mode (e.g. the full-data mode for a leave-one-out refit)."""
    import emcee

    from semianalytic.thirdparty import run_mcmc

    rng = np.random.default_rng(seed)
    if start is not None and np.isfinite(problem.log_prob(np.asarray(start)[None, :])[0]):
        from scipy.optimize import minimize

        f = lambda u: -float(problem.log_prob(u[None, :])[0])  # noqa: E731
        u0 = minimize(f, np.asarray(start, float), method="Nelder-Mead", options={"xatol": 1e-6, "fatol": 1e-8}).x
    else:
        u0 = _mode(problem, rng)
    ndim = problem.ndim
    walkers = max(walkers, 2 * ndim + 2)
    # CHAINS independent ensembles (own walkers, own random stream): arviz's R-hat between them;
    # each ensemble half the walkers (twice the former cost; a quarter mixed too slowly to meet the
    # quadrature check of tests/test_calibration.py)
    per = max(walkers // 2, 2 * ndim + 2)
    walkers = per * CHAINS
    p0 = u0[None, :] + 1e-2 * rng.standard_normal((walkers, ndim))
    chains, taus, acc = [], [], []
    for c in range(CHAINS):
        sampler = emcee.EnsembleSampler(per, ndim, problem.log_prob, vectorize=True)
        sampler.random_state = np.random.RandomState(seed + 7919 * c).get_state()
        run_mcmc(sampler, p0[c * per:(c + 1) * per], steps, progress=progress,  # Ctrl-C between steps (issue 40)
                 progress_kwargs={"desc": f"sampling {problem.surrogate.model} ({c + 1}/{CHAINS})", "leave": False})
        chains.append(sampler.get_chain(discard=burn))  # (steps - burn, per, ndim)
        taus.append(np.asarray(sampler.get_autocorr_time(discard=burn, tol=0, quiet=True), float))
        acc.append(float(np.mean(sampler.acceptance_fraction)))
    chain = np.concatenate(chains, axis=1)  # (steps - burn, walkers, ndim)
    tau = np.max(np.array(taus), axis=0)
    n_kept = chain.shape[0] * chain.shape[1]
    ess = float(n_kept / np.max(tau)) if np.all(np.isfinite(tau)) else math.nan
    # every walker of every ensemble one chain for arviz (as arviz.from_emcee reads an ensemble)
    nat_chains = np.stack([np.column_stack(problem.to_natural(w)[:2]) for ch in chains for w in np.swapaxes(ch, 0, 1)])
    diagnostics = chain_diagnostics(nat_chains, (*problem.names, "sigma"))
    # thin by steps, keeping every walker (thinning the flattened (step, walker) array would keep
    # the same few walkers at every step)
    thin = max(1, int(math.ceil(chain.shape[0] * chain.shape[1] / max_draws)))
    flat = chain[::thin].reshape(-1, ndim)
    theta, sigma, _ = problem.to_natural(flat)
    R = problem.resistance(theta)
    theta_mode, sigma_mode, _ = problem.to_natural(u0[None, :])
    return Posterior(
        problem.names, theta, R, sigma, float(np.mean(acc)), tuple(map(float, tau)), ess,
        walkers, steps, burn, (*map(float, theta_mode[0]), float(sigma_mode[0])), tuple(map(float, u0)), diagnostics,
    )


CHAINS = 4  # independent ensembles per calibration (issue 22 item 5)


def MOVES():
    """emcee moves of ``calibrate --model regimes``: differential evolution (ter Braak 2006,
    Statistics and Computing 16:239; emcee.moves.DEMove) with its snooker update (ter Braak & Vrugt
    2008) in 1 of 5 steps; from walkers spread over the prior they cross the steps of that posterior
    (a transition passing a shot) faster than the stretch move.  (The other calibrations keep the
    stretch move: their walkers start in a small ball at the mode, which DE moves would not expand.)"""
    import emcee

    return [(emcee.moves.DEMove(), 0.8), (emcee.moves.DESnookerMove(), 0.2)]
RHAT_MAX = 1.01  # Vehtari et al. (2021), Bayesian Analysis 16:667: R-hat < 1.01 and ESS > 400
ESS_MIN = 400
TAIL_PROB = (0.05, 0.95)  # the tail ESS: the 5 % and 95 % quantiles' indicators (Vehtari et al. 2021, sec. 4.3)


def chain_diagnostics(chains, names) -> dict:
    """Per parameter: arviz's rank-normalised split R-hat and bulk and tail effective sample
    sizes (Vehtari, Gelman, Simpson, Carpenter & Buerkner 2021, Bayesian Analysis 16:667; arviz 0.x
    or 1.x, the same numbers) of
    ``chains`` (n_chains, n_draws, n_params), and ``warnings`` naming each parameter with R-hat >
    1.01 or an ESS below 400 (the thresholds of that paper)."""
    import warnings as _w

    with _w.catch_warnings():
        _w.simplefilter("ignore")
        from semianalytic.thirdparty import import_arviz

        az = import_arviz()  # no stamp file in ~/.cache (issue 40)

        chains = np.asarray(chains, float)
        out, warn = {}, []
        for j, name in enumerate(names):
            x = chains[:, :, j]
            rhat = float(az.rhat(x))
            bulk = float(az.ess(x, method="bulk"))
            # the tail quantiles given: arviz 1.x has no default for them (0.x: the same 5 % and 95 %)
            tail = float(az.ess(x, method="tail", prob=TAIL_PROB))
            out[name] = {"r_hat": rhat, "ess_bulk": bulk, "ess_tail": tail}
            if not rhat <= RHAT_MAX:
                warn.append(f"{name}: R-hat {rhat:.3f} > {RHAT_MAX} (the chains disagree; sample longer or reparametrise)")
            if not min(bulk, tail) >= ESS_MIN:
                warn.append(f"{name}: effective sample size {min(bulk, tail):.0f} < {ESS_MIN} (sample longer)")
    return {"parameters": out, "chains": int(chains.shape[0]), "draws_per_chain": int(chains.shape[1]), "ensembles": CHAINS,
            "warnings": warn}


def mixture_quantiles(mu: np.ndarray, sigma: np.ndarray, probs, max_draws: int = 2000, tol: float = 1e-12,
                      max_newton: int = 40) -> np.ndarray:
    """Quantiles of the mixture (1/n) sum_s LogNormal(mu_s, sigma_s^2) for each column of
    mu (n_s, n_x) (sigma (n_s,) or, one per element, (n_s, n_x)); returns (len(probs), n_x) in the
    units of exp(mu).

    Solved for ln q of every (quantile, column) at once by safeguarded Newton steps on the
    mixture CDF F (monotone; F' is the mixture density) inside the bracket [min_s, max_s] of the
    components' own quantiles mu_s + sigma_s z_p (F < p below every component's p-quantile, F > p
    above all of them); a step that leaves the bracket is replaced by bisection, and the bracket
    shrinks with the sign of F - p at every iterate.  Converged when every step is below ``tol``
    (relative, ln q; typically 5-8 iterations); entries not converged after ``max_newton``
    iterations are finished by 64 bisections of their bracket (2^-64 of its width), so the
    result is always converged.  More than ``max_draws`` draws are thinned evenly (the
    Monte-Carlo error of a quantile from 2000 draws is well below the interval widths)."""
    mu = np.atleast_2d(np.asarray(mu, float))
    s = np.asarray(sigma, float)
    if len(s) > max_draws:
        idx = np.linspace(0, len(s) - 1, max_draws).astype(int)
        mu, s = mu[idx], s[idx]
    s = np.broadcast_to(s[:, None] if s.ndim == 1 else s, mu.shape)
    p = np.asarray(probs, float)
    m3, inv = mu[:, None, :], 1.0 / s[:, None, :]
    comp = m3 + special.ndtri(p)[None, :, None] / inv  # (n_s, n_p, n_x): each component's own p-quantile
    lo, hi = comp.min(axis=0), comp.max(axis=0)
    x = np.mean(comp, axis=0)
    pp = p[:, None]
    norm = 1.0 / math.sqrt(2.0 * math.pi)
    done = np.zeros(x.shape, bool)
    for _ in range(max_newton):
        z = (x[None] - m3) * inv
        g = np.mean(special.ndtr(z), axis=0) - pp  # F(x) - p
        dens = np.mean(np.exp(-0.5 * z * z) * inv, axis=0) * norm  # F'(x)
        lo = np.where(g < 0, x, lo)
        hi = np.where(g > 0, x, hi)
        with np.errstate(divide="ignore", invalid="ignore"):
            new = x - g / dens
        new = np.where(np.isfinite(new) & (new >= lo) & (new <= hi), new, 0.5 * (lo + hi))
        done = (g == 0) | (np.abs(new - x) <= tol * np.maximum(1.0, np.abs(x)))
        x = np.where(g == 0, x, new)
        if done.all():
            return np.exp(x)
    for _ in range(64):  # the safeguard: plain bisection of the remaining brackets
        mid = 0.5 * (lo + hi)
        below = np.mean(special.ndtr((mid[None] - m3) * inv), axis=0) < pp
        lo = np.where(below, mid, lo)
        hi = np.where(below, hi, mid)
    return np.exp(np.where(done, x, 0.5 * (lo + hi)))


def log_predictive_density(mu: np.ndarray, sigma: np.ndarray, depth: np.ndarray) -> np.ndarray:
    """ln p(ln P_obs | data) = ln mean_s N(ln P_obs; mu_s, sigma_s^2) per column (density of ln P)."""
    mu = np.atleast_2d(mu)
    s = np.asarray(sigma, float)[:, None]
    z = (np.log(np.asarray(depth, float))[None, :] - mu) / s
    lp = -0.5 * z * z - np.log(s) - 0.5 * math.log(2 * math.pi)
    return special.logsumexp(lp, axis=0) - math.log(mu.shape[0])
