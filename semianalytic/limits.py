"""Physical bounds of the inputs every layer checks against (SI units)."""

from __future__ import annotations

MAX_STRIKING_VELOCITY = 12e3
"""The generic physical bound of a striking velocity [m/s] (each model warns about its own, lower
validity): the fastest laboratory launchers (two-stage light-gas guns) reach about 10 km/s, and every
model of Part I assumes a projectile that stays intact, which it does not at hypervelocity.  Above
12 km/s a case is refused (exit status 2) rather than warned."""

MIN_STRIKING_VELOCITY = 1e-3
"""Below 1 mm/s [m/s] an impact is a quasi-static indentation (and the ODE of the motion has no
resolvable time scale): refused."""

SOLID_STRIKING_VELOCITY = 6e3
"""Above 6 km/s [m/s] the shock pressure of a metal-on-metal impact exceeds ~100 GPa, the projectile
melts or vaporises, and no model here (each assumes a solid projectile) reaches: warned."""
