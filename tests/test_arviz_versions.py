"""chain_diagnostics on the installed arviz (0.x on the 3.11 leg of CI, 1.x on the 3.13 leg:
``make test`` runs both): arviz 1.x has no default tail quantiles (``az.ess(x, method="tail")``
raised a TypeError there), so they are given, and the numbers are checked against the theory of
an AR(1) chain, which neither arviz version computes."""

from __future__ import annotations

import numpy as np
import pytest

from semianalytic.calibration.sampler import chain_diagnostics


def _ar1(rng, rho, chains, draws):
    x = np.empty((chains, draws))
    x[:, 0] = rng.standard_normal(chains)
    e = rng.standard_normal((chains, draws)) * np.sqrt(1 - rho * rho)  # stationary N(0, 1)
    for t in range(1, draws):
        x[:, t] = rho * x[:, t - 1] + e[:, t]
    return x


def test_tail_and_bulk_ess_against_ar1_theory():
    """iid N(0, 1) (rho = 0): bulk and tail ESS near the 4000 draws; AR(1) with rho = 0.8: the
    bulk ESS near N (1 - rho)/(1 + rho) = 444 (the integrated autocorrelation time of AR(1)).
    Tolerances: 25 % for iid (the estimates' own scatter at this size is about 5 %; the tail ESS,
    from 5 % indicators, scatters more) and 30 % for the AR(1) (a 10000-draw estimate of a
    correlated chain scatters by about 10 %)."""
    rng = np.random.default_rng(11)
    iid = rng.standard_normal((4, 1000, 1))
    p = chain_diagnostics(iid, ("a",))["parameters"]["a"]
    assert p["ess_bulk"] == pytest.approx(4000, rel=0.25) and p["ess_tail"] == pytest.approx(4000, rel=0.25)
    assert p["r_hat"] < 1.01
    x = _ar1(rng, 0.8, 4, 2500)[:, :, None]
    p = chain_diagnostics(x, ("b",))["parameters"]["b"]
    assert p["ess_bulk"] == pytest.approx(10000 * 0.2 / 1.8, rel=0.3)
    assert p["ess_tail"] < 0.5 * 10000  # correlated indicators: far fewer than the draws

