"""Errors that map onto the command-line exit statuses.

``InputError`` is bad input (exit status 2): it names the offending field, e.g.
``projectile.diameter``, and says what was expected.  ``ModelError`` is raised by the models
(pure functions of SI values, which know no case fields) when their inputs lie outside what
they can compute; the CLI dispatcher turns it into exit status 2 with one line, as bad input.
``ConvergenceError`` is the ModelError of an iterative solve that did not converge (never a
silent result).  Anything else escaping a command is an internal failure (exit status 1).

A model names its inputs in model words (``ModelError(message, field="cavity.tensile_strength")``);
the case layer that built the model's inputs from a case file maps the name to the key the user
wrote, with :func:`model_field` (``with model_field({"cavity.": "material."}): solve_cavity(...)``),
so that the line the user sees is the one a case-layer check would have written.
"""

import copy
from collections.abc import Iterator, Mapping
from contextlib import contextmanager


def one_line(text: str) -> str:
    """``text`` with every unprintable character (newline, tab, NUL, ...) escaped, so that an
    error message stays one line whatever the user typed."""
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() or c == " " else repr(c)[1:-1] for c in text)


class InputError(ValueError):
    """Bad input in a case file or on the command line (exit status 2)."""

    def __init__(self, field: str, message: str):
        field, message = one_line(str(field)), one_line(str(message))  # a key may hold a newline
        self.field = field
        self.message = message
        super().__init__(f"{field}: {message}" if field else message)


class ModelError(ValueError):
    """A model cannot compute with these inputs (exit status 2 through the CLI dispatcher, one
    line ``error: <field>: <message>``; ``field`` defaults to "model")."""

    def __init__(self, message: str, field: str = "model"):
        self.field = one_line(str(field))
        self.message = one_line(str(message))
        super().__init__(f"{self.field}: {self.message}")


def case_key(field: str, names: Mapping[str, str]) -> str:
    """The case key of a model-level name: ``names[field]`` when present, else the longest prefix of
    ``names`` ending in "." replaced (``{"cavity.": "material."}``), else ``field`` itself."""
    if field in names:
        return names[field]
    prefixes = [p for p in names if p.endswith(".") and field.startswith(p)]
    if prefixes:
        p = max(prefixes, key=len)
        return names[p] + field[len(p):]
    return field


@contextmanager
def model_field(names: Mapping[str, str]) -> Iterator[None]:
    """Within the block, a :class:`ModelError` is raised again (same class and message) with its
    field mapped by :func:`case_key` to the case key the user wrote."""
    try:
        yield
    except ModelError as exc:
        key = case_key(exc.field, names)
        if key == exc.field:
            raise
        mapped = copy.copy(exc)  # the same class (and attributes), the case key as its field
        mapped.field = key
        mapped.args = (f"{key}: {exc.message}",)
        raise mapped from None


class ConvergenceError(ModelError):
    """An iterative solve did not converge (the status of every iterative solve is either
    returned, e.g. :class:`semianalytic.penetration.motion.RootResult`, or raised as this)."""


class ModelValidityWarning(UserWarning):
    """An input the model accepts but that lies outside its stated validity (also
    :data:`ValidityWarning`): ``warnings.simplefilter("ignore", ValidityWarning)`` silences
    them, ``"error"`` turns them into exceptions; the commands print them on stderr."""


ValidityWarning = ModelValidityWarning


class ExtrapolationWarning(ModelValidityWarning):
    """A value read outside the range a table or a fit was built on."""


def summarise(values, fmt: str = "{:.0f}", limit: int = 12) -> str:
    """``values`` as a short text: all of them up to ``limit``, else their count and range with
    the first and last few (``"1000 values, 400 to 1800 (400, 401, 403, ..., 1799, 1800)"``)."""
    vals = list(values)
    if len(vals) <= limit:
        return ", ".join(fmt.format(v) for v in vals)
    head = ", ".join(fmt.format(v) for v in vals[:3])
    tail = ", ".join(fmt.format(v) for v in vals[-2:])
    return f"{len(vals)} values, {fmt.format(min(vals))} to {fmt.format(max(vals))} ({head}, ..., {tail})"


def exit_status(main) -> int:
    """Run ``main()`` of a ``python -m`` tool outside the CLI dispatcher (benchmarks): bad input
    is one line on stderr and exit 2, as in every command, never a traceback."""
    import sys

    try:
        return int(main() or 0)
    except (InputError, ModelError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
