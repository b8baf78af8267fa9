"""What a sweep computes for each case: thin adapters onto the models (no physics here).

A kernel names its output columns (SI units in the names), the case keys it evaluates
vectorised without re-validating the case (``fast_keys``: the striking velocity), and the
shared resource it needs (the coefficient table of the projectile's nose, keyed by the
geometry and the BEM options).

- ``penetration`` (Part I): final depth of the rigid projectile for each striking velocity
  (eq. (11), through :func:`semianalytic.penetration.motion.final_depth`), the critical impact
  velocity U_sC (eqs. (33)/(36)) and whether the projectile yields (U_s >= U_sC).  With
  ``full=True`` also the quasi-rigid and elastic depths, case by case, through the
  penetration module's own evaluation (slower).
- ``cavity`` (Part II): the cavity-expansion solution of a ``[material]``.
"""

from __future__ import annotations

import contextlib
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from semianalytic.case import Case
from semianalytic.errors import InputError, ModelError
from semianalytic.sweep.spec import VELOCITY_KEY, Axis, SweepSpec

# [projectile] keys that do NOT change the coefficient table of the nose (the material, the mass
# and the shank); every other projectile key, and every [bem] and [coefficients] key, is taken to
# change it (a new nose parameter is never missed: at worst a table is looked up once more)
_NOT_GEOMETRY = frozenset({
    "projectile.shank_length", "projectile.length", "projectile.density", "projectile.mass",
    "projectile.youngs_modulus", "projectile.poisson_ratio", "projectile.yield_stress",
    "projectile.dynamic_yield_stress", "projectile.buckling", "projectile.buckling_table",
    "projectile.hardness", "projectile.dynamic_factor",
})


# keys a penetration kernel evaluates on arrays (Monte Carlo): the resistance fields, the densities, the mass
_ARRAY_PREFIXES = ("target.resistance.", "target.density", "projectile.density", "projectile.mass")


def changes_table(key: str) -> bool:
    """Whether a case key changes the coefficient table (the one list: :data:`_NOT_GEOMETRY`)."""
    if key.startswith(("bem.", "coefficients.")):
        return True
    return key.startswith("projectile.") and key not in _NOT_GEOMETRY


def geometry_key(case: Case) -> str:
    """The content key of everything the coefficient table depends on: the cache's own key
    (:func:`semianalytic.cache.case_table_key`, every nose parameter) with the B reading."""
    from semianalytic.cache import case_table_key

    return case_table_key(case)


def coefficient_table_for(case: Case, cache_dir=None, progress: bool = False):
    """The (cached) A, B, C table of the case's nose, in the B reading the case selects
    (:func:`semianalytic.cache.coefficients_for_case` with source "bem")."""
    from semianalytic.cache import coefficients_for_case

    return coefficients_for_case(case, "bem", cache_dir=cache_dir, progress=progress)[0]


def _check_velocities(values: np.ndarray) -> None:
    bad = ~(np.isfinite(values) & (values > 0))
    if bad.any():
        raise InputError("impact.striking_velocities", f"must be positive; got {float(values[bad][0]):g} m/s")


@dataclass(frozen=True)
class PenetrationKernel:
    """Part I penetration for many striking velocities (see the module docstring)."""

    cache_dir: str | None = None
    coefficients: Any = None  # a fixed DragCoefficients (e.g. ConstantCoefficients) instead of the BEM table
    full: bool = False
    vectorised: bool = True  # Monte-Carlo samples on arrays (False: each sample validated as its own case)
    name: str = "penetration"
    fast_keys: frozenset = frozenset({VELOCITY_KEY})
    # per-process cache of unit-resistance depth profiles (see _rigid); not part of the identity
    _profiles: dict = field(default_factory=dict, compare=False, repr=False)
    _derived: dict = field(default_factory=dict, compare=False, repr=False)  # per-case constants (evaluate_arrays)
    _tables: dict = field(default_factory=dict, compare=False, repr=False)  # geometry key -> table (prepare)

    @property
    def seconds_per_case(self) -> float:
        """Rough cost of a case for the engine choice: microseconds on arrays, more with ``full``."""
        return 2e-3 if self.full else 0.0

    @property
    def columns(self) -> tuple[str, ...]:
        cols = ("depth_rigid_m", "critical_velocity_m_s", "yields")
        if self.full:
            cols += ("depth_quasi_rigid_m", "depth_elastic_m", "depth_elastic_exact_rod_m")
        return cols

    def complete_spec(self, case: Case, spec: SweepSpec) -> SweepSpec:
        """Without a velocity axis, the case's own striking velocities become one (innermost)."""
        for sec in ("projectile", "target"):
            case.require(sec)
        if VELOCITY_KEY in spec.keys:
            return spec
        imp = case.require("impact")
        axis = Axis(VELOCITY_KEY, tuple(imp.striking_velocities), "m/s")
        return SweepSpec(spec.axes + (axis,), spec.samplers, spec.n_samples, spec.seed)

    def check_fast(self, key: str, values: np.ndarray) -> None:
        _check_velocities(np.asarray(values, float))

    # keys evaluated on arrays (Monte Carlo, issue 14): the case is validated once per batch at the
    # corners of the sampled ranges, then each sample only changes R_t, rho, m and U_s
    def is_array_key(self, key: str) -> bool:
        if self.full or not self.vectorised:
            return False
        return key.startswith(_ARRAY_PREFIXES) and key.count(".") == (2 if key.startswith("target.resistance.") else 1)

    def accepts_arrays(self, case: Case, keys) -> bool:
        """The sampled resistance fields are fields of the case's resistance model (not the cavity
        model's nested material, whose R_t is a Part II solve per sample)."""
        import dataclasses

        from semianalytic.penetration.resistance import resistance_from_case

        res = [k.rsplit(".", 1)[1] for k in keys if k.startswith("target.resistance.")]
        if not res:
            return True
        try:
            model = resistance_from_case(case)
        except InputError:
            return False
        names = {f.name for f in dataclasses.fields(_fields_owner(model))}
        return all(f in names for f in res)

    def _per_case(self, case: Case, coefficients):
        """What a batch needs from its (validated, cached) case: the resistance model, the
        projectile's volume and mass, and the U_sC inputs; kept per worker, reused by every batch."""
        key = (id(case), id(coefficients))
        hit = self._derived.get(key)
        if hit is not None and hit[0] is case and hit[1] is coefficients:
            return hit[2]
        from semianalytic.geometry import projectile_from_section
        from semianalytic.penetration.curve import PenetrationSetup
        from semianalytic.penetration.resistance import resistance_from_case

        psec = case.require("projectile")
        proj = projectile_from_section(psec)
        setup = PenetrationSetup.from_case(case, coefficients, require_material=False)
        derived = {
            "resistance": resistance_from_case(case),
            "volume": proj.volume(),
            "mass": proj.mass,
            "target_density": float(case.require("target").density),
            "critical": setup.critical_inputs() if setup.rod is not None and setup.yield_stress is not None else None,
            "yield_stress": setup.yield_stress,
            "phi": setup.phi,
        }
        if len(self._derived) > 64:
            self._derived.clear()
        self._derived[key] = (case, coefficients, derived)
        return derived

    def evaluate_arrays(self, case: Case, coefficients, arrays: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        """Rigid depth, U_sC and the yield flag per sample (see :func:`semianalytic.penetration.batch.final_depths`).

        R_t per sample from the case's resistance model with the sampled fields replaced (its
        closed form on arrays: eqs. (16)-(19), Part IV eq. (6)); rho, m per sample; one table for
        all; U_sC of eqs. (33)/(34) on arrays (:func:`semianalytic.penetration.batch.critical_velocities`)."""
        from semianalytic.penetration.batch import critical_velocities, final_depths

        U = np.asarray(arrays[VELOCITY_KEY], float)
        n = U.size
        psec = case.require("projectile")
        d = self._per_case(case, coefficients)
        status = np.full(n, "ok", dtype=object)
        message = np.full(n, "", dtype=object)
        base = d["resistance"]
        res_fields = {k.rsplit(".", 1)[1]: np.asarray(v, float) for k, v in arrays.items() if k.startswith("target.resistance.")}
        if res_fields:
            R, bad_msg = resistance_per_sample(base, res_fields, psec.diameter)
            R = np.broadcast_to(np.asarray(R, float), (n,))
            status[bad_msg != ""] = "invalid"
            message[:] = bad_msg
        else:
            R = np.full(n, float(base.pressure(psec.diameter)))
        rho = np.broadcast_to(np.asarray(arrays.get("target.density", d["target_density"]), float), (n,))
        # a sampled projectile density sets c_0 of eq. (33) always, and the mass only when the case gives none
        rho_p = np.asarray(arrays["projectile.density"], float) if "projectile.density" in arrays else None
        if "projectile.mass" in arrays:
            m = np.asarray(arrays["projectile.mass"], float)
        elif rho_p is not None and psec.mass is None:
            m = rho_p * d["volume"]
        else:
            m = np.full(n, d["mass"])
        m = np.broadcast_to(m, (n,))
        bad = ~(np.isfinite(R) & (R > 0) & (U > 0))
        status[bad & (status == "ok")] = "invalid"
        message[bad & (message == "")] = "R_t and U_s must be positive"
        ok = ~bad
        depth = np.full(n, np.nan)
        Usc = np.full(n, np.nan)
        if ok.any():
            with _model_errors_as_input():
                depth[ok] = final_depths(coefficients, m[ok], rho[ok], R[ok], U[ok])
            ci = d["critical"]
            if ci is not None:
                dens = np.full(n, ci.density) if rho_p is None else rho_p
                Usc[ok] = critical_velocities(d["yield_stress"], ci.youngs_modulus, dens[ok], m[ok], ci.diameter, ci.A,
                                              ci.B, ci.C, rho[ok], R[ok], d["phi"])
        return {
            "depth_rigid_m": depth,
            "critical_velocity_m_s": Usc,
            "yields": np.where(np.isfinite(Usc), U >= Usc, False),
            "_status": status,
            "_message": message,
        }

    def affects_resource(self, key: str) -> bool:
        return self.coefficients is None and changes_table(key)

    def resource_key(self, case: Case):
        return "fixed" if self.coefficients is not None else geometry_key(case)

    def prepare(self, case: Case):
        if self.coefficients is not None:
            return self.coefficients
        key = geometry_key(case)
        table = self._tables.get(key)
        if table is None:  # kept per worker: the batches of a geometry sweep ask again for their table
            if len(self._tables) >= 8:
                self._tables.pop(next(iter(self._tables)))
            with _model_errors_as_input():
                table = self._tables[key] = coefficient_table_for(case, self.cache_dir)
        return table

    def evaluate(self, case: Case, coefficients, fast: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        U = np.asarray(fast[VELOCITY_KEY], float)
        status = np.full(U.shape, None, dtype=object)
        message = np.full(U.shape, "", dtype=object)
        bad = ~(np.isfinite(U) & (U > 0))
        status[bad] = "invalid"
        message[bad] = "impact.striking_velocities: must be positive"
        Us = np.where(bad, 1.0, U)
        if self.full:
            from semianalytic.penetration import sweep_support

            res = sweep_support(case, coefficients, Us, full=True)
        else:
            res = self._rigid(case, coefficients, Us)
        out = {c: np.asarray(res[c]) for c in self.columns}
        for c in out:
            if out[c].dtype.kind == "f":
                out[c] = np.where(bad, np.nan, out[c])
        out["_status"] = np.where(status == None, "ok", status)  # noqa: E711
        out["_message"] = message
        return out


    def _rigid(self, case: Case, coefficients, U: np.ndarray) -> dict[str, np.ndarray]:
        """Rigid depth, U_sC and the yield flag for many velocities of one material.

        Part I, eq. (11) in w = u^2 with P as the variable: w(P) = e^(-F) (U_0^2 - G(P)),
        F = int rho B/(m + rho A), G = int 2 C R_t e^F/(m + rho A).  G is proportional to
        R_t and F does not involve it, so one integration with R_t = 1 Pa serves every target
        strength of the same density and projectile mass: P_f(U_0; R_t) = P_f(U_0/sqrt(R_t); 1 Pa).
        The profile is kept per worker (``_profiles``) and reused by every batch.
        """
        from semianalytic.penetration.curve import PenetrationSetup
        from semianalytic.penetration.motion import depth_profile

        setup = PenetrationSetup.from_case(case, coefficients, require_material=False)
        scaled = U / np.sqrt(setup.resistance_pa)
        key = (id(coefficients), setup.mass, setup.target_density)
        prof = self._profiles.get(key)
        if prof is None or prof.U_max < scaled.max():
            if len(self._profiles) > 32:
                self._profiles.clear()
            U_max = 1.5 * float(scaled.max()) if prof is None else 2.0 * max(prof.U_max, float(scaled.max()))
            prof = depth_profile(coefficients, setup.mass, setup.target_density, 1.0, U_max)
            self._profiles[key] = (prof)
        U_sC = setup.critical_velocity()
        return {
            "depth_rigid_m": prof.final_depth(scaled),
            "critical_velocity_m_s": np.full(U.shape, U_sC),
            "yields": (U >= U_sC) if np.isfinite(U_sC) else np.zeros(U.shape, bool),
        }


@contextlib.contextmanager
def _model_errors_as_input():
    """A model's error (a shape the BEM cannot solve, a solve that did not converge) marks the
    sweep's cases invalid, as bad input does (the engine's per-case status)."""
    try:
        yield
    except ModelError as exc:
        raise InputError(exc.field, exc.message) from exc


def _fields_owner(model):
    """The dataclass holding a resistance model's case fields: the model, or the Part II cavity
    model's material (``[target.resistance]`` of model "cavity" gives the material's fields)."""
    material = getattr(model, "material", None)
    return material if material is not None else model


def _with_fields(base, values: Mapping[str, Any]):
    """The resistance model ``base`` with the case fields in ``values`` replaced."""
    import dataclasses

    owner = _fields_owner(base)
    kw = {f.name: getattr(owner, f.name) for f in dataclasses.fields(owner)}
    kw.update(values)
    new = type(owner)(**kw)
    return type(base)(new) if owner is not base else new


def _pressures(base, cols: Mapping[str, list], diameter) -> tuple[np.ndarray, np.ndarray]:
    """R_t of the model ``base`` with the fields in ``cols`` replaced, sample by sample."""
    n = len(next(iter(cols.values())))
    R = np.empty(n)
    msg = np.full(n, "", dtype=object)
    for i in range(n):
        try:
            R[i] = _with_fields(base, {f: v[i] for f, v in cols.items()}).pressure(diameter)
        except (ValueError, ArithmeticError, InputError) as exc:
            R[i], msg[i] = np.nan, f"target.resistance: {exc}"
    return R, msg


def _pressures_on_arrays(base, fields: Mapping[str, np.ndarray], diameter):
    """R_t of the model's closed form evaluated on the sample arrays at once (eqs. (16), (17), (19),
    Part IV eq. (6), constant), or None where the model has no array form (eq. (18)'s integral
    and the Part II cavity model) or a sample is out of its range (then per sample, with messages)."""
    n = len(next(iter(fields.values())))
    try:
        with np.errstate(all="ignore"):
            R = np.asarray(_with_fields(base, {f: np.asarray(v, float) for f, v in fields.items()}).pressure(diameter), float)
    except (TypeError, ValueError, ArithmeticError, InputError):
        return None
    if R.ndim > 1 or R.size not in (1, n) or not np.all(np.isfinite(R) & (R > 0)):
        return None
    return np.broadcast_to(R, (n,)).copy()


def resistance_per_sample(base, fields: Mapping[str, np.ndarray], diameter, n_nodes: int = 17):
    """R_t per sample: the resistance model's closed form (Part I, eqs. (16)-(19), Part IV, eq. (6))
    with the sampled fields replaced.  For one or two sampled fields and many samples, R_t is
    evaluated on a Chebyshev grid over the samples' box and interpolated (it is smooth there:
    the box's corners are valid cases); the interpolation is checked against the closed form at
    three samples and used only if it agrees to 1e-11, else every sample is evaluated."""
    n = len(next(iter(fields.values())))
    names = list(fields)
    R = _pressures_on_arrays(base, fields, diameter)
    if R is not None:
        return R, np.full(n, "", dtype=object)
    if len(names) <= 2 and n > 4 * n_nodes ** len(names):
        from semianalytic.penetration.batch import chebyshev_weights

        axes, Ws = [], []
        for f in names:
            lo, hi = float(np.min(fields[f])), float(np.max(fields[f]))
            if hi > lo:
                nodes, W = chebyshev_weights(fields[f], lo, hi, n_nodes)
            else:
                nodes, W = np.array([lo]), np.ones((n, 1))
            axes.append(nodes)
            Ws.append(W)
        mesh = np.meshgrid(*axes, indexing="ij")
        grid_R, grid_msg = _pressures(base, {f: m.ravel().tolist() for f, m in zip(names, mesh)}, diameter)
        if np.all(np.isfinite(grid_R)):
            grid_R = grid_R.reshape([len(a) for a in axes])
            R = Ws[0] @ grid_R if len(names) == 1 else np.einsum("si,sj,ij->s", Ws[0], Ws[1], grid_R)
            probe = np.unique([0, n // 2, n - 1])
            exact, _ = _pressures(base, {f: np.asarray(fields[f])[probe].tolist() for f in names}, diameter)
            if np.all(np.abs(R[probe] - exact) <= 1e-11 * np.abs(exact)):
                return R, np.full(n, "", dtype=object)
    return _pressures(base, {f: np.asarray(v, float).tolist() for f, v in fields.items()}, diameter)


@dataclass(frozen=True)
class CavityKernel:
    """Part II: the brittle cavity-expansion solution of the case's ``[material]``."""

    name: str = "cavity"
    fast_keys: frozenset = frozenset()
    seconds_per_case: float = 2e-3  # one Part II solve, plus validating its case (engine choice)
    columns: tuple[str, ...] = (
        "cavity_pressure_Pa", "sigma_star_Pa", "theta_star", "theta_k", "a_over_b", "c_over_b",
    )

    def complete_spec(self, case: Case, spec: SweepSpec) -> SweepSpec:
        case.require("material")
        return spec

    def check_fast(self, key, values):  # no fast keys
        pass

    def is_array_key(self, key: str) -> bool:
        return False

    def accepts_arrays(self, case: Case, keys) -> bool:
        return False

    def affects_resource(self, key: str) -> bool:
        return False

    def resource_key(self, case: Case):
        return None

    def prepare(self, case: Case):
        return None

    def evaluate(self, case: Case, resource, fast) -> dict[str, np.ndarray]:
        from semianalytic.cavity import BrittleMaterial, solve_cavity
        from semianalytic.errors import model_field
        from semianalytic.sections.cavity import MODEL_FIELDS

        sec = case.require("material")
        try:
            with model_field(MODEL_FIELDS):
                r = solve_cavity(BrittleMaterial.from_section(sec), sec.solver, warn=False)
        except ModelError as exc:  # a sample the model cannot compute: an invalid row (the engine's InputError)
            raise InputError(exc.field, exc.message) from None
        return {
            "cavity_pressure_Pa": np.array([r.cavity_pressure]),
            "sigma_star_Pa": np.array([r.sigma_star]),
            "theta_star": np.array([r.theta_star]),
            "theta_k": np.array([r.theta_k]),
            "a_over_b": np.array([r.a_over_b]),
            "c_over_b": np.array([r.c_over_b]),
        }


KERNELS = ("penetration", "cavity")
Kernel = PenetrationKernel | CavityKernel


def select_kernel(case: Case, analysis: str | None = None, cache_dir=None, full: bool = False) -> Kernel:
    """The kernel named by ``analysis``, or the one the case's sections call for."""
    if analysis is None:
        if case.projectile is not None:
            analysis = "penetration"
        elif case.section("material") is not None:
            analysis = "cavity"
        else:
            raise InputError("case", "nothing to sweep: the case has neither a [projectile] nor a [material] section")
    if analysis == "penetration":
        return PenetrationKernel(cache_dir=None if cache_dir is None else str(cache_dir), full=full)
    if analysis == "cavity":
        return CavityKernel()
    raise InputError("--analysis", f"must be one of {', '.join(KERNELS)}; got {analysis!r}")
