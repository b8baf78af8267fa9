"""Every shot of a case's ``[ballistic_limit]`` section, evaluated (Part IV): the theoretical
V_cr of eq. (5) with R(1), R(2), R(3), the empirical V_cr of eqs. (7)-(9), the measured value
when given, and the critical areal density and thickness of Table 4 (eq. (9), P = rho_p L_p).

Used by the ``ballistic-limit`` command and by the ``run`` pipeline alike.
"""

from __future__ import annotations

__all__ = ["evaluate_case"]


def evaluate_case(case) -> dict:
    """All shots of a loaded case, evaluated; a JSON-ready dict."""
    from semianalytic.ballistic_limit.shots import critical_values, empirical_limits, theoretical_limits
    from semianalytic.ballistic_limit.tables import load_shots
    from semianalytic.errors import InputError

    section = case.require("ballistic_limit")
    shots = []
    if section.table is not None:
        from semianalytic.io import case_input_path

        path = case_input_path(case.path, section.table, "ballistic_limit.table")
        if not path.is_file():
            raise InputError("ballistic_limit.table", f"file {section.table!r} not found next to the case file")
        shots += load_shots(path)
    from semianalytic.sections.ballistic_limit import check_limits, check_shot

    n_table = len(shots)
    shots += [s.to_shot(section.projectile_density) for s in section.shots]
    rows = []
    for k, shot in enumerate(shots):
        field = "ballistic_limit.table" if k < n_table else f"ballistic_limit.shots.{k - n_table}"
        check_shot(shot, field, shot.name if k < n_table else "")
        row = {"name": shot.name}
        if shot.measured is not None:
            row["measured_V_m_s"] = shot.measured
            if shot.measured_qualifier:
                row["measured_qualifier"] = shot.measured_qualifier
        row.update(theoretical_limits(shot, section.hardness))
        row.update(empirical_limits(shot, section.constants, section.areal_mass))
        crit = [critical_values(shot, v, section.constants) for v in section.critical_velocities]
        if any(crit):
            row["critical"] = [c for c in crit if c]
        check_limits(row, field if k < n_table else f"{field}.{'layers' if shot.layers else 'thickness'}")
        rows.append(row)
    return {
        "case": case.title,
        "hardness_rule": section.hardness,
        "areal_mass_rule": section.areal_mass,
        "constants": section.constants.to_json(),
        "projectile_density_kg_m3": section.projectile_density,
        "rows": rows,
    }
