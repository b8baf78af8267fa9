"""Parameter sweeps and Monte-Carlo studies over case files, executed with dask (issue 6).

- :mod:`~semianalytic.sweep.spec`: ``--vary`` axes and ``--sample`` distributions -> case ids;
- :mod:`~semianalytic.sweep.kernels`: what is computed per case (adapters onto the models);
- :mod:`~semianalytic.sweep.engine`: batches on a dask cluster, append-as-completed, resume;
- :mod:`~semianalytic.sweep.store`: the results file (CSV or Parquet parts);
- :mod:`~semianalytic.sweep.cli`: the ``sweep`` command;
- :mod:`~benchmarks.sweep`: the throughput benchmark (``reports/bench_sweep.md``).
"""
