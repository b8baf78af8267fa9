"""The depth models that ``calibrate`` knows, by name (a leaf module: the case layer reads the
names without importing the models and their scipy solvers)."""

MODELS = ("rigid", "quasi_rigid", "elastic", "elastic_exact_rod", "forrestal", "chen_li")
# Quasi-rigid start plus the exact rod's bounded vibration energy: the model the exact rod
# and the FEM support (the paper's W2 grows without bound, errata item 5).
PHYSICALLY_CONSISTENT = "elastic_exact_rod"
# The eroding rod (Alekseevskii-Tate, penetration.regime): calibrated on the eroded shots, its own
# parameters (R_t and Y_p of the rod equations), never mixed with the models above in one run.
ERODING = "eroding"
CALIBRATION_MODELS = (*MODELS, ERODING)
ERODING_KEYS = ("target.resistance.eroding_resistance", "projectile.dynamic_yield_stress")
