"""Where a run's outputs go: the event log (JSONL), the summary (JSON), the Rerun recording."""

from __future__ import annotations

import json
import os
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from astralis_des.kernel.events import Record
from astralis_des.simulation.outputs import OUTPUTS

if TYPE_CHECKING:
    from astralis_des.simulation import Simulation
    from astralis_des.simulation.result import RunResult


OUTPUT_FILES = ("events.jsonl", "summary.json", "recording.rrd", "run.mcap")


class Output(Protocol):
    def on_event(self, record: Record) -> None: ...
    def close(self, result: RunResult) -> None: ...


class Outputs:
    """The open outputs of one run; each sees every event, then the result. ``seconds`` is
    the wall time they took, opening included, for benchmarks to report their share."""

    def __init__(self, outputs: list[Output], seconds: float = 0.0) -> None:
        self.outputs = outputs
        self.seconds = seconds

    def on_event(self, record: Record) -> None:
        t0 = time.perf_counter()
        for out in self.outputs:
            out.on_event(record)
        self.seconds += time.perf_counter() - t0

    def close(self, result: RunResult) -> None:
        t0 = time.perf_counter()
        for out in self.outputs:
            out.close(result)
        self.seconds += time.perf_counter() - t0


class JsonlWriter:
    """``events.jsonl``: one event a line, written as it happens (line-buffered), so an
    interrupted or killed run keeps every complete line and a reader can follow it."""

    def __init__(self, path: Path) -> None:
        self._file = path.open("w", encoding="utf-8", buffering=1)

    def on_event(self, record: Record) -> None:
        self._file.write(dumps(record) + "\n")

    def close(self, result: RunResult) -> None:
        self._file.close()


class SummaryWriter:
    def __init__(self, path: Path) -> None:
        self.path = path

    def on_event(self, record: Record) -> None:
        pass

    def close(self, result: RunResult) -> None:
        write_atomic(self.path, json.dumps(result.summary(), indent=2) + "\n")


def dumps(record: Any) -> str:
    return json.dumps(record, separators=(",", ":"), ensure_ascii=False)


def write_atomic(path: Path, text: str) -> None:
    """Write through a temporary file and rename, so no reader sees half a file."""
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)


@OUTPUTS.register("files")
def open_sinks(sim: Simulation, out_dir: Path | None) -> Outputs:
    """Open what the mission's ``outputs`` asks for under ``out_dir`` (nothing without one)."""
    t0 = time.perf_counter()
    outputs: list[Output] = []
    if out_dir is not None:
        cfg = sim.mission.spec.outputs
        out_dir.mkdir(parents=True, exist_ok=True)
        for name in OUTPUT_FILES:  # an earlier run's files never sit beside this run's
            (out_dir / name).unlink(missing_ok=True)
        if cfg.events:
            outputs.append(JsonlWriter(out_dir / "events.jsonl"))
        if cfg.summary:
            outputs.append(SummaryWriter(out_dir / "summary.json"))
        if cfg.recording:
            from astralis_des.sinks.recording import RerunRecorder

            outputs.append(RerunRecorder(sim, out_dir / "recording.rrd", view=sim.view))
        if cfg.mcap:
            from astralis_des.sinks.mcap_out import McapWriter

            outputs.append(McapWriter(sim, out_dir / "run.mcap"))
    sinks = Outputs(outputs, time.perf_counter() - t0)
    sim.log.sinks.append(sinks.on_event)
    return sinks
