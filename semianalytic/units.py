"""Physical quantities at the edges: unit strings in, SI floats out.

Case files write quantities as strings with units (``"7.11 mm"``, ``"400 MPa"``,
``"1.0 km/s"``).  They are parsed with pint, checked for dimension and converted to SI.
Inside the code every quantity is a plain float in SI units.

The pydantic types at the bottom (``Length``, ``Pressure``, ...) are what case-file section
models use; a bad value is reported with the field name, the value and what was expected.
"""

from __future__ import annotations

import functools
import math
from typing import Annotated, Any

from pydantic import BeforeValidator

# kind -> (pint dimensionality, SI unit, example for messages)
KINDS: dict[str, tuple[str, str, str]] = {
    "length": ("[length]", "m", "7.11 mm"),
    "area": ("[length]**2", "m^2", "1 cm^2"),
    "volume": ("[length]**3", "m^3", "1 cm^3"),
    "mass": ("[mass]", "kg", "20.9 g"),
    "time": ("[time]", "s", "10 us"),
    "velocity": ("[length]/[time]", "m/s", "1.0 km/s"),
    "pressure": ("[mass]/[length]/[time]**2", "Pa", "400 MPa"),
    "density": ("[mass]/[length]**3", "kg/m^3", "7830 kg/m^3"),
    "areal_density": ("[mass]/[length]**2", "kg/m^2", "12.7 g/cm^2"),
    "energy": ("[mass]*[length]**2/[time]**2", "J", "2.6 kJ"),
    "surface_energy": ("[mass]/[time]**2", "J/m^2", "12 J/m^2"),
    "angle": ("", "rad", "30 deg"),
}


def _import_pint():
    """pint without its optional dask support: pint.compat imports dask.base whenever dask is
    installed (about 80 ms at every start-up), and the product never hands dask arrays to pint.
    dask is hidden only while pint loads; importing dask later works as usual."""
    import sys

    if "pint" in sys.modules or "dask" in sys.modules:
        import pint

        return pint
    sys.modules["dask"] = None  # find_spec("dask") -> None, "import dask" -> ImportError
    try:
        import pint
    finally:
        if sys.modules.get("dask", 0) is None:
            del sys.modules["dask"]
    return pint


@functools.cache
def registry():
    """The pint unit registry (built once, on first use: it takes a moment)."""
    pint = _import_pint()
    ureg = pint.UnitRegistry()
    ureg.formatter.default_format = "~P"
    return ureg


def parse_quantity(value: Any, kind: str, field: str = "") -> float:
    """Parse ``value`` (e.g. ``"7.11 mm"``) as a quantity of ``kind``; return SI float.

    Plain numbers are rejected for dimensional kinds (a bare ``7.11`` could be mm or m);
    an angle given as a plain number is taken in degrees only if written as a string with
    ``deg``.  Raises ``InputError`` naming ``field``.
    """
    from semianalytic.errors import InputError

    dim, si, example = KINDS[kind]
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        raise InputError(field, f"expected a {kind} with a unit, e.g. '{example}'; got {value!r}")
    if isinstance(value, (int, float)):
        raise InputError(
            field, f"expected a {kind} with a unit, e.g. '{example}'; got the bare number {value!r}"
        )
    ureg = registry()
    try:
        q = ureg.Quantity(value.strip())
    except Exception:
        raise InputError(field, f"cannot read {value!r} as a {kind}; expected e.g. '{example}'") from None
    if not isinstance(q, ureg.Quantity):  # a bare number inside a string
        raise InputError(field, f"expected a {kind} with a unit, e.g. '{example}'; got {value!r}")
    if kind == "angle":
        if not q.dimensionless:
            raise InputError(field, f"expected an angle, e.g. '{example}'; got {value!r}")
        if str(q.units) in ("", "dimensionless"):
            raise InputError(field, f"expected an angle with a unit, e.g. '{example}'; got {value!r}")
        out = float(q.to("radian").magnitude)
    else:
        if q.dimensionality != ureg.get_dimensionality(dim):
            raise InputError(
                field, f"expected a {kind} (SI unit {si}), e.g. '{example}'; got {value!r}"
            )
        out = float(q.to(si.replace("^", "**")).magnitude)
    if not math.isfinite(out):
        raise InputError(field, f"{value!r} is not a finite {kind}")
    return out


def format_quantity(value: float, unit: str, digits: int = 4) -> str:
    """Format an SI float in a display unit, e.g. ``format_quantity(7.11e-3, 'mm')``."""
    q = registry().Quantity(value, _si_of(unit)).to(unit.replace("^", "**"))
    return f"{q.magnitude:.{digits}g} {unit}"


def _si_of(unit: str) -> str:
    ureg = registry()
    dim = ureg.get_dimensionality(unit.replace("^", "**"))
    for d, si, _ in KINDS.values():
        if d and ureg.get_dimensionality(d) == dim:
            return si.replace("^", "**")
    return "dimensionless"


# --------------------------------------------------------------------------------------
# pydantic field types (the loc of the error gives the field name; see case.py)


def _quantity_validator(kind: str, positive: bool = False, nonnegative: bool = False):
    def validate(value: Any) -> float:
        from semianalytic.errors import InputError

        try:
            out = parse_quantity(value, kind)
        except InputError as exc:
            raise ValueError(exc.message) from None
        if positive and not out > 0:
            raise ValueError(f"must be positive; got {value!r}")
        if nonnegative and out < 0:
            raise ValueError(f"must not be negative; got {value!r}")
        return out

    return BeforeValidator(validate)


Length = Annotated[float, _quantity_validator("length", positive=True)]
NonNegativeLength = Annotated[float, _quantity_validator("length", nonnegative=True)]
Mass = Annotated[float, _quantity_validator("mass", positive=True)]
Time = Annotated[float, _quantity_validator("time", positive=True)]
Velocity = Annotated[float, _quantity_validator("velocity", positive=True)]
Pressure = Annotated[float, _quantity_validator("pressure", positive=True)]
NonNegativePressure = Annotated[float, _quantity_validator("pressure", nonnegative=True)]
Density = Annotated[float, _quantity_validator("density", positive=True)]
ArealDensity = Annotated[float, _quantity_validator("areal_density", positive=True)]
Energy = Annotated[float, _quantity_validator("energy", positive=True)]
SurfaceEnergy = Annotated[float, _quantity_validator("surface_energy", positive=True)]
Angle = Annotated[float, _quantity_validator("angle", positive=True)]
