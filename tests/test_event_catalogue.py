"""One catalogue of events (issue 40): every kind the package emits is catalogued with its
fields and level, every catalogued kind is emitted somewhere, and the log refuses the rest."""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from pathlib import Path

import pytest
import simpy

from astralis_des import Simulation, load_mission
from astralis_des.kernel.catalogue import EVENTS, EventKind, event, level_of, markdown
from astralis_des.kernel.events import EventLog

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "astralis_des"


def emitted_in_source() -> dict[str, list[str]]:
    """Each kind a ``.emit("kind", ...)`` call of the package names, and where."""
    found: dict[str, list[str]] = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) \
                    and node.func.attr == "emit" and node.args:
                first = node.args[0]
                where = f"{path.relative_to(ROOT)}:{node.lineno}"
                assert isinstance(first, ast.Constant) and isinstance(first.value, str), \
                    f"{where}: an event's kind is a literal, so that this test can see it"
                found.setdefault(first.value, []).append(where)
    return found


def test_every_kind_emitted_is_catalogued_and_every_catalogued_kind_is_emitted() -> None:
    emitted = emitted_in_source()
    assert sorted(emitted) == sorted(EVENTS)
    assert len(emitted) == 22  # 21, and the fork (astralis run --fork-at)


def test_the_log_refuses_an_uncatalogued_kind_or_field() -> None:
    log = EventLog(simpy.Environment())
    with pytest.raises(LookupError, match="unknown event kind 'task_failed'; did you mean "
                       "'task_finished'"):
        log.emit("task_failed", "uav1")
    with pytest.raises(ValueError, match="a fault event has no field cause"):
        log.emit("fault", "uav1", reason="battery", cause="x")
    with pytest.raises(ValueError, match="a fault event lacks reason"):
        log.emit("fault", "uav1")
    with pytest.raises(ValueError, match="a fault event names a robot"):
        log.emit("fault", reason="battery")
    with pytest.raises(ValueError, match="a mission_end event names no robot"):
        log.emit("mission_end", "uav1", outcome="found")
    assert log.records == []


def test_a_record_holds_plain_values_rounded_to_the_microsecond() -> None:
    """Times and floats rounded to 6 decimals (the events of one instant too), numpy values
    made plain, other values as they are."""
    import numpy as np

    env = simpy.Environment(initial_time=1.23456789)
    log = EventLog(env)
    first = log.emit("task_started", "uav1", task=1, action="hover", room=None)
    second = log.emit("task_finished", "uav1", task=1, action="hover", room="A.1",
                      status="succeeded", message="", distance=np.float64(2.0000004),
                      coverage=0.12345651)
    third = log.emit("landed", "uav1", at=1.5000004, position=np.array([1.0, 2.0000006, 3]))
    assert first == {"t": 1.234568, "kind": "task_started", "robot": "uav1", "task": 1,
                     "action": "hover", "room": None}
    assert second["t"] == 1.234568 and second["distance"] == 2.0
    assert second["coverage"] == round(0.12345651, 6)
    assert third["t"] == 1.5 and third["position"] == [1.0, 2.000001, 3.0]
    assert log.in_order


def test_a_failed_task_is_a_warning_and_the_start_is_information() -> None:
    """``task_failed`` had the level WARN but was never emitted: failed tasks showed as DEBUG
    in the replay, and the mission's start too."""
    finished = {"kind": "task_finished", "status": "failed"}
    assert level_of(finished) == "WARN"
    assert level_of({**finished, "status": "succeeded"}) == "INFO"
    assert level_of({"kind": "task_started"}) == "INFO"  # the mission's story, not noise
    assert level_of({"kind": "task_queued"}) == "DEBUG"
    assert level_of({"kind": "mission_start"}) == "INFO"
    assert level_of({"kind": "detection"}) == "CRITICAL"


@pytest.mark.parametrize("mission", ["urban_search", "faults", "fig7"])
def test_every_event_of_a_shipped_mission_has_its_kinds_fields(mission: str) -> None:
    result = Simulation(load_mission(ROOT / "missions" / f"{mission}.yaml")).run()
    for record in result.events:
        kind = EVENTS.get(record["kind"])
        payload = {k: v for k, v in record.items() if k not in ("t", "kind", "robot")}
        assert set(kind.fields) <= set(payload) <= set(kind.fields) | set(kind.optional)


def test_a_plug_in_registers_a_kind_of_its_own() -> None:
    mine = event(EventKind("battery_low", "a plug-in's robot runs low", ("charge",),
                           robot="always", level="WARN"))
    try:
        log = EventLog(simpy.Environment())
        log.emit("battery_low", "dog1", charge=0.1)
        assert log.records == [{"t": 0.0, "kind": "battery_low", "robot": "dog1",
                                "charge": 0.1}]
        assert level_of(log.records[0]) == "WARN"
    finally:
        EVENTS.remove(mine.name)


def test_docs_events_md_is_up_to_date() -> None:
    page = (ROOT / "docs" / "events.md").read_text(encoding="utf-8")
    assert page == markdown(), "run: astralis schema --events -o docs/events.md"
    done = subprocess.run([sys.executable, "-m", "astralis_des.cli", "schema", "--events"],
                          capture_output=True, text=True, check=True)
    assert done.stdout == page
    assert all(f"| `{name}` |" in page for name in EVENTS)
    assert json.dumps(sorted(EVENTS))  # names are plain strings
