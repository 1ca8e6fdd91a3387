"""A mission study of a mission whose timeline names robots (found by the fuzzer): the
study's team takes the ids of its mix (uav1, ..., human1), and the timeline's events follow the
members they named, so a fault still downs its robot; a variant whose team lacks one is refused
when the study loads, in one line (before: every scenario failed with a traceback)."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from astralis_des.cli import main
from astralis_des.errors import InputError
from astralis_des.studies import load_study, run_study

ROOT = Path(__file__).resolve().parents[1]


def study_file(folder: Path, mission: Path, **extra: object) -> Path:
    doc = {"name": "timeline", "mission": str(mission), "seed": 5, "scenarios": 2,
           "evaluate": "mission", "vary": {"strategy": ["greedy"]}, **extra}
    path = folder / "study.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
    return path


def test_the_timeline_follows_the_members_it_named(tmp_path: Path) -> None:
    """faults.yaml downs uav2 and commands ugv1; its human is op1, the study's human1."""
    mission = yaml.safe_load((ROOT / "missions" / "faults.yaml").read_text())
    mission["world"] = str(ROOT / "worlds" / "urban_default.yaml")
    mission["team"][1]["id"] = "second"  # named as a user might: the fault still finds it
    mission["timeline"][0]["robot"] = mission["timeline"][3]["robot"] = "second"
    path = tmp_path / "mission.yaml"
    path.write_text(yaml.safe_dump(mission, sort_keys=False), encoding="utf-8")
    study = load_study(study_file(tmp_path, path))
    result = run_study(study, workers=1, out=tmp_path / "out", recordings=True)
    assert not result.failures
    logs = sorted((tmp_path / "out").rglob("events.jsonl"))
    assert len(logs) == 2
    for events in logs:
        faults = [line for line in events.read_text().splitlines() if '"kind":"fault"' in line]
        assert len(faults) == 1 and '"robot":"uav2"' in faults[0]


def test_a_variant_without_a_member_the_timeline_names_is_refused(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = study_file(tmp_path, ROOT / "missions" / "faults.yaml",
                      set={"team": {"uav": 1, "ugv": 1, "human": 1}})
    with pytest.raises(InputError, match="the mission's timeline names uav2, and variant "
                       "'greedy' has no such member"):
        load_study(path)
    assert main(["study", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    [line] = capsys.readouterr().err.splitlines()
    assert line.startswith(f"error: {path}:2: mission: the mission's timeline names uav2")
    assert not (tmp_path / "out").exists()
