"""``python -m semianalytic fit-constants DATA [--json] [--method mean|least-squares]
[--areal-mass mass-per-area|cylinder|paper-implied]``.

Refits C1, C2, C3 of Part IV, eqs. (7)-(9) from a shot table (CSV, the columns of
``cases/part4_table3.csv``) over its single-plate rows with a measured V_cr (rows with a
"<"/">" qualifier and composite rows are left out).  ``mean`` is the paper's rule (arithmetic
mean of V^2/x); ``least-squares`` minimises the squared error in V^2.  ``paper-implied`` takes
each row's areal mass from its printed eq. (7) value (needs ``printed_V_eq7_m_s``): with it the
paper's constants 1.52e6, 0.79e6, 1.69e6 come back (errata 26).
"""

from __future__ import annotations

import argparse
import builtins
import functools

__all__ = ["add_arguments", "run"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("data", help="shot table (CSV with '#' header lines)")
    from semianalytic.report.formats import add_format_arguments

    add_format_arguments(parser, json_help="print one JSON object (keys carry units)")
    parser.add_argument("--method", choices=("mean", "least-squares"), default="mean")
    parser.add_argument("--areal-mass", choices=("mass-per-area", "cylinder", "paper-implied"),
                        default="mass-per-area", help="projectile areal mass P (default m/(pi d^2/4), errata 26)")


def run(args) -> int:
    from semianalytic.ballistic_limit.empirical import PAPER_CONSTANTS, fit_constants
    from semianalytic.ballistic_limit.shots import fit_sample, is_fittable, projectile_areal_mass
    from semianalytic.ballistic_limit.tables import load_shots, read_rows
    from semianalytic.errors import InputError
    from semianalytic.report.formats import Output, chosen_format, emit

    fmt = chosen_format(args)
    shots = load_shots(args.data)
    printed7: list[float | None] = [None] * len(shots)
    if args.areal_mass == "paper-implied":
        rows = read_rows(args.data)
        if "printed_V_eq7_m_s" not in rows[0][1]:
            raise InputError("--areal-mass", "paper-implied needs a 'printed_V_eq7_m_s' column in the data")
        for i, (lineno, row) in enumerate(rows):
            text = row["printed_V_eq7_m_s"]
            try:
                printed7[i] = float(text) if text else None
            except ValueError:
                raise InputError(f"line {lineno}:printed_V_eq7_m_s", f"expected a number; got {text!r}") from None
    samples, skipped = [], []
    for shot, v7 in zip(shots, printed7):
        if not is_fittable(shot) or (args.areal_mass == "paper-implied" and v7 is None):
            skipped.append(shot.name)
            continue
        if args.areal_mass == "paper-implied":  # eq. (7) solved for P with the paper's C1
            P = PAPER_CONSTANTS.C1 * shot.target_density * shot.thickness / v7**2
        else:
            P = projectile_areal_mass(shot, args.areal_mass)
        samples.append(fit_sample(shot, P))
    if not samples:
        raise InputError("data", "no single-plate row with a measured V_cr to fit")
    fit = fit_constants(samples, args.method)
    out = {"data": str(args.data), "areal_mass_rule": args.areal_mass, **fit.to_json(), "skipped": skipped}
    emit(Output(data=out, json_options={"indent": 2, "allow_nan": False},
                text=lambda s: _text(fit, args, skipped, s)), fmt)
    return 0


def _text(fit, args, skipped, stream) -> None:
    print = functools.partial(builtins.print, file=stream)
    c = fit.constants
    print(f"{fit.n} rows ({args.method}, P = {args.areal_mass}); skipped: {', '.join(skipped) or 'none'}")
    print(f"C1 = {c.C1:.4g} m^2/s^2           rms error in V {fit.rms_error[0]:.1%}, worst {fit.max_error[0]:+.1%}")
    print(f"C2 = {c.C2_per_GPa:.4g} (m/s)^2/GPa = {c.C2:.4g} m^3/kg   rms {fit.rms_error[1]:.1%}, worst {fit.max_error[1]:+.1%}")
    print(f"C3 = {c.C3:.4g} m^2/s^2           rms error in V {fit.rms_error[2]:.1%}, worst {fit.max_error[2]:+.1%}")
