"""Part III theoretical strength of nanocrystals against the paper's Table 4.

One row per study row (material and geometry) with the strengths in compression and tension.
"""

from semianalytic import api

frame = api.nanostrength(api.load_case("cases/part3_nanostrength.toml")).to_frame()
columns = [c for c in ("study", "material", "basis", "sigma1_compression_GPa", "sigma2_tension_GPa") if c in frame.columns]
print(frame[columns].head(12).round(1).to_string(index=False))
