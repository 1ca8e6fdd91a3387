"""Every mission in missions/ runs, and shows what its comment says it shows."""

from __future__ import annotations

from pathlib import Path

import pytest

from astralis_des import Simulation, load_mission

MISSIONS = sorted((Path(__file__).resolve().parents[1] / "missions").glob("*.yaml"))


@pytest.mark.parametrize("path", MISSIONS, ids=lambda p: p.stem)
def test_every_mission_runs_and_writes_its_outputs(path: Path, tmp_path: Path) -> None:
    """A mission ends with an outcome, an event log that starts and ends, and a summary."""
    result = Simulation(load_mission(path), out_dir=tmp_path).run()
    assert result.outcome in {"found", "not_found", "time_limit", "team_lost"}
    assert result.events[0]["kind"] == "mission_start"
    assert result.events[-1] == {"t": round(result.end_time, 6), "kind": "mission_end",
                                 "outcome": result.outcome}
    assert (tmp_path / "events.jsonl").read_text().count("\n") == len(result.events)
    assert (tmp_path / "summary.json").is_file() and (tmp_path / "recording.rrd").is_file()
    assert len(result.rounds) >= 1


def test_urban_search_finds_the_target() -> None:
    """The default mission finds its target in building A, in the room the seed drew."""
    result = Simulation(load_mission(MISSIONS[[p.stem for p in MISSIONS].index("urban_search")]))\
        .run()
    assert result.outcome == "found"
    detection = next(e for e in result.events if e["kind"] == "detection")
    assert detection["target_room"] == result.target["room"]
    assert result.time_to_find == detection["t"]
    assert result.target["room"] in result.rooms_searched or any(
        m["room"] == result.target["room"] for r in result.rounds for m in r["matching"])


def test_fig7_reproduces_the_papers_assignment() -> None:
    """Fig. 7: UAVs take the high-risk rooms (inward spiral), the UGV peeks, the human waits."""
    result = Simulation(load_mission(Path(MISSIONS[0]).parent / "fig7.yaml")).run()
    first = result.rounds[0]
    matching = {m["agent"]: (m["room"], m["action"]) for m in first["matching"]}
    assert matching == {
        "uav1": ("A.1.1.1", "spiral_inward"),
        "uav2": ("A.1.1.2", "spiral_inward"),
        "ugv1": ("A.1.1.3", "sneak_peek"),
    }
    assert first["unassigned"] == ["op1"]
    assert result.outcome == "found" and result.found_by == "uav2"


def test_faults_mission_fails_retries_preempts_and_recovers() -> None:
    """uav2 fails at 25 s, on its way to its room (it took off first, and ducked under the
    lintel); its room is retried; ugv1 is preempted at 35 s."""
    result = Simulation(load_mission(Path(MISSIONS[0]).parent / "faults.yaml")).run()
    finished = [e for e in result.events if e["kind"] == "task_finished"]
    failed = [e for e in finished if e["status"] == "failed"]
    assert [(e["t"], e["robot"], e["action"]) for e in failed] == [(25.0, "uav2", "move")]
    retried = failed[0]["room"]
    later = [r for r in result.rounds if r["t"] > 25.0]
    assert any(m["room"] == retried for r in later for m in r["matching"])
    assert all("uav2" not in r["agents"] for r in later if r["t"] < 100.0)
    assert any("uav2" in r["agents"] for r in later if r["t"] >= 100.0)
    preempted = [e for e in finished if e["status"] == "preempted"]
    assert [(e["t"], e["robot"]) for e in preempted] == [(35.0, "ugv1")]
    started = [e for e in result.events if e["kind"] == "task_started" and e["t"] == 35.0]
    assert started[0]["robot"] == "ugv1" and started[0]["action"] == "sneak_peek"
    change = next(e for e in result.events if e["kind"] == "room_change")
    round_a21 = next(r for r in result.rounds if r["segment"] == "A.2.1")
    assert round_a21["risk"][round_a21["rooms"].index("A.2.1.1")] == change["risk"] == 0.95


def test_hospital_search_searches_the_imported_rooms() -> None:
    """The hospital's 18 rooms, found in its model, are searched room by room; the UGV finds
    the target in H.1.1.6 after three rooms, as the mission's comment says."""
    mission = load_mission(Path(MISSIONS[0]).parent / "hospital_search.yaml")
    assert len(mission.searched_rooms()) == 18
    assert mission.world.interior is not None and mission.world.interior.group == "H"
    result = Simulation(mission).run()
    assert result.outcome == "found" and result.found_by == "ugv1"
    assert result.target["room"] == "H.1.1.6" and len(result.rooms_searched) == 3
    assert all(room.startswith("H.1.") for room in result.rooms_searched)
