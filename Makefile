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

$(VENV)/.installed: pyproject.toml
	test -x $(PY) || python3 -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check -e ".[test]"
	touch $@

demo: $(VENV)/.installed
	$(PY) -m semianalytic demo

# The import contracts of pyproject.toml (layers, pure models, fem_check kept apart), then the suite.
test: $(VENV)/.installed
	$(VENV)/bin/lint-imports --no-cache
	$(PY) -m pytest -q -n 2 --dist loadfile

# Long convergence studies and benchmarks; they write into reports/.
bench: $(VENV)/.installed
	$(PY) -m semianalytic bench-bem --out reports --force

reports: bench
	$(PY) -m pytest -q -m slow
	for c in fig5_ogive fig5_sphere body_sphere body_spheroid_7to1; do $(PY) -m fem_check verify cases/$$c.toml --out reports --force || exit 1; done
	$(PY) -m fem_check rod cases/fig9_ogive_7075T651.toml --out reports --force
	$(PY) -m fem_check cavity --out reports --force
	$(PY) -m fem_check bench --out reports --force
	$(PY) tests/hardening_tally.py --out reports

clean:
	rm -rf $(VENV) meshes/cache .pytest_cache
