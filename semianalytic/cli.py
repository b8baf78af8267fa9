"""``python -m semianalytic COMMAND ...``: a thin dispatcher.

Each command lives beside the model it runs, in a module exposing ``add_arguments(parser)``
and ``run(args) -> int``.  Only the chosen command's module is imported.
Exit status: 0 success, 2 bad input (one line naming the field), 1 internal failure.
"""

from __future__ import annotations

import importlib
import os
import sys
import traceback
import warnings

from semianalytic.cli_types import OneLineParser, memory_size
from semianalytic.errors import InputError, ModelError
from semianalytic.guards import set_memory_limit

# name -> (module, one-line help)
COMMANDS: dict[str, tuple[str, str]] = {
    "coefficients": ("semianalytic.commands.coefficients.cli", "BEM drag coefficients A(P), B(P), C(P) (Part I, eqs. 12-15)"),
    "bench-bem": ("benchmarks.bench_bem", "benchmark the BEM against exact solutions; writes reports/bench_bem.md"),
    "penetrate": ("semianalytic.commands.penetrate.cli", "depth and time of penetration, critical impact velocity (Part I)"),
    "perforate": ("semianalytic.commands.perforate.cli", "perforation of plates: residual velocity, ballistic limit (Part I eq. 11, Part IV)"),  # noqa: E501
    "cavity": ("semianalytic.commands.cavity.cli", "brittle spherical-cavity expansion (Part II)"),
    "ballistic-limit": ("semianalytic.commands.ballistic_limit.cli", "ballistic limit velocity (Part IV)"),
    "fit-constants": ("semianalytic.commands.ballistic_limit.fit_cli", "refit the empirical constants C1, C2, C3 (Part IV, eqs. 7-9)"),
    "nanostrength": ("semianalytic.commands.nanostrength.cli", "theoretical strength of diamond-like nanoparticles (Part III)"),
    "run": ("semianalytic.run.cli", "run everything a case asks for and write a report"),
    "calibrate": ("semianalytic.commands.calibrate.cli", "Bayesian calibration of target parameters on measured depths, predictive intervals, cross-validation"),  # noqa: E501
    "sweep": ("semianalytic.sweep.cli", "parallel parameter sweeps and Monte-Carlo studies"),
    "optimize": ("semianalytic.optimize.cli", "nose-shape optimisation with the BEM in the loop (depth or deep drag)"),
    "demo": ("semianalytic.demo", "run the main job on a bundled case and say where its report is"),
}


MAX_WARNINGS_PER_KIND = 3


# The three lines `python -m semianalytic --help` opens with.
START_HERE = (
    "start here: python -m semianalytic demo            (runs a bundled case, prints where its report is)",
    "            python -m semianalytic penetrate CASE  (depth per striking velocity; cases/ holds examples)",
    "            python -m semianalytic COMMAND --help  (options of one command; docs: make docs)",
)


def version_text(prog: str) -> str:
    """``--version``: the program and the package version."""
    from semianalytic import __version__

    return f"{prog} (penetration-mechanics {__version__})"


def dispatch(prog: str, commands: dict[str, tuple[str, str]], argv: list[str] | None,
             start_here: tuple[str, ...] = ()) -> int:
    """Shared by both packages' CLIs: pick the command, import it, run it, map errors."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv and argv[0] == "--version":
        print(version_text(prog))
        return 0
    if not argv:  # exit status 2 is one line naming the field (issue 40): the command list is --help's
        example = "demo" if "demo" in commands else next(iter(commands))
        print(f"error: command: missing; give one, e.g. {prog} {example} (the commands: {prog} --help)", file=sys.stderr)
        return 2
    if argv[0] in ("-h", "--help"):
        width = max(len(n) for n in commands)
        lines = [*start_here, *([""] if start_here else []), f"usage: {prog} [--version] COMMAND [options]", "", "commands:"]
        lines += [f"  {name:<{width}}  {help_}" for name, (_, help_) in commands.items()]
        try:
            print("\n".join(lines))
        except BrokenPipeError:  # `--help | head`: the reader went away
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    name, rest = argv[0], argv[1:]
    from semianalytic.thirdparty import keep_caches_out_of_home

    # matplotlib's font cache in this project's per-user cache, not ~/.cache (issue 40); for this command
    # (and the processes it starts) only: tests call main() repeatedly
    mpl_set = keep_caches_out_of_home()
    try:
        return _dispatch_command(prog, commands, name, rest)
    finally:
        if mpl_set is not None and os.environ.get("MPLCONFIGDIR") == mpl_set:
            del os.environ["MPLCONFIGDIR"]


def _dispatch_command(prog: str, commands: dict[str, tuple[str, str]], name: str, rest: list[str]) -> int:
    if name not in commands:
        print(f"error: command: unknown command {name!r}; try {prog} --help", file=sys.stderr)
        return 2
    module_name, help_ = commands[name]
    from semianalytic.bundled import resolve_arguments

    rest = resolve_arguments(rest)  # `cases/X.toml` outside a checkout: the bundled case (one note)
    notes: list[str] = []

    def collect(message, category, filename, lineno, file=None, line=None) -> None:
        text = " ".join(str(message).split())
        if text not in notes:
            notes.append(text)

    with warnings.catch_warnings():
        warnings.showwarning = collect
        for category in (DeprecationWarning, PendingDeprecationWarning, FutureWarning, ResourceWarning):
            warnings.simplefilter("ignore", category)  # the libraries' business, not the user's
        from semianalytic.io import interrupt_on_termination

        restore = interrupt_on_termination()
        try:
            rc = _run_command(prog, name, module_name, help_, rest)
        finally:
            set_memory_limit(None)
            restore()  # the flag holds for one command (tests call main() repeatedly)
    if rc != 2:  # bad input: the one line naming the field is all that is printed
        shown: dict[str, int] = {}
        for text in notes:  # a sweep may warn once per value: the first few of each kind
            kind = text.split(":", 1)[0]
            shown[kind] = shown.get(kind, 0) + 1
            if shown[kind] <= MAX_WARNINGS_PER_KIND:
                print(f"warning: {text}", file=sys.stderr)
        for kind, n in shown.items():
            if n > MAX_WARNINGS_PER_KIND:
                print(f"warning: {kind}: {n - MAX_WARNINGS_PER_KIND} more warnings like the above", file=sys.stderr)
    return rc


def _run_command(prog: str, name: str, module_name: str, help_: str, rest: list[str]) -> int:
    try:
        if module_name.startswith("benchmarks."):  # not installed: from a checkout only
            from semianalytic.checkout import import_benchmark

            module = import_benchmark(module_name, f"{prog} {name}")
        else:
            module = importlib.import_module(module_name)
        parser = OneLineParser(prog=f"{prog} {name}", description=help_)
        module.add_arguments(parser)
        parser.add_argument("--memory-limit", type=memory_size, default=None, metavar="SIZE",
                            help="memory budget, e.g. 8GB (default: $SEMIANALYTIC_MEMORY_LIMIT, else 4GB); "
                                 "larger problems are refused before they start")
        args = parser.parse_args(rest)
        set_memory_limit(args.memory_limit)
        return int(module.run(args) or 0)
    except SystemExit as exc:  # argparse: --help (0) or bad arguments (2)
        return int(exc.code or 0)
    except (InputError, ModelError) as exc:  # bad input, or inputs a model cannot compute with
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except RecursionError:
        print(f"error: input: nested too deeply for {prog} {name}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:
        from semianalytic.errors import one_line

        why = one_line(str(exc)) or "Ctrl-C"
        print(f"interrupted ({why}): unfinished output removed (a sweep keeps its finished cases for --resume)", file=sys.stderr)
        return 1
    except BrokenPipeError:  # the reader went away (`... | head`): nothing more to say, no traceback
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())  # Python's flush at exit would raise again
        except (OSError, ValueError):
            pass
        return 1
    except MemoryError:
        print(f"error: memory: {prog} {name} ran out of memory; lower the resolution or raise --memory-limit "
              "only if the machine has the memory", file=sys.stderr)
        return 1
    except Exception:
        traceback.print_exc()
        print(f"internal error in {prog} {name} (see the traceback above)", file=sys.stderr)
        return 1


def main(argv: list[str] | None = None) -> int:
    return dispatch("python -m semianalytic", COMMANDS, argv, START_HERE)
