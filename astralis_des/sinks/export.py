"""``astralis export RUN_DIR --mcap``: ``run.mcap`` for a run already made.

A run is reproducible to the byte, so the export runs the mission again (its seed and
fidelity from the run's event log, its file found by name under ``missions/`` or given) with
only the MCAP output on, checks that the event log it writes is the run's own, byte for byte,
and only then puts ``run.mcap`` beside the run's other outputs.
"""

from __future__ import annotations

import json
import shutil
import tempfile
from pathlib import Path

from astralis_des.errors import InputError
from astralis_des.mission.loader import load_mission
from astralis_des.outdir import Staging, sync
from astralis_des.simulation import Simulation
from astralis_des.sinks.mcap_out import require


def export_mcap(run_dir: str | Path, mission_file: str | Path | None = None) -> Path:
    require()
    folder = Path(run_dir)
    events = folder / "events.jsonl"
    if not events.is_file():
        raise InputError("no events.jsonl here: not a run's output folder", file=folder)
    lines = events.read_bytes().splitlines(keepends=True)
    try:
        start = json.loads(lines[0])
        assert start["kind"] == "mission_start"
        name, seed, fidelity = start["mission"], int(start["seed"]), str(start["fidelity"])
    except (IndexError, ValueError, KeyError, AssertionError, TypeError):
        raise InputError("the first line is not a mission_start event", file=events,
                         line=1) from None
    path = Path(mission_file) if mission_file is not None else Path("missions") / f"{name}.yaml"
    if not path.is_file():
        raise InputError(f"the mission file of run '{name}' is not at {path}: give it with "
                         "--mission", key="--mission")
    mission = load_mission(path)
    if mission.name != name:
        raise InputError(f"{path} is mission '{mission.name}', the run is '{name}'",
                         key="--mission")
    outputs = {"dir": None, "events": True, "summary": False, "recording": False, "mcap": True}
    mission = mission.with_changes(seed=seed, fidelity=fidelity, outputs=outputs)
    with tempfile.TemporaryDirectory() as tmp:
        Simulation(mission, out_dir=tmp).run()
        again = (Path(tmp) / "events.jsonl").read_bytes().splitlines(keepends=True)
        if again != lines:
            differ = next((k for k, (a, b) in enumerate(zip(again, lines, strict=False))
                           if a != b), min(len(again), len(lines)))
            raise InputError(f"{path} does not reproduce this run (the event logs part at "
                             f"line {differ + 1}): was the mission or the world changed?",
                             file=events, line=differ + 1)
        target = folder / "run.mcap"
        with Staging(target, file=True) as staged:  # in place whole, or not at all
            shutil.copyfile(Path(tmp) / "run.mcap", staged / target.name)
            sync(staged / target.name)
    return target
