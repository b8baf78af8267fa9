"""Suite-wide settings.

Hypothesis: the ``ci`` profile (loaded when ``CI`` is set, as ``.ci/run`` does, or with
``HYPOTHESIS_PROFILE=ci``) derandomizes every property test, so a CI run is repeatable; the
``dev`` profile explores new examples on each run.  Both print the blob that reproduces a
failure (``@reproduce_failure``), and the seed is printed by hypothesis's own report.
"""

from __future__ import annotations

import os

try:
    from hypothesis import settings
except ImportError:  # the property tests skip themselves without hypothesis
    settings = None

if settings is not None:
    settings.register_profile("ci", derandomize=True, print_blob=True, deadline=None)
    settings.register_profile("dev", print_blob=True, deadline=None)
    settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE") or ("ci" if os.environ.get("CI") else "dev"))
