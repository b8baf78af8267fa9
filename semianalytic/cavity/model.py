"""Three-zone spherical cavity expansion in a brittle material (Part II, eqs. (13)-(34)).

The unknown is the radial stress sigma* < 0 at the comminution front r = b.  Write
x = -sigma* > 0.  The fracture criterion (19) at the front, with the porosity theta* that
cracking has produced there (eqs. (14), (17)), gives eq. (21):

    x = C(theta*(x)) Y_s,   C(theta) = 2 (1 - theta)^(3/2) / (3 sqrt(theta)),
    theta*(x) = 1 - (1 - theta_0) exp(-e_c(x)),
    e_c(x) = (x/E) [1 - (1 - nu) sqrt(2 sigma_f / x)].

Two solvers:
  ``bracket``      Brent's method on F(x) = x - C(theta*(x)) Y_s, which increases strictly for
                   x > 2 (1 - nu)^2 sigma_f (where e_c > 0), so the root is unique (errata 13).
  ``fixed-point``  the paper's iteration (22), started from sigma*_0 = -Y_s (errata 13: the
                   printed +Y_s makes a square root imaginary).  It converges iff
                   |g'(x*)| < 1, g(x) = C(theta*(x)) Y_s; near (1 - nu) sqrt(2 sigma_f/x*) ~ 0.65
                   it stops converging.  Its convergence factor is reported.

Then v* (26), a/b (29) and e_k (30) with errata items 15-16, e_ks (32), theta_k (33) and the
cavity pressure R_r (34).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import asdict, dataclass, field

import numpy as np

from semianalytic.cavity.material import BrittleMaterial
from semianalytic.cavity.zones import crack_front_ratio, front_strains
from semianalytic.errors import ModelError, ModelValidityWarning

__all__ = [
    "CavityResult",
    "FixedPointRun",
    "FixedPointDivergence",
    "METHODS",
    "porosity_from_volume_strain",
    "induced_porosity",
    "strength_factor",
    "front_porosity",
    "front_equation",
    "iteration_map",
    "iteration_slope",
    "solve_front_stress_bracket",
    "fixed_point_iteration",
    "front_velocity",
    "comminuted_ratio",
    "comminuted_volume_strain",
    "solid_volume_strain",
    "comminuted_porosity",
    "comminuted_porosity_small",
    "cavity_pressure",
    "solve_cavity",
    "cavity_resistance",
    "STRAIN_LIMIT",
    "FIXED_POINT_SOFT_LIMIT",
]

METHODS = ("bracket", "fixed-point")
# Errata item 20: strains are "small" only while Y_s/E stays below about 0.025.
STRAIN_LIMIT = 0.025
# Errata item 13: the iteration (22) diverges when (1 - nu) sqrt(2 sigma_f/|sigma*|) exceeds ~0.65.
FIXED_POINT_SOFT_LIMIT = 0.65


class FixedPointDivergence(ModelError):
    """The paper's iteration (22) did not converge for this material (use ``method='bracket'``)."""

    def __init__(self, message: str, field: str = "cavity.method"):
        super().__init__(message, field)


# ---------------------------------------------------------------------------------------------
# closed forms


def porosity_from_volume_strain(e, theta_0=0.0):
    """theta = 1 - (1 - theta_0) exp(-e): integral (16) of de = dtheta/(1 - theta), eq. (17)."""
    return 1.0 - (1.0 - theta_0) * np.exp(-np.asarray(e, dtype=float))


def induced_porosity(e_c):
    """theta_c = 1 - exp(-e_c), porosity added by cracking (Part II, eq. (18))."""
    return porosity_from_volume_strain(e_c, 0.0)


def strength_factor(theta):
    """C(theta) = 2 (1 - theta)^(3/2) / (3 sqrt(theta)) of Part II, eq. (21) (with the
    dimensionally right flow condition (19), errata item 11: right-hand side (2/3)(1-theta) Y_s^2)."""
    theta = np.asarray(theta, dtype=float)
    return 2.0 * (1.0 - theta) ** 1.5 / (3.0 * np.sqrt(theta))


def _volume_strain(x, m: BrittleMaterial):
    """e_c(x) of eq. (14) at r = b + 0, x = -sigma*."""
    return (x / m.youngs_modulus) * (1.0 - (1.0 - m.poisson_ratio) * math.sqrt(2.0 * m.tensile_strength / x))


def front_porosity(x, material: BrittleMaterial):
    """theta*(x) = 1 - (1 - theta_0) exp(-e_c(x)), eqs. (14) and (17), x = -sigma* [Pa]."""
    return float(porosity_from_volume_strain(_volume_strain(x, material), material.initial_porosity))


def iteration_map(x, material: BrittleMaterial):
    """g(x) = C(theta*(x)) Y_s: eq. (21) reads x = g(x); eq. (22) iterates it.  NaN where
    theta* is not in (0, 1) (no dilatation: the square root in C is imaginary)."""
    theta = front_porosity(x, material)
    if not 0.0 < theta < 1.0:
        return math.nan
    return float(strength_factor(theta)) * material.compressive_strength


def front_equation(x, material: BrittleMaterial):
    """F(x) = x - C(theta*(x)) Y_s (Part II, eq. (21) with x = -sigma*); -inf where theta* <= 0."""
    g = iteration_map(x, material)
    return -math.inf if math.isnan(g) else x - g


def iteration_slope(x, material: BrittleMaterial):
    """g'(x) for g of :func:`iteration_map`, analytically:

    g' = -C Y_s [3/2 + (1 - theta)/(2 theta)] (1/E) [1 - (1 - nu) sqrt(2 sigma_f/x)/2].

    At the root (C Y_s = x) this is -e_phi* [3/2 + (1 - theta*)/(2 theta*)]; the iteration (22)
    converges locally iff |g'(x*)| < 1, oscillating because g' < 0.
    """
    m = material
    theta = front_porosity(x, m)
    s = math.sqrt(2.0 * m.tensile_strength / x)
    de_dx = (1.0 - 0.5 * (1.0 - m.poisson_ratio) * s) / m.youngs_modulus
    C = float(strength_factor(theta))
    return -C * m.compressive_strength * (1.5 + (1.0 - theta) / (2.0 * theta)) * de_dx


# ---------------------------------------------------------------------------------------------
# solvers for sigma*


def _lower_limit(m: BrittleMaterial) -> float:
    """Smallest admissible x = -sigma*: a cracked zone needs x > 2 sigma_f (eq. (13), errata
    14) and dilatation e_c > 0 needs x > 2 (1 - nu)^2 sigma_f (errata 13)."""
    return max(2.0 * m.tensile_strength, 2.0 * (1.0 - m.poisson_ratio) ** 2 * m.tensile_strength)


def solve_front_stress_bracket(material: BrittleMaterial, xtol_rel: float = 1e-14):
    """sigma* from eq. (21) by Brent's method on a bracket (errata item 13).

    Returns ``(sigma_star, iterations)``.  Raises ``ModelError`` (naming
    ``cavity.tensile_strength``) if the root does not lie above 2 sigma_f, i.e. the
    material has no cracked zone (errata item 20).
    """
    m = material
    lo = _lower_limit(m)
    f_lo = front_equation(lo, m)
    if f_lo == -math.inf:  # theta* = 0 exactly at the lower limit (theta_0 = 0): step inside
        lo = lo * (1.0 + 1e-9)
        f_lo = front_equation(lo, m)
    if not f_lo < 0.0:
        x_min = _lower_limit(m)
        raise ModelError(
            f"no cracked zone: eq. (21) has no root with -sigma* > 2 sigma_f = {x_min / 1e9:.4g} GPa "
            f"(C(theta*) Y_s <= 2 sigma_f there); the three-zone model needs -sigma* > 2 sigma_f "
            f"(Part II eq. (13), errata 14, 20): lower the tensile strength or raise Y_s",
            "cavity.tensile_strength",
        )
    hi = max(2.0 * lo, m.compressive_strength)
    for _ in range(200):
        if front_equation(hi, m) > 0.0:
            break
        hi *= 2.0
    else:  # pragma: no cover - F -> +inf as x -> inf, so this cannot happen for valid input
        raise RuntimeError("could not bracket the root of Part II eq. (21)")
    from scipy.optimize import brentq  # on use: loading a case stays light

    x, info = brentq(front_equation, lo, hi, args=(m,), xtol=xtol_rel * lo, rtol=4 * np.finfo(float).eps,
                     full_output=True, maxiter=200)
    if not info.converged:  # pragma: no cover
        raise RuntimeError(f"Brent's method did not converge on Part II eq. (21): {info.flag}")
    return -x, int(info.iterations)


@dataclass(frozen=True)
class FixedPointRun:
    """History of the paper's iteration (22): ``iterates`` are sigma*_n [Pa] from n = 0."""

    iterates: tuple[float, ...]
    converged: bool
    reason: str

    @property
    def iterations(self) -> int:
        return len(self.iterates) - 1

    @property
    def sigma_star(self) -> float:
        return self.iterates[-1]


def fixed_point_iteration(material: BrittleMaterial, rtol: float = 1e-12, max_iter: int = 2000,
                          start: float | None = None) -> FixedPointRun:
    """The paper's simple iteration (Part II, eq. (22)):

        sigma*_{n+1} = -C(theta*_n) Y_s,  theta*_n = theta*(-sigma*_n),  sigma*_0 = -Y_s

    (errata item 13: the start value must be -Y_s).  Stops when successive iterates agree to
    ``rtol``; reports divergence when an iterate leaves the domain (theta* not in (0, 1): no
    dilatation) or ``max_iter`` is reached.  ``start`` overrides sigma*_0 [Pa].
    """
    m = material
    x = m.compressive_strength if start is None else -float(start)
    history = [-x]
    if not x > 0:
        return FixedPointRun(tuple(history), False, "start value sigma*_0 must be negative")
    for _ in range(max_iter):
        x_new = iteration_map(x, m)
        if math.isnan(x_new) or not x_new > 0:
            return FixedPointRun(tuple(history), False,
                                 f"iterate -sigma* = {x / 1e9:.4g} GPa left the domain e_c > 0 "
                                 f"(theta* outside (0, 1): imaginary square root in eq. (21))")
        history.append(-x_new)
        if abs(x_new - x) <= rtol * x_new:
            return FixedPointRun(tuple(history), True, "converged")
        x = x_new
    return FixedPointRun(tuple(history), False, f"no convergence in {max_iter} iterations")


# ---------------------------------------------------------------------------------------------
# comminuted zone and cavity pressure


def front_velocity(sigma_star, material: BrittleMaterial):
    """v* = du(b)/db of Part II, eq. (26):

    v* = -(sigma*/E) (1 - sqrt(2 sigma_f/(-sigma*))) + sigma_f (1 + nu)/E sqrt(-sigma*/(2 sigma_f)).

    Errata item 15: this equals the hoop strain e_phi* at r = b + 0 (it is the rate of u(b)
    following the front, not a particle velocity); kept as printed to reproduce the example.
    """
    E, nu, sf = material.youngs_modulus, material.poisson_ratio, material.tensile_strength
    x = -sigma_star
    return (x / E) * (1.0 - math.sqrt(2.0 * sf / x)) + sf * (1.0 + nu) / E * math.sqrt(x / (2.0 * sf))


def comminuted_ratio(v_star):
    """a/b = (v*)^(1/3): eqs. (28)-(29) combined (errata item 16), for a cavity grown from
    zero radius."""
    return float(v_star) ** (1.0 / 3.0)


def comminuted_volume_strain(v_star, e_phi_star):
    """e_k = -v* / (1 - e_phi*)^3: Part II, eq. (30) with the missing minus sign (errata 16)."""
    return -v_star / (1.0 - e_phi_star) ** 3


def solid_volume_strain(sigma_star, bulk_modulus):
    """e_ks = sigma*/K_s, elastic volume strain of the solid phase (Part II, eq. (32))."""
    return sigma_star / bulk_modulus


def comminuted_porosity(theta_star, e_c, e_k, e_ks):
    """theta_k = 1 - (1 - theta*) exp(e_c - e_k + e_ks) (Part II, eq. (33))."""
    return 1.0 - (1.0 - theta_star) * math.exp(e_c - e_k + e_ks)


def comminuted_porosity_small(theta_star, e_c, e_k, sigma_star, material: BrittleMaterial):
    """Small-value form after Part II, eq. (33): theta_k = theta* - e_c + e_k - e_ks with
    e_ks = sigma*/K_s = 3 (1 - 2 nu_s) sigma*/E_s (errata item 18; printed 3 (1 - nu_s))."""
    return theta_star - e_c + e_k - sigma_star / material.K_s


def cavity_pressure(sigma_star, a_over_b, theta_k):
    """R_r = -sigma* (b/a)^(2 alpha), alpha = 3 theta_k / 2 (Part II, eqs. (24), (34))."""
    return -sigma_star * (1.0 / a_over_b) ** (3.0 * theta_k)


# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class CavityResult:
    """Solution of the three-zone model (Part II).  Stresses in Pa (tension positive),
    strains and porosities dimensionless.

    sigma_star      radial stress at the comminution front r = b, eq. (21)
    C               factor of eq. (21), sigma* = -C Y_s
    theta_star      porosity at r = b + 0, eq. (17);  theta_c induced porosity, eq. (18)
    e_r, e_phi, e_c, gamma_c   strains at r = b + 0, eq. (14) (errata 10)
    v_star          eq. (26) (errata 15)
    c_over_b        eq. (13);  a_over_b = v*^(1/3), eqs. (28)-(29) (errata 16)
    e_k, e_ks       eqs. (30) (errata 16), (32);  theta_k eq. (33);  alpha = 3 theta_k/2
    cavity_pressure R_r, eq. (34) [Pa]
    method, iterations, contraction   solver, its iteration count, and g'(x*) (the
                    iteration (22) converges iff |g'| < 1)
    e_k_exact_balance  (1 - v*)/(1 - e_phi*)^3 - 1: the volume balance that also counts the
                    outward motion u(b) of the front (errata 17; diagnostic only)
    e_k_true_strain -v*/(1 - v*), the "true deformation" note after eq. (30)
    warnings        soft-condition messages (errata 13, 20)
    """

    sigma_star: float
    C: float
    theta_star: float
    theta_c: float
    e_r: float
    e_phi: float
    e_c: float
    gamma_c: float
    v_star: float
    c_over_b: float
    a_over_b: float
    e_k: float
    e_ks: float
    theta_k: float
    alpha: float
    cavity_pressure: float
    method: str
    iterations: int
    contraction: float
    e_k_exact_balance: float
    e_k_true_strain: float
    warnings: tuple[str, ...] = field(default=())

    def to_json(self) -> dict:
        """JSON-ready dict; keys carry units (``sigma_star_Pa``, ``cavity_pressure_Pa``)."""
        d = asdict(self)
        out = {"sigma_star_Pa": d.pop("sigma_star"), "cavity_pressure_Pa": d.pop("cavity_pressure")}
        out.update(d)
        out["warnings"] = list(self.warnings)
        return out


def solve_cavity(material: BrittleMaterial, method: str = "bracket", *, warn: bool = True) -> CavityResult:
    """Solve the three-zone cavity model of Part II for ``material``.

    ``method``: ``"bracket"`` (default, robust) or ``"fixed-point"`` (the paper's eq. (22);
    raises :class:`FixedPointDivergence` if it does not converge).

    Hard conditions (errata item 20) raise ``ModelError`` naming the input (``cavity.<field>``) and the failed
    condition: no cracked zone (-sigma* <= 2 sigma_f), theta_k < 0, a/b >= 1.  Soft ones are
    returned in ``warnings`` and, with ``warn=True``, issued as ``ModelValidityWarning``:
    theta_k > theta*, Y_s/E > 0.025, and for the fixed-point method a convergence factor near 1.
    """
    m = material
    if method not in METHODS:
        raise ModelError(f"must be one of {', '.join(METHODS)}; got {method!r}", "cavity.method")
    sigma_b, it_b = solve_front_stress_bracket(m)  # also checks the cracked-zone condition
    if method == "bracket":
        sigma_star, iterations = sigma_b, it_b
    else:
        run = fixed_point_iteration(m)
        if not run.converged:
            slope = iteration_slope(-sigma_b, m)
            raise FixedPointDivergence(
                f"the fixed-point iteration (22) did not converge ({run.reason}); its factor "
                f"g'(x*) = {slope:.3g} at the root sigma* = {sigma_b / 1e9:.4g} GPa (|g'| must be < 1); "
                f"use method 'bracket'"
            )
        sigma_star, iterations = run.sigma_star, run.iterations

    x = -sigma_star
    strains = front_strains(sigma_star, m)
    e_r, e_phi, e_c, gamma_c = (float(strains[k]) for k in ("e_r", "e_phi", "e_c", "gamma_c"))
    theta_star = float(porosity_from_volume_strain(e_c, m.initial_porosity))
    theta_c = float(induced_porosity(e_c))
    C = float(strength_factor(theta_star))
    c_over_b = float(crack_front_ratio(sigma_star, m.tensile_strength))
    v_star = front_velocity(sigma_star, m)
    if not v_star < 1.0:
        raise ModelError(
            f"strains are not small: v* = (a/b)^3 = {v_star:.3g} >= 1 (Part II eqs. (26)-(29)); "
            f"Y_s/E = {m.compressive_strength / m.youngs_modulus:.3g} is far above {STRAIN_LIMIT}",
            "cavity.compressive_strength",
        )
    a_over_b = comminuted_ratio(v_star)
    e_k = comminuted_volume_strain(v_star, e_phi)
    e_ks = solid_volume_strain(sigma_star, m.K_s)
    theta_k = comminuted_porosity(theta_star, e_c, e_k, e_ks)
    if theta_k < 0.0:
        raise ModelError(
            f"theta_k = {theta_k:.4g} < 0: the comminuted zone would have negative porosity "
            f"(Part II eq. (33), errata 20; happens for nu above about 0.31-0.34, here nu = {m.poisson_ratio:g})",
            "cavity.poisson_ratio",
        )
    alpha = 1.5 * theta_k
    R_r = cavity_pressure(sigma_star, a_over_b, theta_k)

    notes: list[str] = []
    if theta_k > theta_star:
        notes.append(
            f"theta_k = {theta_k:.4g} > theta* = {theta_star:.4g}: the compacted zone is more porous than the "
            f"cracked one (errata 20; happens for nu below about 0.16-0.21, here nu = {m.poisson_ratio:g})"
        )
    ratio = m.compressive_strength / m.youngs_modulus
    if ratio > STRAIN_LIMIT:
        notes.append(f"Y_s/E = {ratio:.3g} > {STRAIN_LIMIT}: strains are not small (errata 20)")
    slope = iteration_slope(x, m)
    q = (1.0 - m.poisson_ratio) * math.sqrt(2.0 * m.tensile_strength / x)
    if method == "fixed-point" and q > FIXED_POINT_SOFT_LIMIT:
        notes.append(
            f"(1 - nu) sqrt(2 sigma_f/|sigma*|) = {q:.3g} > {FIXED_POINT_SOFT_LIMIT}: the iteration (22) is near "
            f"its divergence limit (g'(x*) = {slope:.3g}; errata 13)"
        )
    if warn:
        for note in notes:
            warnings.warn(note, ModelValidityWarning, stacklevel=2)

    return CavityResult(
        sigma_star=float(sigma_star),
        C=C,
        theta_star=theta_star,
        theta_c=theta_c,
        e_r=e_r,
        e_phi=e_phi,
        e_c=e_c,
        gamma_c=gamma_c,
        v_star=float(v_star),
        c_over_b=c_over_b,
        a_over_b=float(a_over_b),
        e_k=float(e_k),
        e_ks=float(e_ks),
        theta_k=float(theta_k),
        alpha=float(alpha),
        cavity_pressure=float(R_r),
        method=method,
        iterations=int(iterations),
        contraction=float(slope),
        e_k_exact_balance=float((1.0 - v_star) / (1.0 - e_phi) ** 3 - 1.0),
        e_k_true_strain=float(-v_star / (1.0 - v_star)),
        warnings=tuple(notes),
    )


def cavity_resistance(material: BrittleMaterial, method: str = "bracket") -> float:
    """Target resistance R_t [Pa] for the Part I dynamics: the cavity pressure R_r of Part II,
    eq. (34).  Soft-condition warnings are issued as ``ModelValidityWarning``."""
    return solve_cavity(material, method).cavity_pressure
