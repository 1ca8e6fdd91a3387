"""Run a study: scenarios in chunks on a backend, one row per scenario and variant.

A scenario's seed derives from the study's seed and its index, and rows are put back in
(scenario, variant) order, so the table does not depend on the backend or the worker count.
An exception inside one scenario is a failed row (its error and seed), and the study goes on.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from contextlib import closing
from pathlib import Path
from typing import TYPE_CHECKING, Any

from astralis_des.exits import Deferral
from astralis_des.studies.backends import Backend, make_backend
from astralis_des.studies.output import fill_folder, staging
from astralis_des.studies.results import StudyResult
from astralis_des.studies.scenarios import ChunkResult, chunks, evaluation_of, run_scenario

if TYPE_CHECKING:
    from astralis_des.studies.spec import Study

__all__ = ["ChunkResult", "StudyResult", "chunks", "evaluation_of", "run_scenario", "run_study"]
Progress = Callable[[int, int], None]  # (scenarios done, scenarios in all)
SCENARIOS_DIR = "scenarios"


def run_study(study: Study, *, workers: int | None = None, backend: str | Backend = "local",
              address: str | None = None, out: str | Path | None = None,
              recordings: bool | None = None, progress: Progress | None = None) -> StudyResult:
    """Run every scenario of ``study`` under every variant.

    ``workers``: processes (default: the CPUs); ``backend``: ``local`` (a process pool) or
    ``ray`` (``address`` for an existing cluster, else a local instance), or a backend made
    and held by the caller (:meth:`Backend.hold`, a tune's trials). With ``out``, the
    study folder is written there, all or nothing; ``recordings`` (default: the study file's
    ``outputs.recordings``) writes each mission's outputs under it. Interrupted (Ctrl-C,
    SIGTERM, SIGHUP), it returns, and writes, the rows of the scenarios done, with
    ``interrupted`` set.
    """
    workers = workers or os.cpu_count() or 1
    runner = make_backend(backend, workers, address) if isinstance(backend, str) else backend
    record = study.spec.outputs.recordings if recordings is None else recordings
    if record and out is None:
        from astralis_des.errors import InputError

        raise InputError("recordings need an output folder", key="recordings")
    t0 = time.perf_counter()
    # once the scenarios are done, or interrupted, the folder is written whole and put in
    # place; a signal meanwhile marks the result interrupted
    shield = Deferral(raise_after=False)
    with shield, staging(Path(out) if out is not None else None) as tmp:
        rec_dir = tmp / SCENARIOS_DIR if (tmp is not None and record) else None
        rows: list[dict[str, Any]] = []
        failures: list[str] = []
        done = 0
        parts = runner.run(study, chunks(study.scenarios, runner.workers), rec_dir)
        interrupted = False
        with closing(parts):  # an interrupted run stops its workers at once
            try:
                for part in parts:
                    rows += part.rows
                    failures += part.failures
                    done += part.scenarios
                    if progress is not None:
                        progress(done, study.scenarios)
                if tmp is not None:
                    shield.hold()
            except KeyboardInterrupt:  # keep the scenarios done
                interrupted = True
                if tmp is not None:
                    shield.hold()
        order = {v.name: v.index for v in study.variants}
        rows.sort(key=lambda r: (r["scenario"], order[r["variant"]]))
        result = StudyResult(study, rows, failures, time.perf_counter() - t0, runner.name,
                             runner.workers, interrupted)
        if tmp is not None:
            fill_folder(result, tmp)
    result.interrupted = result.interrupted or bool(shield.caught)
    return result
