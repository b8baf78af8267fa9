"""Prior distributions of the calibrated parameters and of the model-discrepancy scale.

Each prior is a frozen dataclass over SI values with ``logpdf(x)`` (vectorised, -inf outside
the support), ``ppf(q)`` (quantiles, for the surrogate's range and the report) and
``positive`` (sampled in ln x when True).  The case layer parses the strings
("lognormal(300 MPa, 0.5)") into these; nothing here knows about units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["LogNormal", "Normal", "Uniform", "HalfNormal", "Prior"]


@dataclass(frozen=True)
class LogNormal:
    """ln x ~ N(ln median, sigma^2)."""

    median: float
    sigma: float
    positive = True

    def logpdf(self, x):
        x = np.asarray(x, float)
        with np.errstate(divide="ignore", invalid="ignore"):
            z = (np.log(x) - math.log(self.median)) / self.sigma
            out = -0.5 * z * z - np.log(x * self.sigma * math.sqrt(2 * math.pi))
        return np.where(x > 0, out, -np.inf)

    def ppf(self, q):
        from scipy import special  # scipy.stats/special load on use: case loading stays light

        return self.median * np.exp(self.sigma * special.ndtri(np.asarray(q, float)))

    def describe(self, unit_scale: float = 1.0, unit: str = "") -> str:
        return f"lognormal(median {self.median / unit_scale:.4g} {unit}, sigma {self.sigma:g})".replace(" )", ")")


@dataclass(frozen=True)
class Normal:
    mean: float
    sd: float
    positive = False

    def logpdf(self, x):
        z = (np.asarray(x, float) - self.mean) / self.sd
        return -0.5 * z * z - math.log(self.sd * math.sqrt(2 * math.pi))

    def ppf(self, q):
        from scipy import special  # the normal quantile, without loading scipy.stats (~0.4 s)

        return self.mean + self.sd * special.ndtri(np.asarray(q, float))

    def describe(self, unit_scale: float = 1.0, unit: str = "") -> str:
        return f"normal({self.mean / unit_scale:.4g} {unit}, {self.sd / unit_scale:.4g} {unit})"


@dataclass(frozen=True)
class Uniform:
    low: float
    high: float
    positive = False

    def logpdf(self, x):
        x = np.asarray(x, float)
        return np.where((x >= self.low) & (x <= self.high), -math.log(self.high - self.low), -np.inf)

    def ppf(self, q):
        return self.low + np.asarray(q, float) * (self.high - self.low)

    def describe(self, unit_scale: float = 1.0, unit: str = "") -> str:
        return f"uniform({self.low / unit_scale:.4g} {unit}, {self.high / unit_scale:.4g} {unit})"


@dataclass(frozen=True)
class HalfNormal:
    """|N(0, scale^2)|: the prior of the discrepancy scale sigma (ln-depth units)."""

    scale: float
    positive = True

    def logpdf(self, x):
        x = np.asarray(x, float)
        z = x / self.scale
        return np.where(x > 0, -0.5 * z * z + math.log(math.sqrt(2 / math.pi) / self.scale), -np.inf)

    def ppf(self, q):
        from scipy import special  # |N(0, scale^2)| has the quantile scale * Phi^-1((1 + q) / 2)

        return self.scale * special.ndtri(0.5 * (1.0 + np.asarray(q, float)))

    def describe(self, unit_scale: float = 1.0, unit: str = "") -> str:
        return f"halfnormal({self.scale:g})"


Prior = LogNormal | Normal | Uniform | HalfNormal
