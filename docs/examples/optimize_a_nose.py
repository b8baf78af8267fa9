"""Optimise the ogive's calibre-radius-head for depth at fixed mass.

`api.optimize` is `python -m semianalytic optimize` with typed arguments: the design variable
`projectile.crh` between 1 and 5, the objective the depth at the case's striking velocity
(maximised: the optimiser minimises its negative), the mass held (the shank adapts). A coarse
grid and a few polls keep this example fast.
"""

from semianalytic import api

case = api.case_from_dict({
    "title": "Fig. 5 ogive into a constant resistance",
    "projectile": {"nose": "ogive", "crh": 3.0, "diameter": "7.11 mm", "shank_length": "59.3 mm",
                   "density": "7830 kg/m^3", "youngs_modulus": "210 GPa", "poisson_ratio": 0.29,
                   "yield_stress": "1.5 GPa"},
    "target": {"density": "2710 kg/m^3", "resistance": {"model": "constant", "value": "1.2 GPa"}},
    "impact": {"striking_velocities": ["600 m/s"]},
})
g = case.geometry
print(f"start: crh 3.0, nose length {g.nose_length_m * 1e3:.2f} mm, mass {g.mass_kg * 1e3:.2f} g, "
      f"L/D {g.length_over_diameter:.2f}, depth {api.depth(case, 600.0, model='rigid') * 1e3:.1f} mm")
result = api.optimize(case, ["projectile.crh=1:5"], "depth", constraint=["mass"], coarse=3, confirm=0, maxfev=6,
                      quiet=True)
optimum = result["optimum"]
print(f"optimum: crh {optimum['x'][0]:.3f}, depth {-optimum['objective'] * 1e3:.1f} mm (same mass)")
