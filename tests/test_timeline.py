"""Tests for the mission timeline: rounds segment by segment, and scheduled events.

Each test runs the paper's mission (``missions/urban_search.yaml``, seed 42) or a variant of
it made with ``Mission.with_changes``; without ``out_dir`` a run writes nothing.

In the unchanged mission round 1 (t=0) sends uav1 to A.1.1.2 and uav2 to A.1.1.3, each with a
``move`` to the door (uav1 arrives at t~21.9, uav2 at t~19.9) then a spiral, and ugv1 to
observe the corridor of A.1.1.1; it sees 85% of that room, under the 90% a room needs, so
round 2 (t~54.1) sends uav1 to search A.1.1.1 again; round 3 starts at t~73.9 on segment
A.1.2, and uav1 finds the target in A.1.2.1 at t~85.9 (the UGV turns on the spot only
beyond 60 degrees off its way, as the physics Husky does: its look ends 5 s sooner).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from astralis_des import InputError, Mission, RunResult, Simulation, load_mission
from astralis_des.assignment import table4_action
from astralis_des.kernel.robot import Motion
from astralis_des.kinds import CLIMB_SPEED, KIND_DEFAULTS

UAV = KIND_DEFAULTS["uav"]


def flown_in(result: RunResult, robot: str, seconds: float) -> float:
    """How far the robot's first route takes it in ``seconds``, under its speed profile."""
    start = next(e for e in result.events if e["kind"] == "task_started" and e["robot"] == robot)
    assert start["t"] == 0.0
    sim = Simulation(load_mission(MISSION))
    here = sim.robots[robot]
    points = route_to(sim, here, start["room"])
    up = Motion(np.array([here.pose, here.pose + [0.0, 0.0, here.height - here.pose[2]]]),
                CLIMB_SPEED, accel=UAV.accel)  # it takes off first
    return up.length + Motion(points, UAV.speed, accel=UAV.accel).travelled(
        seconds - up.duration)


def route_to(sim: Simulation, robot: Any, room: str) -> Any:
    from astralis_des.actions.common import route

    return route(sim, robot, sim.world.rooms[room].door_point("corridor")).points
ROOT = Path(__file__).resolve().parents[1]
MISSION = ROOT / "missions" / "urban_search.yaml"


@pytest.fixture(scope="module")
def mission() -> Mission:
    return load_mission(MISSION)


@pytest.fixture(scope="module")
def baseline(mission: Mission) -> RunResult:
    return Simulation(mission).run()


def run(mission: Mission, **changes: Any) -> RunResult:
    return Simulation(mission.with_changes(**changes)).run()


def events(result: RunResult, kind: str, robot: str | None = None) -> list[dict[str, Any]]:
    return [e for e in result.events
            if e["kind"] == kind and (robot is None or e.get("robot") == robot)]


def segment_round(result: RunResult, segment: str) -> dict[str, Any]:
    return next(r for r in result.rounds if r["segment"] == segment)


def finished(result: RunResult, task: int) -> dict[str, Any]:
    (record,) = [e for e in events(result, "task_finished") if e["task"] == task]
    return record


def test_baseline(baseline: RunResult) -> None:
    """The unchanged mission runs as the module docstring says (the other tests rely on it)."""
    assert baseline.outcome == "found"
    assert baseline.found_by == "uav1"
    assert baseline.target["room"] == "A.1.2.1"
    team = ["uav1", "uav2", "ugv1", "op1"]
    assert [(r["segment"], r["agents"]) for r in baseline.rounds] == [
        ("A.1.1", team), ("A.1.1", team), ("A.1.2", team)]
    assert [e["room"] for e in events(baseline, "room_undercovered")] == ["A.1.1.1"]
    assert [(m["agent"], m["room"]) for m in baseline.rounds[1]["matching"]] == [
        ("uav1", "A.1.1.1")]
    started = {e["task"]: (e["robot"], e["action"], e["t"])
               for e in events(baseline, "task_started")}
    assert started[1] == ("uav1", "move", 0.0)
    assert started[3] == ("uav2", "move", 0.0)
    assert finished(baseline, 1)["t"] > 15
    assert finished(baseline, 3)["t"] > 14
    assert baseline.rooms["A.1.1.1"]["status"] == "searched"
    assert [s["robot"] for s in baseline.rooms["A.1.1.1"]["searches"]] == ["ugv1", "uav1"]


# -- fault and recover ----------------------------------------------------------------------
def test_fault_fails_the_running_task(mission: Mission) -> None:
    """A fault at t=10 ends the robot's running task FAILED at t=10, its queue CANCELLED."""
    result = run(mission, timeline=[{"at": 10, "event": "fault", "robot": "uav1",
                                     "reason": "rotor"}])
    assert events(result, "fault") == [{"t": 10.0, "kind": "fault", "robot": "uav1",
                                         "reason": "rotor"}]
    move = finished(result, 1)
    assert (move["robot"], move["action"], move["t"]) == ("uav1", "move", 10.0)
    assert move["status"] == "failed"
    assert move["message"] == "robot fault: rotor"
    assert move["distance"] == pytest.approx(flown_in(result, "uav1", 10.0))
    spiral = finished(result, 2)
    assert (spiral["action"], spiral["t"], spiral["status"]) == ("spiral_inward", 10.0,
                                                                 "cancelled")
    assert result.robots["uav1"].faulted is True
    assert result.robots["uav1"].distance == pytest.approx(move["distance"])


def test_faulted_robot_takes_no_later_round(mission: Mission) -> None:
    """After a fault at t=10 the robot is in no later round and starts no task."""
    result = run(mission, timeline=[{"at": 10, "event": "fault", "robot": "uav1"}])
    later = [r for r in result.rounds if r["t"] > 10]
    assert later, "the mission should have rounds after the fault"
    assert all("uav1" not in r["agents"] for r in later)
    assert all(r["agents"] == ["uav2", "ugv1", "op1"] for r in later)
    assert [e["t"] for e in events(result, "task_started", "uav1")] == [0.0]
    # Its room, left unsearched, is tried again by someone else in the next round (with the
    # room the UGV saw too little of).
    assert later[0]["segment"] == "A.1.1"
    assert later[0]["rooms"] == ["A.1.1.1", "A.1.1.2"]


def test_recover_brings_the_robot_back(mission: Mission) -> None:
    """A robot that recovers at t=20 from a fault at t=10 is in the next round again."""
    result = run(mission, timeline=[{"at": 10, "event": "fault", "robot": "uav1"},
                                    {"at": 20, "event": "recover", "robot": "uav1"}])
    assert [e["t"] for e in events(result, "recover", "uav1")] == [20.0]
    later = [r for r in result.rounds if r["t"] > 20]
    assert later
    assert "uav1" in later[0]["agents"]
    assert result.robots["uav1"].faulted is False


@pytest.mark.parametrize(("event", "status"), [
    ({"event": "fault"}, "failed"),
    ({"event": "cancel"}, "cancelled"),
    ({"event": "command", "action": "hover", "preempt": True}, "preempted"),
], ids=["fault", "cancel", "preempt"])
def test_event_at_time_zero_stops_the_first_task(mission: Mission, event: dict[str, Any],
                                                 status: str) -> None:
    """A fault, cancel or preempting command at t=0 stops the robot's first task at t=0."""
    result = run(mission, timeline=[{"at": 0, "robot": "uav1", **event}])
    move = finished(result, 1)
    assert (move["action"], move["t"], move["status"]) == ("move", 0.0, status)


# -- room_change ----------------------------------------------------------------------------
def test_room_change_is_seen_by_the_next_round(mission: Mission, baseline: RunResult) -> None:
    """A room_change at t=10 sets the risk the next round uses, and the action it picks."""
    before = segment_round(baseline, "A.1.2")
    assert before["rooms"][0] == "A.1.2.1"
    assert before["risk"][0] < 0.5
    assert {m["room"]: m["action"] for m in before["matching"]}["A.1.2.1"] == "sweep_horizontal"

    result = run(mission, timeline=[{"at": 10, "event": "room_change", "room": "A.1.2.1",
                                     "risk": 0.9, "messiness": 0.1}])
    assert events(result, "room_change") == [{"t": 10.0, "kind": "room_change",
                                               "room": "A.1.2.1", "risk": 0.9,
                                               "messiness": 0.1}]
    after = segment_round(result, "A.1.2")
    assert after["risk"] == [0.9, *before["risk"][1:]]
    assert after["messiness"] == [0.1, *before["messiness"][1:]]
    pair = next(m for m in after["matching"] if m["room"] == "A.1.2.1")
    kind = {m.id: m.kind for m in mission.spec.team}[pair["agent"]]
    assert pair["action"] == table4_action(kind, 0.9, 0.1)  # high risk, low messiness
    assert (pair["agent"], pair["action"]) == ("ugv1", "observe_corridor")


def test_room_change_keeps_unset_fields(mission: Mission, baseline: RunResult) -> None:
    """A room_change giving only messiness leaves the room's risk as drawn."""
    result = run(mission, timeline=[{"at": 10, "event": "room_change", "room": "A.1.2.2",
                                     "messiness": 0.05}])
    after = segment_round(result, "A.1.2")
    assert after["risk"] == segment_round(baseline, "A.1.2")["risk"]
    assert after["messiness"][1] == 0.05


# -- command --------------------------------------------------------------------------------
def test_command_enqueues_at_its_time(mission: Mission, baseline: RunResult) -> None:
    """A command at t=10 queues the task then; it runs after the robot's queued tasks."""
    result = run(mission, timeline=[{"at": 10, "event": "command", "robot": "uav2",
                                     "action": "hover", "params": {"duration": 3}}])
    (queued,) = [e for e in events(result, "task_queued", "uav2") if e["origin"] == "timeline"]
    assert (queued["t"], queued["action"], queued["room"]) == (10.0, "hover", None)
    assert [e["t"] for e in events(result, "command", "uav2")] == [10.0]
    hover = queued["task"]
    # uav2 had move (task 3) then spiral_inward (task 4); neither is disturbed.
    assert finished(result, 3) == finished(baseline, 3)
    assert finished(result, 4) == finished(baseline, 4)
    (start,) = [e for e in events(result, "task_started", "uav2") if e["task"] == hover]
    assert start["t"] == finished(baseline, 4)["t"]
    end = finished(result, hover)
    assert end["status"] == "succeeded"
    assert end["message"] == "hovered 3 s"
    assert end["t"] - start["t"] == pytest.approx(3.0)


def test_command_with_preempt(mission: Mission) -> None:
    """A command with ``preempt: true`` ends the running task PREEMPTED at its time, runs now."""
    result = run(mission, timeline=[{"at": 10, "event": "command", "robot": "uav2",
                                     "action": "hover", "params": {"duration": 3},
                                     "preempt": True}])
    move = finished(result, 3)
    assert (move["action"], move["t"], move["status"]) == ("move", 10.0, "preempted")
    assert move["distance"] == pytest.approx(flown_in(result, "uav2", 10.0))
    order = [(e["kind"], e["task"], e["t"]) for e in result.events
             if e.get("robot") == "uav2" and e["kind"] in ("task_started", "task_finished")]
    hover = next(e["task"] for e in events(result, "task_queued", "uav2")
                 if e["origin"] == "timeline")
    assert order[:5] == [("task_started", 3, 0.0), ("task_finished", 3, 10.0),
                         ("task_started", hover, 10.0), ("task_finished", hover, 13.0),
                         ("task_started", 4, 13.0)]


# -- cancel ---------------------------------------------------------------------------------
def test_cancel_event_cancels_the_robots_tasks(mission: Mission) -> None:
    """A cancel at t=10 cancels the robot's running and queued tasks at t=10."""
    result = run(mission, timeline=[{"at": 10, "event": "cancel", "robot": "uav1"}])
    (cancel,) = events(result, "cancel", "uav1")
    assert cancel["t"] == 10.0
    assert sorted(cancel["tasks"]) == [1, 2]
    for task in (1, 2):
        record = finished(result, task)
        assert (record["t"], record["status"]) == (10.0, "cancelled")
        assert record["message"] == "cancelled by the timeline"
    # Not a fault: the robot stays in the team, and its room is searched in the next round.
    assert result.robots["uav1"].faulted is False
    assert "A.1.1.2" in result.rounds[1]["rooms"]
    assert "uav1" in result.rounds[1]["agents"]
    assert "A.1.1.2" in result.rooms_searched


def test_cancel_event_only_touches_its_robot(mission: Mission, baseline: RunResult) -> None:
    """Cancelling uav1's tasks leaves uav2's tasks as they were."""
    result = run(mission, timeline=[{"at": 10, "event": "cancel", "robot": "uav1"}])
    assert finished(result, 3) == finished(baseline, 3)
    assert finished(result, 4) == finished(baseline, 4)


# -- rounds and outcomes --------------------------------------------------------------------
def test_rounds_go_segment_by_segment(mission: Mission) -> None:
    """With the target in the last segment the rounds take the segments in search order."""
    order = mission.searched_segments()
    assert order == ["A.1.1", "A.1.2", "A.2.1", "A.2.2", "A.3.1", "A.3.2"]
    result = run(mission, target={"room": "A.3.2.3"})
    segments = [r["segment"] for r in result.rounds]
    ranks = [order.index(s) for s in segments]
    assert ranks == sorted(ranks)
    assert len(set(segments)) >= 4
    assert [r["round"] for r in result.rounds] == list(range(1, len(result.rounds) + 1))
    times = [r["t"] for r in result.rounds]
    assert times == sorted(times)


def test_not_found_visits_every_segment(mission: Mission) -> None:
    """A target outside the searched building: every segment, in order (a segment takes
    another round for a room seen too little); not_found, and every room searched."""
    result = run(mission, target={"room": "B.1.1.1"})
    assert result.outcome == "not_found"
    segments = [r["segment"] for r in result.rounds]
    assert [s for i, s in enumerate(segments) if i == 0 or s != segments[i - 1]] == \
        mission.searched_segments()
    assert {r["status"] for r in result.rooms.values()} <= {"searched", "undercovered"}
    assert sorted(result.rooms_searched) == sorted(mission.searched_rooms())
    assert events(result, "detection") == []
    assert result.time_to_find is None and result.found_by is None


@pytest.mark.parametrize("changes", [
    {}, {"target": {"room": "A.3.2.3"}}, {"target": {"room": "B.1.1.1"}}, {"time_limit": 30},
    {"seed": 3},
], ids=["baseline", "last-segment", "elsewhere", "time-limit", "seed-3"])
def test_found_iff_detection(mission: Mission, changes: dict[str, Any]) -> None:
    """Outcome is found iff there is a detection event, and time_to_find is its time."""
    result = run(mission, **changes)
    detections = events(result, "detection")
    assert len(detections) <= 1
    assert (result.outcome == "found") == bool(detections)
    if detections:
        (hit,) = detections
        assert result.time_to_find == hit["t"]
        assert result.found_by == hit["robot"]
        assert hit["target_room"] == result.target["room"]
        landed = [e["t"] for e in events(result, "landed")]  # the UAVs land, then it ends
        assert landed and min(landed) > hit["t"]
        assert result.end_time == pytest.approx(max(landed), abs=1e-6)
    else:
        assert result.time_to_find is None
    assert result.events[-1]["kind"] == "mission_end"
    assert result.events[-1]["outcome"] == result.outcome


def test_time_limit(mission: Mission) -> None:
    """A time limit shorter than the mission ends it at the limit, outcome time_limit."""
    result = run(mission, time_limit=30)
    assert result.outcome == "time_limit"
    assert result.end_time == 30.0
    assert result.events[-1] == {"t": 30.0, "kind": "mission_end", "outcome": "time_limit"}
    assert max(e["t"] for e in result.events) == 30.0
    assert all(r["t"] <= 30 for r in result.rounds)


# -- with_changes ---------------------------------------------------------------------------
def test_with_changes_validates_the_schema(mission: Mission) -> None:
    """``with_changes`` re-validates: a malformed timeline event is refused."""
    with pytest.raises(InputError, match=r"timeline\[0\]\.risk: .*less than or equal to 1"):
        mission.with_changes(timeline=[{"at": 1, "event": "room_change", "room": "A.1.1.1",
                                        "risk": 2.0}])


def test_with_changes_leaves_the_original(mission: Mission) -> None:
    """``with_changes`` returns a copy; the original mission is unchanged."""
    changed = mission.with_changes(seed=3, timeline=[{"at": 10, "event": "fault",
                                                      "robot": "uav1"}])
    assert (changed.spec.seed, len(changed.spec.timeline)) == (3, 1)
    assert (mission.spec.seed, mission.spec.timeline) == (42, [])
    assert changed.world is mission.world


def test_with_changes_refuses_an_unknown_robot(mission: Mission) -> None:
    """A timeline event naming a robot not in the team is an InputError before the run."""
    with pytest.raises(InputError, match="nobody"):
        changed = mission.with_changes(timeline=[{"at": 10, "event": "fault",
                                                  "robot": "nobody"}])
        Simulation(changed)


def test_rooms_a_kind_cannot_reach_are_excluded_edges(tmp_path: Path) -> None:
    """With stairs the UGV cannot climb, it is never matched to an upper floor's room: the
    round records that edge's cost as null (infinite) and leaves the UGV unassigned."""
    text = (ROOT / "worlds" / "urban_default.yaml").read_text(encoding="utf-8")
    text = text.replace("    segments:\n      - {side: north, rooms: 3}\n      - {side: south, "
                        "rooms: 3}", "    stairs_passable_by: [uav, human]\n    segments:\n"
                        "      - {side: north, rooms: 3}\n      - {side: south, rooms: 3}")
    world = tmp_path / "no_ramp.yaml"
    world.write_text(text, encoding="utf-8")
    mission = load_mission(MISSION)
    mission_text = MISSION.read_text(encoding="utf-8").replace(
        "world: ../worlds/urban_default.yaml", f"world: {world}")
    mission_file = tmp_path / "mission.yaml"
    mission_file.write_text(mission_text + "target: {room: B.1.1.1}\n", encoding="utf-8")
    result = Simulation(load_mission(mission_file).with_changes(time_limit=900)).run()
    upper = [r for r in result.rounds if not r["segment"].startswith("A.1.")]
    assert upper, "the search reached the upper floors"
    for rnd in upper:
        ugv = rnd["agents"].index("ugv1")
        assert rnd["costs"][ugv] == [None] * len(rnd["rooms"])
        assert "ugv1" in rnd["unassigned"]
    lower = [r for r in result.rounds if r["segment"].startswith("A.1.")]
    assert any(m["agent"] == "ugv1" for r in lower for m in r["matching"])
    assert mission.spec.name == "urban_search"
