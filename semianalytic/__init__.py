"""Semi-analytic models of penetration mechanics.

Implements the paper "Mechanical, mathematical and computer modeling in penetration
mechanics IV": Part I (BEM potential flow, drag coefficients A, B, C, equation of motion,
elastic oscillations, critical impact velocity), Part II (brittle spherical cavity
expansion), Part III (theoretical strength of diamond-like crystals) and Part IV
(ballistic limit velocity).  SI units throughout the code; unit strings at the edges.
"""

__version__ = "0.1.0"
