"""Perforation of a plate: residual velocity against striking velocity.

The Fig. 5 ogive through a 26.3 mm 6061-T651 plate with the constant resistance R_t of
Part I, eq. (16) up to the exit (`cases/perforation_ogive_6061T651_constant.toml`): one row per
striking velocity, as `python -m semianalytic perforate CASE --json` prints it, and the
ballistic limit by bisection on eq. (11) with its numerical error estimate.
"""

from semianalytic import api

case = api.load_case("cases/perforation_ogive_6061T651_constant.toml")
result = api.perforate(case, ["300 m/s", "400 m/s", "600 m/s", "900 m/s"])
frame = result.to_frame()[["striking_velocity_m_s", "perforated", "residual_velocity_m_s", "depth_m"]]
print(frame.to_string(index=False))
print(f"ballistic limit: {result['ballistic_limit_m_s']:.1f} +- {result['ballistic_limit_error_m_s']:.2f} m/s")
