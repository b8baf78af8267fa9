"""The ``[regimes]`` case section: every choice of the regimes model set as a case-file key.

Example::

    [regimes]
    onset = "nose_meyer"         # rigid -> deforming (penetration/regime.py ONSET_CRITERIA)
    erosion = "nose_meyer"       # deforming -> eroding (EROSION_CRITERIA)
    nose_load = "part1"          # the nose's load: part1, forrestal or tip (penetration/nose_load.py)
    resistance = "tate1986"      # R_t of the eroding rod: part1 or tate1986
    rod_strength = "static_ultimate"   # Y_p of the eroding rod
    deforming = "two_stage"      # depth in the deforming band
    deformed_depth = "forrestal" # depth of a bent rod that keeps its nose: part1 or forrestal
    rigid_depth = "part1"        # depth of the rigid rod: part1 or forrestal
    discrepancy = "shared"       # depth scatter: shared or per_regime

A key left out takes the default of ``semianalytic.calibration.regimes.Options`` (chosen by
transfer, reports/validation_regimes.md).  ``calibrate --model regimes`` fits this model set and
``calibrate --option KEY=VALUE`` overrides a key; ``penetrate`` without a posterior uses
``nose_load``, ``resistance``, ``rod_strength`` and ``deformed_depth`` of its ``nose_load`` rule.
"""

from __future__ import annotations

from typing import Literal

from semianalytic.penetration import regime as rg
from semianalytic.penetration.nose_load import NOSE_LOADS
from semianalytic.schema import Section

__all__ = ["RegimesSection"]

_DEPTHS = ("part1", "forrestal")


class RegimesSection(Section):
    """``[regimes]`` (see the module docstring)."""

    onset: Literal[rg.ONSET_CRITERIA] | None = None  # type: ignore[valid-type]
    erosion: Literal[rg.EROSION_CRITERIA] | None = None  # type: ignore[valid-type]
    nose_load: Literal[NOSE_LOADS] | None = None  # type: ignore[valid-type]
    resistance: Literal[rg.RESISTANCE_RELATIONS] | None = None  # type: ignore[valid-type]
    rod_strength: Literal[rg.ROD_STRENGTHS] | None = None  # type: ignore[valid-type]
    deforming: Literal[rg.DEFORMING_MODELS] | None = None  # type: ignore[valid-type]
    deformed_depth: Literal[_DEPTHS] | None = None  # type: ignore[valid-type]
    rigid_depth: Literal[_DEPTHS] | None = None  # type: ignore[valid-type]
    discrepancy: Literal[("shared", "per_regime")] | None = None  # type: ignore[valid-type]

    def choices(self) -> dict:
        """The keys given in the case (None ones left out)."""
        return {k: v for k, v in self.model_dump().items() if v is not None}
