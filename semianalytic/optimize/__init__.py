"""Nose-shape optimisation with the BEM in the loop (issue 14): ``python -m semianalytic optimize``.

- :mod:`~semianalytic.optimize.model`: pure functions: the constraints (fixed mass, fixed
  length) applied to a nose, the objectives reduced from the depths or the deep drag;
- :mod:`~semianalytic.optimize.case`: ``--vary KEY=LOW:HIGH``, ``--objective``, ``--constraint``
  parsed and checked against the case (exit 2 naming the flag);
- :mod:`~semianalytic.optimize.evaluate`: one design -> its coefficient table (cached by the
  geometry hash) -> the objective; the differential-evolution driver on the sweep's dask
  layer; the confirmation grid and the classic noses;
- :mod:`~semianalytic.optimize.report`: optimum and history (JSON, CSV), the nose figure, Markdown;
- :mod:`~semianalytic.optimize.cli`: the thin command.
"""
