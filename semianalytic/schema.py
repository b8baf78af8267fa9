"""The base of every case-file section (the case layer's foundation).

:class:`Section` is a frozen pydantic model that rejects unknown keys; :func:`validate_section`
turns the first pydantic error into one :class:`~semianalytic.errors.InputError` naming the
field.  :mod:`semianalytic.case` and each package's ``case`` module build on these; models
never import them.
"""

from __future__ import annotations

import math
import re
import types
import typing
from typing import Any

from pydantic import BaseModel, ConfigDict, ValidationError, ValidationInfo, field_validator

from semianalytic.errors import InputError

__all__ = ["Section", "pydantic_message", "validate_section", "read_toml_text", "check_tree", "MAX_CASE_BYTES", "MAX_DEPTH"]

MAX_CASE_BYTES = 4 * 1024 * 1024  # a case file is a few kB; the largest table nose is ~100 kB
MAX_DEPTH = 8  # tables and arrays nested in a case file: [section.sub] = 2, points = [[x, r]] = 2 more
MAX_ITEMS = 200_000  # values in one case (a table of 100 000 points is already absurd)


class Section(BaseModel):
    """Base of every case-file section: frozen, unknown keys rejected, and strict numbers.

    A plain number field (``crh``, ``poisson_ratio``, ``order``, the pairs of a ``points``
    table) takes a TOML number only: a string (``crh = "3"``) or a boolean is rejected
    instead of being coerced, and so is ``inf`` or ``nan``.  Quantity fields (unit strings)
    are checked by :mod:`semianalytic.units`.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    @field_validator("*", mode="before")
    @classmethod
    def _strict_numbers(cls, value: Any, info: ValidationInfo) -> Any:
        field = cls.model_fields.get(info.field_name) if info.field_name else None
        if field is not None and not any(type(m).__name__.endswith("Validator") for m in field.metadata):
            problem = number_problem(field.annotation, value)
            if problem:
                raise ValueError(problem)
        return value

    @field_validator("*", mode="after")
    @classmethod
    def _plausible(cls, value: Any, info: ValidationInfo) -> Any:
        """The field's plausible range (:data:`semianalytic.units.PLAUSIBLE_RANGES`, issue 27)."""
        from semianalytic.units import plausibility_problem

        problem = plausibility_problem(info.field_name or "", value)
        if problem:
            raise ValueError(problem)
        return value


_NUMBER_TYPES = (float, int)


def _is_plain_number_type(annotation: Any) -> bool:
    return annotation in _NUMBER_TYPES


def number_problem(annotation: Any, value: Any) -> str | None:
    """Why ``value`` is not acceptable where ``annotation`` wants plain numbers (or None).

    Walks ``float``, ``int``, ``X | None``, ``list[...]`` and ``tuple[...]``; anything else
    (quantities, strings, literals, nested sections) is left to pydantic.
    """
    origin = typing.get_origin(annotation)
    if origin in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(annotation) if a is not type(None)]
        if value is None:
            return None
        if len(args) == 1:
            return number_problem(args[0], value)
        return None
    if annotation is bool:
        if not isinstance(value, bool):
            return f"expected true or false (a TOML boolean); got {value!r}"
        return None
    if _is_plain_number_type(annotation):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            kind = "an integer" if annotation is int else "a number"
            return f"expected {kind} (a TOML number, not a string or boolean); got {value!r}"
        if isinstance(value, float) and not math.isfinite(value):
            return f"expected a finite number; got {value!r}"
        if isinstance(value, float) and annotation is float and value != 0 and not 1e-300 < abs(value) < 1e300:
            return f"{value!r} is not representable in the computations (|x| between 1e-300 and 1e300)"
        return None
    if origin in (list, tuple) and isinstance(value, (list, tuple)):
        args = typing.get_args(annotation)
        if origin is tuple and args and args[-1] is not Ellipsis:
            items = zip(args, value)
        else:
            items = ((args[0] if args else Any, v) for v in value)
        for k, (arg, item) in enumerate(items):
            problem = number_problem(arg, item)
            if problem:
                return f"item {k}: {problem}"
    return None


def pydantic_message(err: dict) -> str:
    """One pydantic error in the case files' wording."""
    msg = err.get("msg", "invalid")
    typ = err.get("type", "")
    if typ == "missing":
        return "missing (required)"
    if typ == "extra_forbidden":
        return "unknown key"
    for prefix in ("Value error, ", "Assertion failed, "):
        if msg.startswith(prefix):
            msg = msg[len(prefix):]
    if "input" in err and typ not in ("value_error",) and not isinstance(err["input"], dict):
        msg = f"{msg}; got {err['input']!r}"
    return msg


def validate_section(name: str, model: type[BaseModel], data: Any) -> Any:
    """Validate one section's table with ``model``; errors become ``InputError``."""
    if not isinstance(data, dict):
        raise InputError(name, f"must be a table [{name}]; got {type(data).__name__}")
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        errors = exc.errors()
        # an unknown (misspelt) key first: the "missing" error it causes is only its consequence
        err = next((e for e in errors if e.get("type") == "extra_forbidden"), errors[0])
        inner = (err.get("ctx") or {}).get("error")
        if isinstance(inner, InputError):  # a cross-field check that names its own field
            raise InputError(inner.field, inner.message) from None
        parts, node = [name], data
        for p in err.get("loc", ()):
            if isinstance(node, dict) and p not in node and node.get("model") == p:
                continue  # the tag of a discriminated union (e.g. [target.resistance] model), not a key
            parts.append(str(p))
            node = node.get(p) if isinstance(node, dict) else None
        if err.get("type") in ("union_tag_invalid", "union_tag_not_found"):  # name the tag's key itself
            parts.append(str((err.get("ctx") or {}).get("discriminator", "model")).strip("'"))
        raise InputError(".".join(parts), _project_words(err, model) or pydantic_message(err)) from None


def _models_in(annotation: Any) -> list[type[BaseModel]]:
    """The pydantic models an annotation can hold (through Optional, unions, Annotated, lists)."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    return [m for a in typing.get_args(annotation) for m in _models_in(a)]


def allowed_values(annotation: Any) -> list[Any]:
    """The values of a ``Literal`` annotation (through Optional and Annotated), else []."""
    if typing.get_origin(annotation) is typing.Literal:
        return list(typing.get_args(annotation))
    return [v for a in typing.get_args(annotation) for v in allowed_values(a)]


def _keys_at(model: type[BaseModel], loc: tuple) -> list[str]:
    """The valid keys of the table at ``loc`` (the last item of ``loc`` is the bad key)."""
    classes = [model]
    for p in loc[:-1]:
        if isinstance(p, int):
            continue
        fields = [c.model_fields[p] for c in classes if p in c.model_fields]
        if fields:
            classes = [m for f in fields for m in _models_in(f.annotation)]
        else:  # the tag of a discriminated union: the member whose `model` literal holds it
            tagged = [c for c in classes if p in allowed_values(getattr(c.model_fields.get("model"), "annotation", None))]
            classes = tagged or classes
    return sorted({k for c in classes for k in c.model_fields})


def did_you_mean(word: str, choices: list[str]) -> str:
    """`` (did you mean 'x'?)`` for the closest of ``choices`` (difflib), else ``""``."""
    import difflib

    close = difflib.get_close_matches(str(word), [str(c) for c in choices], n=1, cutoff=0.6)
    return f"; did you mean {close[0]!r}?" if close else ""


def _project_words(err: dict, model: type[BaseModel]) -> str | None:
    """An unknown key with its closest valid key, a wrong choice with the valid ones: the
    project's words for pydantic's ``extra_forbidden``, ``literal_error`` and
    ``union_tag_invalid`` errors (None for any other error)."""
    typ, loc, ctx = err.get("type"), tuple(err.get("loc", ())), err.get("ctx") or {}
    if typ == "extra_forbidden" and loc:
        keys = _keys_at(model, loc)
        return f"unknown key{did_you_mean(loc[-1], keys)} (valid keys: {', '.join(keys)})"
    if typ == "literal_error":
        choices = re.findall(r"'([^']*)'", str(ctx.get("expected", "")))
        got = err.get("input")
        return f"{got!r} is not one of {', '.join(choices)}{did_you_mean(got, choices)}"
    if typ == "union_tag_invalid":
        choices = re.findall(r"'([^']*)'", str(ctx.get("expected_tags", "")))
        got = ctx.get("tag", err.get("input"))
        return f"{got!r} is not one of {', '.join(choices)}{did_you_mean(got, choices)}"
    if typ == "union_tag_not_found":
        return f"missing {str(ctx.get('discriminator', 'model')).strip(chr(39))!r} (the kind of table this is)"
    return None


def read_toml_text(path: Any) -> dict:
    """Read a TOML case file safely: it must exist, be at most :data:`MAX_CASE_BYTES`, be UTF-8
    text (no NUL bytes), parse as TOML and nest at most :data:`MAX_DEPTH` levels.  Every
    failure is one ``InputError`` on the field ``case``."""
    import tomllib
    from pathlib import Path

    path = Path(path)
    try:
        if not path.is_file():
            what = "is a folder, not a case file" if path.is_dir() else "does not exist"
            raise InputError("case", f"file {str(path)!r} {what}")
        size = path.stat().st_size
        if size > MAX_CASE_BYTES:
            raise InputError("case", f"{path.name} is {size / 2**20:.1f} MiB; a case file is at most {MAX_CASE_BYTES // 2**20} MiB of TOML text")
        with path.open("rb") as fh:
            raw = fh.read(MAX_CASE_BYTES + 1)
    except OSError as exc:
        raise InputError("case", f"cannot read {str(path)!r}: {exc.strerror or exc}") from None
    if len(raw) > MAX_CASE_BYTES:
        raise InputError("case", f"{path.name} is larger than {MAX_CASE_BYTES // 2**20} MiB; a case file is TOML text")
    nul = raw.find(b"\x00")
    if nul >= 0:
        raise InputError("case", f"{path.name} is a binary file (NUL byte at offset {nul}); expected TOML text")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise InputError("case", f"{path.name} is not UTF-8 text (byte 0x{raw[exc.start]:02x} on line {line}); save it as UTF-8") from None
    depth = _bracket_depth(text)
    if depth > MAX_DEPTH:
        raise InputError("case", f"{path.name} nests arrays or tables {depth} deep; a case needs at most {MAX_DEPTH}")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError("case", f"{path.name} is not valid TOML: {exc}") from None
    except RecursionError:
        raise InputError("case", f"{path.name} nests arrays or tables too deeply") from None
    return data


def _bracket_depth(text: str) -> int:
    """An upper bound of the nesting of inline arrays and tables (brackets and braces outside
    comments; strings may inflate it, which only makes the check stricter on absurd files)."""
    depth = deepest = 0
    for line in text.splitlines():
        for ch in line.split("#", 1)[0] if '"' not in line and "'" not in line else line:
            if ch in "[{":
                depth += 1
                deepest = max(deepest, depth)
            elif ch in "]}":
                depth = max(depth - 1, 0)
        if deepest > MAX_DEPTH:
            break
    return deepest


def check_tree(data: Any, where: str = "case") -> None:
    """Refuse a parsed case nested deeper than :data:`MAX_DEPTH` or with more than
    :data:`MAX_ITEMS` values, without recursion (any tree, also one built in Python)."""
    stack = [(data, 0, where)]
    count = 0
    while stack:
        node, depth, loc = stack.pop()
        count += 1
        if count > MAX_ITEMS:
            raise InputError(where, f"more than {MAX_ITEMS} values; a case file is small")
        if isinstance(node, dict):
            if depth >= MAX_DEPTH:
                raise InputError(loc, f"nested more than {MAX_DEPTH} levels deep")
            for k, v in node.items():
                if not isinstance(k, str):
                    raise InputError(loc, f"keys must be strings; got {k!r}")
                stack.append((v, depth + 1, k if loc == "case" else f"{loc}.{k}"))
        elif isinstance(node, (list, tuple)):
            if depth >= MAX_DEPTH:
                raise InputError(loc, f"nested more than {MAX_DEPTH} levels deep")
            stack.extend((v, depth + 1, loc) for v in node)


# Measured elastic constants of one isotropic material agree to a few per cent (the bundled
# ceramics: AD995, SiC, B4C to 0.2 %).  A bulk modulus more than 10 % away from
# E / (3 (1 - 2 nu)) is warned about; a factor of 10 or more away (a wrong unit prefix) is
# refused.  Between the two the model still runs (K enters only the compressed zone), which
# keeps sensitivity studies of nu at a fixed measured K possible.
BULK_MODULUS_WARN = 0.10
BULK_MODULUS_FACTOR = 10.0


def check_brittle_constants(section: str, youngs_modulus: float, poisson_ratio: float, tensile_strength: float,
                            compressive_strength: float, bulk_modulus: float | None) -> None:
    """Cross-field checks of a brittle material (Part II): the tensile strength sigma_f below
    the compressive strength Y_s (the material fails in tension first: that is what makes the
    cracked zone of Part II, Fig. 1), and K_s consistent with E and nu (isotropic elasticity,
    K = E / (3 (1 - 2 nu))).  Raises ``InputError`` naming the field."""
    if not tensile_strength < compressive_strength:
        raise InputError(
            f"{section}.tensile_strength",
            f"sigma_f = {tensile_strength / 1e9:.4g} GPa must lie below compressive_strength (Y_s = {compressive_strength / 1e9:.4g} GPa) "
            "for a brittle material: otherwise no cracked zone forms (Part II, Fig. 1)",
        )
    if bulk_modulus is not None and poisson_ratio < 0.5:
        implied = youngs_modulus / (3 * (1 - 2 * poisson_ratio))
        apart = abs(bulk_modulus / implied - 1)
        ratio = bulk_modulus / implied
        if not 1 / BULK_MODULUS_FACTOR < ratio < BULK_MODULUS_FACTOR:
            raise InputError(
                f"{section}.bulk_modulus",
                f"{bulk_modulus / 1e9:.4g} GPa is inconsistent with youngs_modulus and poisson_ratio, which give "
                f"K = E / (3 (1 - 2 nu)) = {implied / 1e9:.4g} GPa (a factor {max(ratio, 1 / ratio):.3g} apart); "
                "leave bulk_modulus out to use that value",
            )
        if apart > BULK_MODULUS_WARN:
            import warnings

            from semianalytic.errors import ModelValidityWarning

            warnings.warn(
                f"{section}.bulk_modulus: {bulk_modulus / 1e9:.4g} GPa is {apart:.0%} away from E / (3 (1 - 2 nu)) = "
                f"{implied / 1e9:.4g} GPa; check the elastic constants", ModelValidityWarning, stacklevel=2)
