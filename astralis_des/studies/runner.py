"""Run a study: scenarios in chunks on a backend, one row per scenario and variant.

A scenario's seed derives from the study's seed and its index, and rows are put back in
(scenario, variant) order, so the table does not depend on the backend or the worker count.
An exception inside one scenario is a failed row (its error and seed), and the study goes on.
"""

from __future__ import annotations

import logging
import math
import os
import time
import traceback
from collections.abc import Callable, Sequence
from contextlib import closing
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any

from astralis_des.studies.evaluation import EVALUATIONS, Evaluation, load_evaluations

if TYPE_CHECKING:
    import pyarrow as pa

    from astralis_des.studies.spec import Study

log = logging.getLogger(__name__)
Progress = Callable[[int, int], None]  # (scenarios done, scenarios in all)
SCENARIOS_DIR = "scenarios"


@dataclass
class ChunkResult:
    """What a worker sends back for a chunk of scenarios."""

    scenarios: int
    rows: list[dict[str, Any]]
    failures: list[str]  # a traceback per failed row


def evaluation_of(study: Study) -> Evaluation:
    load_evaluations()
    return EVALUATIONS.get(study.spec.evaluate)


def run_scenario(study: Study, index: int, *, recordings: Path | None = None,
                 variants: Sequence[str] | None = None,
                 raise_errors: bool = False) -> ChunkResult:
    """Scenario ``index`` under each variant (or the named ones): its rows, in variant order.

    With ``raise_errors`` an exception propagates (a replay, to debug it); otherwise it
    becomes a failed row.
    """
    evaluation = evaluation_of(study)
    scenario = study.scenario(index)
    chosen = [study.variant(v) for v in variants] if variants else list(study.variants)
    rows, failures = [], []
    for variant in chosen:
        row: dict[str, Any] = {"scenario": index, "seed": scenario.seed,
                               "variant": variant.name, **variant.columns}
        out = (recordings / f"{index:06d}" / f"{variant.index:02d}_{_slug(variant.name)}"
               if recordings is not None else None)
        try:
            values = evaluation.run(study, scenario, variant, out)
        except Exception as exc:
            if raise_errors:
                raise
            log.warning("scenario %d (%s, seed %d) failed: %s", index, variant.name,
                        scenario.seed, exc)
            failures.append(f"scenario {index}, variant {variant.name}, seed {scenario.seed}:\n"
                            + traceback.format_exc())
            rows.append({**row, "status": "failed", "error": _one_line(exc)})
            continue
        rows.append({**row, "status": "ok", "error": None, **values})
    return ChunkResult(1, rows, failures)


def run_chunk(study: Study, indices: Sequence[int], recordings: Path | None) -> ChunkResult:
    done = ChunkResult(0, [], [])
    for index in indices:
        one = run_scenario(study, index, recordings=recordings)
        done.scenarios += 1
        done.rows += one.rows
        done.failures += one.failures
    return done


def chunks(n: int, workers: int) -> list[list[int]]:
    """Scenario indices in chunks: about 8 per worker for balance, 25 scenarios at most."""
    size = max(1, min(25, math.ceil(n / (workers * 8))))
    return [list(range(i, min(i + size, n))) for i in range(0, n, size)]


@dataclass
class StudyResult:
    """The rows of a study run, with how it was run."""

    study: Study
    rows: list[dict[str, Any]]
    failures: list[str] = field(default_factory=list)
    wall_time: float = 0.0
    backend: str = "local"
    workers: int = 1

    @cached_property
    def table(self) -> pa.Table:
        """One row per scenario and variant: its inputs and outcomes (a pyarrow Table)."""
        from astralis_des.studies.table import to_table

        return to_table(self.rows)

    @property
    def failed(self) -> int:
        return sum(r["status"] == "failed" for r in self.rows)

    def summary(self) -> list[dict[str, Any]]:
        """Per variant and metric: the estimate and its 95% confidence interval."""
        from astralis_des.studies.table import summarize

        return summarize(self.table, evaluation_of(self.study).metrics,
                         [v.name for v in self.study.variants])

    def write(self, folder: str | Path) -> Path:
        """Write the folder (table, summary, plots, study file, version) all at once."""
        from astralis_des.studies.output import write_folder

        return write_folder(self, Path(folder))


def run_study(study: Study, *, workers: int | None = None, backend: str = "local",
              address: str | None = None, out: str | Path | None = None,
              recordings: bool | None = None, progress: Progress | None = None) -> StudyResult:
    """Run every scenario of ``study`` under every variant.

    ``workers``: processes (default: the CPUs); ``backend``: ``local`` (a process pool) or
    ``ray`` (``address`` for an existing cluster, else a local instance). With ``out``, the
    study folder is written there, all or nothing; ``recordings`` (default: the study file's
    ``outputs.recordings``) writes each mission's outputs under it.
    """
    from astralis_des.studies.backends import make_backend
    from astralis_des.studies.output import staging

    workers = workers or os.cpu_count() or 1
    runner = make_backend(backend, workers, address)
    record = study.spec.outputs.recordings if recordings is None else recordings
    if record and out is None:
        from astralis_des.errors import InputError

        raise InputError("recordings need an output folder", key="recordings")
    t0 = time.perf_counter()
    with staging(Path(out) if out is not None else None) as tmp:
        rec_dir = tmp / SCENARIOS_DIR if (tmp is not None and record) else None
        rows: list[dict[str, Any]] = []
        failures: list[str] = []
        done = 0
        parts = runner.run(study, chunks(study.scenarios, runner.workers), rec_dir)
        with closing(parts):  # an interrupted run stops its workers at once
            for part in parts:
                rows += part.rows
                failures += part.failures
                done += part.scenarios
                if progress is not None:
                    progress(done, study.scenarios)
        order = {v.name: v.index for v in study.variants}
        rows.sort(key=lambda r: (r["scenario"], order[r["variant"]]))
        result = StudyResult(study, rows, failures, time.perf_counter() - t0, backend,
                             runner.workers)
        if tmp is not None:
            from astralis_des.studies.output import fill_folder

            fill_folder(result, tmp)
    return result


def _slug(name: str) -> str:
    return "".join(c if c.isalnum() or c in "._-=" else "_" for c in name)[:60]


def _one_line(exc: BaseException) -> str:
    return " ".join(f"{type(exc).__name__}: {exc}".split())
