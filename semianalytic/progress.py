"""Progress on stderr, by one rule for every command and API call that may take more than
about 2 s: a tqdm bar with a total when stderr is a terminal; one line per stage when stderr is
a file (a log: ``cmd 2> log``); nothing with ``--quiet`` (``quiet=True``) or when stderr is a
pipe (tests, ``| tee``).  In a Jupyter notebook (stderr is the kernel's stream) the bar.  ``SEMIANALYTIC_PROGRESS=bar|lines|off`` overrides the choice."""  # noqa: E501

from __future__ import annotations

import os
import stat
import sys
import time

__all__ = ["mode", "stages", "counter"]


def mode(quiet: bool = False) -> str:
    """``"bar"``, ``"lines"`` or ``"off"`` for the current stderr (see the module docstring)."""
    if quiet:
        return "off"
    forced = os.environ.get("SEMIANALYTIC_PROGRESS", "").strip().lower()
    if forced in ("bar", "lines", "off"):
        return forced
    try:
        if sys.stderr.isatty():
            return "bar"
        return "lines" if stat.S_ISREG(os.fstat(sys.stderr.fileno()).st_mode) else "off"
    except (AttributeError, OSError, ValueError):  # a replaced stderr: a notebook's, pytest's capture, StringIO
        return "bar" if "ipykernel" in sys.modules and type(sys.stderr).__name__ == "OutStream" else "off"


class _Off:
    """The progress when it is off: the same calls, nothing printed."""

    def step(self, description: str) -> None:
        pass

    def update(self, n: int = 1) -> None:
        pass

    def close(self) -> None:
        pass


class _Lines:
    """One line per stage on stderr (``what: [k/total] description``), and at the end the
    elapsed time."""

    def __init__(self, total: int, what: str):
        self.total, self.what, self.k, self.t0 = total, what, 0, time.perf_counter()

    def step(self, description: str) -> None:
        self.k += 1
        print(f"{self.what}: [{self.k}/{self.total}] {description}", file=sys.stderr, flush=True)

    def update(self, n: int = 1) -> None:
        pass

    def close(self) -> None:
        print(f"{self.what}: done in {time.perf_counter() - self.t0:.1f} s", file=sys.stderr, flush=True)


class _Bar:
    def __init__(self, total: int, what: str):
        from tqdm import tqdm

        self._bar = tqdm(total=total, desc=what, file=sys.stderr, unit="step", leave=False,
                         bar_format="{desc}: {n_fmt}/{total_fmt} steps [{elapsed}] {postfix}")
        self._started = False

    def step(self, description: str) -> None:
        """Mark the previous step done and show the one that starts now."""
        if self._started:
            self._bar.update(1)
        self._started = True
        self._bar.set_postfix_str(description)

    def update(self, n: int = 1) -> None:
        pass

    def close(self) -> None:
        if self._started:
            self._bar.update(1)
        self._bar.close()


def stages(total: int, what: str, quiet: bool = False):
    """Progress of ``total`` stages named ``what``: ``.step(text)`` as each stage starts,
    ``.close()`` at the end (the rule of :func:`mode`)."""
    m = mode(quiet)
    if total <= 0 or m == "off":
        return _Off()
    return _Bar(total, what) if m == "bar" else _Lines(total, what)


class _GrowingBar:
    """A tqdm counter whose total is an estimate, raised by a quarter whenever it is passed (the
    adaptive coefficient table does not know its knot count in advance)."""

    def __init__(self, estimate: int, what: str, unit: str):
        from tqdm import tqdm

        self._bar = tqdm(total=estimate, desc=f"{what} (total estimated)", unit=unit, file=sys.stderr, leave=False)

    def update(self, n: int = 1) -> None:
        if self._bar.n + n > self._bar.total:
            self._bar.total = int((self._bar.n + n) * 1.25) + 1
            self._bar.refresh()
        self._bar.update(n)

    def step(self, description: str) -> None:
        self._bar.set_postfix_str(description)

    def close(self) -> None:
        self._bar.close()


class _CountLines(_Off):
    def __init__(self, what: str, unit: str):
        self.what, self.unit, self.n, self.t0 = what, unit, 0, time.perf_counter()
        print(f"{what}: started", file=sys.stderr, flush=True)

    def update(self, n: int = 1) -> None:
        self.n += n

    def close(self) -> None:
        print(f"{self.what}: {self.n} {self.unit}s in {time.perf_counter() - self.t0:.1f} s", file=sys.stderr, flush=True)


def counter(estimate: int, what: str, unit: str = "item", quiet: bool = False):
    """A counter of work whose size is only estimated (``.update(n)``, ``.close()``): a bar
    with the estimate as its total on a terminal; a start and an end line in a log."""
    m = mode(quiet)
    if m == "off":
        return _Off()
    return _GrowingBar(estimate, what, unit) if m == "bar" else _CountLines(what, unit)
