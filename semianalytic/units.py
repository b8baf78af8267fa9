"""Physical quantities at the edges: unit strings in, SI floats out.

Case files write quantities as strings with units (``"7.11 mm"``, ``"400 MPa"``,
``"1.0 km/s"``).  They are parsed with pint, checked for dimension and converted to SI; the
most common unit strings are converted with pint's own factors without loading pint (start-up
time; the same floats, see ``_COMMON_UNITS``).
Inside the code every quantity is a plain float in SI units.

The pydantic types at the bottom (``Length``, ``Pressure``, ...) are what case-file section
models use; a bad value is reported with the field name, the value and what was expected.
"""

from __future__ import annotations

import functools
import math
import re
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


# kind -> (smallest, largest) magnitude in SI that a case may give (zero is left to each field).
# Not the validity of any model (each model warns about its own range): the physical range
# of the quantity in anything this product computes, so that an absurd value ("1e300 m",
# "1e-300 m") is refused at the door instead of overflowing inside a solver.
PHYSICAL_BOUNDS: dict[str, tuple[float, float, str]] = {
    "length": (1e-12, 1e4, "1 pm (below an atom) to 10 km"),
    "area": (1e-24, 1e8, "1 pm^2 to 100 km^2"),
    "volume": (1e-36, 1e12, "1 pm^3 to 1000 km^3"),
    "mass": (1e-30, 1e7, "1e-30 kg (an electron) to 10 000 t"),
    "time": (1e-18, 1e7, "1 as to 4 months"),
    # above 100 km/s nothing in the solar system moves relative to a target (meteoroids reach
    # 72 km/s); the striking velocities have their own, lower bound (semianalytic.case)
    "velocity": (1e-9, 1e5, "1 nm/s to 100 km/s"),
    # the theoretical strength and moduli of diamond are ~1 TPa; 10 TPa is beyond any solid
    "pressure": (1e-3, 1e13, "1 mPa to 10 TPa"),
    # air is 1.2 kg/m^3, osmium 22 590 kg/m^3
    "density": (1e-2, 1e5, "0.01 to 100 000 kg/m^3"),
    "areal_density": (1e-6, 1e7, "1 mg/m^2 to 10 000 t/m^2"),
    "energy": (1e-30, 1e15, "1e-30 J to 1 PJ"),
    "surface_energy": (1e-6, 1e6, "1 uJ/m^2 to 1 MJ/m^2"),
    "angle": (1e-12, 2 * math.pi, "1e-12 rad to 360 deg"),
}


# field name -> (smallest, largest SI value, reason): the plausible range of a material or
# plate quantity wherever a case section names it (issue 27; this project's own limits, wider
# than any material in the bundled cases and the literature it reproduces, far narrower than
# PHYSICAL_BOUNDS).  Checked by schema.Section for every section, so each field has its range
# and its reason in one place.  Outside: exit status 2 naming the field.
_STRENGTH = (1e3, 1e12, "1 kPa (softer than wet clay: a fluid for these solid-mechanics models) to 1 TPa "
                        "(ten times the theoretical strength of diamond)")
_MODULUS = (1e5, 1e13, "0.1 MPa (softer than rubber) to 10 TPa (ten times diamond's 1.2 TPa)")
_DENSITY = (50.0, 3e4, "50 kg/m^3 (the lightest rigid foams; a gas or an aerogel is not a target or projectile "
                       "of these models) to 30 000 kg/m^3 (above osmium, 22 590)")
PLAUSIBLE_RANGES: dict[str, tuple[float, float, str]] = {
    **{name: _STRENGTH for name in (
        "yield_stress", "dynamic_yield_stress", "cavity_yield_stress", "tensile_strength", "compressive_strength",
        "hardness", "target_hardness", "projectile_hardness", "resistance", "eroding_resistance")},
    **{name: _MODULUS for name in ("youngs_modulus", "bulk_modulus", "shear_modulus")},
    **{name: _DENSITY for name in ("density", "target_density", "projectile_density")},
    "thickness": (1e-6, 10.0, "1 um (a film, not a plate: Part IV's plates are millimetres thick) to 10 m "
                              "(thicker than any armour plate)"),
}


def plausibility_problem(name: str, value: Any) -> str | None:
    """Why the SI ``value`` of the field ``name`` lies outside :data:`PLAUSIBLE_RANGES`, or None."""
    bounds = PLAUSIBLE_RANGES.get(name)
    if bounds is None or isinstance(value, bool) or not isinstance(value, float) or value == 0:
        return None
    low, high, why = bounds
    if low <= abs(value) <= high:
        return None
    unit = {"thickness": "m"}.get(name, "kg/m^3" if "density" in name else "Pa")
    return f"{value:.4g} {unit} lies outside the plausible range {why}"


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

    _, si, example = KINDS[kind]
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        raise InputError(field, f"expected a {kind} with a unit, e.g. '{example}'; got {value!r}")
    if isinstance(value, (int, float)):
        raise InputError(
            field, f"expected a {kind} with a unit, e.g. '{example}'; got the bare number {value!r}"
        )
    if not _NUMBER_FIRST.match(value):  # pint reads a bare "mm" as 1 mm
        raise InputError(field, f"expected a {kind} as a number and a unit, e.g. '{example}'; got {value!r}")
    out = _common_unit_si(value, kind)
    if out is None:  # anything but a plain number and one of the common units: pint decides
        try:
            out = _pint_si(value, kind, field, example, si)
        except (OverflowError, ZeroDivisionError, ArithmeticError, TypeError, ValueError) as exc:
            if isinstance(exc, InputError):
                raise
            # e.g. '2**2000 mm': an integer too large for a float (or 1/0) inside pint's arithmetic
            raise InputError(field, f"{value!r} is not a finite {kind} ({type(exc).__name__}); "
                                    f"expected e.g. '{example}'") from None
    if not math.isfinite(out):
        raise InputError(field, f"{value!r} is not a finite {kind}")
    low, high, text = PHYSICAL_BOUNDS[kind]
    if out != 0 and not low <= abs(out) <= high:
        raise InputError(field, f"{value!r} lies outside the physical range of a {kind} ({text})")
    return out


def _pint_si(value: str, kind: str, field: str, example: str, si: str) -> float:
    """``value`` parsed by pint, checked for the dimension of ``kind``, in SI."""
    from semianalytic.errors import InputError

    dim = KINDS[kind][0]
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
    return out


# The unit strings case files and flags use most, with pint's own factor to SI (the magnitude
# pint's ``Quantity(value).to(SI)`` returns is the number times this factor, bit for bit:
# tests/test_units_fast_path.py checks every entry against pint on many numbers and spellings).
# Parsing these without pint spares a command pint's import and its unit registry (~0.4 s);
# every other string, and every string whose unit is not of the kind asked for, goes to pint.
_COMMON_UNITS: dict[str, tuple[str, float]] = {
    "m": ("length", 1.0), "mm": ("length", 0.001), "cm": ("length", 0.01), "um": ("length", 1e-06),
    "µm": ("length", 1e-06), "km": ("length", 1000.0), "nm": ("length", 1e-09),
    "kg": ("mass", 1.0), "g": ("mass", 0.001), "mg": ("mass", 1e-06),
    "s": ("time", 1.0), "ms": ("time", 0.001), "us": ("time", 1e-06), "µs": ("time", 1e-06), "ns": ("time", 1e-09),
    "m/s": ("velocity", 1.0), "km/s": ("velocity", 1000.0), "mm/us": ("velocity", 1000.0),
    "mm/s": ("velocity", 0.001),
    "Pa": ("pressure", 1.0), "kPa": ("pressure", 1000.0), "MPa": ("pressure", 1000000.0),
    "GPa": ("pressure", 1000000000.0), "TPa": ("pressure", 1000000000000.0),
    "kg/m^3": ("density", 1.0), "kg/m**3": ("density", 1.0),
    "g/cm^3": ("density", 999.9999999999999), "g/cm**3": ("density", 999.9999999999999),  # pint's factor
    "kg/m^2": ("areal_density", 1.0), "g/cm^2": ("areal_density", 10.0),
    "J": ("energy", 1.0), "kJ": ("energy", 1000.0), "MJ": ("energy", 1000000.0),
    "J/m^2": ("surface_energy", 1.0),
    "deg": ("angle", 0.017453292519943295), "degree": ("angle", 0.017453292519943295),
    "degrees": ("angle", 0.017453292519943295), "rad": ("angle", 1.0), "radian": ("angle", 1.0),
    "m^2": ("area", 1.0), "mm^2": ("area", 1e-06), "cm^2": ("area", 0.0001),
    "m^3": ("volume", 1.0), "mm^3": ("volume", 1e-09), "cm^3": ("volume", 1.0000000000000002e-06),
}
_COMMON_QUANTITY = re.compile(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?) ([^\s]+)\s*")


def _common_unit_si(value: str, kind: str) -> float | None:
    """``value`` in SI when it is a decimal number, one space and a unit of ``kind`` from
    :data:`_COMMON_UNITS` (the same float pint gives); else None."""
    match = _COMMON_QUANTITY.fullmatch(value)
    if match is None:
        return None
    number, unit = match.groups()
    unit_kind, factor = _COMMON_UNITS.get(unit, ("", 0.0))
    digits = number.lstrip("+-")
    if unit_kind != kind or (digits[:1] == "0" and digits[1:2].isdigit()):
        return None  # another kind (pint words the error), or a leading zero as in "07" (pint's tokenizer decides)
    try:  # as pint's evaluator: an integer stays an int ("-0" is 0), anything else a float ("-0.0")
        return float((int(number) if digits.isdigit() else float(number)) * factor)
    except OverflowError:
        return None


_NUMBER_FIRST = re.compile(r"\s*[-+]?(\d|\.\d|inf|nan)", re.IGNORECASE)


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

    validate.quantity_kind = kind  # read by the case-file reference of the docs (docs_hooks)
    validate.sign = "positive" if positive else "non-negative" if nonnegative else ""
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
