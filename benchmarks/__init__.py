"""Benchmarks and studies of the project (not installed: a wheel holds what users import).

Run from a checkout: ``python -m benchmarks.sweep``, ``python -m benchmarks.run``,
``python -m benchmarks.optimize``, ``python -m benchmarks.startup``, ``python -m benchmarks.fem_verify``;
``python -m semianalytic bench-bem`` and ``python -m fem_check bench`` run :mod:`benchmarks.bench_bem`
and :mod:`benchmarks.fem` (from an installed wheel they exit 2: no benchmarks there).  Their reports
go into the checkout's ``reports/`` (``make reports``, ``make report-docs``) or the folder given.
"""
