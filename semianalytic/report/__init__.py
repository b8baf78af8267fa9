"""Case-driven runs and their reports (issue 6).

``python -m semianalytic run CASE.toml --out DIR`` runs every analysis the case asks for and
writes ``DIR/results.json``, ``DIR/report.md`` and ``DIR/report.html`` with PNG figures that
mirror the paper's (Part I Figs. 6-16), VTK files of the velocity field (Part I eq. (23),
Figs. 12-13) and a pyvista render.  Modules:

- :mod:`~semianalytic.report.case`: the optional ``[run]`` section;
- :mod:`~semianalytic.report.output`: the output folder, staged and swapped in atomically;
- :mod:`~semianalytic.report.document`: report blocks rendered to Markdown;
- :mod:`~semianalytic.report.html`: the same blocks rendered to a self-contained HTML page;
- :mod:`~semianalytic.report.figures`: matplotlib (object API) figures;
- :mod:`~semianalytic.report.vtk`: the velocity field on a revolved grid -> ``.vtu``;
- :mod:`~semianalytic.report.context`: what the steps of one run share;
- :mod:`~semianalytic.report.steps` (+ :mod:`.steps_part1`, :mod:`.steps_other`): one step per
  analysis (added mass, coefficients, penetration, critical velocity, validation, velocity
  field, FEM field, cavity, ballistic limit, nanostrength);
- :mod:`~semianalytic.report.run`: the ``run`` command;
- :mod:`~semianalytic.report.benchmark`: run times -> ``reports/bench_run.md``.
"""
