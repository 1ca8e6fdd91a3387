"""How a study evaluates one scenario under one variant, by registry (``evaluate:`` picks it).

An evaluation returns the row's outcome columns; it names the metrics its summary reports
(a rate with a Wilson interval, or a mean with a t interval), the few of them the terminal
shows (the rest are in ``report.md``) and the trade-off it plots.
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
    headline: tuple[str, ...]  # the metric columns the terminal's summary shows

    def headline_metrics(self) -> list[Metric]:
        return [m for m in self.metrics if m.column in self.headline]


EVALUATIONS: Registry[str, Evaluation] = registries.EVALUATIONS


def evaluation(name: str, metrics: tuple[Metric, ...], tradeoff: tuple[str, str],
               headline: tuple[str, ...] | None = None) -> Callable[[Run], Run]:
    """Register ``run`` as the evaluation ``name``; ``headline``: the metric columns the
    terminal's summary shows (default: the first two)."""
    shown = headline if headline is not None else tuple(m.column for m in metrics[:2])
    unknown = set(shown) - {m.column for m in metrics}
    if unknown:
        raise ValueError(f"headline metrics {sorted(unknown)} are not among the metrics")

    def add(run: Run) -> Run:
        EVALUATIONS.register(name)(Evaluation(run, metrics, tradeoff, shown))
        return run

    return add

