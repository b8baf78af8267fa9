"""The mutation check (tools/mutation_check.py) still has every target it breaks: each text to break
occurs exactly once in its file and each test it runs exists.  A refactor that moves a target fails
here, in `make check`, instead of leaving a report that claims kills it can no longer make."""

from __future__ import annotations

import importlib.util
import shutil
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("mutation_check", ROOT / "tools" / "mutation_check.py")
mc = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(mc)


def test_every_target_is_present_once():
    assert len(mc.MUTATIONS) >= 10
    assert mc.missing_targets() == []


def test_a_missing_target_is_reported(tmp_path):
    """Break the check's input once: the first target's text removed from a copy -> reported."""
    cat, file, old, _new, node, _ = mc.MUTATIONS[0]
    for rel in (file, node.partition("::")[0]):
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(ROOT / rel, tmp_path / rel)
    assert [m for m in mc.missing_targets(tmp_path) if m.startswith(cat)] == []
    (tmp_path / file).write_text((ROOT / file).read_text().replace(old, "pass  # moved"))
    assert any("occurs 0 times" in m for m in mc.missing_targets(tmp_path) if m.startswith(cat))
    assert mc.main(["--targets"]) == 0
