"""The pipeline of ``python -m semianalytic run CASE.toml --out DIR``: which analyses a case
asks for, computed by the models and handed to :mod:`semianalytic.report` as documents.

- :mod:`~semianalytic.run.cli`: the ``run`` command (parses, calls :func:`~semianalytic.run.pipeline.run_case`, prints);
- :mod:`~semianalytic.run.pipeline`: :func:`run_case`: validate, preflight every step, run them into a staged folder;
- :mod:`~semianalytic.run.case`: the optional ``[run]`` section (``ANALYSES``, ``RunSection``);
- :mod:`~semianalytic.run.context`: what the steps of one run share;
- :mod:`~semianalytic.run.registry`: :class:`Step`, the registry and step selection;
- the steps, one module per family: :mod:`.bodies` (added mass), :mod:`.fields` (BEM velocity
  field and the FEM field of fem_check, the only import of :mod:`fem_check.api`),
  :mod:`.part1` (coefficients, penetration, critical velocity, validation), :mod:`.part2`
  (cavity), :mod:`.parts34` (ballistic limit, nanostrength);
- :mod:`~benchmarks.run`: run times -> ``reports/bench_run.md``.

Importing this package is cheap; :mod:`.pipeline` imports the steps.
"""
