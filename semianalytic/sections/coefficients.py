"""Command-line inputs of ``coefficients`` (case layer): the depths of ``--at`` and the
table's tolerance (``--tolerance`` / ``[coefficients] tolerance``)."""

from __future__ import annotations

import math
import re

from semianalytic.errors import InputError

__all__ = ["parse_depths", "parse_tolerance"]

_LH = re.compile(r"^\s*([-+0-9.eE]+)\s*Lh\s*$")


def parse_depths(text: str, nose_length: float, field: str = "--at") -> list[float]:
    """Depths [m] from a comma-separated list of lengths with units ("10 mm,59.0 mm") or of
    nose-length multiples with the suffix ``Lh`` ("0.5Lh,5Lh").  Each must be finite and > 0."""
    from semianalytic.units import PHYSICAL_BOUNDS, parse_quantity

    items = [t.strip() for t in str(text).split(",")]
    if not items or any(not t for t in items):
        raise InputError(field, f"expected a comma-separated list of depths, e.g. '10 mm,59.0 mm' or '0.5Lh,5Lh'; got {text!r}")
    out = []
    for item in items:
        m = _LH.match(item)
        if m:
            try:
                k = float(m.group(1))
            except ValueError:
                raise InputError(field, f"cannot read {item!r} as a multiple of the nose length, e.g. '0.5Lh'") from None
            if nose_length <= 0:
                raise InputError(field, "this nose has no length L_h (flat); give depths with units, e.g. '2 mm'")
            P = k * nose_length
            low, high, text = PHYSICAL_BOUNDS["length"]  # the same door as a length with units
            if math.isfinite(P) and P > 0 and not low <= P <= high:
                raise InputError(field, f"{item!r} is {P:g} m, outside the physical range of a length ({text})")
        else:
            P = parse_quantity(item, "length", field)
        if not (math.isfinite(P) and P > 0):
            raise InputError(field, f"depths must be positive; got {item!r}")
        out.append(P)
    return out


def parse_tolerance(value, field: str = "--tolerance") -> float:
    """A table tolerance: a number in (0, 0.1) (relative to each coefficient's largest magnitude)."""
    from semianalytic.coefficients.table import check_tolerance

    return check_tolerance(value, field)
