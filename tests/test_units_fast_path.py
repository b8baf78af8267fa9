"""The common unit strings are parsed without pint (start-up, issue 14); pint stays the authority.

The reference is pint itself: every entry of ``units._COMMON_UNITS`` (each once), any number in
any spelling with any of them (a hypothesis property, 300 examples) and every quantity string of
the bundled cases parse to the same float, bit for bit (sign of zero included), or to the same
error, with the fast path as without it.  Exact equality, no tolerance: the fast path multiplies
by pint's own conversion factor, as pint does.
"""

from __future__ import annotations

import math
import random
import re
import struct
import tomllib
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from semianalytic import units
from semianalytic.errors import InputError

ROOT = Path(__file__).resolve().parent.parent

NUMBERS = ["0", "-0", "-0.0", "0.0", "1", "7.11", "5.", ".5", "+3", "-3", "1e3", "1E-3", "1e+3", "2.5e-7",
           "12345678901234567890", "0.1", "1e400", "-1e400", "1e-400", "07", "00.5", "0.000", "400", "68.9",
           "1.0", "0.29", "1234.5678", "9e307"]
_rng = random.Random(20261124)  # a fixed seed: the same numbers on every run
NUMBERS += [repr(_rng.uniform(0, 1e4)) for _ in range(8)] + [repr(10 ** _rng.uniform(-12, 12)) for _ in range(8)]
SPELLINGS = ["{n} {u}", "  {n} {u}\t", "{n}{u}"]


def _outcome(value: str, kind: str, fast: bool, monkeypatch) -> tuple:
    """('ok', bits of the float) or ('error', field, message) of parse_quantity."""
    with monkeypatch.context() as m:
        if not fast:
            m.setattr(units, "_common_unit_si", lambda value, kind: None)
        try:
            out = units.parse_quantity(value, kind, "f")
        except InputError as exc:
            return ("error", exc.field, exc.message)
    return ("ok", struct.pack("<d", out))


@pytest.mark.parametrize("unit", sorted(units._COMMON_UNITS))
def test_every_common_unit_parses_as_pint_does(unit, monkeypatch):
    """Each unit of the fast path once, in each spelling, against pint (the table itself, all of it)."""
    kind = units._COMMON_UNITS[unit][0]
    assert units._common_unit_si(f"7.11 {unit}", kind) is not None  # the fast path takes it
    for spelling in SPELLINGS:
        value = spelling.format(n="7.11", u=unit)
        assert _outcome(value, kind, True, monkeypatch) == _outcome(value, kind, False, monkeypatch), value


# numbers as a user types them: the hand-picked edge cases, or any float / integer in any notation
_NUMBER = st.one_of(
    st.sampled_from(NUMBERS),
    st.floats(allow_nan=False, allow_infinity=False).map(repr),
    st.integers(-10**20, 10**20).map(str),
    st.builds(lambda m, e: f"{m}e{e}", st.integers(-999, 999), st.integers(-330, 330)),
)


@settings(max_examples=300, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(unit=st.sampled_from(sorted(units._COMMON_UNITS)), number=_NUMBER, spelling=st.sampled_from(SPELLINGS))
def test_common_units_parse_as_pint_does(unit, number, spelling, monkeypatch):
    """Property: for any number, unit and spelling, the fast path gives pint's float, bit for bit
    (sign of zero included), or pint's error."""
    kind = units._COMMON_UNITS[unit][0]
    value = spelling.format(n=number, u=unit)
    assert _outcome(value, kind, True, monkeypatch) == _outcome(value, kind, False, monkeypatch), value


@pytest.mark.parametrize("unit", sorted(units._COMMON_UNITS))
def test_a_unit_of_another_kind_goes_to_pint(unit):
    own = units._COMMON_UNITS[unit][0]
    for kind in units.KINDS:
        if kind != own:
            assert units._common_unit_si(f"7.11 {unit}", kind) is None


def _quantity_strings(obj):
    if isinstance(obj, dict):
        for v in obj.values():
            yield from _quantity_strings(v)
    elif isinstance(obj, list):
        for v in obj:
            yield from _quantity_strings(v)
    elif isinstance(obj, str) and re.match(r"\s*[-+]?(\d|\.\d)", obj):
        yield obj


def test_every_bundled_case_quantity_parses_as_pint_does(monkeypatch):
    strings = set()
    for path in (ROOT / "cases").glob("*.toml"):
        strings.update(_quantity_strings(tomllib.loads(path.read_text())))
    assert len(strings) > 20
    fast_hits = 0
    for value in sorted(strings):
        for kind in units.KINDS:
            fast = _outcome(value, kind, True, monkeypatch)
            assert fast == _outcome(value, kind, False, monkeypatch), (value, kind)
            fast_hits += units._common_unit_si(value, kind) is not None
    assert fast_hits >= 0.8 * len(strings)  # nearly every bundled quantity skips pint


def test_the_fast_factors_are_pints():
    ureg = units.registry()
    for unit, (kind, factor) in units._COMMON_UNITS.items():
        si = "radian" if kind == "angle" else units.KINDS[kind][1].replace("^", "**")
        assert ureg.Quantity(1.0, unit.replace("^", "**")).to(si).magnitude == factor, unit
        assert math.isfinite(factor)
