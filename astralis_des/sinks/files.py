"""Where a run's outputs go: the event log (JSONL), the summary (JSON), the Rerun recording
(registered in ``OUTPUTS`` as ``files``)."""

from __future__ import annotations

import contextlib
import time
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

from astralis_des.kernel.events import Record
from astralis_des.outdir import Staging, checked, result_files, write_failure, write_file
from astralis_des.outdir import dumps as strict_dumps
from astralis_des.simulation.outputs import OUTPUTS
from astralis_des.strict_json import encoder

if TYPE_CHECKING:
    from astralis_des.simulation import Simulation
    from astralis_des.simulation.result import RunResult


OUTPUT_FILES = result_files("events.jsonl", "summary.json", "recording.rrd", "run.mcap",
                            key="summary.json")


class Output(Protocol):
    path: Path  # the file it writes (in the staging folder)

    def on_event(self, record: Record) -> None: ...
    def close(self, result: RunResult) -> None: ...  # all handed on (may still be written)
    def finish(self) -> None: ...  # wait until it is written whole (else an OSError)
    def discard(self) -> None: ...  # the run's outputs are abandoned: let go of the file


class Outputs:
    """The open outputs of one run; each sees every event, then the result. They are written
    into a staging folder (:class:`~astralis_des.outdir.Staging`) put in place when the run
    closes, also when it was interrupted; a failed write removes it and raises, one line
    (:func:`~astralis_des.outdir.write_failure`). ``seconds`` is the wall time they took,
    opening included, for benchmarks to report their share."""

    def __init__(self, outputs: list[Output], seconds: float = 0.0,
                 stage: Staging | None = None) -> None:
        self.outputs = outputs
        self.seconds = seconds
        self.stage = stage
        self.failed: Exception | None = None  # the first failed write: nothing more is written

    def on_event(self, record: Record) -> None:
        if self.failed is not None:
            return
        t0 = time.perf_counter()
        try:
            for out in self.outputs:
                out.on_event(record)
        except OSError as exc:  # a full disk: the run stops here, and its outputs go
            self.failed = self._failure(exc)
            self._abandon()
            raise self.failed from exc
        finally:
            self.seconds += time.perf_counter() - t0

    def close(self, result: RunResult) -> None:
        t0 = time.perf_counter()
        try:
            if self.failed is not None:
                raise self.failed
            for out in reversed(self.outputs):  # the recording first: Rerun's threads
                out.close(result)                 # encode it while the others are written
            for out in self.outputs:
                out.finish()
                if self.stage is not None:  # on disk while the others are finished
                    self.stage.settle(out.path)
        except OSError as exc:
            self._abandon()
            raise self._failure(exc) from exc
        except BaseException:
            self._abandon()
            raise
        if self.stage is not None:
            self.stage.commit()
        self.seconds += time.perf_counter() - t0

    def _failure(self, exc: OSError) -> Exception:
        where = self.stage.target if self.stage is not None else Path(exc.filename or ".")
        return write_failure(where, exc)

    def _abandon(self) -> None:
        for out in self.outputs:
            out.discard()
        if self.stage is not None:
            self.stage.abandon()


class JsonlWriter:
    """``events.jsonl``: one event a line, written as it happens (line-buffered), so an
    interrupted run keeps every complete line and a reader can follow it (in the staging
    folder, :func:`~astralis_des.outdir.staging_path`, until the run ends)."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self._file = path.open("w", encoding="utf-8", buffering=1)

    def on_event(self, record: Record) -> None:
        self._file.write(dumps(record) + "\n")

    def close(self, result: RunResult) -> None:
        self._file.close()  # on disk by the staging (Outputs.close settles it)

    def finish(self) -> None:
        pass

    def discard(self) -> None:
        with contextlib.suppress(OSError):  # its bytes could not be written: no matter now
            self._file.close()


class SummaryWriter:
    def __init__(self, path: Path) -> None:
        self.path = path

    def on_event(self, record: Record) -> None:
        pass

    def close(self, result: RunResult) -> None:
        write_file(self.path, strict_dumps(result.summary(), indent=2) + "\n", sync=False)

    def finish(self) -> None:
        pass

    def discard(self) -> None:
        pass


dumps = encoder(separators=(",", ":"), ensure_ascii=False)  # an event log's line


@OUTPUTS.register("files")
def open_sinks(sim: Simulation, out_dir: Path | None) -> Outputs:
    """Open what the mission's ``outputs`` asks for, staged for ``out_dir`` (nothing without
    one); an earlier run's files there are replaced only when this run closes."""
    t0 = time.perf_counter()
    outputs: list[Output] = []
    stage = None
    if out_dir is not None:
        cfg = sim.mission.spec.outputs
        stage = Staging(out_dir, owned=OUTPUT_FILES, last="summary.json",
                        keep_interrupted=True)
        folder = stage.open()
        try:
            with checked(out_dir):
                if cfg.events:
                    outputs.append(JsonlWriter(folder / "events.jsonl"))
                if cfg.summary:
                    outputs.append(SummaryWriter(folder / "summary.json"))
                if cfg.recording:
                    from astralis_des.sinks.recording import RerunRecorder

                    outputs.append(RerunRecorder(sim, folder / "recording.rrd", view=sim.view))
                if cfg.mcap:
                    from astralis_des.sinks.mcap_out import McapWriter

                    outputs.append(McapWriter(sim, folder / "run.mcap"))
        except BaseException:
            for out in outputs:
                out.discard()
            stage.abandon()
            raise
    sinks = Outputs(outputs, time.perf_counter() - t0, stage)
    sim.log.sinks.append(sinks.on_event)
    return sinks
