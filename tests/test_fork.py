"""Forking a run at a decision (``astralis run --fork-at``, ``Simulation.fork``): the event log
up to the fork is the original's byte for byte, then a ``fork`` line and the changed run.

The original run's outputs are shared (module scope); kinematic but for one short physics fork.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from terminal import run_cli

from astralis_des.errors import InputError
from astralis_des.mission.changes import apply_changes, parse_changes
from astralis_des.mission.loader import Mission
from astralis_des.simulation import RunResult, Simulation
from astralis_des.simulation.fork import ForkNotReached
from astralis_des.simulation.timeline import regroup

ROOT = Path(__file__).resolve().parents[1]
MISSION = ROOT / "missions" / "urban_search.yaml"


def quiet(mission: Mission) -> Mission:
    """The mission without its recording (the event log and the summary are what is compared)."""
    return mission.with_changes(outputs={"recording": False})


def lines(folder: Path) -> list[bytes]:
    return (folder / "events.jsonl").read_bytes().splitlines(keepends=True)


@pytest.fixture(scope="module")
def original(urban_search: Mission, tmp_path_factory: pytest.TempPathFactory
             ) -> tuple[Path, RunResult]:
    out = tmp_path_factory.mktemp("original") / "run"
    return out, Simulation(quiet(urban_search), out_dir=out).run()


@pytest.fixture(scope="module")
def to_cbba(urban_search: Mission, tmp_path_factory: pytest.TempPathFactory
            ) -> tuple[Path, RunResult]:
    """The default mission forked from ``mixed`` to ``cbba`` at round 3."""
    out = tmp_path_factory.mktemp("cbba") / "run"
    result = Simulation(quiet(urban_search), out_dir=out).fork(
        "round:3", {"assignment.strategy": "cbba"})
    return out, result


def fork_line(folder: Path) -> int:
    """The index of the ``fork`` line in a run's event log."""
    kinds = [json.loads(line)["kind"] for line in lines(folder)]
    return kinds.index("fork")


@pytest.mark.parametrize("at", ["round:3", "event:20", "time:60"])
def test_the_log_before_the_fork_is_the_original_byte_for_byte(
        at: str, urban_search: Mission, original: tuple[Path, RunResult],
        tmp_path: Path) -> None:
    """Each kind of fork point: the original's lines, then the fork's line saying where."""
    result = Simulation(quiet(urban_search), out_dir=tmp_path).fork(
        at, {"assignment.strategy": "greedy"})
    k = fork_line(tmp_path)
    assert lines(tmp_path)[:k] == lines(original[0])[:k]
    fork = json.loads(lines(tmp_path)[k])
    assert fork["point"] == at
    assert fork["lines"] == k
    assert fork["changes"] == {"assignment.strategy": "greedy"}
    first_after = json.loads(lines(original[0])[k])
    expected = {"round:3": lambda: first_after["kind"] == "assignment"
                and first_after["round"] == 3,
                "event:20": lambda: k == 20,
                "time:60": lambda: fork["t"] == 60.0 and first_after["t"] >= 60.0}
    assert expected[at]()
    summary = json.loads((tmp_path / "summary.json").read_text(encoding="utf-8"))
    assert summary["fork"] == fork == result.fork


def test_a_fork_that_changes_nothing_goes_on_as_the_original(
        urban_search: Mission, original: tuple[Path, RunResult], tmp_path: Path) -> None:
    """Replay is exact: the weights set to their own values, the log is the original's but
    for the fork line (the mission as the fork rebuilds it runs as the file does)."""
    Simulation(quiet(urban_search), out_dir=tmp_path).fork(
        "time:60", {"assignment.weights.risk.human": 10.0})
    forked = lines(tmp_path)
    k = fork_line(tmp_path)
    assert json.loads(forked[k])["changes"] == {}
    assert forked[:k] + forked[k + 1:] == lines(original[0])


def test_a_run_without_a_fork_has_none_in_its_summary(original: tuple[Path, RunResult]) -> None:
    summary = json.loads((original[0] / "summary.json").read_text(encoding="utf-8"))
    assert "fork" not in summary
    assert original[1].fork is None


def test_cbba_from_round_3_plans_every_room_left(original: tuple[Path, RunResult],
                                                 to_cbba: tuple[Path, RunResult]) -> None:
    """Rounds 1 and 2 are the original's; round 3 is cbba's, given the pending rooms of the
    segment and every later one at once; the target is still found."""
    before, after = original[1].rounds, to_cbba[1].rounds
    assert [r["matching"] for r in after[:2]] == [r["matching"] for r in before[:2]]
    assert (before[2]["strategy"], before[2]["segment"]) == ("mixed", "A.1.2")
    assert (after[2]["strategy"], after[2]["segment"]) == ("cbba", "all")
    assert after[2]["matching"] != before[2]["matching"]
    assert len(after[2]["rooms"]) == 15  # A.1.2's three, and the 12 rooms of A.2 and A.3
    assert to_cbba[1].outcome == "found"


def test_a_fault_added_at_the_fork_keeps_the_robot_out_of_the_round(
        urban_search: Mission, original: tuple[Path, RunResult]) -> None:
    result = Simulation(quiet(urban_search)).fork(
        "round:3", ["timeline+={event: fault, robot: uav1, reason: rotor}"])
    k = next(i for i, e in enumerate(result.events) if e["kind"] == "fork")
    fork, fault = result.events[k], result.events[k + 1]
    assert fork["timeline"] == [{"at": fork["t"], "event": "fault", "robot": "uav1",
                                 "reason": "rotor"}]
    assert (fault["kind"], fault["robot"], fault["t"]) == ("fault", "uav1", fork["t"])
    assert "uav1" in original[1].rounds[2]["agents"]
    assert "uav1" not in result.rounds[2]["agents"]
    assert result.robots["uav1"].faulted


def test_a_room_change_at_the_fork_is_a_room_change_event(urban_search: Mission) -> None:
    result = Simulation(quiet(urban_search)).fork(
        "round:3", ["rooms.set[A.1.2.1].risk=0.95"])
    k = next(i for i, e in enumerate(result.events) if e["kind"] == "fork")
    change = result.events[k + 1]
    assert (change["kind"], change["room"], change["risk"]) == ("room_change", "A.1.2.1", 0.95)
    assert result.rounds[2]["risk"][result.rounds[2]["rooms"].index("A.1.2.1")] == 0.95


def test_a_fork_point_never_reached_says_so(urban_search: Mission) -> None:
    with pytest.raises(ForkNotReached) as caught:
        Simulation(quiet(urban_search)).fork("round:99", {"assignment.strategy": "cbba"})
    assert str(caught.value) == (
        "--fork-at: round:99 was never reached: the run ended (found) at t = 100.5 s after 3 "
        "rounds and 59 events; the run went on unchanged")
    assert caught.value.result.fork is None and len(caught.value.result.rounds) == 3


@pytest.mark.parametrize(("at", "sets", "message"), [
    ("round:3", ["team.0.speed=3"], "--set team.0.speed=3: team: cannot change mid-run: at a "
     "fork only the assignment settings, rooms.set and events appended with timeline+= change"),
    ("round:3", ["assignment.strategy=cbbx"], "--set assignment.strategy=cbbx: unknown "
     "assignment strategy 'cbbx'; did you mean 'cbba'?"),
    ("round:3", ["timeline+={event: fault, robot: uav1, at: 50}"], "--set timeline+={event: "
     "fault, robot: uav1, at: 50}: timeline[0].at: 50 s is before the fork (round:3 comes at "
     "t = 84.0036 s)"),
    ("turn:3", ["assignment.strategy=cbba"], "--fork-at: give round:N, event:N or time:T"),
    ("time:4000", ["assignment.strategy=cbba"], "--fork-at: time:4000 is not before the "
     "mission's time_limit (3600 s)"),
])
def test_what_a_fork_cannot_do_is_one_line(urban_search: Mission, at: str, sets: list[str],
                                           message: str) -> None:
    with pytest.raises(InputError) as caught:
        Simulation(urban_search).fork(at, sets)
    assert caught.value.one_line().startswith(message)


def test_set_paths_take_brackets_dots_and_appends() -> None:
    changes = parse_changes(["assignment.weights.risk.human=0", "rooms.set[A.1.2.1].risk=0.9",
                             "rooms.set.A.1.2.1.sound=loud", "team.1.speed=2",
                             "timeline+=[{event: cancel, robot: uav1, at: 3}]"])
    data = apply_changes({"assignment": {"weights": {"risk": {"human": 10}}},
                          "rooms": {"set": {}}, "team": [{}, {}], "timeline": []}, changes)
    assert data == {"assignment": {"weights": {"risk": {"human": 0}}},
                    "rooms": {"set": {"A.1.2.1": {"risk": 0.9, "sound": "loud"}}},
                    "team": [{}, {"speed": 2}],
                    "timeline": [{"event": "cancel", "robot": "uav1", "at": 3}]}


def test_regroup_merges_or_splits_the_rooms_left(urban_search: Mission) -> None:
    """A switch to a whole-mission planner plans the segment's pending rooms and the later
    segments' as one group; back, they are split by segment in the search order."""
    cbba = urban_search.with_changes(assignment={"strategy": "cbba"})
    left = [("A.1.2", ["A.1.2.3"]), ("A.2.1", ["A.2.1.1", "A.2.1.2"])]
    assert regroup(cbba, left) == [("all", ["A.1.2.3", "A.2.1.1", "A.2.1.2"])]
    assert regroup(urban_search, [("all", ["A.2.1.2", "A.1.2.3", "A.2.1.1"])]) == [
        ("A.1.2", ["A.1.2.3"]), ("A.2.1", ["A.2.1.1", "A.2.1.2"])]


def test_cli_forks_beside_the_run_and_refuses_a_bad_set(tmp_path: Path) -> None:
    out = tmp_path / "urban_search"
    code, _, stderr = run_cli("run", str(MISSION), "-q", "--no-recording", "-o", str(out),
                              "--fork-at", "round:2", "--set", "assignment.strategy=greedy")
    assert code == 0, stderr
    assert json.loads((out / "summary.json").read_text())["fork"]["point"] == "round:2"
    code, stdout, stderr = run_cli("run", str(MISSION), "-q", "-o", str(tmp_path / "bad"),
                                   "--set", "assignment.weights.risk.human=-1")
    assert (code, stdout) == (2, "")
    assert stderr == ("error: --set assignment.weights.risk.human=-1: Input should be greater "
                      "than or equal to 0 (got -1)\n")
    assert not (tmp_path / "bad").exists()


def test_set_without_a_fork_changes_the_mission_from_the_start(tmp_path: Path) -> None:
    code, _, stderr = run_cli("run", str(MISSION), "-q", "--no-recording", "-o", str(tmp_path),
                              "--set", "assignment.strategy=greedy")
    assert code == 0, stderr
    summary: dict[str, Any] = json.loads((tmp_path / "summary.json").read_text())
    assert [r["strategy"] for r in summary["rounds"]] == ["greedy"]
    assert "fork" not in summary


def test_a_physics_fork_keeps_the_prefix(urban_search: Mission) -> None:
    """Physics: a fault at t = 10 s of a 20 s mission; the log before it is the original's."""
    mission = urban_search.with_changes(fidelity="physics", time_limit=20)
    before = Simulation(mission).run()
    after = Simulation(mission).fork("time:10", ["timeline+={event: fault, robot: uav2}"])
    k = next(i for i, e in enumerate(after.events) if e["kind"] == "fork")
    assert after.events[:k] == before.events[:k]
    assert after.events[k]["t"] == 10.0 and after.events[k + 1]["kind"] == "fault"
    assert after.robots["uav2"].faulted and not before.robots["uav2"].faulted
