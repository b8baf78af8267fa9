"""The base of every case-file section (the case layer's foundation).

:class:`Section` is a frozen pydantic model that rejects unknown keys; :func:`validate_section`
turns the first pydantic error into one :class:`~semianalytic.errors.InputError` naming the
field.  :mod:`semianalytic.case` and each package's ``case`` module build on these; models
never import them.
"""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, ConfigDict, ValidationError

from semianalytic.errors import InputError

__all__ = ["Section", "pydantic_message", "validate_section"]


class Section(BaseModel):
    """Base of every case-file section: frozen, unknown keys rejected."""

    model_config = ConfigDict(extra="forbid", frozen=True)


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
        err = exc.errors()[0]
        parts, node = [name], data
        for p in err.get("loc", ()):
            if isinstance(node, dict) and p not in node and node.get("model") == p:
                continue  # the tag of a discriminated union (e.g. [target.resistance] model), not a key
            parts.append(str(p))
            node = node.get(p) if isinstance(node, dict) else None
        raise InputError(".".join(parts), pydantic_message(err)) from None
