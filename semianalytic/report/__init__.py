"""Documents from results: this package computes nothing (issue 16).

The ``run`` pipeline (:mod:`semianalytic.run`) and the per-package report commands compute
with the models and hand the results to these builders:

- :mod:`~semianalytic.report.output`: the output folder, staged and swapped in atomically;
- :mod:`~semianalytic.report.document`: report blocks rendered to Markdown;
- :mod:`~semianalytic.report.html`: the same blocks rendered to a self-contained HTML page
  (figures inline as data: URIs);
- :mod:`~semianalytic.report.figures`: matplotlib (object API) figures;
- :mod:`~semianalytic.report.vtk`: fields already computed -> ``.vtu`` (meshio) and a pyvista render;
- :mod:`~semianalytic.report.provenance`: the command and version that made a report, the case
  by file name and SHA-256 (no machine paths in any output).
"""
