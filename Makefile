# Two entry points (see README): `make demo` and `make test`.
VENV   ?= .venv
PY     := $(VENV)/bin/python
# Small dense BEM solves are much slower with threaded BLAS on a loaded 2-core machine.
export OPENBLAS_NUM_THREADS ?= 1
export OMP_NUM_THREADS ?= 1
export MKL_NUM_THREADS ?= 1
export MPLBACKEND ?= Agg
export PYVISTA_OFF_SCREEN ?= true

.PHONY: demo test bench reports clean

# The browser test (tests/test_browser_report.py) drives Debian's Chromium through playwright's
# executable_path (never `playwright install`: no browser download); installed here when missing.
export CHROMIUM ?= /usr/bin/chromium
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

$(VENV)/.installed: pyproject.toml
	test -x $(PY) || python3 -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check -e ".[test]"
	touch $@

demo: $(VENV)/.installed
	$(PY) -m semianalytic demo

# The import contracts of pyproject.toml (layers, pure models, fem_check kept apart), then the suite.
test: $(VENV)/.installed $(CHROMIUM)
	$(VENV)/bin/lint-imports --no-cache
	$(PY) -m pytest -q -n 2 --dist loadfile

$(CHROMIUM):
	$(SUDO) apt-get update
	$(SUDO) apt-get install -y chromium

# Long convergence studies and benchmarks; they write into reports/.
bench: $(VENV)/.installed
	$(PY) -m semianalytic bench-bem --force

reports: bench
	$(PY) -m pytest -q -m slow

clean:
	rm -rf $(VENV) meshes/cache .pytest_cache
