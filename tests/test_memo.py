"""No hidden state (issue 40): every cache of the package is kept on its owner through
``astralis_des.memo.kept``, is documented there, and changes nothing a run computes."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

import astralis_des.memo as memo
from astralis_des import Simulation, load_mission

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "astralis_des"


def test_no_cache_is_kept_on_an_object_but_through_memo() -> None:
    found = [f"{path.relative_to(ROOT)}:{n}" for path in sorted(PACKAGE.rglob("*.py"))
             if path.name != "memo.py"
             for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
             if "__dict__.setdefault" in line]
    assert found == []


def test_every_cache_name_used_is_documented() -> None:
    used = set()
    for path in sorted(PACKAGE.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Call) and getattr(node.func, "attr", getattr(
                    node.func, "id", None)) in ("kept", "memo") and len(node.args) >= 2 \
                    and isinstance(node.args[1 if getattr(node.func, "id", "") == "kept"
                                             else 0], ast.Constant):
                arg = node.args[1 if getattr(node.func, "id", "") == "kept" else 0]
                used.add(arg.value)
    assert used == set(memo.NAMES)
    documented = set(re.findall(r"``(\w+)``", memo.__doc__ or ""))
    assert set(memo.NAMES) <= documented
    with pytest.raises(KeyError, match=r"'scratch' is not one of astralis_des\.memo\.NAMES"):
        memo.kept(object(), "scratch")


def test_a_run_is_the_same_with_every_cache_empty() -> None:
    """What a process keeps between runs never changes a run: the second run of a mission,
    its world's caches full, and a third after they are all emptied, log the same events."""
    mission = load_mission(ROOT / "missions" / "urban_search.yaml")
    first = Simulation(mission).run().events
    again = Simulation(mission).run().events
    world = mission.world
    emptied = [k for k in list(vars(world)) if k.startswith("_memo_")]
    assert emptied  # the first run filled some
    for key in emptied:
        vars(world)[key].clear()
    assert again == first == Simulation(mission).run().events
