# Two entry points (see README): `make demo` and `make test`.
VENV   ?= .venv
PY     := $(VENV)/bin/python
# The second leg of `make test`: the newest supported Python (requires-python in pyproject.toml),
# from pyenv (`pyenv install 3.13`) unless PYTHON313 names an interpreter.
VENV313   ?= .venv313
PYENV_ROOT ?= $(shell pyenv root 2>/dev/null || echo $(HOME)/.pyenv)
PYTHON313 ?= $(lastword $(sort $(wildcard $(PYENV_ROOT)/versions/3.13*/bin/python3.13)))
# Small dense BEM solves are much slower with threaded BLAS on a loaded 2-core machine.
export OPENBLAS_NUM_THREADS ?= 1
export OMP_NUM_THREADS ?= 1
export MKL_NUM_THREADS ?= 1
export MPLBACKEND ?= Agg
export PYVISTA_OFF_SCREEN ?= true

.PHONY: demo test test-311 test-313 check lint durations bench reports clean

# The browser test (tests/test_browser_report.py) drives Debian's Chromium through playwright's
# executable_path (never `playwright install`: no browser download); installed here when missing.
export CHROMIUM ?= /usr/bin/chromium
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

# An editable install builds the compiled ring kernels into semianalytic/bem/ (setup.py): again
# whenever _ring.c changes (a library built from another version of it is never loaded).
BUILD_INPUTS := pyproject.toml setup.py semianalytic/bem/_ring.c

# `make demo`: only what the package needs to run (no test or docs tools), and no byte-compiling of
# every installed module (half of pip's CPU time; the modules a command imports compile on first use).
$(VENV)/.runtime: $(BUILD_INPUTS)
	test -x $(PY) || python3 -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check --no-compile -e .
	touch $@

$(VENV)/.installed: $(BUILD_INPUTS)
	test -x $(PY) || python3 -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check -e ".[test]"
	touch $@ $(VENV)/.runtime

# Before anything runs: the 3.13 leg's interpreter is there, or one line says how to get it.
.PHONY: python313
python313:
	@test -n "$(PYTHON313)" && test -x "$(PYTHON313)" || { echo "error: make test needs Python 3.13 for its second leg: none under $(PYENV_ROOT)/versions/3.13* (pyenv install 3.13, or PYTHON313=/path/to/python3.13)" >&2; exit 2; }

# The 3.13 leg takes the newest releases the dependency ranges allow (--upgrade, eager).
$(VENV313)/.installed: $(BUILD_INPUTS) | python313
	test -x $(VENV313)/bin/python || $(PYTHON313) -m venv $(VENV313)
	$(VENV313)/bin/python -m pip install --quiet --disable-pip-version-check --upgrade --upgrade-strategy eager -e ".[test]"
	touch $@

demo: $(VENV)/.runtime
	$(PY) -m semianalytic demo

# The whole suite on the oldest and the newest supported Python: 3.11 with the compiled kernels,
# 3.13 on the numpy kernels (SEMIANALYTIC_KERNEL=numpy: the fallback of a build without a C
# compiler runs the whole suite too).  The import contracts of pyproject.toml first.
test: python313 test-311 test-313

test-311: $(VENV)/.installed $(CHROMIUM)
	$(VENV)/bin/lint-imports --no-cache
	$(PY) -m pytest -q -n 2 --dist loadfile

test-313: $(VENV313)/.installed $(CHROMIUM)
	SEMIANALYTIC_KERNEL=numpy $(VENV313)/bin/python -m pytest -q -n 2 --dist loadfile

# The inner loop (at most a minute on two idle cores), on 3.11: lint, then the suite without the `long`
# tests (measured: tests/durations.json, tests/conftest.py LONG_SECONDS; `make test` runs them too).
check: $(VENV)/.installed lint
	$(VENV)/bin/lint-imports --no-cache
	$(PY) -m pytest -q -n 2 --dist loadfile -m "not slow and not long"

# ruff and mypy as configured in pyproject.toml; the mutation check's targets still exist (tools/lint_fix.sh).
lint: $(VENV)/.installed
	$(VENV)/bin/ruff check --quiet . && $(VENV)/bin/mypy && $(PY) tools/mutation_check.py --targets

# Re-measure what is `long`: every test's duration into tests/durations.json (one worker, the whole suite).
durations: $(VENV)/.installed $(CHROMIUM)
	$(PY) -m pytest -q -p no:cacheprovider --write-durations tests/durations.json

$(CHROMIUM):
	$(SUDO) apt-get update
	$(SUDO) apt-get install -y chromium

# Long convergence studies and benchmarks; they write into reports/.
bench: $(VENV)/.installed
	$(PY) -m semianalytic bench-bem --out reports --force

reports: bench
	$(PY) -m pytest -q -m slow
	for c in fig5_ogive fig5_sphere body_sphere body_spheroid_7to1; do $(PY) -m fem_check verify cases/$$c.toml --out reports --force || exit 1; done
	$(PY) -m fem_check verify cases/cone30.toml --depths 0.5,2,5,20 --out reports --force
	$(PY) -m fem_check verify cases/flat_nose.toml --depths 0.5,2,5,20 --name fem_verify_flat --out reports --force
	$(PY) -m fem_check rod cases/fig9_ogive_7075T651.toml --out reports --force
	$(PY) -m fem_check cavity --out reports --force
	$(PY) -m fem_check bench --out reports --force
	$(PY) -m fem_check plate --out reports --force
	$(PY) tests/hardening_tally.py --out reports

clean:
	rm -rf $(VENV) $(VENV313) meshes/cache .pytest_cache site build dist semianalytic/bem/_ring.*.so

# The documentation site (MkDocs + mkdocstrings, mkdocs.yml) into site/ (ignored by git);
# warnings are errors, as in tests/test_docs.py.
.PHONY: docs
docs: $(VENV)/.installed
	$(VENV)/bin/mkdocs build --strict --site-dir site

# Every committed report by the command it names ("Generated by ..."); tests/test_report_freshness.py
# fails on a stale one.  Minutes of work (the FEM studies and benchmarks are the slow part).
VALIDATION_CASES := cases/piekutowski1999_var4340.toml cases/piekutowski1999_aermet100.toml \
	cases/piekutowski1999_var4340_Y276.toml cases/piekutowski1999_aermet100_Y276.toml \
	cases/fig9_ogive_7075T651.toml cases/fig9_sphere_7075T651.toml cases/fig14_sphere_6061T651.toml \
	cases/fig15a_ogive_6061T651.toml cases/fig15b_ogive_7075T651.toml cases/fig16_limestone.toml \
	cases/appendix_yield_stress.toml
.PHONY: report-docs
reports: report-docs
report-docs: $(VENV)/.installed
	$(PY) -m semianalytic run cases/fig12_sphere_velocity_field.toml --out reports/fig12_velocity_field --force
	$(PY) -m semianalytic run cases/fig13_ogive_velocity_field.toml --out reports/fig13_velocity_field --force
	$(PY) -m semianalytic.commands.ballistic_limit.report --out reports --force
	$(PY) -m semianalytic.commands.cavity.report --out reports --force
	$(PY) -m semianalytic penetrate $(VALIDATION_CASES) --report reports --force
	$(PY) -m semianalytic perforate cases/perforation_ogive_6061T651.toml cases/perforation_ogive_6061T651_constant.toml cases/perforation_part4_table3.toml cases/perforation_steel12_hemispherical.toml --report reports
	$(PY) -m semianalytic nanostrength cases/part3_nanostrength.toml --report reports --force
	$(PY) -m benchmarks.run --force
	$(PY) -m benchmarks.sweep --force
	$(PY) -m semianalytic calibrate cases/piekutowski1999_var4340.toml --cross-validate --diagnose --steps 12000 --out reports/calibration_piekutowski1999 --report reports/validation.md --force --quiet
	$(PY) -m semianalytic calibrate cases/piekutowski1999_var4340_eroding.toml --cross-validate --out reports/calibration_piekutowski1999_eroding --force --quiet
	$(PY) -m semianalytic calibrate cases/piekutowski1999_var4340_hardness_regimes.toml --model regimes --cross-validate --transfer cases/piekutowski1999_aermet100_hardness_regimes.toml --out reports/calibration_piekutowski1999_regimes --report reports/validation_regimes.md --force
	$(PY) -m semianalytic optimize cases/optimize_fig5_into_fig15a.toml --report reports/optimize_constrained_crh.md --force --vary projectile.crh=1:12 --objective depth --constraint length --table-depths 20 --table-nose-lengths 40 --scheduler inline --no-progress
	$(PY) -m semianalytic optimize cases/optimize_power_into_fig15a.toml --report reports/optimize_constrained_power.md --force --vary projectile.exponent=0.3:1 --objective depth --constraint mass --constraint length --scheduler inline --no-progress
	$(PY) -m semianalytic optimize cases/optimize_spline_into_fig15a.toml --report reports/optimize_constrained_spline.md --force --vary projectile.control_radii.0=0.3:0.6 --vary projectile.control_radii.1=0.5:0.8 --vary projectile.control_radii.2=0.7:0.95 --objective depth --constraint mass --constraint length --method de --popsize 6 --maxiter 30 --confirm 3 --scheduler inline --no-progress
	$(PY) -m semianalytic optimize cases/optimize_power_deep_drag.toml --report reports/optimize_power.md --force --vary projectile.exponent=0.3:1 --objective deep_drag --scheduler inline --no-progress
	$(PY) -m benchmarks.optimize --force
