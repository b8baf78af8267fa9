"""``python -m semianalytic COMMAND ...``: a thin dispatcher.

Each command lives beside the model it runs, in a module exposing ``add_arguments(parser)``
and ``run(args) -> int``.  Only the chosen command's module is imported.
Exit status: 0 success, 2 bad input (one line naming the field), 1 internal failure.
"""

from __future__ import annotations

import argparse
import importlib
import sys
import traceback

from semianalytic.errors import InputError

# name -> (module, one-line help)
COMMANDS: dict[str, tuple[str, str]] = {
    "coefficients": ("semianalytic.coefficients.cli", "BEM drag coefficients A(P), B(P), C(P) (Part I, eqs. 12-15)"),
    "bench-bem": ("semianalytic.coefficients.bench", "benchmark the BEM against exact solutions; writes reports/bench_bem.md"),
    "penetrate": ("semianalytic.penetration.cli", "depth and time of penetration, critical impact velocity (Part I)"),
    "cavity": ("semianalytic.cavity.cli", "brittle spherical-cavity expansion (Part II)"),
    "ballistic-limit": ("semianalytic.ballistic_limit.cli", "ballistic limit velocity (Part IV)"),
    "fit-constants": ("semianalytic.ballistic_limit.fit_cli", "refit the empirical constants C1, C2, C3 (Part IV, eqs. 7-9)"),
    "nanostrength": ("semianalytic.nanostrength.cli", "theoretical strength of diamond-like nanoparticles (Part III)"),
    "run": ("semianalytic.run.cli", "run everything a case asks for and write a report"),
    "sweep": ("semianalytic.sweep.cli", "parallel parameter sweeps and Monte-Carlo studies"),
    "optimize": ("semianalytic.optimize.cli", "nose-shape optimisation with the BEM in the loop (depth or deep drag)"),
    "demo": ("semianalytic.demo", "run the main job on a bundled case and say where its report is"),
}


def dispatch(prog: str, commands: dict[str, tuple[str, str]], argv: list[str] | None) -> int:
    """Shared by both packages' CLIs: pick the command, import it, run it, map errors."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if not argv or argv[0] in ("-h", "--help"):
        width = max(len(n) for n in commands)
        lines = [f"usage: {prog} COMMAND [options]", "", "commands:"]
        lines += [f"  {name:<{width}}  {help_}" for name, (_, help_) in commands.items()]
        print("\n".join(lines))
        return 0 if argv else 2
    name, rest = argv[0], argv[1:]
    if name not in commands:
        print(f"error: command: unknown command {name!r}; try {prog} --help", file=sys.stderr)
        return 2
    module_name, help_ = commands[name]
    try:
        module = importlib.import_module(module_name)
        parser = argparse.ArgumentParser(prog=f"{prog} {name}", description=help_)
        module.add_arguments(parser)
        args = parser.parse_args(rest)
        return int(module.run(args) or 0)
    except SystemExit as exc:  # argparse: --help (0) or bad arguments (2)
        return int(exc.code or 0)
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 1
    except Exception:
        traceback.print_exc()
        print(f"internal error in {prog} {name} (see the traceback above)", file=sys.stderr)
        return 1


def main(argv: list[str] | None = None) -> int:
    return dispatch("python -m semianalytic", COMMANDS, argv)
