"""Predicted against measured depths of the Piekutowski et al. (1999) shots.

The bundled VAR 4340 case has a `[data]` section: `penetrate` then predicts every rigid shot
and gives the relative error of each model, as the command's per-shot table does.
"""

from semianalytic import api

case = api.load_case("cases/piekutowski1999_var4340.toml")
result = api.penetrate(case)
print("shot        U_s [m/s]   measured [mm]   elastic, exact rod [mm]   error [%]")
for shot in result["validation"]["shots"]:
    predicted, measured = shot["elastic_exact_rod"], shot["measured_m"]
    print(f"{shot['shot']:<10} {shot['velocity_m_s']:10.0f}   {measured * 1e3:13.1f}   {predicted * 1e3:23.1f}   "
          f"{(predicted - measured) / measured * 100:+9.1f}")
for model, stats in result["validation"]["statistics"].items():
    print(f"{model:<18} mean |error| {stats['mean_abs'] * 100:.1f} % over {stats['n']} shots")
