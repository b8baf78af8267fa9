"""Perforation of finite and layered targets (issue 23): Part I, eq. (11) through plates with
a back face, residual velocity, the ballistic limit found by the model itself
(``ballistic_limit_search``), the thin-plate models and failure modes (:mod:`.thin_plate`), the
Lambert-Jonas fit.

Models: :mod:`.model` (pure; ``ballistic_limit`` and ``residual_velocity`` are the entry points
for sweeps and the optimiser); case layer: :mod:`.case`; the ``perforate`` command:
:mod:`.evaluate` and :mod:`.cli`; the validation report: :mod:`.report`.  The model is imported
on first use (the case layer imports :mod:`.case` at start-up).
"""

__all__ = ["ballistic_limit", "ballistic_limit_search", "residual_velocity"]


def __getattr__(name):
    if name in __all__:
        from semianalytic.perforation import model

        return getattr(model, name)
    raise AttributeError(name)
