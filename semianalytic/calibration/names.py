"""The depth models that ``calibrate`` knows, by name (a leaf module: the case layer reads the
names without importing the models and their scipy solvers)."""

MODELS = ("rigid", "quasi_rigid", "elastic", "elastic_exact_rod", "forrestal", "chen_li")
# Quasi-rigid start plus the exact rod's bounded vibration energy: the model the exact rod
# and the FEM support (the paper's W2 grows without bound, errata item 5).
PHYSICALLY_CONSISTENT = "elastic_exact_rod"
