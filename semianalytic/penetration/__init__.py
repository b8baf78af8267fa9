"""Penetration dynamics of Part I: target resistance R_t (eqs. (16)-(19), Part IV eq. (6)),
the equation of motion (11), the elastic projectile (eqs. (24)-(30')), the critical impact
velocity (eqs. (31)-(36)), peer models and the validation against experiments.

Modules: :mod:`.resistance`, :mod:`.motion`, :mod:`.rod`, :mod:`.elastic`, :mod:`.critical`,
:mod:`.peers`, :mod:`.curve` (all models for many striking velocities), :mod:`.validation`
(models); :mod:`.case` (the ``[target.resistance]`` and ``[data]`` schemas), :mod:`.options`;
:mod:`.evaluate` (everything ``penetrate`` prints), :mod:`.cli`, :mod:`.report`.  Importing this
package is cheap.
"""

__all__ = ["sweep_support"]


def sweep_support(case, coefficients, striking_velocities, full: bool = False):
    """Columns for the sweep kernel: see :func:`semianalytic.penetration.curve.sweep_support`."""
    from semianalytic.penetration.curve import sweep_support as _impl

    return _impl(case, coefficients, striking_velocities, full=full)
