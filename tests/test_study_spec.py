"""Study files: what they set and vary, and bad input answered with file, line and key."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import pytest

from astralis_des.cli import main
from astralis_des.errors import InputError
from astralis_des.studies import load_study, make_study

ROOT = Path(__file__).parents[1]
MISSION = ROOT / "missions" / "urban_search.yaml"

GOOD = f"""\
name: s
mission: {json.dumps(str(MISSION))}
seed: 3
scenarios: 10
evaluate: assignment
draw: {{positions: building}}
vary:
  strategy: [naive, mixed]
  w1.human: [5, 10]
"""


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "study.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def error_of(tmp_path: Path, text: str) -> str:
    with pytest.raises(InputError) as info:
        load_study(write(tmp_path, text))
    return str(info.value)


def test_variants_cross_the_varied_values(tmp_path: Path) -> None:
    """Two parameters of two values each give four variants, named and set in file order."""
    study = load_study(write(tmp_path, GOOD))
    assert [v.name for v in study.variants] == [
        "strategy=naive,w1.human=5", "strategy=naive,w1.human=10",
        "strategy=mixed,w1.human=5", "strategy=mixed,w1.human=10"]
    last = study.variants[3]
    assert last.columns == {"strategy": "mixed", "w1.human": 10.0}
    assert (last.setting.strategy, last.setting.weights["risk"]) == (
        "mixed", {"human": 10.0, "uav": 5.0, "ugv": 3.0})


def test_named_values_and_set(tmp_path: Path) -> None:
    """A mapping names its values; ``set`` applies to every variant; scales multiply."""
    vary = "vary:\n  strategy: [naive, mixed]\n  w1.human: [5, 10]\n"
    assert GOOD.count(vary) == 1
    text = GOOD.replace(vary, "set: {risk: {dist: beta, a: 2, b: 5}, w2_scale: 2}\n"
                        "vary:\n  team: {paper: {uav: 2, ugv: 1, human: 1}, duo: {uav: 2}}\n")
    study = load_study(write(tmp_path, text))
    assert [v.name for v in study.variants] == ["paper", "duo"]
    assert study.variants[1].setting.team == {"uav": 2, "ugv": 0, "human": 0}
    assert study.variants[0].columns == {"team": "paper"}
    assert study.variants[0].setting.weights["messiness"] == {"human": 10.0, "uav": 0.0,
                                                              "ugv": 20.0}
    assert study.variants[0].setting.risk.a == 2


def test_scenario_seeds_come_from_the_study_seed_and_index(tmp_path: Path) -> None:
    """A scenario's seed and draws depend on the study's seed and its index only."""
    study = load_study(write(tmp_path, GOOD))
    again = study.with_changes(scenarios=5000)
    assert study.scenario(7).seed == again.scenario(7).seed
    assert study.scenario(7).start("ugv", 0) == again.scenario(7).start("ugv", 0)
    assert study.scenario(7).seed != study.scenario(8).seed
    other = study.with_changes(seed=4)
    assert other.scenario(7).seed != study.scenario(7).seed


def test_a_larger_team_keeps_the_starts_of_a_smaller_one(tmp_path: Path) -> None:
    """Each (kind, k) has its own stream: uav2's start does not move uav1's."""
    scenario = load_study(write(tmp_path, GOOD)).scenario(0)
    first = scenario.start("uav", 0)
    scenario2 = load_study(write(tmp_path, GOOD)).scenario(0)
    scenario2.start("uav", 1)
    assert scenario2.start("uav", 0) == first


def test_make_study_from_python() -> None:
    """A study needs no file: a base mission, a count, what varies."""
    study = make_study(MISSION, name="py", scenarios=3, evaluate="assignment",
                       vary={"strategy": ["naive", "greedy"]})
    assert [v.name for v in study.variants] == ["naive", "greedy"]
    assert "strategy" in study.text


@pytest.mark.parametrize(("old", "new", "line", "says"), [
    ("  w1.human: [5, 10]", "  w1.humn: [5, 10]", 9,
     "vary.w1.humn: unknown parameter 'w1.humn' to vary; did you mean 'w1.human'?"),
    ("  w1.human: [5, 10]", "  w1.human: []", 9,
     "vary.w1.human: empty range: give at least one value"),
    ("scenarios: 10", "scenarios: 0", 4,
     "scenarios: give between 1 and 10,000,000 scenarios (got 0)"),
    ("[naive, mixed]", "[naive, mixd]", 8,
     "vary.strategy[1]: strategy: unknown assignment strategy 'mixd'; did you mean 'mixed'?"),
    ("evaluate: assignment", "evaluate: assignmnt", 5,
     "evaluate: unknown study evaluation 'assignmnt'; did you mean 'assignment'?"),
    ("  w1.human: [5, 10]", "  fidelity: [physics]", 9,
     "vary.fidelity: 'fidelity' means nothing when evaluate is 'assignment'"),
    ("  w1.human: [5, 10]", "  w1.human: 5", 9,
     "vary.w1.human: give a list of values or a mapping of names to values (got 5)"),
    ("  w1.human: [5, 10]", "  w1.human: [5, -1]", 9,
     "vary.w1.human[1]: w1.human: Input should be greater than or equal to 0 (got -1)"),
    ("seed: 3", "seed: 3\nsed: 4", 4, "sed: unknown key 'sed'; did you mean 'seed'?"),
    ("draw: {positions: building}", "draw: {positions: buildings}", 6,
     "draw.positions.type: unknown type 'buildings'; did you mean 'building'?"),
])
def test_bad_input_names_file_line_and_key(tmp_path: Path, old: str, new: str, line: int,
                                           says: str) -> None:
    """Each mistake is one line: FILE:LINE: KEY: message (with 'did you mean' where it helps)."""
    assert GOOD.count(old) == 1
    message = error_of(tmp_path, GOOD.replace(old, new))
    assert message.startswith(f"{tmp_path / 'study.yaml'}:{line}: ")
    assert says in message


def test_missing_mission_file(tmp_path: Path) -> None:
    """A study whose mission does not exist names the mission key."""
    message = error_of(tmp_path, GOOD.replace(json.dumps(str(MISSION)), "nowhere.yaml"))
    assert ":2: mission: no such mission file: " in message


def test_cli_bad_study_exit_2_one_line_nothing_written(tmp_path: Path) -> None:
    """``astralis study`` on a bad file: exit code 2, one line on stderr, no folder."""
    path = write(tmp_path, GOOD.replace("w1.human: [5, 10]", "w1.human: []"))
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["study", str(path), "--out", str(tmp_path / "out")])
    assert code == 2
    assert err.getvalue() == (f"error: {path}:9: vary.w1.human: empty range: give at least "
                              "one value\n")
    assert not (tmp_path / "out").exists()
    assert [p.name for p in tmp_path.iterdir()] == ["study.yaml"]


def test_outdoor_starts_are_starts_the_mission_validator_accepts() -> None:
    """A drawn start beside a wall was refused when the scenario's mission was checked: 50
    of the first 1,000 scenarios of the outcome and baseline studies failed a run (scenario
    39 first). Each start is drawn clear of every solid by its kind's body."""
    from astralis_des.studies.scenarios import run_scenario
    from astralis_des.world.placement import problem

    study = load_study(ROOT / "studies" / "outcomes.yaml")
    team = study.mission.spec.team
    for index in range(60):
        scenario = study.scenario(index)
        for member in team:
            k = [m.id for m in team if m.kind == member.kind].index(member.id)
            start = scenario.start(member.kind, k)
            assert isinstance(start, tuple)
            assert problem(study.mission.world, start, member.kind) is None, (index, member.id)
    rows = run_scenario(study, 39).rows
    assert [r["status"] for r in rows] == ["ok"] * 3
