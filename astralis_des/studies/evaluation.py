"""How a study evaluates one scenario under one variant, by registry (``evaluate:`` picks it).

An evaluation returns the row's outcome columns; it names the metrics its summary reports
(a rate with a Wilson interval, or a mean with a t interval) and the trade-off it plots.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from astralis_des.registry import Registry
from astralis_des.studies import registries

if TYPE_CHECKING:
    from astralis_des.studies.draws import Scenario
    from astralis_des.studies.spec import Study, Variant


@dataclass(frozen=True)
class Metric:
    column: str
    label: str
    kind: Literal["rate", "mean"]
    unit: str = ""  # "s", "m" (a rate is shown in %)


Run = Callable[["Study", "Scenario", "Variant", Path | None], dict[str, Any]]


@dataclass(frozen=True)
class Evaluation:
    run: Run
    metrics: tuple[Metric, ...]
    tradeoff: tuple[str, str]  # the trade-off plot's x and y metric columns


EVALUATIONS: Registry[str, Evaluation] = registries.EVALUATIONS


def evaluation(name: str, metrics: tuple[Metric, ...],
               tradeoff: tuple[str, str]) -> Callable[[Run], Run]:
    def add(run: Run) -> Run:
        EVALUATIONS.register(name)(Evaluation(run, metrics, tradeoff))
        return run

    return add

