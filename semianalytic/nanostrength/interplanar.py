"""Bulk interplanar law Phi(d) of the weakest {111} layer pair and the stress of eq. (14).

The paper computes Phi(d, rho) from a pseudo-potential whose form factors are not given
(errata item 21), so Tables 1-2 cannot be recomputed from first principles.  Here Phi(d) is a
documented analytic relation calibrated to each crystal's Table 1-2 values:

``cutoff`` (default)
    Phi(d) = Phi_0 exp(-q(x)),  x = (d - d_0)/d_0,
    q(x) = k x^2/2 + alpha_t x^p_t (tension, x > 0),  k x^2/2 + alpha_c |x|^p_c (compression).
    A harmonic well of depth Phi_0 (Table 1) with an anharmonic cut-off; it tends to 0 on
    separation, so the work of separation is |Phi_0|.  k = E d_0/|Phi_0| gives Young's
    modulus; (alpha, p) on each side put the first peak of the stress of eq. (14) at
    (e**, sigma_2^max) in tension and at (-e*, -sigma_1^max) in compression.  So the five
    numbers of Table 2 are met exactly, with the depth of Table 1, by one relation whose
    anharmonic term has its own constants on each side of d_0.  Why the cut-off is needed:
    with the depth of Table 1 and E of Table 2 the harmonic energy E d_0 e^2/2 reaches |Phi_0|
    at e ~ 0.15, just past the tensile peak e** ~ 0.146, and the compressive strength is about
    twice E e* -- curves that no two-parameter binding relation can follow (see ``uber``).
    Beyond the compressive peak the stress falls back to zero (no repulsive wall): the law is
    meant for -e* <= e, where the paper's Fig. 2 has its interval from B to D and beyond.

``uber``
    The universal binding-energy relation of Rose, Ferrante and Smith (1981),
    Phi(d) = -Phi_b (1 + a) exp(-a), a = (d - d_0)/l, with Phi_b and l calibrated to E and
    sigma_2^max.  It is shown for comparison: its tensile peak sits at the wrong strain and it
    has no compressive maximum at all (stress grows without bound in compression).

Stress, Part III, eq. (14) (and eq. (29) for a mesolayer):
    sigma_z = (1/d) dPhi/de_z,   d = d_0 (1 + e_z).
``stress_measure = "current"`` takes d as printed, the current spacing; ``"reference"`` takes
d_0.  They agree at small strain and differ by (1 + e) at the peaks; each law is calibrated
with the measure it is used with.

A free surface multiplies Phi by Phi_i / Phi_0 (Part III, eqs. (17)-(28)); the whole curve is
scaled, so sigma_max scales by the same factor and e* does not change (this is what Table 4
shows: sigma_1 and sigma_2 change by the same ratio in every crystal).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Literal

import numpy as np

from semianalytic.nanostrength.crystal import Crystal

Measure = Literal["current", "reference"]
MEASURES = ("current", "reference")
LAWS = ("cutoff", "uber")


class CalibrationError(ValueError):
    """The law cannot be calibrated to the given crystal data (``.crystal`` names it)."""

    def __init__(self, crystal: str, message: str):
        self.crystal = crystal
        super().__init__(f"{crystal}: {message}")


@dataclass(frozen=True)
class Strength:
    """Peaks of sigma(e): tension (sigma_t > 0 at e_t > 0) and compression (magnitudes; nan if
    the law has no compressive maximum)."""

    sigma_t: float
    e_t: float
    sigma_c: float
    e_c: float


class _Law:
    """Shared part: stress of eq. (14) from dPhi/de and d2Phi/de2 (subclasses give those)."""

    d0: float
    measure: Measure

    # subclasses: energy(d), _g1(x) = dPhi/de, _g2(x) = d2Phi/de2 (x = e)
    def stress(self, e):
        """sigma_z = (1/d) dPhi/de_z [Pa]; Part III, eq. (14) (eq. (29) for a mesolayer)."""
        e = np.asarray(e, dtype=float)
        g1 = self._g1(e)
        if self.measure == "current":
            return (g1 / (self.d0 * (1 + e)))[()]
        return (g1 / self.d0)[()]

    def stress_slope(self, e):
        """d sigma_z / d e_z [Pa]."""
        e = np.asarray(e, dtype=float)
        g1, g2 = self._g1(e), self._g2(e)
        if self.measure == "current":
            return ((g2 * (1 + e) - g1) / (self.d0 * (1 + e) ** 2))[()]
        return (g2 / self.d0)[()]

    @property
    def youngs_modulus(self) -> float:
        """E = d sigma / de at e = 0 [Pa] (text before Table 2: sigma = E delta d / d_0)."""
        return float(self.stress_slope(0.0))

    def strength(self, e_max: float = 2.0, e_min: float = -0.9, samples: int = 4000) -> Strength:
        """First maximum of sigma(e) for e > 0 and first minimum for e < 0 (Part III, Fig. 2:
        points D and B), refined by a root of d sigma/de."""
        out = []
        for end in (e_max, e_min):
            e = np.linspace(0.0, end, samples + 1)[1:]
            s = self.stress_slope(e)
            bad = np.nonzero(s <= 0)[0]
            if bad.size == 0:
                out.append((math.nan, math.nan))
                continue
            k = bad[0]
            lo = 0.0 if k == 0 else e[k - 1]
            from scipy.optimize import brentq  # imported when needed (start-up time)
            root = brentq(lambda x: float(self.stress_slope(x)), lo, e[k], xtol=1e-14, rtol=1e-13)
            out.append((abs(float(self.stress(root))), abs(root)))
        (st, et), (sc, ec) = out
        return Strength(st, et, sc, ec)

    def deformation_energy(self, e: float) -> float:
        """Delta Phi = Phi(d_0 (1 + e)) - Phi(d_0) [J/m^2] (text after Part III, eq. (16))."""
        return float(self.energy(self.d0 * (1 + e)) - self.energy(self.d0))

    def work_to(self, e: float) -> float:
        """int_{d_0}^{d_0 (1+e)} sigma(u) du [J/m^2], by quadrature of the stress: Part III,
        eq. (15) with d_max = d_0 (1 + e).  Equals :meth:`deformation_energy` for the
        reference measure; for the current one it differs by the weight d_0/d."""
        from scipy.integrate import quad  # imported when needed (start-up time)
        val, _ = quad(lambda x: float(self.stress(x)), 0.0, e, epsabs=0.0, epsrel=1e-12, limit=200)
        return val * self.d0


@dataclass(frozen=True)
class CutoffLaw(_Law):
    """Harmonic well with an anharmonic cut-off (see module doc):

        Phi(d) = Phi_0 exp(-q(x)),  x = d/d_0 - 1,
        q(x) = k x^2 / 2 + alpha_t x^p_t      (x >= 0, tension)
        q(x) = k x^2 / 2 + alpha_c |x|^p_c    (x < 0, compression)

    phi0 [J/m^2] < 0, d0 [m]; k, alpha_t, p_t, alpha_c, p_c dimensionless (alpha > 0, p > 2).
    """

    phi0: float
    d0: float
    k: float
    alpha_t: float
    p_t: float
    alpha_c: float
    p_c: float
    measure: Measure = "current"

    def _q(self, x, der: int = 0):
        x = np.asarray(x, dtype=float)
        t = x >= 0
        ax = np.abs(x)
        alpha = np.where(t, self.alpha_t, self.alpha_c)
        p = np.where(t, self.p_t, self.p_c)
        sign = np.where(t, 1.0, -1.0)
        if der == 0:
            return 0.5 * self.k * x * x + alpha * ax**p
        if der == 1:
            return self.k * x + sign * p * alpha * ax ** (p - 1)
        return self.k + p * (p - 1) * alpha * ax ** (p - 2)

    def energy(self, d):
        """Phi(d) [J/m^2] of the layer pair at spacing d [m] (d > 0)."""
        x = np.asarray(d, dtype=float) / self.d0 - 1
        return (self.phi0 * np.exp(-self._q(x)))[()]

    def _g1(self, x):  # dPhi/de = |Phi_0| q' e^{-q}
        return -self.phi0 * self._q(x, 1) * np.exp(-self._q(x))

    def _g2(self, x):  # d2Phi/de2 = |Phi_0| (q'' - q'^2) e^{-q}
        q1 = self._q(x, 1)
        return -self.phi0 * (self._q(x, 2) - q1 * q1) * np.exp(-self._q(x))

    def scaled(self, factor: float) -> CutoffLaw:
        """The same curve with Phi multiplied by ``factor`` (a mesolayer: Phi_i / Phi_0)."""
        return replace(self, phi0=self.phi0 * factor)


@dataclass(frozen=True)
class UberLaw(_Law):
    """Rose-Ferrante-Smith universal binding-energy relation,
    Phi(d) = -Phi_b (1 + a) exp(-a), a = (d - d_0)/l.  phi_b [J/m^2] > 0, d0, l [m]."""

    phi_b: float
    d0: float
    l: float
    measure: Measure = "current"

    @property
    def phi0(self) -> float:
        return -self.phi_b

    def energy(self, d):
        a = (np.asarray(d, dtype=float) - self.d0) / self.l
        return (-self.phi_b * (1 + a) * np.exp(-a))[()]

    def _g1(self, x):  # dPhi/de = d0 dPhi/dd = (Phi_b d0 / l) a e^{-a}
        lam = self.l / self.d0
        a = x / lam
        return self.phi_b / lam * a * np.exp(-a)

    def _g2(self, x):
        lam = self.l / self.d0
        a = x / lam
        return self.phi_b / lam**2 * (1 - a) * np.exp(-a)

    def scaled(self, factor: float) -> UberLaw:
        return replace(self, phi_b=self.phi_b * factor)


Law = CutoffLaw | UberLaw


def _peak_amplitudes(K: float, p: float, x: float, measure: Measure) -> list[float]:
    """Roots A = alpha |x|^p > 0 of the peak condition d sigma/de = 0 at strain x.

    With K = k x^2, x q' = K + p A and x^2 q'' = K + p (p - 1) A, the condition is
    reference: x^2 q'' = (x q')^2;  current: (x^2 q'' - (x q')^2)(1 + x) = x (x q')
    -- a quadratic in A.
    """
    w1 = 1.0 + x if measure == "current" else 1.0
    w2 = x if measure == "current" else 0.0
    a = -p * p * w1
    b = (p * (p - 1) - 2 * K * p) * w1 - w2 * p
    c = (K - K * K) * w1 - w2 * K
    disc = b * b - 4 * a * c
    if disc < 0:
        return []
    roots = sorted((-b + s * math.sqrt(disc)) / (2 * a) for s in (1.0, -1.0))
    return [r for r in roots if r > 0]


def _calibrate_side(crystal: Crystal, x: float, sigma: float, measure: Measure) -> list[tuple[float, float]]:
    """Candidate (alpha, p) putting the stress peak sigma at strain x (signed) for the well
    q = k x^2/2 + alpha |x|^p.  Scans p, then refines each sign change with brentq."""
    A0 = -crystal.phi0
    k = crystal.E * crystal.d0 / A0
    K = k * x * x
    w = 1.0 / (1.0 + x) if measure == "current" else 1.0

    def residual(p: float, branch: int) -> float:
        roots = _peak_amplitudes(K, p, x, measure)
        if len(roots) <= branch:
            return math.nan
        A = roots[branch]
        return A0 / crystal.d0 * (K + p * A) / abs(x) * math.exp(-K / 2 - A) * w / sigma - 1

    out = []
    ps = np.geomspace(2.02, 200.0, 1500)
    for branch in (0, 1):
        f = np.array([residual(p, branch) for p in ps])
        for j in np.nonzero(np.isfinite(f[:-1]) & np.isfinite(f[1:]) & (np.sign(f[:-1]) != np.sign(f[1:])))[0]:
            from scipy.optimize import brentq  # imported when needed (start-up time)
            p = brentq(residual, ps[j], ps[j + 1], args=(branch,), xtol=1e-14, rtol=1e-14)
            A = _peak_amplitudes(K, p, x, measure)[branch]
            out.append((A / abs(x) ** p, p))
    return out


def calibrate_cutoff(crystal: Crystal, measure: Measure = "current") -> CutoffLaw:
    """Calibrate :class:`CutoffLaw` to Table 1 (Phi_0, d_0 = c_0/4) and Table 2 (E, and
    sigma_max at e* in tension and in compression); stress of Part III, eq. (14).

    k = E d_0 / |Phi_0| gives E.  On each side the peak condition is a quadratic in
    A = alpha |e*|^p (see :func:`_peak_amplitudes`) and the strength condition then fixes p.
    Raises :class:`CalibrationError` if no well has these peaks as its first extrema.
    """
    if measure not in MEASURES:
        raise ValueError(f"measure must be one of {MEASURES}")
    k = crystal.E * crystal.d0 / -crystal.phi0
    tension = _calibrate_side(crystal, crystal.e_t, crystal.sigma_t, measure)
    compression = _calibrate_side(crystal, -crystal.e_c, crystal.sigma_c, measure)
    for alpha_t, p_t in tension:
        for alpha_c, p_c in compression:
            law = CutoffLaw(crystal.phi0, crystal.d0, k, alpha_t, p_t, alpha_c, p_c, measure)
            s = law.strength()
            if math.isclose(s.e_t, crystal.e_t, rel_tol=1e-7) and math.isclose(s.e_c, crystal.e_c, rel_tol=1e-7):
                return law
    raise CalibrationError(
        crystal.name,
        f"no well Phi_0 exp(-k x^2/2 - alpha |x|^p) with E = {crystal.E / 1e9:g} GPa has its first "
        f"stress peaks at e = {crystal.e_t:g} (tension) and -{crystal.e_c:g} (compression) with the given strengths"
    )


def calibrate_uber(crystal: Crystal, measure: Measure = "current") -> UberLaw:
    """Calibrate the universal binding-energy relation to E and sigma_2^max (tension).

    reference measure: sigma = (Phi_b/(d_0 lam)) a e^{-a}, peak at a = 1:
        E = Phi_b/(d_0 lam^2), sigma_t = E lam / e  ->  lam = e sigma_t / E.
    current measure: the peak moves to a* = (sqrt(1 + 4 lam) - 1)/(2 lam) and
        sigma_t = E lam a* e^{-a*} / (1 + lam a*), solved for lam (lam = l/d_0).
    """
    E, st = crystal.E, crystal.sigma_t
    if measure == "reference":
        lam = math.e * st / E
    else:
        def f(lam):
            a = (math.sqrt(1 + 4 * lam) - 1) / (2 * lam)
            return E * lam * a * math.exp(-a) / (1 + lam * a) - st

        if not f(1e-6) < 0 < f(1e3):
            raise CalibrationError(crystal.name, "the universal binding-energy relation cannot reach this tensile strength")
        from scipy.optimize import brentq  # imported when needed (start-up time)
        lam = brentq(f, 1e-6, 1e3, xtol=1e-15, rtol=1e-14)
    phi_b = E * crystal.d0 * lam**2
    return UberLaw(phi_b, crystal.d0, lam * crystal.d0, measure)


def calibrate(crystal: Crystal, law: str = "cutoff", measure: Measure = "current") -> Law:
    """The bulk law ``law`` ('cutoff' or 'uber') calibrated to ``crystal``."""
    if law == "cutoff":
        return calibrate_cutoff(crystal, measure)
    if law == "uber":
        return calibrate_uber(crystal, measure)
    raise ValueError(f"law must be one of {LAWS}; got {law!r}")
