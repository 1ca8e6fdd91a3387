"""Where a run's outputs go: the event log (JSONL), the summary (JSON), the Rerun recording
(registered in ``OUTPUTS`` as ``files``)."""

from __future__ import annotations

import contextlib
import os
import threading
import time
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any, Protocol

from astralis_des.kernel.events import Record
from astralis_des.outdir import Staging, checked, result_files, write_failure
from astralis_des.outdir import dumps as strict_dumps
from astralis_des.simulation.outputs import OUTPUTS

if TYPE_CHECKING:
    from astralis_des.simulation import Simulation
    from astralis_des.simulation.result import RunResult


OUTPUT_FILES = result_files("events.jsonl", "summary.json", "recording.rrd", "run.mcap",
                            key="summary.json")


class Output(Protocol):
    def on_event(self, record: Record) -> None: ...
    def close(self, result: RunResult) -> None: ...
    def discard(self) -> None: ...  # the run's outputs are abandoned: let go of the file


class Outputs:
    """The open outputs of one run; each sees every event, then the result. They are written
    into a staging folder (:class:`~astralis_des.outdir.Staging`) put in place when the run
    closes, also when it was interrupted; a failed write removes it and raises, one line
    (:func:`~astralis_des.outdir.write_failure`). ``seconds`` is the wall time they took,
    opening included, for benchmarks to report their share."""

    def __init__(self, outputs: list[Output], seconds: float = 0.0,
                 stage: Staging | None = None, syncs: Syncs | None = None) -> None:
        self.outputs = outputs
        self.seconds = seconds
        self.stage = stage
        self.syncs = syncs or Syncs()
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
            for out in self.outputs:
                out.close(result)
            self.syncs.wait()
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
        self.syncs.wait(quiet=True)  # a file being synced is closed by its sync
        for out in self.outputs:
            out.discard()
        if self.stage is not None:
            self.stage.abandon()


class Syncs:
    """The ``fsync`` of each written file, each on a thread of its own, so that the disk
    works while the recording is made (3 to 7 ms a run, one after the other); :meth:`wait`
    raises the first that failed (a full disk, an I/O error), before anything is put in
    place. Each file is closed once synced."""

    def __init__(self) -> None:
        self._threads: list[threading.Thread] = []
        self._failed: list[OSError] = []

    def start(self, file: IO[Any]) -> None:
        """Sync and close ``file`` (its bytes flushed to the system already)."""
        thread = threading.Thread(target=self._sync, args=(file,), name="astralis-fsync",
                                  daemon=True)
        thread.start()
        self._threads.append(thread)

    def _sync(self, file: IO[Any]) -> None:
        try:
            try:
                os.fsync(file.fileno())
            finally:
                file.close()
        except OSError as exc:
            self._failed.append(exc)

    def wait(self, *, quiet: bool = False) -> None:
        """Wait for every sync started; raise the first failure (none with ``quiet``)."""
        threads, self._threads = self._threads, []
        for thread in threads:
            thread.join()
        failed, self._failed = self._failed, []
        if failed and not quiet:
            raise failed[0]


class JsonlWriter:
    """``events.jsonl``: one event a line, written as it happens (line-buffered), so an
    interrupted run keeps every complete line and a reader can follow it (in the staging
    folder, :func:`~astralis_des.outdir.staging_path`, until the run ends)."""

    def __init__(self, path: Path, syncs: Syncs) -> None:
        self._file = path.open("w", encoding="utf-8", buffering=1)
        self._syncs = syncs

    def on_event(self, record: Record) -> None:
        self._file.write(dumps(record) + "\n")

    def close(self, result: RunResult) -> None:
        self._file.flush()
        self._syncs.start(self._file)

    def discard(self) -> None:
        with contextlib.suppress(OSError):  # its bytes could not be written: no matter now
            self._file.close()


class SummaryWriter:
    def __init__(self, path: Path, syncs: Syncs) -> None:
        self.path = path
        self._syncs = syncs

    def on_event(self, record: Record) -> None:
        pass

    def close(self, result: RunResult) -> None:
        """Written whole to the system here (a full disk fails here), synced meanwhile."""
        text = strict_dumps(result.summary(), indent=2) + "\n"
        file = self.path.open("w", encoding="utf-8")
        try:
            file.write(text)
            file.flush()
        except BaseException:
            with contextlib.suppress(OSError):
                file.close()
            raise
        self._syncs.start(file)

    def discard(self) -> None:
        pass


def dumps(record: Any) -> str:
    return strict_dumps(record, separators=(",", ":"), ensure_ascii=False)


@OUTPUTS.register("files")
def open_sinks(sim: Simulation, out_dir: Path | None) -> Outputs:
    """Open what the mission's ``outputs`` asks for, staged for ``out_dir`` (nothing without
    one); an earlier run's files there are replaced only when this run closes."""
    t0 = time.perf_counter()
    outputs: list[Output] = []
    stage = None
    syncs = Syncs()
    if out_dir is not None:
        cfg = sim.mission.spec.outputs
        stage = Staging(out_dir, owned=OUTPUT_FILES, last="summary.json",
                        keep_interrupted=True)
        folder = stage.open()
        try:
            with checked(out_dir):
                if cfg.events:
                    outputs.append(JsonlWriter(folder / "events.jsonl", syncs))
                if cfg.summary:
                    outputs.append(SummaryWriter(folder / "summary.json", syncs))
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
    sinks = Outputs(outputs, time.perf_counter() - t0, stage, syncs)
    sim.log.sinks.append(sinks.on_event)
    return sinks
