"""A robot kind is one record: code asks it, never compares the kind's name, and its legs are
planned by the planner it names in ``PLANNERS``."""

from __future__ import annotations

import ast
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pytest

from astralis_des import Simulation, load_mission
from astralis_des.kinds import KIND_DEFAULTS
from astralis_des.planning.planners import PLANNERS, Host, Leg, Planned
from astralis_des.registry import UnknownEntry
from astralis_des.world.clutter import Clutter, Placed

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "astralis_des"
NAMES = {"uav", "ugv", "human"}
# where the kinds are defined (their records, and the Literal types of the input files)
DEFINING = {"kinds.py", "world/spec.py", "mission/types.py"}
MOST = 5  # comparisons against a kind's name allowed elsewhere


def _names_a_kind(node: ast.expr) -> bool:
    if isinstance(node, ast.Constant):
        return node.value in NAMES
    if isinstance(node, ast.Tuple | ast.List | ast.Set):
        return any(isinstance(e, ast.Constant) and e.value in NAMES for e in node.elts)
    return False


def kind_comparisons() -> list[str]:
    """``file:line`` of each comparison against "uav", "ugv" or "human" (or a tuple holding
    one) outside the modules that define the kinds."""
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        name = path.relative_to(PACKAGE).as_posix()
        if name in DEFINING:
            continue
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Compare) and any(
                    _names_a_kind(part) for part in (node.left, *node.comparators)):
                found.append(f"{name}:{node.lineno}: {ast.unparse(node)}")
            elif isinstance(node, ast.MatchValue) and _names_a_kind(node.value):
                found.append(f"{name}:{node.lineno}: case {ast.unparse(node.value)}")
    return found


def test_the_package_asks_the_kinds_record_rather_than_compare_its_name() -> None:
    """At most five comparisons against "uav", "ugv" or "human" outside the kinds' modules."""
    found = kind_comparisons()
    assert len(found) <= MOST, "compare against a kind's record instead:\n" + "\n".join(found)


def test_the_scan_sees_a_comparison() -> None:
    """The scan finds ``kind == "uav"`` and ``kind in ("ugv",)`` (it is not blind)."""
    tree = ast.parse('a = kind == "uav"\nb = kind in ("ugv", "x")\nc = kind == "boat"\n')
    compares = [n for n in ast.walk(tree) if isinstance(n, ast.Compare)]
    assert [any(_names_a_kind(p) for p in (n.left, *n.comparators)) for n in compares] == [
        True, True, False]


def test_each_kind_names_a_registered_planner() -> None:
    """The UAV flies, the UGV drives, a person walks: each a planner in ``PLANNERS``."""
    assert {k: d.planner for k, d in KIND_DEFAULTS.items()} == {
        "uav": "fly", "ugv": "drive", "human": "walk"}
    assert all(d.planner in PLANNERS for d in KIND_DEFAULTS.values())
    assert list(PLANNERS) == ["drive", "fly", "walk"]


def test_an_unknown_planner_is_refused_with_a_suggestion() -> None:
    """``fyl`` is no planner; the error says which one was meant."""
    with pytest.raises(UnknownEntry, match=r"unknown planner 'fyl'; did you mean 'fly'\?"):
        PLANNERS.get("fyl")


def test_a_planner_is_registered_once() -> None:
    """A second ``walk`` is a bug, refused."""
    with pytest.raises(ValueError, match="planner 'walk' is registered twice"):
        PLANNERS.register("walk")(lambda host, leg: (None, ""))


@dataclass
class Toy:
    """A robot of the toy kind (what routing needs of one)."""

    kind: str
    height: float


def test_a_new_kind_plans_its_legs_with_the_planner_its_record_names() -> None:
    """A toy kind (a person's body, planned by a ``hop`` planner of its own) added to the
    records: a leg a cabinet blocks is handed to ``hop``, with the toy's record and body."""
    legs: list[Leg] = []

    def hop(host: Host, leg: Leg) -> Planned:
        legs.append(leg)
        middle = (leg.a + leg.b) / 2 + np.array([1.5, 0.0, 0.0])  # round the cabinet's end
        return np.array([leg.a, middle, leg.b]), ""

    KIND_DEFAULTS["toy"] = replace(KIND_DEFAULTS["human"], planner="hop", radius=0.2)
    PLANNERS.register("hop")(hop)
    try:
        mission = load_mission(ROOT / "missions" / "fig7.yaml")
        sim = Simulation(mission.with_changes(planning={"method": "map"}))
        room = sim.world.rooms["A.1.1.2"]
        floor, x = room.box.lo[2], room.center[0]
        sim.scene.set_clutter(room.id, Clutter((Placed(
            "cabinet", room.id, (x, 83.0, floor + 1.0), (1.0, 0.5, 2.0), 0.0),), ()))
        toy = Toy("toy", 1.6)
        a, b = np.array([x, 81.0, floor + 1.6]), np.array([x, 85.0, floor + 1.6])
        route = sim.navigator.refine(toy, np.array([a, b]))
    finally:
        del KIND_DEFAULTS["toy"]
        PLANNERS.remove("hop")
    assert route.points is not None and len(route.points) == 3
    assert len(legs) == 1 and legs[0].kind.planner == "hop"
    assert legs[0].radius == pytest.approx(0.2 + mission.spec.planning.margin)
    assert "hop" not in PLANNERS and "toy" not in KIND_DEFAULTS
