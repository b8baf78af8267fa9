"""Predictive 90 % intervals from a calibration's posterior.

`reports/calibration_piekutowski1999/posterior.json` was written by
`python -m semianalytic calibrate` (Bayesian calibration of the target's yield stress on the
VAR 4340 shots); here it predicts the depth at new striking velocities, with the 5 % and
95 % quantiles bounding the 90 % predictive interval.
"""

from semianalytic import api

case = api.load_case("cases/piekutowski1999_var4340.toml")
q = api.predict_with_posterior(case, "reports/calibration_piekutowski1999/posterior.json", [600.0, 900.0])
for model, quantiles in q["depth_quantiles_m"].items():
    cells = ", ".join(f"{m * 1e3:.0f} mm (90 % interval {lo * 1e3:.0f}-{hi * 1e3:.0f} mm)"
                      for m, lo, hi in zip(quantiles["0.5"], quantiles["0.05"], quantiles["0.95"]))
    print(f"{model:<18} at 600 and 900 m/s: {cells}")
