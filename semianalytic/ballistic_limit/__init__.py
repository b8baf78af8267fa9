"""Part IV: ballistic limit velocity V_cr.

- :mod:`.theory`       rigid projectile, eqs. (1)-(6) (errata 22-24); ``resistance_part4(Y, E)``
- :mod:`.indentation`  plasticity characteristic delta_H from a Vickers test, eqs. (10)-(14)
- :mod:`.empirical`    empirical laws (7)-(9), refitting C1-C3, composites, Table 4 criticals
- :mod:`.energy`       plastic-deformation energy, eqs. (15)-(17)
- :mod:`.shots`        a shot (target + projectile) and its predicted limits
- :mod:`.tables`       Tables 1-5 (``cases/part4_*.csv``) and generic shot tables
- :mod:`.paper`        the paper's own arithmetic behind Tables 2-4 (errata 25-27)
"""

from semianalytic.ballistic_limit.theory import ballistic_limit, resistance_part4

__all__ = ["ballistic_limit", "resistance_part4"]
