"""Depth of penetration from a case built as a dict.

The Fig. 5 ogive (d = 7.11 mm, psi = 3) into 6061-T651 aluminium, written as a Python dict
instead of a TOML file; the depth of the rigid projectile and the regime-aware depth at three
striking velocities.
"""

from semianalytic import api

case = api.case_from_dict({
    "title": "Fig. 5 ogive into 6061-T651 (from a dict)",
    "projectile": {"nose": "ogive", "crh": 3.0, "diameter": "7.11 mm", "shank_length": "59.3 mm",
                   "density": "7830 kg/m^3", "youngs_modulus": "210 GPa", "poisson_ratio": 0.29,
                   "yield_stress": "1.5 GPa"},
    "target": {"density": "2710 kg/m^3",
               "resistance": {"model": "elastic-plastic", "yield_stress": "400 MPa",
                              "youngs_modulus": "68.9 GPa", "poisson_ratio": 0.33}},
    "impact": {"striking_velocities": ["500 m/s", "800 m/s", "1.0 km/s"]},
})

result = api.penetrate(case)
print("U_s [m/s]   rigid [mm]   regime-aware [mm]   regime")
for U, rigid, d, regime in zip(result["striking_velocity_m_s"], result["depth_rigid_m"], result["depth_m"],
                               result["regime"]):
    print(f"{U:9.0f}   {rigid * 1e3:10.1f}   {d * 1e3:17.1f}   {regime}")
print(f"depth at 650 m/s, rigid projectile: {api.depth(case, 650.0, model='rigid') * 1e3:.1f} mm")
