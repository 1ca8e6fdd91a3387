"""``evaluate: falsify``: each scenario of a study is given, not drawn (a falsify trial's
mission changes), and run under each variant's strategy; its row holds the run's metrics.

Which way is worse, by metric: larger, except for the few where a smaller value is the bad
one (:data:`SMALLEST_IS_WORST`). A trial's *badness* is the metric oriented so that larger is
worse; a metric with no value in a run counts as described in :func:`badness`.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from astralis_des.kernel.events import plain
from astralis_des.studies.eval_mission import METRICS as MISSION_METRICS
from astralis_des.studies.evaluation import Metric, evaluation
from astralis_des.studies.factors import Setting, factor

if TYPE_CHECKING:
    from astralis_des.mission.loader import Mission
    from astralis_des.simulation.result import RunResult
    from astralis_des.studies.draws import Scenario
    from astralis_des.studies.spec import Study, Variant

METRICS = (  # RunResult.metrics (summary.json's), and not_found (summary.json: not found)
    *MISSION_METRICS,
    Metric("not_found", "not found", "rate"),
    Metric("tasks_failed", "failed tasks", "mean"),
    Metric("rooms_per_robot", "rooms per robot", "mean"),
    Metric("high_risk_rooms", "high-risk rooms", "mean"),
    Metric("high_mess_rooms", "high-messiness rooms", "mean"),
)
SMALLEST_IS_WORST = frozenset({"found", "human_min_distance", "rooms_per_robot"})


def metric_names() -> list[str]:
    return [m.column for m in METRICS]


def worst_is_largest(metric: str) -> bool:
    return metric not in SMALLEST_IS_WORST


def badness(metric: str, value: float | None, time_limit: float,
            largest: bool | None = None) -> float | None:
    """``value`` oriented so that larger is worse. Time to find of a target never found is
    the time limit; any other metric with no value (no search ended, no robot ever moved near
    the person) has none, and the trial counts as failed for the optimiser."""
    if value is None and metric == "time_to_find":
        value = time_limit
    if value is None:
        return None
    worse_up = worst_is_largest(metric) if largest is None else largest
    return float(value) if worse_up else -float(value)


@factor("given", list[dict[str, Any]], only="falsify")
def _given(s: Setting, value: list[dict[str, Any]]) -> Setting:
    """each scenario's mission changes (astralis falsify sets it)"""
    return replace(s, given=tuple(value))


def trial_mission(base: Mission, changes: dict[str, Any], strategy: str,
                  outputs: bool) -> Mission:
    """The base mission with a trial's changes, under ``strategy`` (checked like a file)."""
    assignment = {**changes["assignment"], "strategy": strategy}
    return base.with_changes(**{**changes, "assignment": assignment}, outputs={
        "dir": None, "events": outputs, "summary": outputs, "recording": outputs})


def run_metrics(result: RunResult) -> dict[str, Any]:
    """A finished run's metrics as its ``summary.json`` holds them (rounded), and
    ``not_found``: so a trial's value is the file's to the byte."""
    metrics: dict[str, Any] = plain(result.metrics)
    return {**metrics, "not_found": not metrics["found"]}


@evaluation("falsify", METRICS, tradeoff=("human_high_risk_s", "ugv_high_mess_s"),
            headline=("found", "time_to_find"))
def evaluate_given(study: Study, scenario: Scenario, variant: Variant,
                   out_dir: Path | None) -> dict[str, Any]:
    from astralis_des.simulation import Simulation

    s = variant.setting
    mission = trial_mission(study.mission, s.given[scenario.index], s.strategy,
                            out_dir is not None)
    result = Simulation(mission, out_dir=out_dir).run()
    return {"outcome": result.outcome, "end_time": result.end_time,
            "target_room": result.target["room"], **run_metrics(result)}
