"""Error estimates of the predicted depths: the coefficients' error estimates carried through
Part I, eq. (11) and the models built on it, plus the integrator's error.

- Coefficients: each of A, B, C is shifted by its estimated error (interpolation plus BEM,
  :meth:`semianalytic.coefficients.table.CoefficientTable.error`; the deep limit by its
  extrapolation error), one at a time, and the depths recomputed; the estimate is the sum
  of the three changes (first order in the errors, no assumption on their signs).
- Integrator: the integration in P and the time grid are refined (panels halved, time grid
  doubled) and the change is added.

The paper's quoted constants (``--coefficients paper``) carry no numerical error of their
own (they are inputs); only the integrator's part remains.
"""

from __future__ import annotations

import dataclasses

import numpy as np

__all__ = ["MODEL_KEYS", "ShiftedCoefficients", "depth_error_estimate"]

MODEL_KEYS = {
    "rigid": "depth_rigid_m",
    "quasi_rigid": "depth_quasi_rigid_m",
    "elastic": "depth_elastic_m",
    "elastic_exact_rod": "depth_elastic_exact_rod_m",
}


class ShiftedCoefficients:
    """A coefficient table with one coefficient (``A``, ``B`` or ``C``) shifted by its
    estimated error; everything else passes through."""

    def __init__(self, table, which: str):
        self._table, self._which = table, which

    def __getattr__(self, name):
        return getattr(self._table, name)

    def _shift(self, name: str, P, value):
        return value + (self._table.error(name, P) if name[0] == self._which else 0.0)

    def A(self, P):
        return self._shift("A", P, self._table.A(P))

    def B(self, P, reading: str | None = None):
        reading = reading or self._table.reading
        return self._shift(f"B_{reading}", P, self._table.B(P, reading))

    def C(self, P):
        return self._shift("C", P, self._table.C(P))

    def deep_limit(self, reading: str | None = None):
        t = self._table
        reading = reading or t.reading
        A, B, C = t.deep_limit(reading)
        names = ("A", f"B_{reading}", "C")
        shifted = [v + ((t.limit_errors.get(n, 0.0) + t.bem_errors.get(n, 0.0)) if n[0] == self._which else 0.0)
                   for v, n in zip((A, B, C), names)]
        return tuple(shifted)


def depth_error_estimate(setup, velocities, nominal: dict, *, w1: str = "neglect", curve=None) -> dict:
    """{"rigid": [...], "quasi_rigid": [...], "elastic": [...], "elastic_exact_rod": [...]}:
    the estimated numerical error [m] of each depth of ``nominal`` (the output of
    :func:`semianalytic.penetration.curve.penetration_curve` for ``setup``), per striking velocity."""
    from semianalytic.penetration.curve import penetration_curve

    curve = curve or penetration_curve
    U = np.atleast_1d(np.asarray(velocities, float))
    total = {k: np.zeros(U.shape) for k in MODEL_KEYS}

    def add(res):
        for k, key in MODEL_KEYS.items():
            total[k] += np.abs(np.asarray(res[key], float) - np.asarray(nominal[key], float))

    coef = setup.coefficients
    if callable(getattr(coef, "error", None)):
        for which in ("A", "B", "C"):
            add(curve(dataclasses.replace(setup, coefficients=ShiftedCoefficients(coef, which)), U, w1=w1))
    add(curve(setup, U, w1=w1, n_grid=1024, panel_scale=0.5))
    return {k: [float(x) for x in v] for k, v in total.items()}
