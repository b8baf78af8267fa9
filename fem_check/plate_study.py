"""The verification study behind ``reports/plate_coefficients.md`` (issue 23, item 2): computes, the
report module only renders.

- exact solution: the slab Green's function of a point source inside the nose (two independent
  series, :func:`slab_green`) against the BEM's surface potential for Neumann data taken from it;
- half-space limit: A, B, C of the plate against today's half-space at growing H, raw and after
  the analytic image term of the monopole (:func:`semianalytic.coefficients.plate.far_field_correction`);
- FEM: ``fem_check.plate.plate_potential`` on the same domain under refinement;
- A, B, C against P for a few H, and one adaptive table with its estimates checked off the knots.
"""

from __future__ import annotations

import math
import time

import numpy as np

D = 7.11e-3  # Fig. 5 calibre


def noses():
    from semianalytic.geometry import cone_nose, ogive_nose

    return {"3-CRH ogive": ogive_nose(D, 3.0), "30 deg cone": cone_nose(D, math.radians(15))}


# --------------------------------------------------------------------------------------
# exact solution of the slab: Neumann at x = 0, Dirichlet at x = H, unit point source at (xs, 0)


def _modes(x, r, xs, H, n_modes):
    from scipy.special import k0e, k1e

    k = ((np.arange(n_modes) + 0.5) * math.pi / H)[:, None]
    e = np.exp(-k * r)
    c = np.cos(k * xs) / (math.pi * H)
    u = np.sum(np.cos(k * x) * c * k0e(k * r) * e, axis=0)
    ux = np.sum(-k * np.sin(k * x) * c * k0e(k * r) * e, axis=0)
    ur = np.sum(-k * np.cos(k * x) * c * k1e(k * r) * e, axis=0)
    return u, ux, ur


def _images(x, r, xs, H, K=400):
    from scipy.special import digamma

    u, ux, ur = (np.zeros_like(x) for _ in range(3))
    for k in range(-K, K + 1):
        for z in (xs + 2 * k * H, -xs + 2 * k * H):
            d = np.sqrt((x - z) ** 2 + r**2)
            s = (-1.0) ** k / (4 * math.pi)
            u += s / d
            ux -= s * (x - z) / d**3
            ur -= s * r / d**3
    z = K + 1.0
    u += 4 * (-1.0) ** (K + 1) * 0.5 * (digamma(0.5 * (z + 1)) - digamma(0.5 * z)) / (2 * H) / (4 * math.pi)
    return u, ux, ur


def slab_green(x, r, xs, H):
    """The slab Green's function and its gradient: the eigenfunction series sum_n (1/(pi H))
    cos(k_n x) cos(k_n xs) K0(k_n r), k_n = (n + 1/2) pi/H, where r > H/50 (exponential
    convergence), the image series near the axis (the two agree to 1e-9)."""
    u, ux, ur = (np.empty_like(x) for _ in range(3))
    far = r > 0.02 * H
    if far.any():
        n = int(40 * H / (math.pi * r[far].min())) + 50
        u[far], ux[far], ur[far] = _modes(x[far], r[far], xs, H, n)
    if (~far).any():
        u[~far], ux[~far], ur[~far] = _images(x[~far], r[~far], xs, H)
    return u, ux, ur


def exact_check(cases=((0.5, 2.0), (0.9, 2.0), (2.0, 2.5), (1.3, 1.0), (1.5, 1.0), (0.7, 0.3)),
                refinements=(0.3, 1.0)) -> list[dict]:
    from semianalytic.bem.panels import LayoutOptions
    from semianalytic.bem.slab import slab_layout, solve_slab

    out = []
    for name, nose in noses().items():
        L = nose.length
        for p, h in cases:
            P, H = p * L, h * L
            lo, hi = max(P - L, 0.0), min(P, H)
            xs = lo + 0.35 * (hi - lo) if P > L else 0.5 * (lo + hi)

            def neumann(x, r, nx, nr, xs=xs, H=H):
                _, ux, ur = slab_green(x, r, xs, H)
                return ux * nx + ur * nr

            row = {"nose": name, "P_over_L": p, "H_over_L": h, "xs_over_L": xs / L}
            for ref in refinements:
                sol = solve_slab(slab_layout(nose, P, H, LayoutOptions(8, ref, 6)), neumann=neumann)
                nd = sol.nodes
                row["gap_over_L"] = float(np.min(np.hypot(nd.x - xs, nd.r)) / L)  # source to surface
                u, _, _ = slab_green(nd.x, nd.r, xs, H)
                row[f"err_{ref}"] = float(np.max(np.abs(nd.phi - u)) / np.max(np.abs(u)))
                row[f"unknowns_{ref}"] = int(sol.unknowns)
            out.append(row)
    return out


def _dC_dP(nose, P):
    from semianalytic.bem.panels import param_at_x

    def r(p):
        for s in nose.segments:
            if float(s.point(s.t1)[0]) <= -p:
                return float(s.point(param_at_x(s, -p))[1])

    h = 1e-6 * P
    return math.pi * (r(P + h) ** 2 - r(P - h) ** 2) / (2 * h) if P < nose.length else 0.0


def halfspace_limit(depths=(0.5, 2.0), thicknesses=(5.0, 10.0, 20.0, 50.0, 100.0, 200.0)) -> list[dict]:
    from semianalytic.coefficients.plate import far_field_correction, plate_coefficients_at
    from semianalytic.coefficients.table import coefficients_at

    out = []
    for name, nose in noses().items():
        L = nose.length
        Ps = np.array(depths) * L
        half = coefficients_at(nose, Ps, refinement=0.3, levels=6)
        for h in thicknesses:
            plate = plate_coefficients_at(nose, h * L, Ps)
            for i, P in enumerate(Ps):
                dA, dB = far_field_correction(float(half["C"][i]), _dC_dP(nose, P), h * L)
                a, b = abs(half["A"][i]), abs(half["B_body"][i])
                out.append({
                    "nose": name, "P_over_L": float(depths[i]), "H_over_L": h,
                    "A_raw": float((plate["A"][i] - half["A"][i]) / a),
                    "B_raw": float((plate["B_body"][i] - half["B_body"][i]) / b),
                    "A_corrected": float((plate["A"][i] - half["A"][i] - dA) / a),
                    "B_corrected": float((plate["B_body"][i] - half["B_body"][i] - dB) / b),
                    "C": float(plate["C"][i] / half["C"][i] - 1),
                })
    return out


def fem_agreement(cases=((0.6, 1.0), (1.4, 1.0), (0.5, 2.0), (2.5, 2.0)), hs=(0.08, 0.05, 0.04, 0.03)) -> list[dict]:
    from fem_check.meshing import MeshOptions
    from fem_check.plate import plate_potential
    from semianalytic.coefficients.plate import plate_coefficients_at

    out = []
    for name, nose in noses().items():
        L = nose.length
        for p, h in cases:
            bem = plate_coefficients_at(nose, h * L, [p * L], refinement=1.0, levels=12)
            for hh in hs:
                f = plate_potential(nose, p * L, h * L, MeshOptions(h=hh))
                out.append({"nose": name, "P_over_L": p, "H_over_L": h, "h_over_d": hh, "dofs": f.n_dofs,
                            "A_fem": f.A, "A_bem": float(bem["A"][0]), "A_rel": float(f.A / bem["A"][0] - 1),
                            "C_rel": float(f.C / bem["C"][0] - 1), "bem_unknowns": int(bem["unknowns"][0])})
    return out


def fem_drag(hs=(0.08, 0.05, 0.04)) -> list[dict]:
    """FEM dA/dP (shape difference on the moved mesh) against the BEM's B_bernoulli, P = 1.4 L_h, H = 2 L_h."""
    from fem_check.meshing import MeshOptions
    from fem_check.plate import plate_potential
    from semianalytic.coefficients.plate import plate_coefficients_at

    out = []
    for name, nose in noses().items():
        L = nose.length
        bem = plate_coefficients_at(nose, 2.0 * L, [1.4 * L], refinement=1.0, levels=12)
        for hh in hs:
            f = plate_potential(nose, 1.4 * L, 2.0 * L, MeshOptions(h=hh), derivative=True)
            out.append({"nose": name, "h_over_d": hh, "dofs": f.n_dofs, "B_over_S": float(bem["B_bernoulli"][0] / (math.pi * nose.radius**2)),  # noqa: E501
                        "rel": float(f.dA_dP / bem["B_bernoulli"][0] - 1)})
    return out


def profiles(thicknesses=(0.5, 1.0, 2.0), n: int = 24) -> list[dict]:
    from semianalytic.coefficients.plate import plate_coefficients_at

    out = []
    for name, nose in noses().items():
        L = nose.length
        for h in thicknesses:
            Ps = np.linspace(0.02, h + 1.0, n) * L
            r = plate_coefficients_at(nose, h * L, Ps)
            S = math.pi * nose.radius**2
            out.append({"nose": name, "H_over_L": h, "P_over_L": (Ps / L).tolist(),
                        **{k: (r[k] / S).tolist() for k in ("A", "B_body", "B_bernoulli", "C")},
                        "identity": (np.abs(r["B_bernoulli"] - r["dA_dP"]) / S).tolist()})
    return out


def certified_table(h_over_L: float = 2.0, tolerance: float = 1e-4, n_check: int = 8, seed: int = 2026) -> dict:
    """One adaptive table (the ogive, H = 2 L_h): cost, and its error estimates against direct
    solves at random depths off the knots (the estimate must bound the error)."""
    from semianalytic.coefficients.plate import CONTROLLED, plate_coefficient_table, plate_coefficients_at

    nose = noses()["3-CRH ogive"]
    L = nose.length
    t0 = time.process_time()
    table = plate_coefficient_table(nose, h_over_L * L, tolerance=tolerance)
    cpu = time.process_time() - t0
    rng = np.random.default_rng(seed)
    Ps = np.sort(rng.uniform(0.01, h_over_L + 0.99, n_check)) * L
    direct = plate_coefficients_at(nose, h_over_L * L, Ps)
    rows = []
    for i, P in enumerate(Ps):
        row = {"P_over_L": float(P / L)}
        for q in CONTROLLED:
            val = table.B(P, q[2:]) if q.startswith("B_") else getattr(table, q)(P)
            row[f"{q}_err"] = float(abs(val - direct[q][i]) / table.max_abs[q])
            row[f"{q}_est"] = float(table.error(q, P) / table.max_abs[q])
        rows.append(row)
    return {"H_over_L": h_over_L, "tolerance": tolerance, "knots": int(len(table.depth)), "cpu_s": cpu,
            "noise_limited": table.options.get("noise_limited_intervals"), "bem_errors": {
                k: v / table.max_abs[k] for k, v in table.bem_errors.items()}, "checks": rows}


def plate_study(quick: bool = False) -> dict:
    """Everything the report shows (``quick``: fewer cases, no table)."""
    import os

    out = {"load": os.getloadavg()[0]}
    t = time.perf_counter()
    out["exact"] = exact_check(cases=((0.9, 2.0), (1.5, 1.0)) if quick else exact_check.__defaults__[0])
    out["limit"] = halfspace_limit(thicknesses=(10.0, 50.0)) if quick else halfspace_limit()
    out["fem"] = fem_agreement(cases=((0.6, 1.0),), hs=(0.08, 0.05)) if quick else fem_agreement()
    out["fem_drag"] = fem_drag(hs=(0.08,)) if quick else fem_drag()
    out["profiles"] = profiles(thicknesses=(1.0,), n=8) if quick else profiles()
    out["table"] = None if quick else certified_table()
    out["seconds"] = time.perf_counter() - t
    return out
