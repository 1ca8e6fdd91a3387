"""examples/: an external coordination algorithm that runs on the API alone."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path
from types import ModuleType

import pytest

from astralis_des import Mission
from astralis_des.api import Client
from astralis_des.api.local import Background

ROOT = Path(__file__).resolve().parents[1]


def _example(name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(name, ROOT / "examples" / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _coordinate(mission: Mission, out: Path) -> tuple[dict, list[str]]:
    coordinator = _example("external_coordinator")
    background = Background(mission, running=False, out_dir=out)
    with Client(background.start(), timeout=10.0) as client:
        nearest = coordinator.Nearest(client)
        status = nearest.run(step=2.0)
        client.shutdown()
    background.stop()
    return status, nearest.searched


def test_an_external_coordinator_finds_the_target_reproducibly(urban_search: Mission,
                                                               tmp_path: Path) -> None:
    manual = urban_search.with_changes(assignment={"auto": False, "search": ["A"]})
    status, searched = _coordinate(manual, tmp_path / "one")
    assert status["found"] and status["found_by"] is not None
    assert searched and "A.1.2.1" not in searched  # found in A.1.2.1 while searching it
    events = [json.loads(x) for x in (tmp_path / "one" / "events.jsonl").read_text()
              .splitlines()]
    origins = {(e["origin"], e["action"]) for e in events if e["kind"] == "task_queued"}
    assert {o for o, _ in origins} == {"api", "mission"}  # the UAVs land at the end
    assert {a for o, a in origins if o == "mission"} == {"land"}
    assert [e["kind"] for e in events].count("assignment") == 0
    detection = next(e for e in events if e["kind"] == "detection")
    assert detection["target_room"] == "A.1.2.1"
    _coordinate(manual, tmp_path / "two")  # the same requests at the same simulated times
    assert (tmp_path / "one" / "events.jsonl").read_bytes() == \
        (tmp_path / "two" / "events.jsonl").read_bytes()
    assert (tmp_path / "one" / "summary.json").read_bytes() == \
        (tmp_path / "two" / "summary.json").read_bytes()


def test_the_env_example_the_heuristic_beats_random() -> None:
    pytest.importorskip("pettingzoo")
    example = _example("env_policies")
    runs = example.compare(ROOT / "missions" / "urban_search.yaml", 6)
    mean = {name: sum(r for r, _, _ in rows) / len(rows) for name, rows in runs.items()}
    assert set(mean) == {"random", "mixed heuristic"}
    assert all(len(rows) == 6 for rows in runs.values())
    assert mean["mixed heuristic"] > mean["random"]
