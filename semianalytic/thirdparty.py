"""Third-party libraries kept out of the user's home folder (issue 40).

matplotlib keeps a font cache (and reads its configuration) in ``$MPLCONFIGDIR``, else
``~/.config/matplotlib`` and ``~/.cache/matplotlib``; arviz writes ``~/.cache/arviz/daily_warning``
when imported.  No option of this project asks for either, so:

- :func:`keep_caches_out_of_home` (called by the dispatcher before any command) points
  ``MPLCONFIGDIR`` at ``matplotlib/`` of this project's per-user cache, only when the user has not
  set ``MPLCONFIGDIR`` and has no ``matplotlibrc`` of their own in matplotlib's default folder (their
  own configuration keeps working as before);
- :func:`import_arviz` imports arviz with its once-a-day notice stamped in a temporary folder that
  is removed right after (the notice itself is a FutureWarning, which the dispatcher does not show),
  unless the user has set ``XDG_CACHE_HOME`` (their own choice of cache);
- :func:`run_mcmc` runs an emcee sampler with Ctrl-C and SIGTERM raised between its steps, and
  :class:`deferred_interrupts` holds them off while a library is mid-way (a dask cluster starting).
"""

from __future__ import annotations

import os

__all__ = ["keep_caches_out_of_home", "import_arviz", "MPL_SUBDIR", "deferred_interrupts", "run_mcmc"]

MPL_SUBDIR = "matplotlib"


def _user_matplotlibrc() -> bool:
    """Whether matplotlib's default configuration folder holds the user's own matplotlibrc."""
    base = os.environ.get("XDG_CONFIG_HOME") or os.path.join(os.path.expanduser("~"), ".config")
    return os.path.isfile(os.path.join(base, "matplotlib", "matplotlibrc"))


def keep_caches_out_of_home() -> str | None:
    """Set ``MPLCONFIGDIR`` to this project's per-user cache (see the module docstring); returns
    the folder set, or None where the user's own setting stays."""
    if os.environ.get("MPLCONFIGDIR") or "matplotlib" in __import__("sys").modules or _user_matplotlibrc():
        return None
    from semianalytic.native import cache_root

    folder = cache_root() / MPL_SUBDIR
    os.environ["MPLCONFIGDIR"] = str(folder)  # matplotlib creates it on first use (mode 0700 not needed: a cache)
    return str(folder)


def import_arviz():
    """``import arviz`` without its stamp file in the user's cache (see the module docstring)."""
    import sys

    if "arviz" in sys.modules or os.environ.get("XDG_CACHE_HOME"):
        import arviz

        return arviz
    import tempfile

    with tempfile.TemporaryDirectory(prefix="semianalytic-arviz-") as tmp:
        os.environ["XDG_CACHE_HOME"] = tmp
        try:
            import arviz
        finally:
            del os.environ["XDG_CACHE_HOME"]
    return arviz


class deferred_interrupts:
    """SIGINT and SIGTERM noted, not raised, inside the block; the list it yields holds the name of
    the signal that came ("Ctrl-C", "signal SIGTERM"), for the caller to raise KeyboardInterrupt
    where it is safe: outside a library that catches every exception and prints its traceback
    (emcee's likelihood wrapper) or cleans up half-made state noisily (a dask cluster starting).
    Only in the main thread; elsewhere a no-op."""

    def __enter__(self):
        import signal
        import threading

        self.got, self.old = [], {}
        if threading.current_thread() is threading.main_thread():
            for sig in (signal.SIGINT, signal.SIGTERM):
                try:
                    self.old[sig] = signal.signal(sig, self._note)
                except (ValueError, OSError):
                    pass
        return self.got

    def _note(self, signum, frame):
        import signal

        self.got.append("Ctrl-C" if signum == signal.SIGINT else f"signal {signal.Signals(signum).name}")

    def __exit__(self, *exc):
        import signal

        for sig, handler in self.old.items():
            signal.signal(sig, handler)
        return False


def run_mcmc(sampler, p0, steps: int, **kwargs):
    """``sampler.run_mcmc(p0, steps, **kwargs)`` of emcee, step by step, with Ctrl-C and SIGTERM
    raised between steps (KeyboardInterrupt, one line from the dispatcher): raised inside the
    likelihood, emcee's wrapper printed its own traceback first (issue 40)."""
    state = None
    with deferred_interrupts() as got:
        for state in sampler.sample(p0, iterations=steps, **kwargs):  # noqa: B007
            if got:
                break
    if got:
        raise KeyboardInterrupt(got[0])
    return state
