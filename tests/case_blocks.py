"""TOML blocks shared by the tests' inline cases (one place for the target most of them use)."""

# 6061-T651 aluminium, elastic-perfectly plastic (Part I, eq. (16)) with the paper's Y = 400 MPa
TARGET_6061_T651 = """[target]
density = "2710 kg/m^3"
[target.resistance]
model = "elastic-plastic"
yield_stress = "400 MPa"
youngs_modulus = "68.9 GPa"
poisson_ratio = 0.33
"""
