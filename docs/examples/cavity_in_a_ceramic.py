"""Part II's three-zone cavity in a ceramic, and its validity notices as Python warnings.

The cavity pressure R_r (Part II, eq. (34)) of AD995 alumina; notices that the model is used
outside its stated validity come as `semianalytic.errors.ValidityWarning` (here collected and
printed; `warnings.simplefilter("ignore", ValidityWarning)` silences them).
"""

import warnings

from semianalytic import api
from semianalytic.errors import ValidityWarning

for name in ("cavity_ad995", "cavity_sic"):
    with warnings.catch_warnings(record=True) as notices:
        warnings.simplefilter("always", ValidityWarning)
        result = api.cavity(api.load_case(f"cases/{name}.toml"))
    print(f"{name}: cavity pressure R_r = {result['cavity_pressure_Pa'] / 1e9:.3f} GPa, "
          f"front stress sigma* = {result['sigma_star_Pa'] / 1e9:.3f} GPa")
    for w in notices:
        print(f"  validity: {w.message}")
