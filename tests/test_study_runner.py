"""Running studies: worker-count independence, failed scenarios as rows, replays, missions."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from pathlib import Path

import numpy as np
import pytest

from astralis_des.assignment import STRATEGIES, Agent, RoomInfo, Weights
from astralis_des.assignment.eq1 import eq1_costs
from astralis_des.assignment.strategies import Strategy
from astralis_des.studies import StudyResult, load_study, make_study, run_scenario, run_study
from astralis_des.studies.eval_mission import scenario_mission
from astralis_des.studies.runner import chunks

ROOT = Path(__file__).parents[1]
MISSION = ROOT / "missions" / "urban_search.yaml"
TABLE5 = ROOT / "studies" / "table5.yaml"
OUTCOMES = ROOT / "studies" / "outcomes.yaml"


def without_wall_time(result: StudyResult) -> bytes:
    import pyarrow as pa
    import pyarrow.csv as csv

    sink = pa.BufferOutputStream()
    csv.write_csv(result.table, sink)
    return bytes(sink.getvalue())


def test_chunks_cover_every_scenario_once() -> None:
    """Chunks are in order, cover 0..n-1 once, and hold at most 25 scenarios."""
    parts = chunks(1000, 2)
    assert [i for part in parts for i in part] == list(range(1000))
    assert max(len(p) for p in parts) == 25
    assert chunks(3, 8) == [[0], [1], [2]]


def test_assignment_table_is_the_same_for_1_and_2_workers() -> None:
    """An assignment study gives the same table, byte for byte, on 1 and 2 processes."""
    study = load_study(TABLE5).with_changes(scenarios=300)
    one = run_study(study, workers=1)
    two = run_study(study, workers=2)
    assert (one.workers, two.workers) == (1, 2)
    assert without_wall_time(one) == without_wall_time(two)
    assert one.table.num_rows == 600
    assert one.table.column("scenario").to_pylist()[:4] == [0, 0, 1, 1]
    assert one.table.column("variant").to_pylist()[:4] == ["naive", "mixed", "naive", "mixed"]


def test_mission_table_is_the_same_for_1_and_2_workers() -> None:
    """Full kinematic missions too: the same rows whichever process ran which scenario."""
    study = load_study(OUTCOMES).with_changes(scenarios=4)
    one = run_study(study, workers=1)
    two = run_study(study, workers=2)
    assert without_wall_time(one) == without_wall_time(two)
    assert one.table.num_rows == 12
    assert set(one.table.column("status").to_pylist()) == {"ok"}


def test_variants_share_the_scenario_draws() -> None:
    """Every variant of a scenario runs the same target, rooms and starts (only the strategy
    differs): common random numbers."""
    study = load_study(OUTCOMES).with_changes(scenarios=2)
    rows = run_study(study, workers=1).rows
    for scenario in (0, 1):
        mine = [r for r in rows if r["scenario"] == scenario]
        assert [r["variant"] for r in mine] == ["naive", "mixed", "greedy"]
        assert len({(r["seed"], r["target_room"], r["high_risk_rooms"]) for r in mine}) == 1


def test_scenario_mission_carries_the_draws() -> None:
    """The mission a scenario runs has its seed, the variant's team at the drawn starts,
    each room's drawn values and the variant's strategy."""
    study = load_study(OUTCOMES)
    scenario = study.scenario(3)
    variant = study.variant("greedy")
    mission = scenario_mission(study, scenario, variant.setting, outputs=False)
    spec = mission.spec
    assert spec.seed == scenario.seed
    assert [m.id for m in spec.team] == ["uav1", "uav2", "ugv1", "human1"]
    assert tuple(spec.team[2].start) == scenario.start("ugv", 0)
    risk, mess = scenario.values(variant.setting.risk, variant.setting.messiness)["A.2.1.3"]
    assert (spec.rooms.set["A.2.1.3"].risk, spec.rooms.set["A.2.1.3"].messiness) == (risk, mess)
    assert spec.assignment.strategy == "greedy"
    assert (spec.outputs.events, spec.outputs.recording) == (False, False)


def _explodes(agents: Sequence[Agent], rooms: Sequence[RoomInfo],
              weights: Weights) -> np.ndarray:
    if max(r.risk for r in rooms) > 0.9:
        raise RuntimeError("boom: a risk above 0.9")
    return eq1_costs(agents, rooms, weights)


@pytest.fixture
def explodes(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """A strategy that raises when a room's risk is above 0.9 (registered for this test)."""
    monkeypatch.setitem(STRATEGIES._entries, "explodes", Strategy(_explodes))
    yield


def test_failed_scenarios_are_rows_and_the_study_goes_on(explodes: None) -> None:
    """An exception in one scenario is a failed row with its error and seed; the others run,
    on 1 worker and on 2 alike."""
    study = make_study(MISSION, name="x", scenarios=40, seed=1, evaluate="assignment",
                       draw={"positions": "building"},
                       vary={"strategy": ["naive", "explodes"]})
    one = run_study(study, workers=1)
    assert without_wall_time(one) == without_wall_time(run_study(study, workers=2))
    failed = [r for r in one.rows if r["status"] == "failed"]
    assert failed and len(failed) < 40
    assert {r["variant"] for r in failed} == {"explodes"}
    assert failed[0]["error"] == "RuntimeError: boom: a risk above 0.9"
    assert failed[0]["seed"] == study.scenario(failed[0]["scenario"]).seed
    assert failed[0].get("human_high_risk") is None
    assert one.failed == len(failed) == len(one.failures)
    assert "Traceback" in one.failures[0] and f"seed {failed[0]['seed']}" in one.failures[0]
    ok = [r for r in one.rows if r["status"] == "ok"]
    assert len(ok) == 80 - len(failed)
    # The row's scenario replays alone, and raises the same error.
    with pytest.raises(RuntimeError, match="boom"):
        run_scenario(study, failed[0]["scenario"], variants=["explodes"], raise_errors=True)
    again = run_scenario(study, failed[0]["scenario"], variants=["explodes"])
    assert again.rows == [failed[0]]


def test_recordings_only_when_asked(tmp_path: Path) -> None:
    """With recordings on, each mission writes its outputs under scenarios/INDEX/VARIANT/."""
    study = load_study(OUTCOMES).with_changes(scenarios=1, vary={"strategy": ["mixed"]})
    run_study(study, workers=1, out=tmp_path / "plain")
    assert not (tmp_path / "plain" / "scenarios").exists()
    run_study(study, workers=1, out=tmp_path / "rec", recordings=True)
    folder = tmp_path / "rec" / "scenarios" / "000000" / "00_mixed"
    assert sorted(p.name for p in folder.iterdir()) == ["events.jsonl", "recording.rrd",
                                                        "summary.json"]
