"""The import contracts see every module and the packages (issue 26, item 5), checked on the
graph grimp builds from the source (it runs none of it):

* every module of semianalytic/ and fem_check/ (package ``__init__`` files aside) is named by a
  contract of pyproject.toml (a layer, a container's layer or a forbidden contract's source), not
  only by the blanket "semianalytic never imports fem_check";
* the model packages, seen as packages (their pure model modules, the pure-models contract), import
  each other without a cycle: a package-level cycle the module-level test cannot see fails here.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

grimp = pytest.importorskip("grimp")

ROOT = Path(__file__).resolve().parent.parent
CONTRACTS = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]["contracts"]
ROOTS = ("semianalytic", "fem_check")


@pytest.fixture(scope="module")
def graph():
    return grimp.build_graph(*ROOTS, cache_dir=None)


def _named() -> set[str]:
    named = set()
    for c in CONTRACTS:
        for layer in c.get("layers", []):
            for part in layer.replace(":", "|").split("|"):
                part = part.strip().strip("()")
                named.update(f"{box}.{part}" for box in c["containers"]) if c.get("containers") else named.add(part)
        named.update(m for m in c.get("source_modules", []) if m not in ROOTS)
    return named


def _is_package(module: str) -> bool:
    return (ROOT / module.replace(".", "/") / "__init__.py").is_file()


def test_every_module_is_in_a_contract(graph):
    named = _named()
    modules = sorted(m for m in graph.modules if m.startswith(ROOTS) and not _is_package(m))
    assert len(modules) > 100
    loose = [m for m in modules if not any(m == n or m.startswith(n + ".") for n in named)]
    assert not loose, f"modules in no import contract (add them to pyproject.toml): {loose}"


def test_model_packages_have_no_package_cycle(graph):
    (pure,) = [c for c in CONTRACTS if c.get("id") == "pure-models"]
    models = [m for m in pure["source_modules"] if m.count(".") >= 2]  # package.module (bem, geometry: whole)

    def package(module: str) -> str:
        return ".".join(module.split(".")[:2])

    edges = set()
    for a in models:
        for b in graph.find_modules_directly_imported_by(a):
            if b in models and package(a) != package(b):
                edges.add((package(a), package(b)))
    assert edges, "no edge between model packages: the check would be vacuous"
    succ: dict[str, set[str]] = {}
    for a, b in edges:
        succ.setdefault(a, set()).add(b)

    def reaches(start: str, goal: str) -> bool:
        seen, stack = set(), [start]
        while stack:
            x = stack.pop()
            for y in succ.get(x, ()):
                if y == goal:
                    return True
                if y not in seen:
                    seen.add(y)
                    stack.append(y)
        return False

    cycles = sorted((a, b) for a, b in edges if reaches(b, a))
    assert not cycles, f"package-level import cycles among the model packages: {cycles}"
