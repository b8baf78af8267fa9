"""Suite-wide settings.

Hypothesis: the ``ci`` profile (loaded when ``CI`` is set, as ``.ci/run`` does, or with
``HYPOTHESIS_PROFILE=ci``) derandomizes every property test, so a CI run is repeatable; the
``dev`` profile explores new examples on each run.  Both print the blob that reproduces a
failure (``@reproduce_failure``), and the seed is printed by hypothesis's own report.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

try:
    from hypothesis import settings
except ImportError:  # the property tests skip themselves without hypothesis
    settings = None

if settings is not None:
    settings.register_profile("ci", derandomize=True, print_blob=True, deadline=None)
    settings.register_profile("dev", print_blob=True, deadline=None)
    settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE") or ("ci" if os.environ.get("CI") else "dev"))


# --------------------------------------------------------------------------------------------
# The inner loop.  `make check` runs the suite without the `long` tests; `make test` (and so CI)
# runs everything that is not `slow`.  A test function is `long` when its measured duration (setup,
# call and teardown, summed over its parameters, one worker) in tests/durations.json is at least
# LONG_SECONDS.  The file is measured, not edited: `make durations` (pytest --write-durations
# tests/durations.json) rewrites the entries of the tests it ran, in quiet-core seconds (the
# measured seconds times cores / load average over the run, when the load exceeds the cores); a
# test not in the file is short until it is measured, except those of "long_until_measured" (the
# hand list this replaced, for the tests not yet measured: a run removes the ones it measures).
DURATIONS = Path(__file__).with_name("durations.json")
LONG_SECONDS = 1.5  # quiet-core seconds: the check set then sums to about 73 s of one core (37 s on two)


def _test_id(nodeid: str) -> str:
    return nodeid.split("[", 1)[0]


def measured_durations() -> dict[str, float]:
    """Seconds per test function, and per file the longest setup of one of its functions: a slow
    shared (module-scoped) fixture is paid by whichever test of the file runs first, so such a file
    is long as a whole."""
    if not DURATIONS.is_file():
        return {}
    doc = json.loads(DURATIONS.read_text())
    out = {k: float(v) for k, v in doc["seconds"].items()}
    out.update({k: math.inf for k in doc.get("long_until_measured", []) if k not in out})
    for k, v in doc.get("setup_seconds", {}).items():
        f = k.split("::", 1)[0]
        out[f] = max(out.get(f, 0.0), float(v))
    return out


def pytest_addoption(parser):
    parser.addoption("--write-durations", metavar="PATH", default=None,
                     help="write the measured duration of every test function run into PATH (JSON; merged)")


def pytest_configure(config):
    config._durations_seen = {}
    config._durations_failed = set()
    config._durations_setup = {}  # a test that failed or errored is not measured (an error is quick)


def pytest_collection_modifyitems(config, items):
    import pytest

    seconds = measured_durations()
    for item in items:
        test = _test_id(item.nodeid)
        if max(seconds.get(test, 0.0), seconds.get(test.split("::", 1)[0], 0.0)) >= LONG_SECONDS:
            item.add_marker(pytest.mark.long)


def pytest_runtest_logreport(report):
    seen = getattr(_CONFIG, "_durations_seen", None)
    if seen is not None:
        key = _test_id(report.nodeid)
        seen[key] = seen.get(key, 0.0) + float(report.duration)
        if report.when == "setup":
            setups = _CONFIG._durations_setup
            setups[key] = max(setups.get(key, 0.0), float(report.duration))
        if report.failed:
            _CONFIG._durations_failed.add(key)
        if report.when == "teardown" and _CONFIG.getoption("--write-durations"):
            _write_durations(_CONFIG)  # after every test: an interrupted run keeps what it measured


_CONFIG = None


def pytest_sessionstart(session):
    global _CONFIG
    _CONFIG = session.config
    session.config._durations_load0 = os.getloadavg()[0]


def pytest_sessionfinish(session, exitstatus):
    if session.config.getoption("--write-durations"):
        _write_durations(session.config)


def _write_durations(config):
    """Merge this run's durations into the --write-durations file (xdist: the controller writes)."""
    if hasattr(config, "workerinput"):
        return
    path = Path(config.getoption("--write-durations"))
    if not hasattr(config, "_durations_base"):  # the file as it was before this run
        config._durations_base = json.loads(path.read_text()) if path.is_file() else {}
    old = config._durations_base
    load = 0.5 * (config._durations_load0 + os.getloadavg()[0])
    cores = os.cpu_count() or 1
    factor = min(1.0, cores / load) if load > 0 else 1.0
    seen = {k: v for k, v in config._durations_seen.items() if k not in config._durations_failed}
    seconds = dict(old.get("seconds", {}))
    seconds.update({k: round(v * factor, 2) for k, v in seen.items()})
    setup = dict(old.get("setup_seconds", {}))
    setup.update({k: round(v * factor, 2) for k, v in config._durations_setup.items()
                  if k in seen and v * factor >= 0.5})
    setup = {k: v for k, v in setup.items() if v >= 0.5}
    runs = [*old.get("runs", []), {"tests": len(seen), "load_average": round(load, 1), "cores": cores,
                                   "factor": round(factor, 3)}]
    doc = {"about": "quiet-core seconds per test function (setup + call + teardown, all parameters, one "
                    "worker; measured seconds times cores / load average when the load exceeds the cores); "
                    "tests/conftest.py marks those >= LONG_SECONDS as long; written by "
                    "`pytest --write-durations tests/durations.json` (make durations)",
           "runs": runs[-10:],
           "long_until_measured": sorted(e for e in old.get("long_until_measured", []) if e not in seconds
                                         and not any(k.startswith(e + "::") for k in seen)),
           "setup_seconds": dict(sorted(setup.items())),
           "seconds": dict(sorted(seconds.items()))}
    path.write_text(json.dumps(doc, indent=1) + "\n")
