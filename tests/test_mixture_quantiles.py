"""Quantiles of a log-normal mixture (calibration.sampler.mixture_quantiles) against a scalar
root finder (scipy.optimize.brentq on the mixture CDF, column by column) and the closed form of
a single log-normal: an independent method at points the implementation did not choose."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import optimize, special, stats

from semianalytic.calibration.sampler import mixture_quantiles

PROBS = (0.01, 0.05, 0.25, 0.5, 0.75, 0.95, 0.99)


def _brentq(mu_col, s_col, p):
    def g(y):
        return np.mean(special.ndtr((y - mu_col) / s_col)) - p
    return optimize.brentq(g, mu_col.min() - 12 * s_col.max(), mu_col.max() + 12 * s_col.max(), xtol=1e-14, rtol=1e-15)


@pytest.mark.parametrize("per_element", [False, True])
@pytest.mark.parametrize("newton", [40, 0])  # 0: the bisection safeguard alone
def test_against_brentq(per_element, newton):
    rng = np.random.default_rng(7)
    n_s, n_x = 600, 9
    # a wide, skewed spread of components (log-normal sigmas over a factor 30, means over 2 in ln)
    mu = rng.standard_t(3, (n_s, n_x)) * 0.4 + np.linspace(-4, -2, n_x)
    sig = np.exp(rng.uniform(np.log(0.01), np.log(0.3), (n_s, n_x) if per_element else n_s))
    q = mixture_quantiles(mu, sig, PROBS, max_newton=newton)
    sfull = np.broadcast_to(sig if per_element else sig[:, None], mu.shape)
    for j in range(n_x):
        for k, p in enumerate(PROBS):
            # 1e-9 in ln q: both solvers stop near 1e-12-1e-14; the rest is rounding of the 600-term sums
            assert np.log(q[k, j]) == pytest.approx(_brentq(mu[:, j], sfull[:, j], p), abs=1e-9)


def test_single_component_closed_form():
    q = mixture_quantiles(np.full((3, 4), np.log(0.05)), np.full(3, 0.2), PROBS)
    exact = stats.lognorm(0.2, scale=0.05).ppf(PROBS)
    assert np.allclose(q, exact[:, None], rtol=1e-10)  # 1e-10: the closed form to rounding


def test_bimodal_cdf_reaches_p():
    """Two far modes: the CDF at each returned quantile equals p (where the CDF is flat, any point
    of the flat stretch is a p-quantile, so the check is on F, not on the position)."""
    mu = np.concatenate([np.full((300, 2), -4.0), np.full((700, 2), -1.0)])
    s = np.full(1000, 0.05)
    for p in (0.1, 0.3, 0.31, 0.6, 0.9):
        y = np.log(mixture_quantiles(mu, s, (p,))[0])
        F = np.mean(special.ndtr((y[None, :] - mu) / s[:, None]), axis=0)
        assert np.allclose(F, p, atol=1e-9)
