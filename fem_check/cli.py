"""``python -m fem_check COMMAND ...``: a thin dispatcher (see :mod:`semianalytic.cli`)."""

from __future__ import annotations

from semianalytic.cli import dispatch

COMMANDS: dict[str, tuple[str, str]] = {
    "verify": ("fem_check.verify", "FEM vs BEM: added mass and A, B, C for a case; writes a verification report"),
    "cavity": ("fem_check.cavity", "FEM of the pressurised elastic spherical cavity and the Part II zones vs analytic"),
    "rod": ("fem_check.rod", "FEM of the suddenly loaded free-free rod vs the series solution (Part I, eq. 24)"),
    "plate": ("fem_check.plate_report", "plate coefficients (issue 23): slab BEM vs an exact solution, the half-space and FEM; writes reports/"),  # noqa: E501
    "bench": ("benchmarks.fem", "time-to-accuracy of FEM (P1, P2) against the BEM; writes reports/"),
}


def main(argv: list[str] | None = None) -> int:
    return dispatch("python -m fem_check", COMMANDS, argv)
