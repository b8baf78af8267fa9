"""What ``perforate`` prints for one case: per striking velocity ``perforated``,
``residual_velocity_m_s``, ``depth_m``, ``exit_time_s``; the ballistic limit by bisection with
its error estimate; the Lambert-Jonas fit of the computed curve; Part IV's V_cr formulas; with
``[perforation] data``, the measured residual velocities beside the predictions.

The models are :mod:`semianalytic.perforation.model` (eq. (11) through the layers) and
:mod:`semianalytic.ballistic_limit.shots` (Part IV); the plate coefficients come from ONE
function, :func:`plate_coefficients`.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from semianalytic.errors import InputError, ModelValidityWarning

__all__ = ["PerforationSetup", "plate_coefficients", "perforation_setup", "evaluate_case", "part4_limits",
           "load_perforation_data", "shot_table_validation", "JSON_KEYS"]

JSON_KEYS = ("striking_velocity_m_s", "perforated", "residual_velocity_m_s", "depth_m", "exit_time_s",
             "ballistic_limit_m_s", "ballistic_limit_error_m_s", "ballistic_limit_bound", "failure_mode",
             "lambert_jonas", "part4_v_cr_m_s")

PART4_NAMES = {"V_R1_m_s": "eq5_R1", "V_R2_m_s": "eq5_R2", "V_R3_m_s": "eq5_R3",
               "V_eq7_m_s": "eq7", "V_eq8_m_s": "eq8", "V_eq9_m_s": "eq9"}


def plate_coefficients(case, thickness: float, cache_dir=None, shift: str | None = None):
    """(coefficients, description, approximate) of the case's nose in a plate of ``thickness``:
    the one place that picks the table.  ``shift`` = "A", "B" or "C": that coefficient shifted by
    its error estimate (:class:`semianalytic.penetration.accuracy.ShiftedCoefficients`).

    The plate table of Part I with the back face (:func:`semianalytic.cache.cached_plate_table`,
    :mod:`semianalytic.coefficients.plate`: phi = 0 on x = H), cached per nose and thickness.
    With ``[perforation] coefficients = "half-space"`` (or a version lacking the plate module)
    the half-space table stands in through
    :class:`semianalytic.perforation.model.HalfSpaceDifference` (``approximate`` True)."""
    from semianalytic.sections.perforation import PerforationSection

    opts = case.section("perforation") or PerforationSection()
    try:
        from semianalytic.cache import cached_plate_table
        from semianalytic.geometry import nose_from_section  # noqa: F401
    except ImportError:
        return _half_space_stand_in(case, thickness, cache_dir, shift)
    if opts.coefficients == "half-space":
        return _half_space_stand_in(case, thickness, cache_dir, shift)
    cs = case.coefficients
    kwargs = dict(order=case.bem.order, tolerance=cs.tolerance, reading=cs.reading)
    if case.bem.refinement is not None:
        kwargs["refinement"] = case.bem.refinement
    import sys

    from semianalytic.coefficients.plate import ScaledPlateTable

    nose, H_key, scale = plate_table_request(case, float(thickness))
    table = cached_plate_table(nose, H_key, cache_dir, progress=sys.stderr.isatty(), **kwargs)
    if scale != 1.0:
        table = ScaledPlateTable(table, scale)
    desc = (f"plate BEM table (phi = 0 on the back face; order {case.bem.order}, {len(table.depth)} knots, tolerance "
            f"{cs.tolerance:g}, 0 <= P <= H + L_h; B reading '{cs.reading}')")
    if shift is not None:
        from semianalytic.penetration.accuracy import ShiftedCoefficients

        table = ShiftedCoefficients(table, shift)
    return table, desc, False


def plate_table_request(case, thickness: float):
    """(nose, H, scale) of the cached plate table that serves the case's nose in a plate of
    ``thickness``: for the ogive, sphere, cone and flat noses (shapes fixed by the diameter and
    dimensionless parameters) the nose of unit diameter in a plate of H/d, scaled back by d
    (:class:`semianalytic.coefficients.plate.ScaledPlateTable`: one table per thickness ratio serves
    every calibre); other noses as they are (scale 1)."""
    from semianalytic.geometry import cone_nose, flat_nose, nose_from_section, ogive_nose

    sec = case.require("projectile")
    d = float(sec.diameter)
    meplat = (getattr(sec, "meplat_diameter", None) or 0.0) / d
    tip = (getattr(sec, "tip_radius", None) or 0.0) / d
    if sec.nose == "ogive":
        return ogive_nose(1.0, sec.crh, meplat, tip), thickness / d, d
    if sec.nose == "sphere":
        return ogive_nose(1.0, 0.5), thickness / d, d
    if sec.nose == "cone":
        return cone_nose(1.0, sec.half_angle, meplat, tip), thickness / d, d
    if sec.nose == "flat":
        return flat_nose(1.0, (getattr(sec, "corner_radius", None) or 0.0) / d), thickness / d, d
    return nose_from_section(sec), thickness, 1.0


def _half_space_stand_in(case, thickness: float, cache_dir=None, shift: str | None = None):
    from semianalytic.cache import coefficients_for_case
    from semianalytic.perforation.model import HalfSpaceDifference

    table, desc, _ = coefficients_for_case(case, "bem", cache_dir=cache_dir)
    if shift is not None:
        from semianalytic.penetration.accuracy import ShiftedCoefficients

        table = ShiftedCoefficients(table, shift)
    return (HalfSpaceDifference(table, thickness),
            f"{desc}; APPROXIMATION: half-space table with the part of the nose past the back face removed "
            "(X(P) - X(P - H)); the back face's effect on A and B is ignored", True)


@dataclass(frozen=True, eq=False)
class PerforationSetup:
    """The model's inputs for one case (SI): the layered coefficients, the projectile's mass,
    length, density, diameter, the total target thickness and the notes for the output
    (``failure_mode`` per layer with its reason, ``thin_plate`` notes, the validity limit
    ``v_max`` [m/s] of the rigid-projectile model with its reason)."""

    coefficients: object
    mass: float
    length: float
    density: float
    diameter: float
    thickness: float
    layers: tuple
    description: str
    approximate: bool
    back_face: str
    failure: str
    failure_modes: tuple = ()
    notes: tuple = ()
    v_max: float = 3000.0
    v_max_reason: str = ""


BACK_FACE_DEFAULT = "sphere-to-cylinder"
"""The back face of ``back_face = "auto"``, chosen by transfer (reports/validation_perforation.md,
section "Back face by transfer": Part IV Table 3 with Y = HV/3 (Tabor) and nothing fitted)."""

MIN_THICKNESS_DIAMETERS = 1e-3
MAX_THICKNESS_DIAMETERS = 1e4
NO_STRENGTH_V_MAX = 3000.0


def _layer_inputs(case):
    """[(name, gap, thickness, density, resistance model)] of the case's target."""
    from semianalytic.penetration.resistance import resistance_from_case

    t = case.require("target")
    base = resistance_from_case(case)
    if t.layers:
        return [(ly.name or f"layer {k}", ly.gap or 0.0, ly.thickness, ly.density or t.density,
                 ly.resistance.build() if ly.resistance is not None else base) for k, ly in enumerate(t.layers)]
    if t.thickness is None:
        raise InputError("target.thickness", "missing: perforate needs a plate ('thickness', e.g. '20 mm') or [[target.layers]]")
    return [("plate", 0.0, t.thickness, t.density, base)]


# CPU seconds of eq. (11) through n layers, lower bounds measured on this project's machine (half-space
# stand-in, 0.1 mm layers of 6061 and the 3-CRH ogive: 100 layers 24 s, 30 layers 3.5 s, each including the
# error estimate's four integrations): the evaluation of the layered coefficients sums every layer at
# every depth of an integration whose depths grow with n, so the work grows like n^2
LAYER_PAIR_SECONDS = 1e-3
PLATE_TABLE_SECONDS = 3.0  # one plate BEM table, the cheapest measured (demo plate: 10 s CPU at tolerance 1e-5)


def check_layer_work(case, inputs, nose, cache_dir=None) -> float:
    """Refuse, before any work, a target whose estimated time exceeds the time budget
    (:func:`semianalytic.guards.check_work`, exit 2 naming ``target.layers`` or ``target.thickness``
    with the estimate and what to change): n^2 LAYER_PAIR_SECONDS for the integration through n
    layers plus PLATE_TABLE_SECONDS per plate table not in the cache.  Returns the estimate [s]."""
    from semianalytic.guards import check_work
    from semianalytic.sections.perforation import PerforationSection

    opts = case.section("perforation") or PerforationSection()
    n = len(inputs)
    seconds = LAYER_PAIR_SECONDS * n * n
    new_tables = 0
    if opts.coefficients == "plate":
        try:
            from semianalytic.cache import plate_table_key, table_dir

            cs = case.coefficients
            kw = dict(order=case.bem.order, tolerance=cs.tolerance)
            if case.bem.refinement is not None:
                kw["refinement"] = case.bem.refinement
            for H in {float(x[2]) for x in inputs}:
                knose, kH, _ = plate_table_request(case, H)
                if not (table_dir(cache_dir) / f"{plate_table_key(knose, kH, **kw)}.npz").is_file():
                    new_tables += 1
        except Exception:  # noqa: BLE001 - the estimate only; a key that cannot be formed counts every table
            new_tables = len({float(x[2]) for x in inputs})
    seconds += PLATE_TABLE_SECONDS * new_tables
    field = "target.layers" if case.target.layers else "target.thickness"
    check_work(field, f"perforation of {n} layer(s) ({new_tables} new plate table(s))", seconds=seconds,
               hint="use fewer, thicker layers (layers of one material and no gap can be one plate), or "
                    "[perforation] coefficients = 'half-space' (no plate tables), or raise the time budget")
    return seconds


def validity_limit(psec, layers) -> tuple[float, str]:
    """(v_max [m/s], reason): the largest striking velocity at which the rigid-projectile model holds:
    Tate's (1967) criterion with the nose as a constrained indenter, (1/2) rho_t V^2 + R_t = 3 Y_p
    (:func:`semianalytic.penetration.regime.tate_erosion_velocity`, C = Tabor's 3), the lowest over the
    layers; without a projectile yield stress, 3 km/s (the top of the rigid-projectile data of
    Piekutowski et al. 1999)."""
    from semianalytic.penetration.regime import TABOR_CONSTRAINT, tate_erosion_velocity

    Y_p = getattr(psec, "yield_stress", None)
    if Y_p is None:
        return NO_STRENGTH_V_MAX, "no projectile yield stress given: 3 km/s, the top of the rigid-projectile data"
    v = min(float(tate_erosion_velocity(Y_p, ly.resistance, ly.density, TABOR_CONSTRAINT)) for ly in layers)
    return max(v, 1.0), (f"rigid projectile while (1/2) rho_t V^2 + R_t < 3 Y_p (Tate 1967 with Tabor's constraint), "
                         f"Y_p = {Y_p / 1e6:.4g} MPa")


def perforation_setup(case, cache_dir=None, shift: str | None = None) -> PerforationSetup:
    """Build :class:`~semianalytic.perforation.model.LayeredCoefficients` from the case: per layer the
    failure mode (:func:`semianalytic.perforation.thin_plate.failure_mode` with ``failure = "auto"``),
    the back face (``back_face``; "auto" = :data:`BACK_FACE_DEFAULT`) and, where the plate is thinner
    than the spherical plastic zone (:func:`~semianalytic.perforation.thin_plate.spherical_zone_fits`),
    the cylindrical cavity expansion of the thin plate instead of Part I's spherical resistance."""
    from semianalytic.geometry import projectile_from_section
    from semianalytic.perforation import thin_plate as tp
    from semianalytic.perforation.model import LayeredCoefficients, PlateLayer
    from semianalytic.sections.perforation import PerforationSection

    psec = case.require("projectile")
    opts = case.section("perforation") or PerforationSection()
    proj = projectile_from_section(psec)
    d = float(psec.diameter)
    a = 0.5 * d
    back = BACK_FACE_DEFAULT if opts.back_face == "auto" else opts.back_face
    layers, descs, approx, modes, notes = [], [], False, [], []
    front = 0.0
    inputs = _layer_inputs(case)
    tables: dict = {}
    check_layer_work(case, inputs, proj.nose, cache_dir)
    for k, (name, gap, H, rho, res) in enumerate(inputs):  # noqa: B007
        field = f"target.layers.{k}.thickness" if case.target.layers else "target.thickness"
        if not (MIN_THICKNESS_DIAMETERS * d <= H <= MAX_THICKNESS_DIAMETERS * d):
            raise InputError(field, f"{H * 1e3:.6g} mm is outside every model's validity ({MIN_THICKNESS_DIAMETERS:g} to "
                             f"{MAX_THICKNESS_DIAMETERS:g} projectile diameters, {MIN_THICKNESS_DIAMETERS * d * 1e3:.3g} to "
                             f"{MAX_THICKNESS_DIAMETERS * d:.3g} m): a foil (membrane) or a thickness no rigid rod model covers")
        front += gap
        R = float(res.pressure(d))
        where = f"target.layers.{k}.resistance" if case.target.layers else "target.resistance"
        if not R > 0:
            raise InputError(where, f"the resistance must be positive; got {R:g} Pa")
        Y, E = getattr(res, "yield_stress", None), getattr(res, "youngs_modulus", None)
        has_YE = Y is not None and E is not None and not np.ndim(Y) and not np.ndim(E) and (2 * E / (3 * Y)) > 1
        if opts.failure == "auto":
            mode, why = tp.failure_mode(proj.nose, float(H))
        elif opts.failure == "plug":
            mode, why = "shear plugging", "failure = 'plug' (case)"
        else:
            mode, why = "ductile hole enlargement", "failure = 'hole-growth' (case)"
        ratio, tau, floor = None, None, None
        layer_back = back
        if mode == "shear plugging":
            tau = opts.shear_strength
            if tau is None:
                if Y is None:
                    raise InputError("perforation.shear_strength", "missing: the plug criterion needs the target's shear "
                                     "strength (e.g. '230 MPa') or a resistance model with a yield stress")
                tau = tp.von_mises_shear_strength(Y)
            layer_back = "plug"
        elif back in ("finite-sphere", "cylindrical", "sphere-to-cylinder") and not has_YE:
            if opts.back_face != "auto":
                raise InputError("perforation.back_face", f"'{back}' needs the yield stress and Young's modulus of "
                                 f"{where} (models elastic-plastic, hardening, part4); use back_face = 'constant'")
            layer_back = "constant"
            notes.append(f"layer {k}: no Y and E in {where}: back face 'constant' (R_t to the exit)")
        if layer_back != "constant" and layer_back != "plug":
            thin = not tp.spherical_zone_fits(float(H), a, float(Y), float(E))
            sigma_s = tp.cylindrical_cavity_stress(float(Y), float(E))
            if mode == "petalling":
                R = 0.5 * float(Y)  # Thomson (1955): W = (pi/2) a^2 H Y = int (Y/2) C dP
                layer_back = "petalling (Thomson 1955)"
                notes.append(f"layer {k}: thin-plate model: petalling, Thomson (1955) work (pi/2) a^2 H Y (R = Y/2 on the "
                             "nose inside the plate)")
            elif thin or layer_back == "cylindrical":
                R = sigma_s
                if thin and layer_back != "cylindrical":
                    c = tp.spherical_plastic_radius(a, float(Y), float(E))
                    notes.append(f"layer {k}: thin-plate model: H = {H * 1e3:.4g} mm < c = (2E/3Y)^(1/3) d/2 = {c * 1e3:.4g} mm "
                                 "(no spherical plastic zone fits): cylindrical cavity expansion, sigma_s = (Y/sqrt 3)"
                                 "[1 + ln(E/(sqrt 3 Y))] (Forrestal, Rosenberg, Luk & Bless 1987) to the exit")
                layer_back = "cylindrical"
            else:
                ratio = tp.spherical_plastic_radius(1.0, float(Y), float(E))  # c / a
                if layer_back == "sphere-to-cylinder":
                    floor = sigma_s
        modes.append({"layer": k, "failure_mode": mode, "reason": why, "back_face": layer_back})
        if float(H) not in tables:  # one table per distinct thickness (layers of one thickness share it)
            tables[float(H)] = plate_coefficients(case, H, cache_dir, shift)
        coef, desc, ap = tables[float(H)]
        approx |= ap
        descs.append(desc)
        layers.append(PlateLayer(front, float(H), float(rho), R, coef, ratio, tau, floor))
        front += H
    lc = LayeredCoefficients(layers, proj.nose.length, d)
    rho_p = psec.density if psec.density is not None else proj.mass / proj.volume()
    v_max, v_why = validity_limit(psec, layers)
    failure = "plug" if modes[0]["failure_mode"] == "shear plugging" else "hole-growth"
    return PerforationSetup(lc, float(proj.mass), float(proj.length), float(rho_p), d, front, tuple(layers),
                            descs[0], approx, modes[0]["back_face"] if len(modes) == 1 else back, failure,
                            tuple(modes), tuple(notes), v_max, v_why)


def part4_limits(case, setup: PerforationSetup) -> dict:
    """{name: V_cr [m/s]} of every Part IV formula the case's inputs allow (eq. (5) with R(1),
    R(2), R(3); eqs. (7)-(9)), through :mod:`semianalytic.ballistic_limit.shots`."""
    from semianalytic.ballistic_limit.shots import Layer, Shot, empirical_limits, theoretical_limits
    from semianalytic.penetration.resistance import resistance_from_case
    from semianalytic.sections.perforation import PerforationSection

    opts = case.section("perforation") or PerforationSection()
    res = resistance_from_case(case)
    Y = opts.yield_stress if opts.yield_stress is not None else getattr(res, "yield_stress", None)
    E = opts.youngs_modulus if opts.youngs_modulus is not None else getattr(res, "youngs_modulus", None)
    layers = ()
    if case.target.layers:
        layers = tuple(Layer(f"layer {k}", ly.density, ly.thickness, opts.target_hardness or float("nan"),
                             opts.target_delta_h or float("nan")) for k, ly in enumerate(setup.layers))
    shot = Shot(
        name=case.title, projectile_length=setup.length, projectile_density=setup.density,
        target_density=None if layers else float(case.target.density), thickness=None if layers else setup.thickness,
        target_hardness=opts.target_hardness, target_delta_H=opts.target_delta_h,
        yield_stress=None if Y is None or np.ndim(Y) else float(Y),
        youngs_modulus=None if E is None or Y is None or np.ndim(E) else float(E),
        projectile_diameter=setup.diameter, projectile_mass=setup.mass,
        projectile_hardness=opts.projectile_hardness, projectile_delta_H=opts.projectile_delta_h, layers=layers,
    )
    out = {}
    for key, val in {**theoretical_limits(shot), **empirical_limits(shot)}.items():
        if key in PART4_NAMES and val is not None and math.isfinite(val):
            out[PART4_NAMES[key]] = float(val)
    return out


def load_perforation_data(case) -> list[dict] | None:
    """Rows {Vs_m_s, Vr_m_s, ...} of the case's ``[perforation] data`` CSV ('#' lines are the
    source notes), or None."""
    import csv

    opts = case.section("perforation")
    if opts is None or opts.data is None:
        return None
    base = case.path.parent if case.path is not None else Path.cwd()
    path = base / opts.data
    if not path.is_file():
        raise InputError("perforation.data", f"file {opts.data!r} not found next to the case file")
    lines = [ln for ln in path.read_text(encoding="utf-8").splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    rows = []
    for k, r in enumerate(csv.DictReader(lines)):
        try:
            row = dict(r)
            row["Vs_m_s"], row["Vr_m_s"] = float(r["Vs_m_s"]), float(r["Vr_m_s"])
        except (KeyError, TypeError, ValueError):
            raise InputError("perforation.data", f"{opts.data}: row {k + 1} needs numbers in columns Vs_m_s and Vr_m_s") from None
        rows.append(row)
    if not rows:
        raise InputError("perforation.data", f"{opts.data}: no data rows")
    return rows


def _reach_warning(setup: PerforationSetup, curve) -> None:
    """A plate thicker than the rod can ever reach: say so (the computation goes on).  'Ever'
    = beyond both the depth at the case's largest velocity and the hydrodynamic limit
    L sqrt(rho_p / rho_t) of an eroding rod (Birkhoff, MacDougall, Pugh & Taylor 1948)."""
    if curve.perforated.any():
        return
    rho_t = setup.layers[0].density
    hydro = setup.length * math.sqrt(setup.density / rho_t)
    reach = max(float(np.nanmax(curve.depth)), hydro)
    if setup.thickness > reach:
        warnings.warn(
            f"target.thickness: {setup.thickness * 1e3:.4g} mm is more than this rod can ever reach with nothing behind "
            f"(largest depth {np.nanmax(curve.depth) * 1e3:.4g} mm at {curve.velocities.max():.0f} m/s; hydrodynamic "
            f"limit L sqrt(rho_p/rho_t) = {hydro * 1e3:.4g} mm); computed anyway",
            ModelValidityWarning, stacklevel=2)


def evaluate_case(case, *, cache_dir=None, velocities=None, ballistic: bool = True, error_estimate: bool = True) -> dict:
    """The ``perforate`` JSON of one case (keys: :data:`JSON_KEYS` and the notes)."""
    from semianalytic.perforation.model import ballistic_limit_search, lambert_jonas_fit, perforation_curve
    from semianalytic.sections.perforation import PerforationSection

    opts = case.section("perforation") or PerforationSection()
    setup = perforation_setup(case, cache_dir)
    U = np.asarray(case.require("impact").striking_velocities if velocities is None else velocities, float)
    curve = perforation_curve(setup.coefficients, setup.mass, U)
    _reach_warning(setup, curve)
    out: dict = {
        "case": str(case.path.name) if case.path else case.title, "title": case.title,
        "thickness_m": setup.thickness,
        "layers": [{"front_m": ly.front, "thickness_m": ly.thickness, "density_kg_m3": ly.density,
                    "resistance_Pa": ly.resistance} for ly in setup.layers],
        "mass_kg": setup.mass, "exit_depth_m": curve.exit_depth,
        "back_face": setup.back_face, "failure": setup.failure,
        "failure_mode": setup.failure_modes[0]["failure_mode"] if len(setup.failure_modes) == 1 else
        [m["failure_mode"] for m in setup.failure_modes],
        "failure_modes": list(setup.failure_modes), "model_notes": list(setup.notes),
        "validity_limit_m_s": setup.v_max, "validity_limit_reason": setup.v_max_reason,
        "coefficients": setup.description, "coefficients_approximate": setup.approximate,
        "striking_velocity_m_s": U.tolist(),
        "perforated": [bool(v) for v in curve.perforated],
        "residual_velocity_m_s": curve.residual_velocity.tolist(),
        "depth_m": [None if not math.isfinite(v) else float(v) for v in curve.depth],
        "exit_time_s": [None if not math.isfinite(v) else float(v) for v in curve.exit_time],
        "plug_layer": [None if k < 0 else int(k) for k in curve.plug],
        "energy_bounded": [bool(v) for v in curve.energy_bounded],
        "resistance_work_J": curve.resistance_work,
    }
    over = U > setup.v_max
    if np.any(over):
        warnings.warn(f"impact.striking_velocities: {int(over.sum())} above the model's validity limit {setup.v_max:.6g} m/s "
                      f"({setup.v_max_reason}); computed anyway", ModelValidityWarning, stacklevel=2)
    out["ballistic_limit_m_s"] = None
    out["ballistic_limit_error_m_s"] = None
    out["ballistic_limit_bound"] = None
    if ballistic:
        shifted = []
        if error_estimate:
            for w in ("A", "B", "C"):
                shifted.append(perforation_setup(case, cache_dir, shift=w).coefficients)
        bl = ballistic_limit_search(setup.coefficients, setup.mass, setup.v_max, tolerance=opts.tolerance, shifted=shifted,
                                    v_max_reason=setup.v_max_reason)
        out["ballistic_limit_m_s"] = bl.value
        out["ballistic_limit_error_m_s"] = bl.error if bl.bound == "exact" else None
        out["ballistic_limit_bound"] = bl.bound
        out["ballistic_limit_reason"] = bl.reason
        out["ballistic_limit_converged"] = bl.converged
        out["ballistic_limit_estimate"] = {"bracket_m_s": bl.bracket, "integration_m_s": bl.integration,
                                           "coefficients_m_s": bl.coefficients, "tolerance_m_s": bl.tolerance,
                                           "iterations": bl.iterations}
        if bl.bound == "lower":
            warnings.warn(f"ballistic limit: above {bl.value:.6g} m/s, the model's validity limit ({setup.v_max_reason}); "
                          "reported as a lower bound", ModelValidityWarning, stacklevel=2)
    V_ref = out["ballistic_limit_m_s"] or curve.ballistic_limit_estimate or float(U.max())
    grid = np.linspace(0.5 * V_ref, max(float(U.max()), 2.0 * V_ref), 49)  # the figure's curve: 50 velocities
    grid = np.sort(np.append(grid, V_ref * (1 + 1e-9)))  # with the limit itself (V_r rises like a square root)
    dense = perforation_curve(setup.coefficients, setup.mass, grid)
    out["curve"] = {"striking_velocity_m_s": grid.tolist(), "residual_velocity_m_s": dense.residual_velocity.tolist()}
    lj = lambert_jonas_fit(U, curve.residual_velocity, out["ballistic_limit_m_s"])
    out["lambert_jonas"] = None if lj is None else {k: lj[k] for k in ("a", "p", "V_bl_m_s")}
    out["part4_v_cr_m_s"] = part4_limits(case, setup)
    data = load_perforation_data(case)
    if data is not None:
        out["data"] = _compare_data(setup, data, opts)
    shots = shot_table_validation(case, cache_dir)
    if shots is not None:
        out["shot_table"] = shots
        out["back_face_study"] = back_face_study(case, cache_dir)
    return out


def thickness_sweep(case, thicknesses, velocities, cache_dir=None) -> list[dict]:
    """Per thickness [m]: failure mode, V_bl (or its lower bound) and max(V_r - V_s) over ``velocities``
    of the case's projectile with the half-space stand-in coefficients (the report's sweep)."""
    import copy

    from semianalytic.case import parse_case
    from semianalytic.perforation.model import ballistic_limit_search, perforation_curve

    rows = []
    for H in thicknesses:
        raw = copy.deepcopy(dict(case.raw))
        raw.pop("ballistic_limit", None)
        raw["target"] = dict(raw["target"], thickness=f"{float(H)!r} m")
        raw["target"].pop("layers", None)
        raw["perforation"] = dict(raw.get("perforation", {}), coefficients="half-space")
        setup = perforation_setup(parse_case(raw, case.path), cache_dir)
        cur = perforation_curve(setup.coefficients, setup.mass, velocities)
        bl = ballistic_limit_search(setup.coefficients, setup.mass, setup.v_max)
        rows.append({"thickness_mm": float(H) * 1e3, "failure_mode": setup.failure_modes[0]["failure_mode"],
                     "V_bl": bl.value, "bound": bl.bound,
                     "max_excess": float(np.max(cur.residual_velocity - cur.velocities))})
    return rows


def _compare_data(setup: PerforationSetup, rows: list[dict], opts) -> dict:
    """Measured against predicted residual velocities; the Lambert-Jonas fit of the data."""
    from semianalytic.perforation.model import lambert_jonas, lambert_jonas_fit, perforation_curve

    Vs = np.array([r["Vs_m_s"] for r in rows])
    Vr = np.array([r["Vr_m_s"] for r in rows])
    pred = perforation_curve(setup.coefficients, setup.mass, Vs).residual_velocity
    fit = lambert_jonas_fit(Vs, Vr)
    return {
        "source": opts.data_source, "file": opts.data,
        "striking_velocity_m_s": Vs.tolist(), "measured_residual_velocity_m_s": Vr.tolist(),
        "predicted_residual_velocity_m_s": pred.tolist(),
        "mean_abs_error_residual_m_s": float(np.mean(np.abs(pred - Vr))),
        "lambert_jonas_data": fit,
        "mean_abs_error_residual_lambert_jonas_data_m_s": None if fit is None else float(
            np.mean(np.abs(lambert_jonas(Vs, fit["a"], fit["p"], fit["V_bl_m_s"]) - Vr))),
    }


def _fitting_ogive(proj: dict, shot) -> dict:
    """The ASSUMED ogive of a Table 3 core, shortened where the case's CRH would be longer than the
    core: psi = min(psi_case, 1/4 + (0.9 L/d)^2), so that L_h = d sqrt(psi - 1/4) <= 0.9 L (this
    project's own assumption: the table gives no nose; the three short cores of 12-12.5 mm)."""
    if proj.get("nose") != "ogive" or shot.projectile_length is None:
        return {}
    psi = float(proj.get("crh", 3.0))
    fit = 0.25 + (0.9 * shot.projectile_length / shot.projectile_diameter) ** 2
    return {"crh": min(psi, fit)} if fit < psi else {}


def shot_table_validation(case, cache_dir=None) -> dict | None:
    """Measured ballistic limits of a Part IV shot table (the case's ``[ballistic_limit] table``,
    e.g. Table 3) against eq. (11) through the plate, beside Part IV's formulas.

    Per single-plate shot with an exactly measured V_cr: the case's nose shape (the tables give no
    nose: an ASSUMPTION stated in the output) scaled to the shot's diameter, its length and mass,
    the shot's target density and thickness, the resistance R(1) = HM delta_H of Part IV
    (constant up to the exit: the tables give no Y and E for the finite-sphere back face), the
    half-space stand-in coefficients (one table per diameter; ``coefficients = "half-space"``).
    Part IV's values come from :func:`semianalytic.commands.ballistic_limit.evaluate.evaluate_case` (its
    constants C1-C3 were fitted on Table 3 itself: in-sample)."""
    import copy

    from semianalytic.ballistic_limit.tables import load_shots
    from semianalytic.ballistic_limit.theory import resistance_R1
    from semianalytic.case import parse_case
    from semianalytic.commands.ballistic_limit.evaluate import evaluate_case as part4_evaluate
    from semianalytic.perforation.model import ballistic_limit_search

    sec = case.section("ballistic_limit")
    if sec is None or sec.table is None:
        return None
    base = case.path.parent if case.path is not None else Path.cwd()
    shots = load_shots((base / sec.table).resolve())
    part4 = part4_evaluate(case)["rows"][: len(shots)]
    rows = []
    for shot, p4 in zip(shots, part4):
        if (shot.is_composite or shot.measured is None or shot.measured_qualifier or shot.projectile_mass is None
                or shot.projectile_diameter is None or shot.HVdelta_t is None):
            continue
        raw = copy.deepcopy(dict(case.raw))
        raw.pop("ballistic_limit", None)
        proj = raw["projectile"]
        for key in ("shank_length", "length", "density", "mass"):
            proj.pop(key, None)
        proj.update(diameter=f"{shot.projectile_diameter!r} m", length=f"{shot.projectile_length!r} m",
                    mass=f"{shot.projectile_mass!r} kg", **_fitting_ogive(proj, shot))
        R1 = float(resistance_R1(shot.target_hardness, shot.target_delta_H, sec.hardness))
        raw["target"] = {"density": f"{shot.target_density!r} kg/m^3", "thickness": f"{shot.thickness!r} m",
                         "resistance": {"model": "constant", "value": f"{R1!r} Pa"}}
        raw["perforation"] = {"coefficients": "half-space", "back_face": "constant", "failure": "hole-growth"}
        try:
            setup = perforation_setup(parse_case(raw, case.path), cache_dir)
        except InputError as exc:
            rows.append({"name": shot.name, "skipped": exc.message})
            continue
        bl = ballistic_limit_search(setup.coefficients, setup.mass, 5000.0, tolerance=0.05)
        row = {"name": shot.name, "measured_V_m_s": shot.measured, "model_V_m_s": bl.value, "R1_Pa": R1,
               "assumed_crh": float(proj.get("crh", float("nan")))}
        row.update({PART4_NAMES[k]: p4[k] for k in PART4_NAMES if p4.get(k) is not None})
        rows.append(row)
    used = [r for r in rows if "model_V_m_s" in r]
    crh = float(case.raw.get("projectile", {}).get("crh", float("nan")))
    own = [r for r in used if not r.get("assumed_crh", crh) < crh]  # the case's nose (not shortened)

    def table_stats(subset):
        out = {}
        for n in ["model_V_m_s", *PART4_NAMES.values()]:
            errs = [abs(r[n] - r["measured_V_m_s"]) for r in subset if r.get(n) is not None]
            if errs:
                out[n] = {"n": len(errs), "mean_abs_error_m_s": float(np.mean(errs)),
                          "mean_abs_relative_error": float(np.mean([abs(r[n] / r["measured_V_m_s"] - 1) for r in subset
                                                                    if r.get(n) is not None]))}
        return out

    return {"table": sec.table, "nose": case.projectile.nose, "rows": rows, "statistics": table_stats(used),
            "statistics_case_nose": table_stats(own)}


TABLE1_E = {"Al-alloys": (71e9, 0.33), "Steels": (210e9, 0.29), "Ti-alloy": (110e9, 0.32)}
"""E and nu of each target class as Part IV, Table 1 assumes them (cases/part4_table1.csv)."""

STUDY_BACK_FACES = ("constant-R1", "constant", "finite-sphere", "cylindrical", "sphere-to-cylinder")
STUDY_CLOSED_FORMS = ("recht-ipson", "hole (quasi-static)")  # thin_plate closed forms beside them


def back_face_study(case, cache_dir=None) -> dict | None:
    """The back face chosen by transfer: V_bl of every single-plate shot of the case's
    ``[ballistic_limit] table`` (Part IV, Table 3) by eq. (11) through the plate with each back face
    of :data:`STUDY_BACK_FACES`, nothing fitted on the table: Y = HV/3 (Tabor 1951, the constraint
    factor 3 of a hardness indent), E and nu of Part IV Table 1's class (:data:`TABLE1_E`),
    R_t = Part I eq. (16) from them ("constant-R1": Part IV's R(1) = HM delta_H instead, the
    resistance of eq. (5)), the case's nose scaled to each core, half-space stand-in coefficients.
    Returns rows and, per back face, the mean |relative error| and the mean signed error per class."""
    import copy

    from semianalytic.ballistic_limit.tables import load_rows, shot_from_row
    from semianalytic.ballistic_limit.theory import resistance_R1
    from semianalytic.case import parse_case
    from semianalytic.perforation.model import ballistic_limit_search

    sec = case.section("ballistic_limit")
    if sec is None or sec.table is None:
        return None
    base = case.path.parent if case.path is not None else Path.cwd()
    entries = load_rows((base / sec.table).resolve(), lambda c, row: (c.text("id"), c.text("material_class"), shot_from_row(c)),
                        require="L_p_mm", what="a shot table")
    rows = []
    for sid, cls, shot in entries:
        if (shot.is_composite or shot.measured is None or shot.measured_qualifier or shot.projectile_mass is None
                or shot.projectile_diameter is None or shot.HVdelta_t is None or cls not in TABLE1_E):
            continue
        E, nu = TABLE1_E[cls]
        Y = shot.target_hardness / 3.0
        row = {"name": sid, "class": cls, "measured_V_m_s": shot.measured, "Y_Pa": Y, "E_Pa": E,
               "nose_shortened": bool(_fitting_ogive(dict(case.raw["projectile"]), shot))}
        from semianalytic.perforation import thin_plate as tp

        d, H, m = shot.projectile_diameter, shot.thickness, shot.projectile_mass
        row["recht-ipson"] = tp.plugging_limit(m, d, H, tp.von_mises_shear_strength(Y), shot.target_density)
        row["hole (quasi-static)"] = tp.hole_enlargement_limit(m, 0.5 * d, H, tp.cylindrical_cavity_stress(Y, E))
        for bf in STUDY_BACK_FACES:
            raw = copy.deepcopy(dict(case.raw))
            raw.pop("ballistic_limit", None)
            proj = raw["projectile"]
            for key in ("shank_length", "length", "density", "mass"):
                proj.pop(key, None)
            proj.update(diameter=f"{shot.projectile_diameter!r} m", length=f"{shot.projectile_length!r} m",
                        mass=f"{shot.projectile_mass!r} kg", **_fitting_ogive(proj, shot))
            if bf == "constant-R1":
                R1 = float(resistance_R1(shot.target_hardness, shot.target_delta_H, sec.hardness))
                res = {"model": "constant", "value": f"{R1!r} Pa"}
            else:
                res = {"model": "elastic-plastic", "yield_stress": f"{Y!r} Pa", "youngs_modulus": f"{E!r} Pa",
                       "poisson_ratio": nu}
            raw["target"] = {"density": f"{shot.target_density!r} kg/m^3", "thickness": f"{shot.thickness!r} m",
                             "resistance": res}
            raw["perforation"] = {"coefficients": "half-space", "back_face": "constant" if bf == "constant-R1" else bf,
                                  "failure": "hole-growth"}
            try:
                setup = perforation_setup(parse_case(raw, case.path), cache_dir)
            except InputError as exc:
                row[bf] = None
                row["skipped"] = exc.message
                continue
            row[bf] = ballistic_limit_search(setup.coefficients, setup.mass, 5000.0, tolerance=0.05).value
        rows.append(row)
    stats, stats_long = {}, {}
    for bf in STUDY_BACK_FACES + STUDY_CLOSED_FORMS:
        _face_stats(stats, bf, [r for r in rows if r.get(bf) is not None])
        _face_stats(stats_long, bf, [r for r in rows if r.get(bf) is not None and not r["nose_shortened"]])
    faces = [k for k in stats if k in STUDY_BACK_FACES]
    best = min(faces, key=lambda k: stats[k]["mean_abs_relative_error"]) if faces else None
    return {"table": sec.table, "nose": case.projectile.nose, "rows": rows, "statistics": stats,
            "statistics_case_nose": stats_long, "best": best}


def _face_stats(stats: dict, bf: str, used: list) -> None:
    if used:
        rel = [r[bf] / r["measured_V_m_s"] - 1.0 for r in used]
        per = {}
        for cls in sorted({r["class"] for r in used}):
            e = [r[bf] / r["measured_V_m_s"] - 1.0 for r in used if r["class"] == cls]
            per[cls] = float(np.mean(e))
        stats[bf] = {"n": len(used), "mean_abs_relative_error": float(np.mean(np.abs(rel))),
                     "mean_relative_error": float(np.mean(rel)), "class_mean_relative_error": per,
                     "worst_class_bias": max(abs(v) for v in per.values())}
