"""FEM of the elastic spherical cavity and of the elastic and cracked zones of Part II.

Sign convention of Part II: tension positive, r the radius.  Two discretisations of the
same problems, both independent of the closed forms they are compared with:

* radially symmetric (1D, weight r^2): P2 elements on a geometrically graded line mesh;
* axisymmetric (2D, weight r_perp in the meridian plane): P2 vector elements on a curved
  quadratic gmsh mesh of the quarter annulus, u_r = 0 on the axis, u_x = 0 on the
  symmetry plane x = 0.

Far field: the exterior elastic solution decays like u = k/r^2, for which the traction on a
sphere of radius R is sigma_r = -4 mu u / R exactly; this Robin condition on the outer
boundary replaces the unbounded medium without truncation error.

Problems:

* ``lame``: pressurised cavity, sigma_r(a) = -p (Part II, eqs. (1)-(3) with u(inf) = 0),
  compared with Lame's solution (``semianalytic.cavity.zones.lame_cavity``).
* ``zones``: cracked zone b < r < c with radial stress only (sigma_phi = 0, sigma_r = E du/dr,
  Part II eqs. (9)-(10), errata items 8-9) bonded to the elastic zone r > c, loaded by
  sigma_r(b) = sigma* (eq. (7)); c from eq. (13).  Compared with eqs. (5), (11), (12), and
  checked for the boundary conditions sigma_phi(c+0) = sigma_f (eq. (4)) and
  sigma_r(c) = -2 sigma_f (eq. (8)), which the FEM is not told.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.sparse.linalg as spla
from skfem import (
    Basis,
    BilinearForm,
    ElementLineP2,
    ElementTriP2,
    ElementTriP3,
    ElementTriP4,
    ElementVector,
    FacetBasis,
    LinearForm,
    MeshLine1,
    condense,
    solve,
)
from skfem.helpers import dot

from fem_check.meshing import MeshOptions, annulus_domain, build_mesh

CRACK_REGULARISATION = 1e-6  # fraction of the isotropic stiffness added in the 2D cracked zone


def lame_parameters(E: float, nu: float) -> tuple[float, float]:
    """(lambda, mu) from Young's modulus and Poisson's ratio."""
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


# ------------------------------------------------------------------------------------
# 1D, spherical symmetry


@dataclass
class RadialSolution:
    """FEM fields at sample points (element quadrature points): r, u, sigma_r, sigma_phi."""

    r: np.ndarray
    u: np.ndarray
    sigma_r: np.ndarray
    sigma_phi: np.ndarray
    n_dofs: int
    seconds: float
    nodes: np.ndarray = field(repr=False, default=None)
    u_nodes: np.ndarray = field(repr=False, default=None)


def graded_nodes(r0: float, r1: float, n: int, ratio: float) -> np.ndarray:
    """n elements on [r0, r1], sizes growing geometrically by ``ratio`` overall (smallest at r0)."""
    q = ratio ** (1.0 / max(n - 1, 1))
    sizes = q ** np.arange(n)
    return r0 + (r1 - r0) * np.concatenate([[0.0], np.cumsum(sizes) / sizes.sum()])


def solve_radial(r_in: float, traction: float, E: float, nu: float, outer: float, n_elements: int = 200,
                 cracked_until: float | None = None, ratio: float | None = None) -> RadialSolution:
    """1D spherically symmetric elasticity on [r_in, outer] (Part II, eqs. (1)-(3), weight r^2).

    sigma_r(r_in) = ``traction`` (tension positive: -p for a pressure p), exact Robin far field
    sigma_r(outer) = -4 mu u/outer.  With ``cracked_until = c`` the zone r_in < r < c has radial
    stress only, sigma_r = E du/dr, sigma_phi = 0 (Part II, eqs. (9)-(10), errata 8-9); the mesh
    has a node at c.
    """
    t0 = time.perf_counter()
    lam, mu = lame_parameters(E, nu)
    ratio = ratio or outer / r_in
    if cracked_until is None:
        nodes = graded_nodes(r_in, outer, n_elements, ratio)
    else:
        c = float(cracked_until)
        n1 = max(4, int(round(n_elements * math.log(c / r_in) / math.log(outer / r_in))))
        inner = graded_nodes(r_in, c, n1, c / r_in)
        rest = graded_nodes(c, outer, max(4, n_elements - n1), outer / c)
        nodes = np.concatenate([inner, rest[1:]])
    mesh = MeshLine1.init_tensor(nodes)
    basis = Basis(mesh, ElementLineP2(), intorder=6)
    centroids = 0.5 * (nodes[:-1] + nodes[1:])
    cracked = (centroids < cracked_until) if cracked_until is not None else np.zeros(len(centroids), bool)
    cracked_q = cracked[:, None] * np.ones(basis.X.shape[1])

    @BilinearForm
    def stiffness(u, v, w):
        r = w.x[0]
        du, dv = u.grad[0], v.grad[0]
        sr = (lam + 2 * mu) * du + 2 * lam * u / r
        sp = lam * du + 2 * (lam + mu) * u / r
        iso = sr * dv + 2 * sp * v / r
        crack = E * du * dv
        return np.where(w["cracked"], crack, iso) * r**2

    K = stiffness.assemble(basis, cracked=cracked_q).tolil()
    f = np.zeros(basis.N)
    i_in = int(basis.nodal_dofs[0, 0])
    i_out = int(basis.nodal_dofs[0, -1])
    K[i_out, i_out] += 4 * mu * outer  # Robin: -sigma_r(R) R^2 v(R) = 4 mu u(R) R v(R)
    f[i_in] = -traction * r_in**2  # boundary term -sigma_r(r_in) r_in^2 v(r_in)
    u = spla.spsolve(K.tocsc(), f)
    ui = basis.interpolate(u)
    r = np.asarray(basis.global_coordinates())[0]
    du = ui.grad[0]
    val = np.asarray(ui)
    sr = np.where(cracked_q, E * du, (lam + 2 * mu) * du + 2 * lam * val / r)
    sp = np.where(cracked_q, 0.0, lam * du + 2 * (lam + mu) * val / r)
    order = np.argsort(r.ravel())
    return RadialSolution(r.ravel()[order], val.ravel()[order], sr.ravel()[order], sp.ravel()[order], int(basis.N),
                          time.perf_counter() - t0, nodes, u[basis.nodal_dofs[0]])


# ------------------------------------------------------------------------------------
# 2D axisymmetric


@dataclass
class AxisymmetricSolution:
    """FEM fields at interior quadrature points: x, rho (meridian coordinates), R = |(x, rho)|,
    u_R, sigma_RR, sigma_hoop (out of plane, theta), sigma_psi (in-plane hoop), sigma_Rpsi."""

    x: np.ndarray
    rho: np.ndarray
    R: np.ndarray
    u_R: np.ndarray
    u_psi: np.ndarray
    sigma_RR: np.ndarray
    sigma_theta: np.ndarray
    sigma_psi: np.ndarray
    sigma_Rpsi: np.ndarray
    n_dofs: int
    n_elements: int
    seconds: float


def solve_axisymmetric(a: float, traction: float, E: float, nu: float, outer: float, options: MeshOptions,
                       cracked_until: float | None = None, degree: int = 2) -> AxisymmetricSolution:
    """Axisymmetric elasticity (meridian plane x, rho; weight rho) around a spherical cavity.

    Same problem as :func:`solve_radial`, solved without using spherical symmetry: P2 vector
    elements on a curved quarter-annulus mesh.  In the cracked zone the stress is
    sigma = E e_RR (e_R e_R) (radial stress only, Part II eqs. (9)-(10), errata 8-9).
    """
    t0 = time.perf_counter()
    lam, mu = lame_parameters(E, nu)
    dom = annulus_domain(a, outer, options, interface=cracked_until)
    dm = build_mesh(dom, options)
    # P3/P4 facet dofs need consistently oriented (sorted) element vertices
    mesh = dataclasses.replace(dm.mesh, t=np.sort(dm.mesh.t, axis=0)) if degree > 2 else dm.mesh
    elem = ElementVector({2: ElementTriP2(), 3: ElementTriP3(), 4: ElementTriP4()}[degree])
    basis = Basis(mesh, elem, intorder=2 * degree)
    if cracked_until is not None:
        xc = mesh.p[:, mesh.t].mean(axis=1)
        cracked = np.hypot(xc[0], xc[1]) < cracked_until
    else:
        cracked = np.zeros(mesh.t.shape[1], bool)
    cracked_q = cracked[:, None] * np.ones(basis.X.shape[1])

    def strains(z, rho):
        """(e_xx, e_rhorho, e_thetatheta, e_xrho) of an axisymmetric displacement field."""
        g = z.grad
        return g[0, 0], g[1, 1], np.asarray(z)[1] / rho, 0.5 * (g[0, 1] + g[1, 0])

    def radial_strain(e, w):
        R = np.sqrt(w.x[0] ** 2 + w.x[1] ** 2)
        nx, nr = w.x[0] / R, w.x[1] / R
        return nx * nx * e[0] + nr * nr * e[1] + 2 * nx * nr * e[3]

    @BilinearForm
    def stiffness(u, v, w):
        eu, ev = strains(u, w.x[1]), strains(v, w.x[1])
        tr = eu[0] + eu[1] + eu[2]
        iso = (lam * tr + 2 * mu * eu[0]) * ev[0] + (lam * tr + 2 * mu * eu[1]) * ev[1] \
            + (lam * tr + 2 * mu * eu[2]) * ev[2] + 4 * mu * eu[3] * ev[3]
        # radial stress only.  That law has no stiffness against non-radial displacements (the 2D
        # problem is singular); a small fraction of the isotropic stiffness regularises it and
        # perturbs the solution by about that fraction (an exploratory check only, see the report)
        crack = E * radial_strain(eu, w) * radial_strain(ev, w) + CRACK_REGULARISATION * iso
        return np.where(w["cracked"], crack, iso) * w.x[1]

    @BilinearForm
    def robin(u, v, w):
        R = np.sqrt(w.x[0] ** 2 + w.x[1] ** 2)
        return (4 * mu / R) * dot(u, w.n) * dot(v, w.n) * w.x[1]

    @LinearForm
    def load(v, w):
        # t = sigma . nu on R = a with nu = -e_R (out of the medium): t = -sigma_RR e_R = traction nu
        return traction * dot(v, w.n) * w.x[1]

    K = stiffness.assemble(basis, cracked=cracked_q)
    far = FacetBasis(mesh, elem, facets=dm.boundaries["far"], intorder=6)
    K = K + robin.assemble(far)
    cav = FacetBasis(mesh, elem, facets=dm.boundaries["cavity"], intorder=6)
    f = load.assemble(cav)
    fixed = np.concatenate([basis.get_dofs(dm.boundaries["axis"]).all(["u^2"]),
                            basis.get_dofs(dm.boundaries["sym"]).all(["u^1"])])
    u = solve(*condense(K, f, D=np.unique(fixed)))
    ui = basis.interpolate(u)
    x, rho = np.asarray(basis.global_coordinates())
    e = strains(ui, rho)
    R = np.hypot(x, rho)
    nx, nr = x / R, rho / R
    tr = e[0] + e[1] + e[2]
    sxx, srr, stt, sxr = (lam * tr + 2 * mu * e[0], lam * tr + 2 * mu * e[1], lam * tr + 2 * mu * e[2], 2 * mu * e[3])
    eRR = nx * nx * e[0] + nr * nr * e[1] + 2 * nx * nr * e[3]
    sRR = nx * nx * sxx + nr * nr * srr + 2 * nx * nr * sxr
    spsi = nr * nr * sxx + nx * nx * srr - 2 * nx * nr * sxr
    sRpsi = -nx * nr * sxx + nx * nr * srr + (nx * nx - nr * nr) * sxr
    cq = cracked_q.astype(bool)
    sRR = np.where(cq, E * eRR, sRR)
    stt = np.where(cq, 0.0, stt)
    spsi = np.where(cq, 0.0, spsi)
    sRpsi = np.where(cq, 0.0, sRpsi)
    uv = np.asarray(ui)
    uR = nx * uv[0] + nr * uv[1]
    upsi = -nr * uv[0] + nx * uv[1]
    return AxisymmetricSolution(x.ravel(), rho.ravel(), R.ravel(), uR.ravel(), upsi.ravel(), sRR.ravel(),
                                stt.ravel(), spsi.ravel(), sRpsi.ravel(), int(basis.N), int(mesh.t.shape[1]),
                                time.perf_counter() - t0)


# ------------------------------------------------------------------------------------
# comparisons and the command `cavity`

# AD995 alumina of Part II's example (cases/cavity_ad995.toml; errata item 19: Y_s = 2.62 GPa)
DEFAULT_MATERIAL = dict(youngs_modulus=373.14e9, poisson_ratio=0.232, tensile_strength=0.262e9,
                        compressive_strength=2.62e9, bulk_modulus=231.8e9, initial_porosity=0.0)


def _maxrel(fem, exact, scale=None) -> float:
    scale = float(np.max(np.abs(exact))) if scale is None else float(scale)
    return float(np.max(np.abs(np.asarray(fem) - np.asarray(exact))) / scale)


def lame_errors_1d(E: float, nu: float, pressure: float, n_elements: int, a: float = 1.0, outer: float = 20.0) -> dict:
    """1D FEM of the pressurised cavity against Lame's solution (errors relative to u(a) and p)."""
    from semianalytic.cavity.zones import lame_cavity

    s = solve_radial(a, -pressure, E, nu, outer * a, n_elements)
    u, sr, sp = lame_cavity(s.r, a, pressure, E, nu)
    return {"n_elements": n_elements, "n_dofs": s.n_dofs, "u": _maxrel(s.u, u), "sigma_r": _maxrel(s.sigma_r, sr, pressure),
            "sigma_phi": _maxrel(s.sigma_phi, sp, pressure), "seconds": s.seconds, "_sol": s}


def lame_errors_2d(E: float, nu: float, pressure: float, h: float, degree: int, a: float = 1.0, outer: float = 10.0) -> dict:
    """2D axisymmetric FEM of the pressurised cavity against Lame's solution (relative to u(a) and p).

    sigma_theta is the out-of-plane hoop stress, sigma_psi the in-plane one: both must equal
    Lame's sigma_phi; the shear sigma_Rpsi and the tangential displacement must vanish."""
    from semianalytic.cavity.zones import lame_cavity

    s = solve_axisymmetric(a, -pressure, E, nu, outer * a, MeshOptions(h=h, growth=2.0), degree=degree)
    u, sr, sp = lame_cavity(s.R, a, pressure, E, nu)
    ua = float(lame_cavity(a, a, pressure, E, nu)[0])
    return {"h_over_d": h, "degree": degree, "n_dofs": s.n_dofs, "n_elements": s.n_elements,
            "u": _maxrel(s.u_R, u, ua), "u_tangential": _maxrel(s.u_psi, 0 * u, ua),
            "sigma_r": _maxrel(s.sigma_RR, sr, pressure), "sigma_phi": _maxrel(s.sigma_theta, sp, pressure),
            "sigma_psi": _maxrel(s.sigma_psi, sp, pressure), "shear": _maxrel(s.sigma_Rpsi, 0 * sp, pressure),
            "seconds": s.seconds}


def zone_errors(material, sigma_star: float, n_elements: int = 400, b: float = 1.0, outer_over_c: float = 10.0,
                axisymmetric_h: float | None = None) -> dict:
    """FEM of the cracked (b < r < c) and elastic (r > c) zones loaded by sigma_r(b) = sigma*
    against Part II, eqs. (5), (11), (12); c from eq. (13).

    Each quantity is measured relative to its own largest value: u, sigma_r (|sigma*|) and, in the
    elastic zone, sigma_phi (sigma_f).  Also returned: the boundary conditions the FEM was not
    given, sigma_phi(c + 0) = sigma_f (eq. (4)) and sigma_r(c) = -2 sigma_f (eq. (8)), and u(b)
    against eq. (14) (errata item 10)."""
    from semianalytic.cavity.zones import crack_front_ratio, cracked_zone, elastic_zone, front_strains

    E, nu, sf = material.youngs_modulus, material.poisson_ratio, material.tensile_strength
    c = b * float(crack_front_ratio(sigma_star, sf))

    def exact(r):
        ue, sre, spe = elastic_zone(r, c, material)
        uc, src = cracked_zone(r, b, c, sigma_star, material)
        inner = r < c
        return np.where(inner, uc, ue), np.where(inner, src, sre), np.where(inner, 0.0 * r, spe)

    s = solve_radial(b, sigma_star, E, nu, outer_over_c * c, n_elements, cracked_until=c)
    u, sr, sp = exact(s.r)
    outer_zone = s.r > c
    # one-sided values at r = c from the quadrature points next to the front, carried to r = c
    # with the local radial dependence (r^-2 in the cracked zone, r^-3 in the elastic zone)
    ic = int(np.argmin(np.abs(s.nodes - c)))
    k_out = int(np.argmax(s.r > c))
    k_in = k_out - 1
    sp_c_plus = float(s.sigma_phi[k_out]) * (s.r[k_out] / c) ** 3
    sr_c_plus = float(s.sigma_r[k_out]) * (s.r[k_out] / c) ** 3
    sr_c_minus = float(s.sigma_r[k_in]) * (s.r[k_in] / c) ** 2
    u_b = float(s.u_nodes[0])
    u_b_14 = float(front_strains(sigma_star, material)["e_phi"]) * b
    out = {
        "c_over_b": c / b, "n_elements": n_elements, "n_dofs": s.n_dofs, "seconds": s.seconds,
        "u": _maxrel(s.u, u), "sigma_r": _maxrel(s.sigma_r, sr, abs(sigma_star)),
        "sigma_phi_elastic": _maxrel(s.sigma_phi[outer_zone], sp[outer_zone], sf),
        # relative deviations (FEM / expected - 1) of conditions the FEM was not given
        "eq4_sigma_phi_c_plus": sp_c_plus / sf - 1,
        "eq8_sigma_r_c_minus": sr_c_minus / (-2 * sf) - 1,
        "sigma_r_c_plus": sr_c_plus / (-2 * sf) - 1,
        "eq14_u_b": u_b / u_b_14 - 1, "eq6_u_c": float(s.u_nodes[ic]) / ((1 + nu) * sf * c / E) - 1,
        "_sol": s, "_exact": exact, "_c": c,
    }
    if axisymmetric_h is not None:
        s2 = solve_axisymmetric(b, sigma_star, E, nu, 4 * c, MeshOptions(h=axisymmetric_h, growth=2.0), cracked_until=c, degree=4)
        u2, sr2, sp2 = exact(s2.R)
        out["axisymmetric"] = {"h_over_d": axisymmetric_h, "n_dofs": s2.n_dofs, "u": _maxrel(s2.u_R, u2),
                               "sigma_r": _maxrel(s2.sigma_RR, sr2, abs(sigma_star)),
                               "sigma_phi_elastic": _maxrel(s2.sigma_theta[s2.R > c], sp2[s2.R > c], sf),
                               "regularisation": CRACK_REGULARISATION, "seconds": s2.seconds}
    return out


def material_from_args(case_path: str | None):
    from semianalytic.case import load_case
    from semianalytic.cavity import BrittleMaterial

    if case_path is None:
        return BrittleMaterial(**DEFAULT_MATERIAL), "AD995 alumina (Part II example, Y_s = 2.62 GPa, errata 19)"
    case = load_case(case_path)
    return BrittleMaterial.from_section(case.require("material")), case.title


def cavity_study(material, quick: bool = False) -> dict:
    """All cavity comparisons: Lame 1D and 2D, the Part II zones; with convergence tables unless ``quick``."""
    from semianalytic.cavity import solve_cavity

    res = solve_cavity(material)
    sigma_star = float(res.sigma_star)
    p = -sigma_star  # cavity pressure of the Lame check: |sigma*| (any value would do: linear)
    E, nu = material.youngs_modulus, material.poisson_ratio
    out: dict = {"sigma_star_Pa": sigma_star, "lame_pressure_Pa": p}
    ns = [400] if quick else [50, 100, 200, 400, 800]
    out["lame_1d"] = [lame_errors_1d(E, nu, p, n) for n in ns]
    hs = [0.06] if quick else [0.2, 0.1, 0.05]
    degrees = [4] if quick else [2, 4]
    out["lame_2d"] = [lame_errors_2d(E, nu, p, h, deg) for deg in degrees for h in hs]
    out["zones_1d"] = [zone_errors(material, sigma_star, n) for n in ([400] if quick else [100, 200, 400, 800])]
    if not quick:
        out["zones_1d"][-1].update(zone_errors(material, sigma_star, 800, axisymmetric_h=0.05))
    best = {"lame_1d": out["lame_1d"][-1 if quick else 3], "lame_2d": [r for r in out["lame_2d"] if r["degree"] == 4][-1],
            "zones_1d": [z for z in out["zones_1d"] if z["n_elements"] == 400][0]}
    errs = {
        "lame_1d": max(best["lame_1d"][k] for k in ("u", "sigma_r", "sigma_phi")),
        "lame_2d": max(best["lame_2d"][k] for k in ("u", "u_tangential", "sigma_r", "sigma_phi", "sigma_psi", "shear")),
        "zones_1d": max(best["zones_1d"][k] for k in ("u", "sigma_r", "sigma_phi_elastic")),
    }
    out["max_rel_error_by_problem"] = errs
    out["max_rel_error"] = max(errs.values())
    out["resolution"] = {"lame_1d_elements": best["lame_1d"]["n_elements"], "lame_2d": f"P4, h = {best['lame_2d']['h_over_d']} d",
                         "zones_1d_elements": 400}
    return out


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from fem_check.report import add_output_arguments

    parser.add_argument("case", nargs="?", help="case TOML with a [material] section (default: AD995 of Part II)")
    parser.add_argument("--quick", action="store_true", help="only the test resolution (no convergence tables)")
    add_output_arguments(parser, "fem_cavity")


def run(args) -> int:
    from fem_check.report import Report, emit_json
    from semianalytic.errors import model_field
    from semianalytic.sections.cavity import MODEL_FIELDS

    with model_field(MODEL_FIELDS):  # the cavity model's input names -> the [material] keys of the case
        material, title = material_from_args(args.case)
    report = None if args.no_report else Report(Path(args.out), args.name, args.force)
    if report:
        report.check()
    with model_field(MODEL_FIELDS):
        study = cavity_study(material, quick=args.quick)
    payload = _public(study)
    payload["material"] = title
    if report:
        _write_report(report, title, material, study)
        payload["report"] = str(report.path)
    if args.json:
        emit_json(payload)
    else:
        print(f"cavity: max relative error {study['max_rel_error']:.2e} "
              + ", ".join(f"{k} {v:.1e}" for k, v in study["max_rel_error_by_problem"].items()))
        if report:
            print(f"report: {report.path}")
    return 0


def _public(obj):
    if isinstance(obj, dict):
        return {k: _public(v) for k, v in obj.items() if not k.startswith("_")}
    if isinstance(obj, list):
        return [_public(v) for v in obj]
    return obj


def _write_report(report, title, material, study) -> None:
    from fem_check.report import fmt, md_table, new_figure, rate

    r = report
    E, nu, sf = material.youngs_modulus, material.poisson_ratio, material.tensile_strength
    r.add("# FEM check of the elastic spherical cavity and the Part II zones", "",
          "Generated by `python -m fem_check cavity --out reports --force`.", "",
          f"Material: {title}: E = {fmt(E / 1e9)} GPa, nu = {fmt(nu)}, sigma_f = {fmt(sf / 1e9)} GPa; "
          f"sigma* = {fmt(study['sigma_star_Pa'] / 1e9)} GPa from `semianalytic.cavity.solve_cavity`.", "",
          "Far field: the exterior elastic field is u = k/r^2, whose traction on r = R is exactly "
          "sigma_r = -4 mu u / R; imposed as a Robin condition, it replaces the infinite medium with no "
          "truncation error, so the tables show discretisation errors only.", "",
          f"**Maximum relative error at the test resolution: {fmt(study['max_rel_error'])}** "
          f"({', '.join(f'{k} {fmt(v)}' for k, v in study['max_rel_error_by_problem'].items())}).", "",
          "## Pressurised cavity, 1D (spherical symmetry, weight r^2, P2, geometric mesh on [a, 20a])", "",
          f"Pressure p = {fmt(study['lame_pressure_Pa'] / 1e9)} GPa. Errors: max over the quadrature points, "
          "relative to u(a) and p. Expected orders in h: 3 for u, 2 for the stresses (P2).", "")
    rows = study["lame_1d"]
    hs = [1.0 / x["n_elements"] for x in rows]
    ru, rs = rate([x["u"] for x in rows], hs), rate([x["sigma_r"] for x in rows], hs)
    r.add(md_table(["elements", "dofs", "u", "order", "sigma_r", "order", "sigma_phi", "s"],
                   [[x["n_elements"], x["n_dofs"], x["u"], a, x["sigma_r"], b, x["sigma_phi"], x["seconds"]]
                    for x, a, b in zip(rows, ru, rs)]), "")
    r.add("## Pressurised cavity, 2D axisymmetric (quarter annulus a <= R <= 10a, curved quadratic gmsh mesh)", "",
          "Errors relative to u(a) and p, max over all quadrature points; sigma_theta is the out-of-plane hoop "
          "stress, sigma_psi the in-plane one (both Lame's sigma_phi); u_t and the shear must vanish. P2 stresses "
          "converge at order 2; P4 on the quadratic geometry is used to reach the 1e-4 target.", "")
    rows = study["lame_2d"]
    r.add(md_table(["degree", "h/d", "dofs", "u", "u_t", "sigma_r", "sigma_theta", "sigma_psi", "shear", "s"],
                   [[x["degree"], x["h_over_d"], x["n_dofs"], x["u"], x["u_tangential"], x["sigma_r"], x["sigma_phi"],
                     x["sigma_psi"], x["shear"], x["seconds"]] for x in rows]), "")
    for deg in sorted({x["degree"] for x in rows}):
        sel = [x for x in rows if x["degree"] == deg]
        orders = rate([x["sigma_r"] for x in sel], [x["h_over_d"] for x in sel])
        r.add(f"Observed orders of sigma_r for P{deg}: " + ", ".join(fmt(o) for o in orders[1:]) + ".", "")
    z = study["zones_1d"]
    zl = z[-1]
    r.add("## Elastic and cracked zones of Part II (1D, weight r^2)", "",
          "The cracked zone b < r < c carries radial stress only (sigma_phi = 0, sigma_r = E du/dr: eqs. (9)-(10) "
          "with errata items 8-9), bonded to the elastic zone r > c; the FEM is given sigma_r(b) = sigma* (eq. (7)) "
          f"and c from eq. (13) (c/b = {fmt(zl['c_over_b'])}), nothing else. Compared with eqs. (5), (11), (12); each "
          "quantity relative to its own maximum (sigma_phi of the elastic zone relative to sigma_f).", "",
          md_table(["elements", "dofs", "u", "order", "sigma_r", "order", "sigma_phi (r > c)"],
                   [[x["n_elements"], x["n_dofs"], x["u"], a, x["sigma_r"], b, x["sigma_phi_elastic"]]
                    for x, a, b in zip(z, rate([x["u"] for x in z], [1 / x["n_elements"] for x in z]),
                                       rate([x["sigma_r"] for x in z], [1 / x["n_elements"] for x in z]))]), "",
          "Conditions the FEM was not given (finest mesh), as FEM / expected - 1 (sigma_phi = 0 in the cracked "
          "zone holds by construction there):", "",
          md_table(["check", "FEM / expected - 1"], [
              ["sigma_phi(c+0) = sigma_f, eq. (4)", zl["eq4_sigma_phi_c_plus"]],
              ["sigma_r(c-0) = -2 sigma_f, eq. (8)", zl["eq8_sigma_r_c_minus"]],
              ["sigma_r(c+0) = -2 sigma_f (continuity)", zl["sigma_r_c_plus"]],
              ["u(c) = (1+nu) sigma_f c / E, eq. (6)", zl["eq6_u_c"]],
              ["u(b) of eq. (14) (errata 10)", zl["eq14_u_b"]],
          ]), "")
    if "axisymmetric" in zl:
        ax2 = zl["axisymmetric"]
        r.add("Exploratory (not a test): the same zones in 2D axisymmetric, P4. The radial-stress-only law of the "
              "cracked zone has no stiffness against non-radial displacements, so without spherical symmetry the "
              f"problem is singular; with {fmt(ax2['regularisation'])} of the isotropic stiffness added there, the errors are "
              f"u {fmt(ax2['u'])}, sigma_r {fmt(ax2['sigma_r'])}, sigma_phi (r > c) {fmt(ax2['sigma_phi_elastic'])} "
              f"({ax2['n_dofs']} dofs): the near-mechanism makes the 2D cracked zone converge slowly.", "")
    s = zl["_sol"]
    u, sr, sp = zl["_exact"](s.r)
    fig = new_figure()
    ax = fig.add_subplot(111)
    step = max(1, len(s.r) // 150)
    ax.plot(s.r, sr / 1e9, "-", color="C0", label="sigma_r, eqs. (5), (11)")
    ax.plot(s.r, sp / 1e9, "-", color="C1", label="sigma_phi, eq. (5); 0 for r < c")
    ax.plot(s.r[::step], s.sigma_r[::step] / 1e9, "o", ms=3, color="C0", label="FEM sigma_r")
    ax.plot(s.r[::step], s.sigma_phi[::step] / 1e9, "s", ms=3, color="C1", label="FEM sigma_phi")
    ax.axvline(zl["_c"], color="k", lw=0.5)
    ax.set_xscale("log")
    ax.set_xlabel("r / b")
    ax.set_ylabel("stress [GPa]")
    ax.legend(fontsize=8)
    r.figure("zones", fig, "stresses in the cracked and elastic zones: FEM points, Part II lines")
    fig = new_figure()
    ax = fig.add_subplot(111)
    rows = study["lame_1d"]
    ax.loglog([x["n_elements"] for x in rows], [x["sigma_r"] for x in rows], "o-", label="1D P2 sigma_r")
    ax.loglog([x["n_elements"] for x in rows], [x["u"] for x in rows], "s-", label="1D P2 u")
    for deg in sorted({x["degree"] for x in study["lame_2d"]}):
        sel = [x for x in study["lame_2d"] if x["degree"] == deg]
        ax.loglog([x["n_dofs"] ** 0.5 for x in sel], [x["sigma_r"] for x in sel], "^-", label=f"2D P{deg} sigma_r (x: sqrt dofs)")
    ax.axhline(1e-4, color="k", lw=0.5, ls=":")
    ax.set_xlabel("elements (1D) or sqrt(dofs) (2D)")
    ax.set_ylabel("max relative error")
    ax.legend(fontsize=8)
    r.figure("convergence", fig, "convergence of the cavity FEM against Lame's solution")
    r.write()
