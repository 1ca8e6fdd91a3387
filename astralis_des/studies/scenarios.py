"""The work of one worker: scenarios of a study under each variant, a row each.

A scenario's seed derives from the study's seed and its index; an exception inside one
scenario is a failed row (its error and seed), and the study goes on.
"""

from __future__ import annotations

import logging
import math
import traceback
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from astralis_des.studies.evaluation import EVALUATIONS, Evaluation

if TYPE_CHECKING:
    from astralis_des.studies.spec import Study

log = logging.getLogger(__name__)


@dataclass
class ChunkResult:
    """What a worker sends back for a chunk of scenarios."""

    scenarios: int
    rows: list[dict[str, Any]]
    failures: list[str]  # a traceback per failed row


def evaluation_of(study: Study) -> Evaluation:
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


def failed_scenario(study: Study, index: int, reason: str) -> ChunkResult:
    """Scenario ``index``'s rows, every variant failed for ``reason`` (its worker died)."""
    scenario = study.scenario(index)
    rows = [{"scenario": index, "seed": scenario.seed, "variant": variant.name,
             **variant.columns, "status": "failed", "error": reason}
            for variant in study.variants]
    return ChunkResult(1, rows, [f"scenario {index}, seed {scenario.seed}: {reason}"])


def run_chunk(study: Study, indices: Sequence[int], recordings: Path | None) -> ChunkResult:
    """Scenarios ``indices`` (what every backend runs, in a worker or in this process)."""
    done = ChunkResult(0, [], [])
    with quiet_missions():
        for index in indices:
            one = run_scenario(study, index, recordings=recordings)
            done.scenarios += 1
            done.rows += one.rows
            done.failures += one.failures
    return done


@contextmanager
def quiet_missions() -> Iterator[None]:
    """The missions of a chunk keep their warnings (a UAV landing where it is, a planner's
    fallback) to themselves: hundreds of missions would bury the progress and the study's own
    warnings (a failed scenario, with its seed to ``--replay`` it, which shows them)."""
    package, studies = logging.getLogger("astralis_des"), logging.getLogger("astralis_des.studies")
    levels = package.level, studies.level
    package.setLevel(logging.ERROR)
    studies.setLevel(logging.WARNING)
    try:
        yield
    finally:
        package.setLevel(levels[0])
        studies.setLevel(levels[1])


def chunks(n: int, workers: int) -> list[list[int]]:
    """Scenario indices in chunks: about 8 per worker for balance, 25 scenarios at most."""
    size = max(1, min(25, math.ceil(n / (workers * 8))))
    return [list(range(i, min(i + size, n))) for i in range(0, n, size)]


def _slug(name: str) -> str:
    return "".join(c if c.isalnum() or c in "._-=" else "_" for c in name)[:60]


def _one_line(exc: BaseException) -> str:
    return " ".join(f"{type(exc).__name__}: {exc}".split())
