"""The compiled ring kernels (semianalytic/bem/_ring.c) against the numpy ones and against
references independent of both: the ring integrals of Part I, eqs. (20)-(22), by scipy's
elliptic integrals and by direct azimuthal quadrature (scipy.integrate.quad); the sphere's
added mass 1/2 (exact) on both paths; the numpy fallback when asked for
(SEMIANALYTIC_KERNEL=numpy); the library built at install time (setup.py) the only one loaded:
no compiler at run time, nothing in the per-user cache loaded, a library of another source refused.
"""

from __future__ import annotations

import ast
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import ellipe, ellipk

from semianalytic.bem import kernels, solve_body
from semianalytic.bem.quadrature import gauss_legendre
from semianalytic.geometry import sphere_body

ROOT = Path(__file__).resolve().parent.parent

needs_c = pytest.mark.skipif(kernels.compiled() is None, reason="no compiled kernels (built without a C compiler, or SEMIANALYTIC_KERNEL=numpy)")  # noqa: E501


@pytest.fixture
def numpy_path(monkeypatch):
    """The numpy kernels in this process (as with SEMIANALYTIC_KERNEL=numpy)."""
    monkeypatch.setattr(kernels, "compiled", lambda: None)


def _points(n=4000, seed=7):
    """Random targets and source rings on a body of size ~1: a quarter far, a quarter near
    (d/|r| down to 1e-9, the differences given as ``delta`` as on one panel), a quarter with the
    target on the axis (r = 0), a quarter with the ring on the axis side (r1 small)."""
    rng = np.random.default_rng(seed)
    x1, r1 = rng.uniform(-1, 1, n), rng.uniform(1e-3, 1, n)
    th = rng.uniform(0, 2 * np.pi, n)
    nx1, nr1 = np.cos(th), np.sin(th)
    x, r = rng.uniform(-1, 1, n), rng.uniform(0, 1, n)
    q = n // 4
    near = slice(q, 2 * q)
    dist = 10.0 ** rng.uniform(-9, -2, q)
    ang = rng.uniform(0, 2 * np.pi, q)
    dx, dr = dist * np.cos(ang), dist * np.sin(ang)
    x[near], r[near] = x1[near] + dx, r1[near] + dr
    r[2 * q:3 * q] = 0.0
    r1[3 * q:] = 10.0 ** rng.uniform(-6, -2, n - 3 * q)
    ddx, ddr = x - x1, r - r1
    ddx[near], ddr[near] = dx, dr
    return x, r, x1, r1, nx1, nr1, (ddx, ddr)


def _scales(x, r, x1, r1, nx1, nr1, delta):
    """Size of each kernel's terms (the double layer is a difference of two terms, so its error
    is measured against their size): |S| and (|E bracket/d^2| + |nr1 K|/2)/(pi sqrt D)."""
    dx, dr = delta
    d2 = dx * dx + dr * dr
    D = dx * dx + (r + r1) ** 2
    K, E = kernels.ellip_ke(d2 / D)
    inv = 1.0 / (math.pi * np.sqrt(D))
    bracket = r1 * (dx * nx1 + dr * nr1) + 0.5 * nr1 * d2
    return r1 * K * inv, (np.abs(E * bracket / d2) + np.abs(0.5 * nr1 * K)) * inv


@needs_c
def test_c_kernels_agree_with_numpy_to_round_off():
    x, r, x1, r1, nx1, nr1, delta = _points()
    sS, sD = _scales(x, r, x1, r1, nx1, nr1, delta)
    # both evaluate the same Cephes polynomials (~1e-16), one by powers, one by Horner's scheme,
    # and the same formulas in the same order: a few units of 2.2e-16 of each term's size
    tol = 2e-15
    for d in (None, delta):
        S, Dl = kernels.single_double(x, r, x1, r1, nx1, nr1, d)
        S0, D0 = kernels._single_double_numpy(x, r, x1, r1, nx1, nr1, d)
        assert np.max(np.abs(S - S0) / sS) < tol
        assert np.max(np.abs(Dl - D0) / sD) < tol
    out = kernels.single_double_split(x, r, x1, r1, nx1, nr1, delta)
    ref = kernels._single_double_split_numpy(x, r, x1, r1, nx1, nr1, delta)
    for a, b, s in zip(out, ref, (sS, sD, sS, sD)):
        assert np.max(np.abs(a - b) / s) < tol
    # the dense block (weights applied) against the numpy one, on 2-D broadcasting as well
    rows, cols = slice(0, 60), slice(1000, 1150)
    w = np.linspace(0.5, 2.0, 150)
    S, Dl = kernels.single_double_dense(x[rows], r[rows], x1[cols], r1[cols], nx1[cols], nr1[cols], w)
    with np.errstate(divide="ignore", invalid="ignore"):
        S0, D0 = kernels._single_double_numpy(x[rows, None], r[rows, None], x1[cols], r1[cols], nx1[cols], nr1[cols])
    S2, D2 = kernels.single_double(x[rows, None], r[rows, None], x1[cols], r1[cols], nx1[cols], nr1[cols])
    assert S.shape == S2.shape == (60, 150)
    assert np.max(np.abs(S - S0 * w) / np.abs(S0 * w)) < tol
    assert np.max(np.abs(Dl - D0 * w) / np.max(np.abs(D0 * w))) < tol
    assert np.max(np.abs(S2 - S0) / np.abs(S0)) < tol


def _elliptic_reference(x, r, x1, r1, nx1, nr1):
    """Part I, eqs. (20)-(22) through scipy's K(m), E(m) with m = 4 r r1 / D."""
    d2 = (x - x1) ** 2 + (r - r1) ** 2
    D = (x - x1) ** 2 + (r + r1) ** 2
    m = 4 * r * r1 / D
    K, E = ellipk(m), ellipe(m)
    S = r1 * K / (math.pi * math.sqrt(D))
    Dl = (E * (r1 * ((x - x1) * nx1 + (r - r1) * nr1) + 0.5 * nr1 * d2) / d2 - 0.5 * nr1 * K) / (math.pi * math.sqrt(D))
    return S, Dl


def _quad_reference(x, r, x1, r1, nx1, nr1):
    """The ring integrals of G = 1/(4 pi R) and dG/dn1 over theta, by adaptive quadrature."""
    def R(t):
        return math.sqrt((x - x1) ** 2 + r * r + r1 * r1 - 2 * r * r1 * math.cos(t))

    S = quad(lambda t: r1 / (4 * math.pi * R(t)), 0, 2 * math.pi, epsabs=0, epsrel=1e-13, limit=200)[0]
    Dl = quad(lambda t: r1 * ((x - x1) * nx1 + nr1 * (r * math.cos(t) - r1)) / (4 * math.pi * R(t) ** 3),
              0, 2 * math.pi, epsabs=0, epsrel=1e-13, limit=200)[0]
    return S, Dl


# (x, r, x1, r1, nx1, nr1), tolerance: far, close (d = 1e-3 r1), target on the axis, a tilted normal.
# Far: scipy's K, E (Cephes, ~1e-16) and quad asked for 1e-13 give ~1e-15.  Close: the paper's
# m = 4 r r1 / D rounds at 1e-16 absolute, so 1 - m ~ 1e-6 carries 1e-10 relative error, K ~ ln(1/(1 - m))
# some 1e-11 (measured 2e-11; the kernels form 1 - m = d^2/D without it), and quad reaches ~1e-11
# on the peaked integrand: 1e-10.
CASES = [
    ((0.3, 0.8, -0.2, 0.5, 0.6, 0.8), 1e-14),
    ((0.1, 0.5 + 1e-3, 0.1 + 2e-4, 0.5, 0.0, 1.0), 1e-10),
    ((0.4, 0.0, 0.1, 0.7, -0.8, 0.6), 1e-14),
    ((1.0, 2.0, 0.0, 1.0, math.cos(2.0), math.sin(2.0)), 1e-14),
]


@pytest.mark.parametrize("path", ["c", "numpy"])
@pytest.mark.parametrize(("case", "tol"), CASES)
def test_kernels_match_independent_references(case, tol, path, monkeypatch):
    if path == "numpy":
        monkeypatch.setattr(kernels, "compiled", lambda: None)
    elif kernels.compiled() is None:
        pytest.skip("no compiled kernels (built without a C compiler, or SEMIANALYTIC_KERNEL=numpy)")
    S, Dl = (float(v) for v in kernels.single_double(*case))
    Se, De = _elliptic_reference(*case)
    Sq, Dq = _quad_reference(*case)
    for got, ell, qd in ((S, Se, Sq), (Dl, De, Dq)):
        assert got == pytest.approx(ell, rel=tol)
        assert got == pytest.approx(qd, rel=tol)
    # the split kernels' S, Dl are the same formulas (Dl divides in another order: 1 ulp)
    Ss, Ds, QS, QD = (float(v) for v in kernels.single_double_split(*case))
    assert (Ss, Ds) == (pytest.approx(S, rel=1e-15), pytest.approx(Dl, rel=1e-15))


def test_sphere_added_mass_on_both_paths(monkeypatch):
    """The sphere's added-mass coefficient is 1/2 exactly; the two paths agree to round-off."""
    c = solve_body(sphere_body(2.0), order=6, refinement=0.5)
    monkeypatch.setattr(kernels, "compiled", lambda: None)
    n = solve_body(sphere_body(2.0), order=6, refinement=0.5)
    # 18 unknowns: the discretisation error is 1.7e-11 (measured); the paths differ by kernel
    # round-off (1e-16 of each term) times the conditioning of (I/2 - D), O(1): 1e-13 is ample
    assert c.added_mass_coefficient == pytest.approx(0.5, abs=1e-10)
    assert c.added_mass_coefficient == pytest.approx(n.added_mass_coefficient, rel=1e-13)
    assert np.allclose(c.phi_nodes, n.phi_nodes, rtol=0, atol=1e-13 * np.max(np.abs(n.phi_nodes)))


def _setup_constant(name):
    """A constant of setup.py, read without running it (setuptools need not be installed)."""
    tree = ast.parse((ROOT / "setup.py").read_text())
    (value,) = [n.value for n in tree.body if isinstance(n, ast.Assign) and any(getattr(t, "id", "") == name for t in n.targets)]
    return ast.literal_eval(value)


def _backend_in_fresh_process(tmp_path, **env):
    """The kernels' backend in a fresh process with the per-user cache at ``tmp_path`` (and
    ``env``), after one kernel evaluation checked against scipy's elliptic integrals."""
    full = {**os.environ, "PYTHONPATH": str(ROOT), "SEMIANALYTIC_CACHE_DIR": str(tmp_path), **env}
    code = ("import logging, warnings; warnings.simplefilter('error');"
            "from semianalytic.bem import kernels; import numpy as np;"
            "S, D = kernels.single_double(0.3, 0.8, -0.2, 0.5, 0.6, 0.8); print(kernels.backend(), float(S))")
    out = subprocess.run([sys.executable, "-c", code], env=full, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stderr == ""  # no warning, no log line on stderr
    backend, S = out.stdout.split()
    assert float(S) == pytest.approx(_elliptic_reference(0.3, 0.8, -0.2, 0.5, 0.6, 0.8)[0], rel=1e-14)
    return backend


def test_numpy_when_asked(tmp_path):
    assert _backend_in_fresh_process(tmp_path, SEMIANALYTIC_KERNEL="numpy") == "numpy"
    assert not list(tmp_path.iterdir())  # nothing written into the cache


@needs_c
@pytest.mark.parametrize("cc", ["/nonexistent/bin/cc", "false"])
def test_no_compiler_at_run_time(tmp_path, cc):
    """The kernels were compiled when the package was installed: a missing or failing compiler
    changes nothing, and nothing is written into the cache folder."""
    assert _backend_in_fresh_process(tmp_path, CC=cc) == "c"
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("content", [b"", b"\x7fELF" + b"\0" * 60, b"not a library"])
def test_nothing_planted_in_the_cache_is_loaded(tmp_path, content):
    """Files at the names the run-time compiler once used (``native/ring-<hash>.so`` under the
    per-user cache: truncated, a bare ELF header, garbage) are never opened: the backend is the
    one the installed package has, with no warning, no crash."""
    native = tmp_path / "native"
    native.mkdir()
    for name in ("ring-0123456789abcdef0123.so", "ring.so", "_ring.so"):
        (native / name).write_bytes(content)
    want = "c" if kernels.compiled() is not None else "numpy"
    assert _backend_in_fresh_process(tmp_path) == want
    assert _backend_in_fresh_process(tmp_path, SEMIANALYTIC_NATIVE_DIR=str(native)) == want


@needs_c
def test_library_of_another_source_is_refused(tmp_path):
    """native.load_library loads a library only beside the source it was built from (its
    ring_source_sha256 against the source's SHA-256): the installed library beside a copy of
    _ring.c loads; beside a changed copy (a stale editable build) it is refused with one warning
    and the caller keeps numpy; a garbage file at the library's name gives one warning, no crash."""
    import shutil
    import warnings

    from semianalytic import native

    lib = native.library_path(kernels._SOURCE)

    def beside(folder, text=None, library=None):  # a fresh folder each: a loaded library stays mapped
        folder.mkdir()
        src = folder / "_ring.c"
        src.write_text(kernels._SOURCE.read_text() if text is None else text)
        if library is None:
            shutil.copyfile(lib, folder / lib.name)
        elif library:
            (folder / lib.name).write_bytes(library)
        return src

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert native.load_library(beside(tmp_path / "same")) is not None
    with pytest.warns(RuntimeWarning, match="another version"):
        assert native.load_library(beside(tmp_path / "changed", kernels._SOURCE.read_text() + "\n/* changed */\n")) is None
    with pytest.warns(RuntimeWarning, match="does not load"):
        assert native.load_library(beside(tmp_path / "garbage", library=b"not a library")) is None
    src = beside(tmp_path / "none", library=b"")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert native.load_library(src) is None  # not built: numpy, silently (one debug line)


@needs_c
@pytest.mark.parametrize(("kind", "f"), [("ogive", 3.5), ("cone", 2.0), ("table", 0.7)])
def test_compiled_rules_agree_with_numpy(kind, f, monkeypatch):
    """The near and self rules of the assembly (PairQuadrature.integrate) compiled after the
    geometry (ring_pair_rules of _ring.c) against the numpy path: the same kernels and the same
    sums against the Lagrange rows, in another order (the numpy path sums by matrix products):
    each block to round-off of the largest entry, a few units of 1e-16 times the rule's point
    count per row (~100): 1e-14.  The layouts cover every block kind (shared end-rule matrices,
    one matrix per self pair, flat rows), the distinct-point shortcut and, on the cone and the
    table nose, the corner panels whose differences go through their anchors.  (Against an
    independent quadrature of each entry: tests/test_tables_speed_and_reach.py, on the path in use.)"""
    from semianalytic.bem.panels import LayoutOptions, halfspace_layout
    from semianalytic.bem.solve import _layers, _layers_split, near_pairs, near_quadrature, plan_assembly
    from semianalytic.commands.coefficients.study import study_nose

    nose = study_nose(kind)
    ps = halfspace_layout(nose, f * nose.depth_unit, LayoutOptions(8, 0.3, 6)).panels()
    # the numpy geometry on both sides: the rules alone are compared here (the compiled geometry,
    # whose pow on corner panels differs from numpy's by an ulp, which a near-singular kernel
    # magnifies, has its own test below)
    ps.__dict__["_compiled_curves"] = None
    N = ps.n_primary * ps.order
    xt, rt = ps.nodes.x.ravel()[:N], ps.nodes.r.ravel()[:N]
    plan = plan_assembly(ps)
    # and field points off the surface (the near rules of varying length of the field evaluation:
    # flat Lagrange rows), a small step along the normal from the nodes
    xu, ru = (a.ravel()[:N] for a in ps.evaluate(np.repeat(np.arange(ps.n_primary), ps.order),
                                                   np.tile(gauss_legendre(ps.order)[0], ps.n_primary))[2:4])
    step = 0.3 * np.min(ps.lengths)
    xf, rf = xt + step * ru / np.hypot(xu, ru), np.abs(rt - step * xu / np.hypot(xu, ru))
    field = near_quadrature(*near_pairs(ps, xf, rf), ps.order)
    rules = ((plan.near_rule, _layers, xt, rt, True), (plan.self_rule, _layers_split, xt, rt, True),
             (field, _layers, xf, rf, False))
    got = [rule.integrate(ps, x, r, k, node_targets=nt) for rule, k, x, r, nt in rules]
    monkeypatch.setattr(kernels, "compiled", lambda: None)
    ref = [rule.integrate(ps, x, r, k, node_targets=nt) for rule, k, x, r, nt in rules]
    kinds = set()
    for (rule, *_), g, e in zip(rules, got, ref):
        kinds |= {0 if lag is None else lag.ndim for *_, lag in rule.blocks}
        for a, b in zip(g, e):
            assert a.shape == b.shape == (len(rule.target), ps.order)
            assert np.max(np.abs(a - b)) <= 1e-14 * np.max(np.abs(b))
    assert kinds == {0, 2, 3}


@needs_c
def test_compiled_panel_geometry(monkeypatch):
    """PanelSet.evaluate and relative on lines, arcs, ellipse arcs and a table nose's cubic spline
    compiled (ring_panel_points, ring_panel_relative of _ring.c; the spline against scipy's
    CubicSpline evaluation, which the numpy path calls): against an exact property of the
    curve (the sphere's points at distance R from its centre, tangents perpendicular to the
    radius, |dy/du| = R dt/du; round-off, 1e-15 of R) and against the numpy path on the layouts of
    the study noses (corner panels, mirror images, the split into anchor and offset; the same
    formulas, libm's sin, cos and pow against numpy's, each within an ulp, times up to three
    rounded factors: a few units of 2.2e-16 of each array's size, 4e-15)."""
    from semianalytic.bem.panels import LayoutOptions, body_panels, halfspace_layout
    from semianalytic.commands.coefficients.study import study_nose
    from semianalytic.geometry import spheroid_body

    rng = np.random.default_rng(3)
    ps = body_panels(sphere_body(2.0))
    assert ps._compiled_curves is not None
    pan = rng.integers(0, ps.n_panels, 2000)
    u = rng.uniform(-1, 1, 2000)
    x, r, xu, ru = ps.evaluate(pan, u)
    R = 1.0
    assert np.max(np.abs(np.hypot(x + ps.offset, r) - R)) <= 1e-15 * 4
    assert np.max(np.abs((x + ps.offset) * xu + r * ru)) <= 1e-15 * 4 * np.max(np.hypot(xu, ru))
    layouts = [halfspace_layout(study_nose(k), f * study_nose(k).depth_unit, LayoutOptions(8, 0.3, 6)).panels()
               for k, f in (("ogive", 3.5), ("cone", 2.0), ("cone", 0.2), ("table", 0.4), ("table", 1.5))] + [
                   body_panels(spheroid_body(3.0, 1.0))]
    got = []
    for i, ps in enumerate(layouts):
        assert ps._compiled_curves is not None
        pan = rng.integers(0, ps.n_panels, 3000)
        if i % 2:  # the points of a panel together, as the rules ask for them (the spline's anchor kept)
            pan = np.sort(pan)
        u, step = rng.uniform(-1, 1, 3000), rng.uniform(-1e-3, 1e-3, 3000)
        got.append((ps, pan, u, step, ps.evaluate(pan, u, split=True) + ps.relative(pan, u, u + step)))
    monkeypatch.setattr(kernels, "compiled", lambda: None)
    for ps, pan, u, step, g in got:
        e = ps.evaluate(pan, u, split=True) + ps.relative(pan, u, u + step)
        for a, b in zip(g, e):
            assert a.shape == b.shape
            assert np.max(np.abs(a - b)) <= 4e-15 * max(np.max(np.abs(b)), 1e-300)


@needs_c
def test_compiled_second_derivatives(monkeypatch):
    """PanelSet.evaluate(..., second=True) compiled (ring_panel_second of _ring.c): against an
    exact property, the curvature |x_u r_uu - r_u x_uu| / |y_u|^3, which does not depend on
    the parametrisation (so it holds on corner panels, whose substituted parameter brings in
    d2t, and on mirror images): 1/R on the ogive's arc (R = crh d) and on a sphere, ab / (a^2
    sin^2 t + b^2 cos^2 t)^(3/2) on a spheroid's ellipse (round-off in a few products and a cube,
    1e-9; on corner panels x_uu is dominated by y' d2t, parallel to y_u, which cancels in the
    cross product: measured 4e-8 on the ogive's tip panels, bounded at 1e-6, far below the O(1)
    error a wrong or missing term causes); and bit for bit against the numpy path (the same operations in the
    same order, numpy's power passed in on corner panels) on lines, arcs, ellipse arcs and a
    table's spline, plain and corner panels, primary and mirrored."""
    from semianalytic.bem.panels import LayoutOptions, body_panels, halfspace_layout
    from semianalytic.commands.coefficients.study import study_nose
    from semianalytic.geometry import spheroid_body

    rng = np.random.default_rng(5)
    ogive = study_nose("ogive")
    cases = [(halfspace_layout(ogive, 0.7 * ogive.length, LayoutOptions(8, 0.3, 6)).panels(), 3.0 * 7.11e-3),
             (body_panels(sphere_body(2.0)), 1.0)]
    for ps, R in cases:
        assert ps._compiled_curves is not None
        pan = rng.integers(0, ps.n_panels, 3000)
        u = rng.uniform(-1, 1, 3000)
        x, r, xu, ru, xuu, ruu = ps.evaluate(pan, u, second=True)
        kappa = np.abs(xu * ruu - ru * xuu) / np.hypot(xu, ru) ** 3
        assert np.max(np.abs(kappa * R - 1.0)) <= 1e-6
    a, b = 1.5, 0.5  # the semi-axes of spheroid_body(3, 1)
    ps = body_panels(spheroid_body(2 * a, 2 * b))
    pan = rng.integers(0, ps.n_panels, 3000)
    u = rng.uniform(-1, 1, 3000)
    x, r, xu, ru, xuu, ruu = ps.evaluate(pan, u, second=True)
    t = np.arctan2(r / b, (x + ps.offset - ps.segments[0].xc) / a)
    exact = a * b / (a**2 * np.sin(t) ** 2 + b**2 * np.cos(t) ** 2) ** 1.5
    assert np.max(np.abs(np.abs(xu * ruu - ru * xuu) / np.hypot(xu, ru) ** 3 / exact - 1.0)) <= 1e-9
    layouts = [halfspace_layout(study_nose(k), f * study_nose(k).depth_unit, LayoutOptions(8, 0.3, 6)).panels()
               for k, f in (("ogive", 3.5), ("ogive", 0.3), ("cone", 2.0), ("cone", 0.2), ("table", 0.4), ("table", 1.5),
                            ("flat", 0.5))] + [body_panels(spheroid_body(3.0, 1.0))]
    got = []
    for ps in layouts:
        assert ps._compiled_curves is not None
        pan = rng.integers(0, ps.n_panels, 3000)
        u = np.concatenate([rng.uniform(-1, 1, 2900), -np.ones(50), np.ones(50)])
        got.append((ps, pan, u, ps.evaluate(pan, u, second=True)))
    assert any(ps._clustered.any() for ps in layouts)
    monkeypatch.setattr(kernels, "compiled", lambda: None)
    for ps, pan, u, g in got:
        for a, b in zip(g, ps.evaluate(pan, u, second=True), strict=True):
            assert np.array_equal(a, b)


@needs_c
def test_compiled_closest_points(monkeypatch):
    """solve.closest_points compiled (ring_closest_points and ring_newton_step of _ring.c):
    against the exact nearest point on a sphere (a target on the normal through a panel point
    y0, inside the circle and within 1e-2 of the radius: the nearest point is y0 itself; two
    Newton steps from the nearest of 17 samples converge to round-off there: measured 1e-15,
    bounded at 1e-12 of the radius), and against the numpy path (kernels.compiled() None: the
    same operations; the final points differ from numpy's geometry by the ulps of libm's pow
    against numpy's on corner panels: 1e-12 relative in u* and du) on the study noses'
    layouts with corner panels, near and far targets, images across the axis."""
    from semianalytic.bem.panels import LayoutOptions, body_panels, halfspace_layout
    from semianalytic.bem.solve import closest_points
    from semianalytic.commands.coefficients.study import study_nose

    rng = np.random.default_rng(11)
    ps = body_panels(sphere_body(2.0))
    pan = rng.integers(0, ps.n_panels, 400)
    x0, r0, _, _ = ps.evaluate(pan, rng.uniform(-1, 1, 400))
    shrink = 1.0 - rng.uniform(1e-6, 1e-2, 400)
    u, du = closest_points(ps, pan, (x0 + ps.offset) * shrink - ps.offset, r0 * shrink)
    x, r, _, _ = ps.evaluate(pan, u)
    assert np.max(np.hypot(x - x0, r - r0)) <= 1e-12
    got = []
    for kind, f in (("ogive", 0.4), ("ogive", 2.5), ("cone", 0.3), ("cone", 2.0), ("table", 0.5), ("flat", 0.7)):
        nose = study_nose(kind)
        ps = halfspace_layout(nose, f * nose.depth_unit, LayoutOptions(8, 0.3, 6)).panels()
        assert ps._compiled_curves is not None
        pan = rng.integers(0, ps.n_panels, 400)
        x, r, _, _ = ps.evaluate(pan, rng.uniform(-1, 1, 400))
        scale = np.where(rng.random(400) < 0.5, 1e-3, 0.3) * ps.lengths[pan]
        xq, rq = x + scale * rng.standard_normal(400), r + scale * rng.standard_normal(400)
        rq[:40] *= -1.0  # images across the axis
        got.append((ps, pan, xq, rq, *closest_points(ps, pan, xq, rq)))
    assert any(ps._clustered.any() for ps, *_ in got)
    monkeypatch.setattr(kernels, "compiled", lambda: None)
    for ps, pan, xq, rq, u, du in got:
        u0, du0 = closest_points(ps, pan, xq, rq)
        assert np.max(np.abs(u - u0)) <= 1e-12
        assert np.max(np.abs(du - du0) / np.maximum(du0, 1e-300)) <= 1e-12


@needs_c
def test_wide_build_gives_the_baseline_numbers(tmp_path, monkeypatch):
    """_ring.c's kernels built for AVX2 (WIDE: target clones, picked by the processor) give the
    numbers of the baseline x86-64 build bit for bit: the same IEEE operations, no contraction
    into fused multiply-adds.  The baseline is compiled here with -DRING_BASELINE (the same
    flags otherwise) and both assemble the half-space matrices of the ogive (arcs) and the table
    nose (a spline, a graded corner, tiny panels): the dense blocks, the near and self rules.
    Exact equality: any difference in operations would show in the last bits of some entry."""
    import ctypes
    import shlex
    import shutil
    import sysconfig

    from semianalytic.bem.panels import LayoutOptions, halfspace_layout
    from semianalytic.bem.solve import assemble, plan_assembly
    from semianalytic.commands.coefficients.study import study_nose

    cmd = shlex.split(os.environ.get("CC") or sysconfig.get_config_var("CC") or "cc")
    if not cmd or shutil.which(cmd[0]) is None:
        pytest.skip("no C compiler")
    cpu = Path("/proc/cpuinfo")
    if not (cpu.is_file() and " avx2" in cpu.read_text()):  # else both builds run the baseline code
        pytest.skip("the processor has no AVX2: the wide clones do not run here")
    so = tmp_path / "ring-baseline.so"
    flags = _setup_constant("RING_CFLAGS")  # the flags of the installed build
    proc = subprocess.run([*cmd, *flags, "-fPIC", "-shared", "-DRING_BASELINE", "-o", str(so), str(kernels._SOURCE), "-lm"],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    baseline = kernels.configured(ctypes.CDLL(str(so)))
    cases = [halfspace_layout(study_nose(k), f * study_nose(k).depth_unit, LayoutOptions(8, 0.3, 6)).panels()
             for k, f in (("ogive", 3.5), ("table", 0.4), ("table", 1.5))]
    wide = [assemble(ps, plan_assembly(ps)) for ps in cases]
    x, r, x1, r1, nx1, nr1, delta = _points()
    wide_points = kernels.single_double_split(x, r, x1, r1, nx1, nr1, delta)
    monkeypatch.setattr(kernels, "compiled", lambda: baseline)
    for ps, (S, D) in zip(cases, wide):
        S0, D0 = assemble(ps, plan_assembly(ps))
        assert np.array_equal(S, S0) and np.array_equal(D, D0)
    for a, b in zip(wide_points, kernels.single_double_split(x, r, x1, r1, nx1, nr1, delta)):
        assert np.array_equal(a, b, equal_nan=True)
