"""A parameter sweep from Python, read back as a DataFrame.

The cavity pressure of AD995 alumina over its Poisson ratio (`python -m semianalytic sweep ...
--vary material.poisson_ratio=0.20:0.26:0.02`), run in this process; `to_frame()` reads the
results table, one row per case.
"""

import tempfile

from semianalytic import api

with tempfile.TemporaryDirectory() as tmp:
    result = api.sweep("cases/cavity_ad995.toml", f"{tmp}/sweep", ["material.poisson_ratio=0.20:0.26:0.02"], quiet=True)
    frame = result.to_frame()
print(f"{result['n_ok']} cases ok")
print(frame.drop(columns=[c for c in frame.columns if c in ("case_id", "status", "error", "message")]).round(4).to_string(index=False))
