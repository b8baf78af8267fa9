"""Progress on stderr for the long commands (``run``, ``fem_check verify``): a tqdm bar that
stays off with ``--quiet`` or when stderr is not a terminal (pipes, CI logs, tests)."""

from __future__ import annotations

import sys

__all__ = ["stages"]


class _Off:
    """The bar when it is off: the same calls, nothing printed."""

    def step(self, description: str) -> None:
        pass

    def close(self) -> None:
        pass


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

    def close(self) -> None:
        if self._started:
            self._bar.update(1)
        self._bar.close()


def stages(total: int, what: str, quiet: bool = False):
    """A progress bar of ``total`` steps named ``what``; ``.step(text)`` as each step starts,
    ``.close()`` at the end.  Off with ``quiet`` or when stderr is not a terminal."""
    if quiet or total <= 0 or not sys.stderr.isatty():
        return _Off()
    return _Bar(total, what)
