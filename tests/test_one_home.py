"""One home per equation (issue 26, item 3): each of these is defined once in the package and
used by every path, checked by reading the source (a copy written anywhere else fails here):

- the right-hand side of Part I, eq. (11) (``motion.eq11_acceleration``),
- the integration of eq. (11) in P and its root finder (``motion.reduced_profiles`` /
  ``DepthProfile.stop``: the penetrate curve, the sweep kernel and the Monte-Carlo batch),
- the coefficient-table cache key (``cache.table_key``, through ``cache.case_table_key``),
- the table loader of ``ballistic_limit/tables.py`` (``load_rows``).

The greps are checked against the code they guard: each pattern is shown to match the line
it is meant to catch (so a pattern that matches nothing cannot pass silently).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
SOURCES = sorted(p for d in ("semianalytic", "fem_check") for p in (ROOT / d).rglob("*.py"))


def _text(rel: str) -> str:
    return (ROOT / rel).read_text(encoding="utf-8")


def _hits(pattern: str) -> list[str]:
    rx = re.compile(pattern)
    out = []
    for path in SOURCES:
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            if rx.search(line):
                out.append(f"{path.relative_to(ROOT)}:{n}: {line.strip()}")
    return out


# eq. (11): the velocity term (rho B u^2/2 in any spelling), the effective mass m + rho A as a divisor
EQ11_PATTERNS = [
    r"0\.5\s*\*\s*[a-z_.]*(rho|density)[a-z_]*\s*\*\s*B\b",
    r"\bB\s*\*\s*[a-z_.]*rho[a-z_]*\s*\*\s*u\b",
    r"/\s*\(\s*[a-z_.]*(m|mass)\s*\+\s*[a-z_.]*(rho|density)[a-z_]*\s*\*\s*A\w*\s*\)",
]


def _home_body() -> str:
    src = _text("semianalytic/penetration/motion.py")
    return src[src.index("def eq11_acceleration"):].split("\n\n\n")[0]


@pytest.mark.parametrize("pattern", EQ11_PATTERNS)
def test_eq11_right_hand_side_is_written_once(pattern):
    home = _home_body()
    hits = [h for h in _hits(pattern) if h.split(": ", 1)[1] not in home]
    assert hits == [], hits


def test_the_home_itself_matches():
    home = _home_body()
    assert re.search(EQ11_PATTERNS[0], home) and re.search(EQ11_PATTERNS[2], home)


@pytest.mark.parametrize("copy", [
    "a = -(0.5 * rho * B * u * u + C * R_t) / (mass + rho * A)",  # the old coefficients/contact.py:49
    "du_dt = -(B * rho * u * u / 2 + C * R_t) / (mass + rho * A)  # Part I, eq. (11)",  # commands/coefficients/report.py
    "f = mass / (mass + target_density * A) / area",  # the old elastic.start_force_coefficients
])
def test_the_eq11_patterns_catch_the_old_copies(copy):
    assert any(re.search(p, copy) for p in EQ11_PATTERNS)


def test_eq11_is_defined_once_and_called_by_every_path():
    (hit,) = _hits(r"^\s*def eq11_acceleration\b")
    assert hit.startswith("semianalytic/penetration/motion.py")
    motion = _text("semianalytic/penetration/motion.py")
    for fn in ("def braking_force", "def solve_motion", "def _w_rates", "def acceleration", "def separated_acceleration",
               "def separation_onset"):
        body = motion[motion.index(fn):].split("\n\n\n")[0]
        assert "eq11_acceleration(" in body, fn
    for rel in ("semianalytic/commands/coefficients/study.py", "semianalytic/penetration/elastic.py"):
        assert "eq11_acceleration(" in _text(rel), rel


def test_eq11_home_against_the_closed_form():
    """The one home agrees with Part IV, eq. (1) (constant coefficients): du/dt = -k (u^2 + a^2)."""
    from semianalytic.penetration.motion import ConstantCoefficientSolution, eq11_acceleration

    s = ConstantCoefficientSolution(2e-7, 3e-6, 4e-5, 0.02, 2700.0, 1e9, 800.0)
    for u in (0.0, 300.0, 800.0):
        assert eq11_acceleration(s.A, s.B, s.C, s.mass, s.target_density, s.resistance_pa, u * u) == pytest.approx(
            -s.k * (u * u + s.a**2), rel=1e-14)


def test_depth_profile_and_root_finder_have_one_home():
    # the spectral panel integration (the matrix _Q) and the root of G(P_f) = U0^2 live in motion.py only
    assert [h for h in _hits(r"_Q\.T") if not h.startswith("semianalytic/penetration/motion.py")] == []
    assert _hits(r"^\s*def (_solve_hermite|_profiles)\(") == []  # batch's old integrator and root finder
    (newton,) = _hits(r"-\s*r\s*/\s*dG\b")  # the Newton step on G(P) - U0^2: DepthProfile.stop only
    assert newton.startswith("semianalytic/penetration/motion.py")
    assert len(_hits(r"^\s*def (reduced_profiles|_integrate_panels)\(")) == 2
    batch = _text("semianalytic/penetration/batch.py")
    assert "reduced_profiles(" in batch and ".stop(" in batch
    kernels = _text("semianalytic/sweep/kernels.py")
    assert "depth_profile(" in kernels and "final_depths(" in kernels
    motion = _text("semianalytic/penetration/motion.py")
    body = motion[motion.index("def depth_profile("):].split("\n\n\n")[0]
    assert "reduced_profiles(" in body


def test_batch_and_profile_give_the_same_depths():
    """The sweep's Monte-Carlo path and depth_profile agree (one integrator, one root): to round-off."""
    from semianalytic.coefficients import ConstantCoefficients
    from semianalytic.penetration.batch import final_depths
    from semianalytic.penetration.motion import ConstantCoefficientSolution, depth_profile

    coef = ConstantCoefficients.from_normalised(1.0e-3, 0.11, 1.0, 7.11e-3)
    U = np.array([300.0, 700.0, 1200.0])
    m, rho, R = 0.0134, 2710.0, 1.1e9
    batch = final_depths(coef, m, rho, R, U)
    prof = depth_profile(coef, m, rho, R, U.max()).final_depth(U)
    exact = [ConstantCoefficientSolution(coef.A(0), coef.B(0), coef.C(0), m, rho, R, u).final_depth for u in U]
    np.testing.assert_allclose(batch, prof, rtol=1e-13)
    np.testing.assert_allclose(prof, exact, rtol=1e-11)  # spectral in P, Newton to 1e-13


def test_table_key_has_one_home():
    assert len(_hits(r"^\s*def table_key\(")) == 1
    kernels = _text("semianalytic/sweep/kernels.py")
    assert "hashlib" not in kernels and "_GEOMETRY_PREFIXES" not in kernels  # no key of its own, no field list
    kernels = _text("semianalytic/sweep/kernels.py")
    body = kernels[kernels.index("def geometry_key("):].split("\n\n\n")[0]
    assert "case_table_key(" in body and "json" not in body


def test_sweep_resource_key_is_the_cache_key(tmp_path):
    """The sweep's resource key names the very file the cache writes; a change of any nose
    parameter, numerical option or reading changes it; the material does not."""
    import dataclasses

    from semianalytic.cache import coefficients_for_case, table_dir
    from semianalytic.case import load_case
    from semianalytic.sweep.kernels import PenetrationKernel, geometry_key

    case = load_case(ROOT / "cases/fig5_ogive.toml")
    key = geometry_key(case)
    coefficients_for_case(case, "bem", cache_dir=tmp_path)
    assert (table_dir(tmp_path) / f"{key.split(':')[0]}.npz").exists()
    p = case.projectile
    assert geometry_key(dataclasses.replace(case, projectile=p.model_copy(update={"crh": 2.0}))) != key
    assert geometry_key(dataclasses.replace(case, projectile=p.model_copy(update={"meplat_diameter": 1e-3}))) != key
    assert geometry_key(dataclasses.replace(case, projectile=p.model_copy(update={"density": 7000.0}))) == key
    cs = case.coefficients
    assert geometry_key(dataclasses.replace(case, coefficients=cs.model_copy(update={"tolerance": 1e-4}))) != key
    k = PenetrationKernel()
    # an unknown (new) nose parameter counts as geometry; the material and mass do not
    assert k.affects_resource("projectile.exponent") and k.affects_resource("projectile.crh")
    assert not k.affects_resource("projectile.mass") and not k.affects_resource("projectile.yield_stress")


def test_one_table_loader():
    src = _text("semianalytic/ballistic_limit/tables.py")
    assert src.count("read_rows(") == 2  # its definition and load_rows
    assert src.count("_Cells(path") == 1  # rows become cells in load_rows only
    for name in ("load_shots", "load_table1", "load_table2", "load_table3", "load_table4", "load_table5"):
        body = src[src.index(f"def {name}("):].split("\n\n\n")[0]
        assert "load_rows(" in body, name


# --- Alekseevskii-Tate and the Meyer conversion (issue 39): one home each ----------------------------

# the interface balance solved for u (any spelling of the discriminant rho_p rho_t v^2 + 2 (rho_p - rho_t)(R - Y)),
# a time integration of dL/dt = -(v - u), and the 68-degree constant
AT_PATTERNS = [
    r"rho_p\s*\*\s*rho_t\s*\*\s*v\s*\*\*\s*2\s*\+\s*2\.0\s*\*\s*\(rho_p\s*-\s*rho_t\)",
    r"\(\s*-\s*Y_p\s*/\s*\(rho_p\s*\*\s*L\)\s*,\s*-\(v\s*-\s*u\)",  # the right-hand side of a time integration
]
VICKERS_PATTERN = r"radians\(68(\.0)?\)|sin\(math\.radians\(68|1\.0785\d*\s*\*"


def _code_hits(pattern):
    """Hits outside docstrings and comments (a line whose code part matches)."""
    out = []
    for h in _hits(pattern):
        code = h.split(": ", 1)[1].split("#")[0]
        if re.search(pattern, code) and not code.lstrip().startswith(('"', "'")) and '"""' not in code:
            out.append(h)
    return out


def test_alekseevskii_tate_has_one_home():
    hits = [h for p in AT_PATTERNS for h in _code_hits(p)]
    assert hits and all(h.startswith("semianalytic/penetration/regime.py") for h in hits), hits
    peers = _text("semianalytic/penetration/peers.py")
    body = peers[peers.index("def tate_penetration("):].split("\n\n\n")[0]
    assert "eroding_depth_per_length(" in body and "solve_ivp" not in peers


def test_the_alekseevskii_tate_patterns_catch_the_old_copies():
    old = ["        disc = rho_p * rho_t * v**2 + 2.0 * (rho_p - rho_t) * (R_t - Y_p)",
           "        return (-Y_p / (rho_p * L), -(v - u), u)"]
    assert all(any(re.search(p, line) for p in AT_PATTERNS) for line in old)


def test_meyer_conversion_has_one_home():
    hits = _code_hits(VICKERS_PATTERN)
    assert len(hits) == 1 and hits[0].startswith("semianalytic/ballistic_limit/theory.py"), hits
    assert re.search(VICKERS_PATTERN, 'VICKERS_DIAMOND = Indenter("Vickers diamond", math.radians(68.0), 1140e9, 0.07)')
    from semianalytic.ballistic_limit.theory import meyer_hardness
    from semianalytic.penetration.hardness import meyer_hardness_from_vickers

    # HV 372 (38 HRC): H_M = 372 / sin 68 deg kgf/mm^2 by hand, in both units
    assert meyer_hardness(372.0) == pytest.approx(372.0 / 0.9271838545667874, rel=1e-14)
    assert meyer_hardness_from_vickers(372.0) == pytest.approx(372.0 / 0.9271838545667874 * 9.80665e6, rel=1e-14)


# Part IV's rigid-rod closed forms (eqs. (2)-(4) of du/dt = -k (u^2 + a^2)) and the right-hand side
# of Part IV, eq. (1): one home each, semianalytic/ballistic_limit/theory.py (quadratic_drag_* and
# eq1_deceleration); Part I's constant-coefficient solution, Tate's rigid phase and the Part IV report's
# ODE check call them.
PART4_HOME = "semianalytic/ballistic_limit/theory.py"
PART4_PATTERNS = {
    "stop time arctan(u/a)": r"\batan\(\s*[\w.]+\s*/\s*(self\.)?a\s*\)",
    "velocity (u - a tan)/(a + u tan)": r"\(\s*(self\.)?a\s*\+\s*[\w.]+\s*\*\s*tg\s*\)",
    "depth ln(cos g + u/a sin g)": r"log\(\s*np\.cos\(",
    "depth ln((a^2 + u_s^2)/(a^2 + u^2))": r"log1?p?\(\s*\(\s*a2\s*\+|log1p\(\s*\(\s*[\w.]+\s*/\s*(self\.)?a\s*\)\s*\*\*\s*2"
                                            r"|log1p\(\s*rho_t\s*\*\s*\w+\s*\*\*\s*2\s*/\s*\(\s*2\.0\s*\*\s*R",
    "eq. (1) right-hand side": r"0\.5\s*\*\s*rho_t\s*\*\s*[\w.\[\]]+\s*\*\*\s*2\s*[-+]\s*R\b",
}


@pytest.mark.parametrize("name", sorted(PART4_PATTERNS))
def test_part4_closed_forms_are_written_once(name):
    hits = [h for h in _hits(PART4_PATTERNS[name]) if not h.startswith(PART4_HOME)]
    assert hits == [], hits
    assert [h for h in _hits(PART4_PATTERNS[name]) if h.startswith(PART4_HOME)], "the home itself must match"


@pytest.mark.parametrize("name, copy", [
    ("stop time arctan(u/a)", "return math.atan(self.U0 / self.a) / (self.a * self.k)"),  # the old motion.py
    ("stop time arctan(u/a)", "T = 2.0 * rho_p * length / (rho_t * a) * math.atan(V / a)"),  # the old peers.py
    ("velocity (u - a tan)/(a + u tan)", "return a * (U - a * tg) / (a + U * tg)"),  # the old motion.py
    ("depth ln(cos g + u/a sin g)", "return np.log(np.cos(g) + self.U0 / self.a * np.sin(g)) / self.k"),
    ("depth ln((a^2 + u_s^2)/(a^2 + u^2))", "return math.log1p((self.U0 / self.a) ** 2) / (2.0 * self.k)"),
    ("depth ln((a^2 + u_s^2)/(a^2 + u^2))", "return np.log((a2 + self.U0**2) / (a2 + u * u)) / (2.0 * self.k)"),
    ("depth ln((a^2 + u_s^2)/(a^2 + u^2))", "P += rho_p * L / rho_t * math.log1p(rho_t * v**2 / (2.0 * R_t))"),
    ("eq. (1) right-hand side", "sol = solve_ivp(lambda _, y: [(-0.5 * rho_t * y[0] ** 2 - R) / (rho_p * L), y[0]],"),
])
def test_the_part4_patterns_catch_the_old_copies(name, copy):
    assert re.search(PART4_PATTERNS[name], copy), (name, copy)


def test_part4_closed_forms_are_called_by_every_path():
    motion = _text("semianalytic/penetration/motion.py")
    body = motion[motion.index("class ConstantCoefficientSolution"):].split("\n\n\n")[0]
    for fn in ("quadratic_drag_stop_time(", "quadratic_drag_velocity(", "quadratic_drag_depth_at_time(",
               "quadratic_drag_depth_at_velocity("):
        assert fn in body, fn
    assert "eq1_deceleration(" in _text("semianalytic/commands/ballistic_limit/study.py")


def test_part4_home_against_eq1_integrated_and_part1_constant_coefficients():
    """The one home against an independent method: eq. (1) integrated (DOP853) to 1e-9, and Part I's
    constant-coefficient solution (which now calls it) against the same integration of eq. (11)."""
    from scipy.integrate import solve_ivp

    from semianalytic.ballistic_limit import theory as T

    R, rho_t, rho_p, L, us = 2.0e9, 7800.0, 7850.0, 0.05, 800.0
    t_end = T.stop_time(us, R, rho_t, rho_p, L)
    t = np.linspace(0.0, t_end, 50)
    # the right-hand side written here, not taken from the home: the check must not share it
    sol = solve_ivp(lambda _, y: [-(rho_t * y[0] ** 2 / 2 + R) / (rho_p * L), y[0]], (0, t_end), [us, 0.0],
                    t_eval=t, rtol=1e-12, atol=1e-12, method="DOP853")
    assert np.abs(T.velocity_at_time(t, us, R, rho_t, rho_p, L) - sol.y[0]).max() <= 1e-9 * us
    assert np.abs(T.depth_at_time(t, us, R, rho_t, rho_p, L) - sol.y[1]).max() <= 1e-9 * sol.y[1][-1]
    assert T.stopping_thickness(us, R, rho_t, rho_p, L) == pytest.approx(sol.y[1][-1], rel=1e-9)
    assert T.quadratic_drag_depth_at_velocity(0.0, 800.0, np.inf, 1.0) == 0.0  # B <= 0 in Part I: a = inf
    from semianalytic.penetration.motion import ConstantCoefficientSolution

    s = ConstantCoefficientSolution(2e-7, 3e-6, 4e-5, 0.02, 2700.0, 1e9, 800.0)
    ode = solve_ivp(lambda _, y: [-s.k * (y[0] ** 2 + s.a**2), y[0]], (0, s.penetration_time), [800.0, 0.0],
                    rtol=1e-12, atol=1e-12, method="DOP853")
    assert s.final_depth == pytest.approx(ode.y[1][-1], rel=1e-9)
