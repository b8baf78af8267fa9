"""``python -m semianalytic optimize CASE --out DIR --vary KEY=LOW:HIGH ... --objective depth|deep_drag``.

Nose-shape optimisation with the BEM in the loop (see :mod:`semianalytic.optimize.evaluate`).
Example (Fig. 5 projectile, mass fixed, into the Fig. 15a target)::

    python -m semianalytic optimize cases/optimize_fig5_into_fig15a.toml --out out/opt \\
        --vary projectile.crh=0.5:8 --objective depth --constraint mass
"""

from __future__ import annotations

import argparse
import shlex
import sys

from semianalytic.errors import InputError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("case", help="case file (TOML) with the starting projectile (and target, impact for depth)")
    parser.add_argument("--out", default=None, help="output folder: optimum.json, history.json/.csv, noses.png, report.md")
    parser.add_argument("--report", default=None, help="also write a Markdown report (and its figure beside it) here")
    parser.add_argument("--force", action="store_true", help="overwrite --out / --report")
    parser.add_argument("--vary", action="append", default=[], metavar="KEY=LOW:HIGH",
                        help="nose parameter and bounds: projectile.crh, projectile.half_angle, "
                             "projectile.meplat_diameter, projectile.tip_radius, projectile.exponent, "
                             "projectile.nose_length, projectile.control_radii.K (a spline nose's K-th control radius, 0-based) (repeatable)")  # noqa: E501
    parser.add_argument("--objective", default="depth", help="depth (mean final depth, maximised), deep_drag (Bbar, "
                        "minimised), ballistic_limit (a plate's V_bl, minimised) or residual_velocity (a plate's mean V_r, "
                        "maximised)")
    parser.add_argument("--striking-velocity", default=None, metavar="V",
                        help="depth: the final depth at this one striking velocity (e.g. '800 m/s') instead of the mean "
                             "over the case's [impact] striking_velocities")
    parser.add_argument("--depth-model", default="rigid", help="rigid or exact-rod (elastic projectile, errata item 5)")
    parser.add_argument("--constraint", action="append", default=[], help="mass, length or caliber (repeatable)")
    parser.add_argument("--method", default="grid-pattern",
                        help="grid-pattern (default: a coarse grid, then a compass search; each poll's designs in "
                             "parallel), grid-nm (the coarse grid, then Nelder-Mead with bounds) or de (differential evolution)")
    parser.add_argument("--coarse", type=int, default=5, help="grid-pattern, grid-nm: points per variable of the coarse grid (default 5)")
    parser.add_argument("--maxfev", type=int, default=60, help="grid-pattern: at most this many polls; grid-nm: at most this many "
                        "Nelder-Mead evaluations (default 60)")
    parser.add_argument("--table-depths", type=int, default=None,
                        help="depths of every design's coefficient table ([coefficients] depths; default: the case's)")
    parser.add_argument("--table-nose-lengths", type=float, default=None,
                        help="deepest depth of every design's table, in nose lengths ([coefficients] "
                             "max_depth_nose_lengths; default: the case's); the optimum is re-evaluated on the case's own tables")
    parser.add_argument("--depth-knots", type=int, default=None,
                        help="depth objective: knots per smooth piece of every design's table over the depths it reads "
                             "(0 to a little past the deepest final depth; default 4; the optimum is confirmed with 8); "
                             "0: the case's own tables to the deep limit")
    parser.add_argument("--popsize", type=int, default=5, help="differential evolution: population per variable (default 5)")
    parser.add_argument("--maxiter", type=int, default=12, help="differential evolution: generations (default 12)")
    parser.add_argument("--tol", type=float, default=1e-5,
                        help="relative tolerance of the objectives (Nelder-Mead simplex; DE population) (default 1e-5)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--resolution", type=float, default=1e-3, help="designs rounded to this fraction of each range")
    parser.add_argument("--confirm", type=int, default=5, help="confirmation grid: points per variable (0: none)")
    parser.add_argument("--scheduler", default=None, help="dask scheduler tcp://HOST:PORT or its scheduler file FILE.json "
                        "(docs/cluster.md), 'inline' or 'local' (default)")
    parser.add_argument("--workers", type=int, default=2, help="workers of the local cluster (default 2)")
    parser.add_argument("--cache-dir", default=None, help="coefficient-table cache folder")
    parser.add_argument("--no-progress", action="store_true")
    from semianalytic.report.formats import add_format_arguments

    add_format_arguments(parser, json_help="print the optimum as JSON")


# the printed objective's unit and meaning (optimize.model: depth_objective, deep_drag)
OBJECTIVE_UNITS = {"depth": " m", "deep_drag": " (Bbar, dimensionless)"}
OBJECTIVE_MEANING = {"depth": "minus the mean final depth, minimised", "deep_drag": "deep-penetration Bbar, minimised"}


def run(args: argparse.Namespace) -> int:
    from semianalytic.optimize.pipeline import run_optimize
    from semianalytic.report.formats import Output, chosen_format, emit

    fmt = chosen_format(args)
    if args.out is None and args.report is None and fmt == "text":
        raise InputError("--out", "give an output folder (--out DIR), --report FILE.md or --json")
    command = "python -m semianalytic optimize " + " ".join(shlex.quote(a) for a in sys.argv[2:])
    result = run_optimize(args, command)
    o = result["optimum"]
    from semianalytic.report.output import json_safe

    emit(Output(data=json_safe({k: v for k, v in result.items() if k != "history"}), json_options={"indent": 2},
                text=lambda s: _text(result, s)), fmt)
    return 0 if o["status"] == "ok" else 1


def _text(result: dict, stream) -> None:
    o = result["optimum"]
    xs = ", ".join(f"{v['key']} = {x:.6g}" for v, x in zip(result["variables"], o["x"]))
    unit = OBJECTIVE_UNITS.get(result["objective"], "")
    print(f"optimum: {xs}; objective {o['objective']:.8g}{unit} ({result['objective']}: "
          f"{OBJECTIVE_MEANING.get(result['objective'], 'minimised')}); "
          f"{result['n_designs_total']} designs in {result['seconds_total']:.1f} s", file=stream)
    g = result.get("confirmation")
    if g:
        print(f"confirmation grid: best {g['best_objective']:.8g}{unit}, confirmed: {'yes' if g['confirmed'] else 'NO'}",
              file=stream)
