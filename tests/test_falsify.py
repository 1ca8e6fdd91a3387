"""``astralis falsify``: the worst scenarios of a strategy, found in the mission's space, written
as missions that reproduce their metric; the gap to another strategy; bad input."""

from __future__ import annotations

import json
from pathlib import Path

import pyarrow.parquet as pq
import pytest
import yaml

from astralis_des.cli import main
from astralis_des.mission.loader import load_mission
from astralis_des.studies.falsify import Falsify, run_falsify
from astralis_des.studies.falsify_space import load_space

ROOT = Path(__file__).resolve().parents[1]
MISSION = ROOT / "missions" / "urban_search.yaml"


@pytest.fixture(scope="module")
def searched(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A small falsify of the default mission: 4 optimised and 4 random trials, 2 worst."""
    out = tmp_path_factory.mktemp("falsify") / "out"
    assert main(["falsify", str(MISSION), "--metric", "time_to_find", "--trials", "4",
                 "--batch", "2", "--workers", "1", "--worst", "2", "-o", str(out), "-q"]) == 0
    return out


@pytest.fixture(scope="module")
def against(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("against") / "out"
    assert main(["falsify", str(MISSION), "--strategy", "mixed", "--against", "greedy",
                 "--metric", "human_high_risk_s", "--trials", "4", "--batch", "2",
                 "--no-baseline", "--workers", "1", "--worst", "1", "-o", str(out),
                 "-q"]) == 0
    return out


def test_the_worst_mission_reproduces_its_metric(searched: Path, tmp_path: Path) -> None:
    """``astralis run worst/01.yaml`` writes the trial's time to find, to the byte."""
    trials = pq.read_table(searched / "trials.parquet").to_pylist()
    worst = max((t for t in trials if t["score"] is not None),
                key=lambda t: t["score"])
    text = (searched / "worst" / "01.yaml").read_text(encoding="utf-8")
    value = json.dumps(worst["value"])
    assert f"# time_to_find = {value} under mixed\n" in text
    assert main(["run", str(searched / "worst" / "01.yaml"), "-o", str(tmp_path / "run"),
                 "--no-recording", "-q"]) == 0
    summary = json.loads((tmp_path / "run" / "summary.json").read_text(encoding="utf-8"))
    assert json.dumps(summary["metrics"]["time_to_find"]) == value
    assert summary["mission"] == "urban_search_worst01"


def test_the_folder_holds_every_trial_and_the_report(searched: Path) -> None:
    """8 trials (4 of TPE, 4 random), each with its parameters; 2 worst, worst first."""
    trials = pq.read_table(searched / "trials.parquet").to_pylist()
    assert [(t["search"], t["trial"]) for t in trials] == [
        *(("optimiser", i) for i in range(4)), *(("random", i) for i in range(4))]
    assert all(t["status"] == "ok" and t["score"] == t["value"] for t in trials)
    assert {t["param.target.room"] for t in trials} <= set(load_mission(MISSION)
                                                           .searched_rooms())
    assert sorted(p.name for p in (searched / "worst").iterdir()) == ["01.yaml", "02.yaml"]
    second = (searched / "worst" / "02.yaml").read_text(encoding="utf-8")
    first = (searched / "worst" / "01.yaml").read_text(encoding="utf-8")
    scores = sorted((t["score"] for t in trials), reverse=True)
    assert f"= {json.dumps(scores[1])} under" in second and f"= {scores[0]!r} under" in first
    world = yaml.safe_load(first)["world"]  # from worst/, where it was put
    assert (searched / "worst" / world).resolve() == ROOT / "worlds" / "urban_default.yaml"
    report = (searched / "report.md").read_text(encoding="utf-8")
    assert "![convergence](plots/convergence.png)" in report
    assert (searched / "plots" / "convergence.png").stat().st_size > 0
    meta = json.loads((searched / "meta.json").read_text(encoding="utf-8"))
    assert meta["trials"] == {"optimiser": 4, "random": 4} and meta["sampler"] == "tpe"


def test_against_scores_the_gap_on_the_same_scenario(against: Path, tmp_path: Path) -> None:
    """With --against, each trial runs both strategies; its score is mixed's less greedy's;
    the worst file runs mixed, to the trial's value."""
    trials = pq.read_table(against / "trials.parquet").to_pylist()
    assert len(trials) == 4
    for t in trials:
        assert t["value"] == t["mixed.human_high_risk_s"]
        assert t["value_against"] == t["greedy.human_high_risk_s"]
        assert t["score"] == pytest.approx(t["value"] - t["value_against"])
    text = (against / "worst" / "01.yaml").read_text(encoding="utf-8")
    best = max(trials, key=lambda t: t["score"])
    assert f"under greedy; the gap (worse for mixed) is {best['score']:.6g}" in text
    assert "strategy: mixed" in text
    assert main(["run", str(against / "worst" / "01.yaml"), "-o", str(tmp_path / "run"),
                 "--no-recording", "-q"]) == 0
    summary = json.loads((tmp_path / "run" / "summary.json").read_text(encoding="utf-8"))
    assert json.dumps(summary["metrics"]["human_high_risk_s"]) == json.dumps(best["value"])


def test_the_trials_depend_on_the_seed_not_the_workers() -> None:
    """The same request on 1 and on 2 workers: the same trials, the same scores."""
    mission = load_mission(MISSION)
    space = load_space(None, mission, strategies=["mixed"], fault_until=100.0)
    f = Falsify(mission, space, "mixed", "time_to_find", 4, batch=2, baseline=False, seed=3)
    one, two = run_falsify(f, workers=1), run_falsify(f, workers=2)
    assert [r["changes"] for r in one.rows] == [r["changes"] for r in two.rows]
    assert [r["score"] for r in one.rows] == [r["score"] for r in two.rows]


def test_a_trial_is_a_complete_mission() -> None:
    """Every drawn value is set: the target on free floor in its room, the fault, the
    starts among the free spots, each room's properties."""
    mission = load_mission(MISSION)
    space = load_space(None, mission, strategies=["mixed", "cbba"], fault_until=100.0)
    params = {name: (dim.choices[-1] if dim.choices else dim.high)
              for name, dim in space.dims.items()}
    params.update({"target.activity": "laying", "target.tied_to_chair": True,
                   "fault.robot": "op1", "fault.at": 12.34567})
    changes = space.changes(params)
    target = changes["target"]
    room = mission.world.rooms[target["room"]]
    assert room.box.contains(target["position"])
    assert target["avatar"]["tied_to_chair"] is False  # only a sitting avatar is
    assert changes["timeline"] == [{"at": 12.3, "event": "fault", "robot": "op1",
                                    "reason": "falsify"}]
    assert changes["assignment"]["options"]["comm_range"] == 100.0
    assert len(changes["rooms"]["set"]) == 18
    assert changes["team"][0]["start"] == space.starts["uav1"][-1]
    mission.with_changes(**changes)  # checked as a file is


def test_a_space_file_narrows_and_widens_the_space(tmp_path: Path) -> None:
    """Sections set to false keep the mission's values; sounds, looks and the seed are
    searched only when named."""
    path = tmp_path / "space.yaml"
    path.write_text("target: {rooms: [A.3.1.1, A.3.1.2], place: false, avatar: true}\n"
                    "rooms: {rooms: [A.3.1.1], risk: false, sound: [loud, minimal]}\n"
                    "faults: false\nmovers: false\nstarts: false\nseed: {low: 0, high: 9}\n",
                    encoding="utf-8")
    space = load_space(path, load_mission(MISSION), strategies=["mixed"], fault_until=1.0)
    assert list(space.dims) == [
        "seed", "target.room", "target.activity", "target.color", "target.gender",
        "target.height", "target.tied_to_chair", "target.messiness", "target.sound",
        "room.A.3.1.1.messiness", "room.A.3.1.1.sound"]
    assert space.dims["room.A.3.1.1.sound"].choices == ("loud", "minimal")
    changes = space.changes({"seed": 4, "target.room": "A.3.1.2", "target.messiness": 0.91234,
                             "target.sound": "loud", "room.A.3.1.1.messiness": 0.2,
                             "room.A.3.1.1.sound": "minimal"})
    assert changes["seed"] == 4 and changes["timeline"] == [] and "position" not in \
        changes["target"]
    assert changes["rooms"]["set"] == {"A.3.1.1": {"messiness": 0.2, "sound": "minimal"},
                                       "A.3.1.2": {"messiness": 0.912, "sound": "loud"}}


def bad(tmp_path: Path, capsys: pytest.CaptureFixture[str], *args: str) -> str:
    out = tmp_path / "out"
    assert main(["falsify", str(MISSION), "--trials", "2", "-o", str(out), "-q",
                 *args]) == 2
    assert not out.exists()
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1, err
    return err


def test_bad_input_is_one_line_and_nothing_written(tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    assert bad(tmp_path, capsys, "--metric", "time_to_fnd") == (
        "error: --metric: unknown metric 'time_to_fnd'; did you mean 'time_to_find'?\n")
    assert bad(tmp_path, capsys, "--strategy", "mixd").startswith(
        "error: --strategy: ")
    assert bad(tmp_path, capsys, "--against", "mixed") == (
        "error: --against: 'mixed' is the strategy itself: compare it with another\n")
    assert bad(tmp_path, capsys, "--sampler", "tpee") == (
        "error: --sampler: unknown sampler 'tpee'; did you mean 'tpe'?\n")
    space = tmp_path / "space.yaml"
    space.write_text("rooms:\n  risk: {low: 0.5, high: 1}\ntarget:\n  roomz: [A.1.1.1]\n",
                     encoding="utf-8")
    assert bad(tmp_path, capsys, "--space", str(space)) == (
        f"error: {space}:4: target.roomz: unknown key 'roomz'; did you mean 'rooms'?\n")
    space.write_text("faults:\n  robots: [uav1, ugv9]\n", encoding="utf-8")
    assert bad(tmp_path, capsys, "--space", str(space)) == (
        f"error: {space}:2: faults.robots[1]: no member 'ugv9' in the team; "
        "did you mean 'ugv1'?\n")
