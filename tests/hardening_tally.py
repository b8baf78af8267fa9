"""Tally of the hardening corpus (issues 13 and 27) and the fault tests -> ``reports/hardening.md``.

    .venv/bin/python tests/hardening_tally.py --out reports

Runs every file of ``tests/corpus/`` and ``tests/bad_cases/`` through all eight commands that
read a case (in-process, each from an empty working folder), then the bad command-line options
of issue 13, and counts: tried, rejected cleanly (exit 2, one line), warned (exit 0 with a
warning), accepted (exit 0), tracebacks, anything else.  It also records the memory guard's
answer on the three cases of the issue and the peak memory of the whole run.
"""

from __future__ import annotations

import argparse
import collections
import os
import resource
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from corpus_runner import ALL_COMMANDS, Outcome, corpus_files, headers, run_command, working_directory  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
OGIVE = str(ROOT / "cases" / "fig5_ogive.toml")

# The bad options of issue 13 (and their neighbours): (package, argv)
OPTIONS = [
    ("semianalytic", ["coefficients", OGIVE, "--max-depth", "-5"]),
    ("semianalytic", ["coefficients", OGIVE, "--refinement", "-1"]),
    ("semianalytic", ["coefficients", OGIVE, "--refinement", "0"]),
    ("semianalytic", ["coefficients", OGIVE, "--order", "1"]),
    ("semianalytic", ["coefficients", OGIVE, "--order", "100"]),
    ("semianalytic", ["coefficients", OGIVE, "--depths", "0"]),
    ("semianalytic", ["coefficients", OGIVE, "--depths", "1e9"]),
    ("semianalytic", ["coefficients", OGIVE, "--max-depth", "nan"]),
    ("semianalytic", ["coefficients", OGIVE, "--refinement", "inf"]),
    ("semianalytic", ["coefficients", OGIVE, "--memory-limit", "lots"]),
    ("semianalytic", ["coefficients", OGIVE, "--refinement", "8", "--memory-limit", "100MB"]),
    ("fem_check", ["verify", OGIVE, "--depths", "1.0"]),
    ("fem_check", ["verify", OGIVE, "--depths", "0"]),
    ("fem_check", ["verify", OGIVE, "--depths", "1,,x"]),
    ("fem_check", ["verify", OGIVE, "--h", "0"]),
    ("fem_check", ["verify", OGIVE, "--out", "{tmp}/d", "--name", "../../x"]),
    ("fem_check", ["rod", "--name", "sub/x", "--out", "{tmp}/d"]),
    ("fem_check", ["rod", "--elements", "1e9"]),
    ("fem_check", ["bench", "--repeat", "-1"]),
    ("semianalytic", ["run", OGIVE, "--out", "{tmp}/afile/sub"]),
    ("semianalytic", ["run", OGIVE, "--out", "/proc/x"]),
    ("semianalytic", ["run", OGIVE, "--out", ""]),
    ("semianalytic", ["penetrate", OGIVE, "--report-name", "../x"]),
    ("semianalytic", ["sweep", str(ROOT / "cases/fig15a_ogive_6061T651.toml"), "--out", "{tmp}/s",
                      "--vary", "impact.striking_velocity=400:500:10 kg", "--scheduler", "inline"]),
    ("semianalytic", ["sweep", str(ROOT / "cases/fig15a_ogive_6061T651.toml"), "--out", "{tmp}/s", "--workers", "0",
                      "--vary", "impact.striking_velocity=400:500:10 m/s"]),
    ("semianalytic", ["sweep", str(ROOT / "cases/fig15a_ogive_6061T651.toml"), "--out", "{tmp}/s", "--samples", "-3",
                      "--vary", "impact.striking_velocity=400:500:10 m/s"]),
    ("semianalytic", ["bench-bem"]),
    ("semianalytic", ["nosuchcommand"]),
    # issue 27: bounds before work, flags accepted silently before, output folders refused outright
    ("semianalytic", ["penetrate", OGIVE, "--memory-limit", "1e30"]),
    ("semianalytic", ["calibrate", str(ROOT / "cases/piekutowski1999_var4340.toml"), "--out", "{tmp}/c",
                      "--steps", "1000000000", "--quiet"]),
    ("semianalytic", ["optimize", str(ROOT / "cases/optimize_fig5_into_fig15a.toml"), "--out", "{tmp}/o",
                      "--vary", "projectile.crh=1:6", "--coarse", "1000", "--no-progress"]),
    ("semianalytic", ["optimize", str(ROOT / "cases/optimize_fig5_into_fig15a.toml"), "--out", "{tmp}/o",
                      "--vary", "projectile.crh=1:6", "--confirm", "1000", "--no-progress"]),
    ("semianalytic", ["optimize", str(ROOT / "cases/optimize_fig5_into_fig15a.toml"), "--out", "{tmp}/o",
                      "--vary", "projectile.crh=1:6", "--method", "de", "--popsize", "1000", "--maxiter", "1000",
                      "--no-progress"]),
    ("semianalytic", ["optimize", str(ROOT / "cases/optimize_fig5_into_fig15a.toml"), "--out", "{tmp}/o",
                      "--vary", "projectile.crh=2:1e6", "--no-progress"]),
    ("semianalytic", ["sweep", str(ROOT / "cases/fig15a_ogive_6061T651.toml"), "--out", "{tmp}/s",
                      "--vary", "projectile.crh=3,1000000", "--scheduler", "inline"]),
    ("semianalytic", ["sweep", str(ROOT / "cases/fig15a_ogive_6061T651.toml"), "--out", "{tmp}/s", "--samples",
                      "10000000", "--sample", "target.density=normal(2710 kg/m^3, 10 kg/m^3)", "--scheduler", "inline"]),
    ("semianalytic", ["sweep", str(ROOT / "cases/fig15a_ogive_6061T651.toml"), "--out", "{tmp}/s", "--samples", "10",
                      "--sample", "target.resistance.yield_stress=normal(400 MPa, 400 MPa)", "--scheduler", "inline"]),
    ("semianalytic", ["sweep", str(ROOT / "cases/fig15a_ogive_6061T651.toml"), "--out", "{tmp}/s",
                      "--vary", "impact.striking_velocity=400:500:100 m/s", "--scheduler", ""]),
    ("semianalytic", ["run", OGIVE, "--out", "/", "--force"]),
    ("semianalytic", ["run", OGIVE, "--out", ".", "--force"]),
    ("semianalytic", ["run", OGIVE, "--out", str(ROOT / "cases"), "--force"]),
    # issue 40: flags that drive work, sweep values outside the case, the bare command
    ("semianalytic", ["coefficients", OGIVE, "--refinement", "8", "--order", "16", "--depths", "2000"]),
    ("semianalytic", ["coefficients", OGIVE, "--refinement", "8", "--depths", "2000"]),
    ("semianalytic", ["calibrate", str(ROOT / "cases/piekutowski1999_var4340_hardness_regimes.toml"), "--model", "regimes",
                      "--out", "{tmp}/c", "--steps", "1000000", "--quiet"]),
    ("semianalytic", ["calibrate", str(ROOT / "cases/piekutowski1999_var4340.toml"), "--out", "{tmp}/c",
                      "--steps", "200000", "--quiet"]),
    ("semianalytic", ["sweep", str(ROOT / "cases/fig15a_ogive_6061T651.toml"), "--out", "{tmp}/s",
                      "--vary", "impact.striking_velocity=1e-9 m/s,500 m/s", "--scheduler", "inline"]),
    ("semianalytic", ["sweep", str(ROOT / "cases/fig15a_ogive_6061T651.toml"), "--out", "{tmp}/s", "--samples", "10",
                      "--sample", "target.density=lognormal(2710 kg/m^3, 50)", "--scheduler", "inline"]),
    ("semianalytic", ["sweep", str(ROOT / "cases/fig15a_ogive_6061T651.toml"), "--out", "{tmp}/s",
                      "--vary", "impact.striking_velocity=400:500:100 m/s", "--scheduler", "tcp://127.0.0.1:9"]),
    ("semianalytic", ["penetrate", str(ROOT / "cases/fig15a_ogive_6061T651.toml"), "--csv",
                      str(ROOT / "cases/fig15a_ogive_6061T651.toml"), "--force"]),
    ("semianalytic", []),
]

# issue 40: the class of each of its corpus files (by name prefix), as the issue groups its findings
I40_CLASSES = {
    "i40_table_nose": "out of memory (the guard built the plan of a 3000-point table nose)",
    "i40_depths": "unbounded work (a fixed grid of 2000 depths at refinement 8)",
    "i40_field_grid": "unbounded work (a large velocity field)",
    "i40_ballistic": "nonsense accepted (Part IV inputs: plate, mass, length, delta_H, measured)",
    "i40_dynamic_factor": "refusal under a key the user did not write",
    "i40_nanostrength": "valid input refused (l = 2040 planes)",
}


# issue 27: the class of each of its corpus files (by name prefix), as the issue groups its findings
I27_CLASSES = {
    "i27_quantity": "traceback ('2**2000' overflow)",
    "i27_velocity_1e-9": "traceback (U_s = 1e-9 m/s)",
    "i27_velocity_11p9": "nonsense accepted (above the models' reach)",
    "i27_target_density": "nonsense accepted (a gas target)",
    "i27_projectile_density": "nonsense accepted (density)",
    "i27_resistance": "nonsense accepted (strength, modulus)",
    "i27_plate": "nonsense accepted or traceback (plate thickness)",
    "i27_ballistic_table": "files outside the asked folders (a path leaving the case folder)",
    "i27_data_file": "files outside the asked folders (a path leaving the case folder)",
    "i27_data_nan": "bad input accepted (NaN in a data CSV)",
    "i27_nanostrength": "out of memory or traceback (nanostrength study size)",
    "i27_table_nose": "out of memory (a table nose of many points)",
}


def i27_class(stem: str) -> str:
    return next((c for prefix, c in {**I27_CLASSES, **I40_CLASSES}.items() if stem.startswith(prefix)), "other")


FAULT_FILES = ("test_hardening_faults.py", "test_hardening_i40.py")


def fault_tests() -> list[tuple[str, str]]:
    """(test, outcome) of tests/test_hardening_faults.py, run by pytest in a subprocess."""
    import re
    import subprocess

    proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-rA", "-p", "no:randomly", "-p", "no:cacheprovider",
                           *(str(Path(__file__).with_name(f)) for f in FAULT_FILES)],
                          capture_output=True, text=True, cwd=ROOT, timeout=3600)
    rows = []
    for line in proc.stdout.splitlines():
        m = re.match(r"(PASSED|FAILED|ERROR|SKIPPED) (?:\S*/)?(test_hardening_\w+)\.py::(\S+)", line)
        if m:
            rows.append((m.group(3), m.group(1).lower(), "40" if m.group(2).endswith("i40") else "27"))
    return rows


def run_option(package: str, argv: list[str], tmp: Path) -> Outcome:
    import contextlib
    import io

    if package == "fem_check":
        from fem_check.cli import main
    else:
        from semianalytic.cli import main
    (tmp / "afile").write_text("a file, not a folder\n")
    argv = [a.replace("{tmp}", str(tmp)) for a in argv]
    err, out = io.StringIO(), io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
        rc = main(argv)
    def unplace(text: str) -> str:  # the report names no machine path: the temporary folder as {tmp}
        return text.replace(str(tmp.resolve()), "{tmp}").replace(str(tmp), "{tmp}")

    return Outcome(rc, unplace(err.getvalue()), unplace(out.getvalue()))


def classify(res: Outcome) -> str:
    if res.rc == 2 and len(res.err.strip().splitlines()) != 1:
        return "rejected, not one line"
    return res.kind


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=None, help="folder of hardening.md (default: print only)")
    args = parser.parse_args(argv)
    os.environ.setdefault("MPLBACKEND", "Agg")
    started = time.time()
    tally: dict[str, collections.Counter] = collections.defaultdict(collections.Counter)
    by_command: dict[str, collections.Counter] = collections.defaultdict(collections.Counter)
    bad_rows, guard_rows, stray = [], [], []
    i27: dict[str, collections.Counter] = collections.defaultdict(collections.Counter)
    files = corpus_files()
    with tempfile.TemporaryDirectory() as tmp_root:
        tmp_root = Path(tmp_root)
        os.environ.setdefault("SEMIANALYTIC_CACHE_DIR", str(tmp_root / "cache"))
        for k, path in enumerate(files):
            group = path.parent.name
            for command in ALL_COMMANDS:
                work = tmp_root / f"w{k}_{command.replace(' ', '_')}"
                work.mkdir()
                with working_directory(work):
                    res = run_command(command, str(path), work / "out")
                kind = classify(res)
                tally[group][kind] += 1
                by_command[command][kind] += 1
                if path.stem.startswith(("i27_", "i40_")):
                    i27[path.name][kind] += 1
                if kind not in ("rejected", "warned", "accepted"):
                    bad_rows.append((f"{group}/{path.name}", command, kind, res.err.strip().splitlines()[-1:] or [""]))
                if {p.name for p in work.iterdir()} - {"out"}:
                    stray.append((f"{group}/{path.name}", command, sorted(p.name for p in work.iterdir())))
                if path.stem in ("crh_1e12_memory", "cone_0p001deg_memory", "field_grid_801_180_memory"):
                    guard_rows.append((path.stem, command, res.rc, res.err.strip()))
            print(f"\r{k + 1}/{len(files)} files", end="", file=sys.stderr, flush=True)
        print(file=sys.stderr)
        options = collections.Counter()
        option_rows = []
        for package, argv_ in OPTIONS:
            tmp = tmp_root / f"opt{len(option_rows)}"
            tmp.mkdir()
            with working_directory(tmp):
                res = run_option(package, argv_, tmp)
            kind = classify(res)
            options[kind] += 1
            shown = (res.err.strip().splitlines() or [""])[-1].replace(str(tmp), "{tmp}").replace(str(ROOT) + "/", "")
            option_rows.append((f"{'python -m ' + package} {' '.join(a if a else repr(a) for a in argv_)}".replace(str(ROOT) + "/", ""),
                                res.rc, shown))
    faults = fault_tests()
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    seconds = time.time() - started

    kinds = ["rejected", "warned", "accepted", "traceback", "rejected, not one line"]
    lines = [
        "# Hardening: bad inputs and faults, tallied (issues 13, 27 and 40)",
        "",
        "Generated by `.venv/bin/python tests/hardening_tally.py --out reports` "
        f"({seconds:.0f} s, peak memory of the whole run {peak_mb:.0f} MB).",
        "",
        f"Every case file of `tests/corpus/` ({sum(1 for f in files if f.parent.name == 'corpus')} files, written for issue 13) and "
        f"`tests/bad_cases/` ({sum(1 for f in files if f.parent.name == 'bad_cases')} files) through the eight commands that read a case "
        f"({', '.join(ALL_COMMANDS)}), in-process, each from an empty working folder; then {len(OPTIONS)} bad command lines.",
        "`rejected`: exit status 2 with one line naming the field; `warned`: exit 0 with a `warning:` line; "
        "`accepted`: exit 0 (a command that does not use the bad section, e.g. `cavity` ignores `[run]`).",
        "The same inputs are asserted file by file in `tests/test_corpus.py` (part of `make test`).",
        "",
        "## Case files",
        "",
        "| corpus | tried | " + " | ".join(kinds) + " |",
        "|---|---|" + "---|" * len(kinds),
    ]
    for group, counter in sorted(tally.items()):
        lines.append(f"| {group} | {sum(counter.values())} | " + " | ".join(str(counter[k]) for k in kinds) + " |")
    total = collections.Counter()
    for counter in tally.values():
        total.update(counter)
    lines.append("| **all** | " + f"**{sum(total.values())}** | " + " | ".join(f"**{total[k]}**" for k in kinds) + " |")
    lines += ["", "| command | tried | " + " | ".join(kinds) + " |", "|---|---|" + "---|" * len(kinds)]
    for command in ALL_COMMANDS:
        counter = by_command[command]
        lines.append(f"| `{command}` | {sum(counter.values())} | " + " | ".join(str(counter[k]) for k in kinds) + " |")
    lines += ["", f"Runs that wrote outside their `--out`: {len(stray)}.", ""]
    if bad_rows:
        lines += ["Runs that were neither rejected cleanly, warned nor accepted:", ""]
        lines += [f"- `{f}` `{c}`: {k}: {e[0][:200]}" for f, c, k, e in bad_rows]
        lines.append("")
    for issue in ("27", "40"):
        names = sorted(n for n in i27 if n.startswith(f"i{issue}_"))
        lines += [f"## Issue {issue}: the new corpus files by class", "",
                  "Each file states what it expects in its header (`# expect:`); the counts are over the eight commands.",
                  "", "| file | class | expects | " + " | ".join(kinds) + " |", "|---|---|---|" + "---|" * len(kinds)]
        for name in names:
            stem = name.rsplit(".", 1)[0]
            expect = headers(next(f for f in files if f.name == name)).get("expect", "")
            lines.append(f"| `{name}` | {i27_class(stem)} | `{expect}` | "
                         + " | ".join(str(i27[name][k]) for k in kinds) + " |")
        if issue == "40":
            by_class: dict[str, collections.Counter] = collections.defaultdict(collections.Counter)
            for name in names:
                by_class[i27_class(name.rsplit(".", 1)[0])].update(i27[name])
                by_class[i27_class(name.rsplit(".", 1)[0])]["files"] += 1
            lines += ["", "By class (issue 40):", "", "| class | files | " + " | ".join(kinds) + " |",
                      "|---|---|" + "---|" * len(kinds)]
            lines += [f"| {c} | {n['files']} | " + " | ".join(str(n[k]) for k in kinds) + " |"
                      for c, n in sorted(by_class.items())]
        lines.append("")
    descriptions = {
        "27": "`tests/test_hardening_faults.py` (part of `make test`): `--force` and foreign files, folders refused "
              "outright, SIGTERM/SIGINT, a second writer of one `--out`, damaged and foreign cache entries, gmsh's "
              "home files, damaged sweep stores, escaped file names, time and memory budgets.",
        "40": "`tests/test_hardening_i40.py` (part of `make test`): schedulers that are not dask (local socket servers: "
              "other bytes, a silent peer, nothing listening), `--csv`/`--report` targets (a case file, a FIFO, a "
              "user's file, a report above the working folder), bounds on the flags that drive work, sweep values and "
              "sample supports outside the case, SIGTERM/SIGINT of a local-cluster sweep and of calibrate (their own "
              "TMPDIR and HOME), matplotlib and arviz caches out of HOME, the bare command.",
    }
    for issue in ("27", "40"):
        rows = [(n, o) for n, o, i in faults if i == issue]
        lines += [f"## Issue {issue}: fault tests", "", descriptions[issue], "", "| test | outcome |", "|---|---|"]
        lines += [f"| `{name}` | {outcome} |" for name, outcome in rows]
        n_pass = sum(1 for _, o in rows if o == "passed")
        lines += ["", f"Fault tests (issue {issue}): {n_pass} of {len(rows)} passed.", ""]
    lines += ["## The memory guard on the three cases of the issue", "",
              "Budget 4 GB (the default; `--memory-limit SIZE` or `$SEMIANALYTIC_MEMORY_LIMIT`). Refused before any "
              "allocation, by the commands that would solve them (the others stop earlier, at a missing section):", ""]
    for stem, command, rc, err in guard_rows:
        if "memory budget" in err:
            lines.append(f"- `{stem}` / `{command}` (exit {rc}): {err}")
    lines += ["", "## Command-line options", "",
              "| command | exit | stderr (last line) |", "|---|---|---|"]
    for cmd, rc, err in option_rows:
        lines.append(f"| `{cmd}` | {rc} | {err.replace('|', '/')[:220]} |")
    lines += ["", "Options: " + ", ".join(f"{k} {v}" for k, v in sorted(options.items())) + ".", ""]
    text = "\n".join(lines) + "\n"
    if args.out:
        sys.path.insert(0, str(ROOT))
        from semianalytic.io import atomic_write_text

        path = atomic_write_text(Path(args.out) / "hardening.md", text)
        print(f"wrote {path}")
    else:
        print(text)
    failed_faults = any(o != "passed" for _, o, _ in faults)
    return 0 if not bad_rows and not stray and not options.get("traceback") and not failed_faults else 1


if __name__ == "__main__":
    raise SystemExit(main())
