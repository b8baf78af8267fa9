"""The separation onset of eq. (15) (``penetrate``'s ``separation_onset_m``), evaluated on
arrays over all knots and velocities, against the definition checked knot by knot here: the
full-contact pressure of eq. (9), p_c = rho phi du/dt + q rho u^2/2 + R_t with du/dt of eq. (11),
is positive on every node with n_x > 0 at each knot before the onset and not at the onset."""

from __future__ import annotations

import numpy as np
import pytest

from semianalytic.cache import coefficients_for_case
from semianalytic.case import load_case
from semianalytic.coefficients.contact import pressure_terms
from semianalytic.penetration.curve import PenetrationSetup
from semianalytic.penetration.motion import depth_profile, separation_onset


def _separates(table, reading, k, u2, setup) -> bool:
    """eq. (9) at knot k with u^2 = u2, scalar arithmetic, node by node."""
    nodes = table.nodes[k]
    phi, q = pressure_terms(nodes, reading)
    P = float(table.depth[k])
    A, B, C = float(table.A(P)), float(table.B(P)), float(table.C(P))
    rho, R = setup.target_density, setup.resistance_pa
    du_dt = -(0.5 * rho * B * u2 + C * R) / (setup.mass + rho * A)  # eq. (11), full contact
    return any(rho * f * du_dt + g * rho * u2 / 2 + R <= 0 and nx > 1e-12 for f, g, nx in zip(phi, q, nodes["nx"]))


@pytest.mark.parametrize("reading", ["body", "bernoulli"])
def test_onset_is_the_first_knot_where_eq9_turns_negative(tmp_path, monkeypatch, reading):
    monkeypatch.setenv("SEMIANALYTIC_CACHE_DIR", str(tmp_path))
    case = load_case("cases/fig14_sphere_6061T651.toml")  # the sphere separates near its shoulder (Fig. 14)
    table = coefficients_for_case(case)[0].with_reading(reading)
    setup = PenetrationSetup.from_case(case, table, require_material=False)
    U = np.array([300.0, 900.0, 1500.0, 2500.0, 3500.0])  # velocities the table's knots did not choose
    prof = depth_profile(table, setup.mass, setup.target_density, setup.resistance_pa, float(U.max()))
    onsets = separation_onset(table, setup.mass, setup.target_density, setup.resistance_pa, prof, U)
    assert onsets[-1] is not None  # at 3.5 km/s the pressure turns negative somewhere
    for U0, onset in zip(U, onsets):
        P_f = float(prof.final_depth(U0))
        for k, P in enumerate(table.depth):
            if P >= P_f or (onset is not None and P > onset):
                break
            u2 = max(float(prof.speed2(U0, P)), 0.0)
            assert _separates(table, reading, k, u2, setup) == (P == onset), (U0, P, onset)
