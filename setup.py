"""What pyproject.toml cannot say statically: the packages (those of semianalytic and fem_check,
and the bundled cases: the folder cases/ installed as the package semianalytic.cases, so that
cases/ stays the real folder of a checkout) and the compiled ring kernels
(semianalytic/bem/_ring.c), built when the package is built or installed.

Everything else is in pyproject.toml.  The library is a plain C shared object (no Python API) that
semianalytic/native.py loads with ctypes from the package folder; it carries the SHA-256 of its
source, so that a library built from another version of _ring.c is never used.  The extension is
optional: without a C compiler the build goes on and the numpy kernels are used (docs/packaging.md).
"""

import hashlib
from pathlib import Path

from setuptools import Extension, find_packages, setup

# IEEE arithmetic with every operation rounded as written (semianalytic/native.py says why);
# the same flags for the baseline build of tests/test_ring_kernel_c.py.
RING_CFLAGS = ["-O3", "-fno-fast-math", "-ffp-contract=off", "-fno-math-errno"]
RING_SOURCE = "semianalytic/bem/_ring.c"


def ring_extension() -> Extension:
    sha = hashlib.sha256((Path(__file__).resolve().parent / RING_SOURCE).read_bytes()).hexdigest()
    return Extension("semianalytic.bem._ring", [RING_SOURCE], extra_compile_args=RING_CFLAGS, libraries=["m"],
                     define_macros=[("RING_SOURCE_SHA256", f'"{sha}"')], optional=True)


PACKAGES = [*find_packages(include=["semianalytic", "semianalytic.*", "fem_check", "fem_check.*"]), "semianalytic.cases"]
PACKAGE_DIR = {"semianalytic.cases": "cases"}
PACKAGE_DATA = {"semianalytic": ["data/*", "bem/*.c"], "semianalytic.cases": ["*.toml", "*.csv", "*.md"]}

if __name__ == "__main__":
    setup(packages=PACKAGES, package_dir=PACKAGE_DIR, package_data=PACKAGE_DATA, ext_modules=[ring_extension()])
