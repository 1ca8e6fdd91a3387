"""What a replay explains beyond poses: each robot's task lane and the mission's metrics as
time series (the assignment rounds are in :mod:`astralis_des.sinks.rounds`). All is derived
from the event log and the rounds when the run closes, and sent in columns."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

from astralis_des.kernel.events import Record
from astralis_des.kinds import KIND_DEFAULTS
from astralis_des.sinks import paths
from astralis_des.sinks.columns import (
    Columns,
    colors,
    descriptor,
    doubles,
    rows,
    send,
    send_static,
    static_columns,
    texts,
    times,
)

IDLE, MOVING, FAILED, FAULTED = "idle", "moving", "failed", "faulted"
LANE_COLORS = {IDLE: (150, 150, 150), MOVING: (70, 150, 255), FAILED: (230, 60, 60),
               FAULTED: (130, 0, 0)}
SEARCH_COLOR = (60, 200, 90)


@dataclass
class Lane:
    times: list[float] = field(default_factory=lambda: [0.0])
    states: list[str] = field(default_factory=lambda: [IDLE])

    def add(self, t: float, state: str) -> None:
        self.times.append(t)
        self.states.append(state)


def task_lanes(records: Sequence[Record], robots: Sequence[str]) -> dict[str, Lane]:
    """Each robot's state over time: idle at the start, then one change per task start
    (``moving``, or ``searching: <action>``) and end (``idle``, or ``failed``), and per fault
    (``faulted``) and recovery (``idle``)."""
    lanes = {rid: Lane() for rid in robots}
    for record in records:
        lane = lanes.get(record.get("robot", ""))
        if lane is None:
            continue
        state = _state(record)
        if state is not None:
            lane.add(record["t"], state)
    return lanes


def _state(record: Record) -> str | None:
    kind = record["kind"]
    if kind == "task_started":
        return MOVING if record["action"] == "move" else f"searching: {record['action']}"
    if kind == "task_finished":
        return FAILED if record["status"] == "failed" else IDLE
    return {"fault": FAULTED, "recover": IDLE}.get(kind)


def log_lanes(rec: Any, lanes: Mapping[str, Lane]) -> None:
    for rid, lane in lanes.items():
        entity = paths.robot_state(rid)
        values = sorted(set(lane.states))
        send_static(rec, entity, "StateConfiguration", values=texts(values),
                    labels=texts(values),
                    colors=colors([LANE_COLORS.get(v, SEARCH_COLOR) for v in values]))
        send(rec, entity, times(lane.times),
             {descriptor("StateChange", "state"): rows(texts(lane.states))})


Series = dict[str, tuple[list[float], list[float]]]


def metrics(records: Sequence[Record], rounds: Sequence[Mapping[str, Any]],
            kinds: Mapping[str, str], high_risk: float, high_messiness: float) -> Series:
    """Time series of the mission: rooms searched, each search's coverage, each robot's
    distance, the human's seconds in high-risk rooms and the UGV's in high-messiness ones."""
    series: Series = {}

    def add(name: str, t: float, value: float) -> None:
        times, values = series.setdefault(name, ([], []))
        times.append(t)
        values.append(value)

    latest: dict[str, tuple[float, float]] = {}  # room -> risk, messiness at its last round
    by_time = sorted(rounds, key=lambda r: r["t"])
    started: dict[int, float] = {}
    searched, distance = 0, dict.fromkeys(kinds, 0.0)
    exposure = {"human_in_high_risk_s": 0.0, "ugv_in_high_messiness_s": 0.0}
    for record in records:
        t, kind = record["t"], record["kind"]
        while by_time and by_time[0]["t"] <= t:
            r = by_time.pop(0)
            latest.update({room: (r["risk"][j], r["messiness"][j])
                           for j, room in enumerate(r["rooms"])})
        if kind == "task_started":
            started[record["task"]] = t
        if kind != "task_finished":
            continue
        robot = record["robot"]
        distance[robot] = distance.get(robot, 0.0) + float(record.get("distance") or 0.0)
        add(f"distance/{robot}", t, distance[robot])
        if "coverage" in record and record["status"] == "succeeded":
            searched += 1
            add("rooms_searched", t, searched)
            add("coverage", t, float(record["coverage"]))
        risk, mess = latest.get(record.get("room") or "", (0.0, 0.0))
        spent = t - started.get(record["task"], t)
        hazard = _hazard(kinds.get(robot))
        if hazard == "risk" and risk >= high_risk:
            exposure["human_in_high_risk_s"] += spent
            add("human_in_high_risk_s", t, exposure["human_in_high_risk_s"])
        if hazard == "messiness" and mess >= high_messiness:
            exposure["ugv_in_high_messiness_s"] += spent
            add("ugv_in_high_messiness_s", t, exposure["ugv_in_high_messiness_s"])
    return series


def log_metrics(rec: Any, series: Series,
                palette: dict[str, tuple[int, int, int, int]] | None = None) -> None:
    """Each series on the timeline; a robot's distance in its colour (``palette``)."""
    for name, (at, values) in series.items():
        entity = paths.mission_metric(name)
        send(rec, entity, times(at), {descriptor("Scalars", "scalars"): rows(doubles(values))})
        robot = name.split("/", 1)[1] if name.startswith("distance/") else None
        send(rec, entity, None, series_style(name, (palette or {}).get(robot or "")))


@lru_cache(maxsize=256)
def series_style(name: str, color: tuple[int, int, int, int] | None) -> Columns:
    """A series' static looks: points for the coverage, else a line; its name, its colour if
    it has one (made once)."""
    looks = {"names": texts([name.replace("_", " ")])}
    if color is not None:
        looks["colors"] = colors([color])
    return static_columns("SeriesPoints" if name == "coverage" else "SeriesLines", **looks)


def _hazard(kind: str | None) -> str | None:
    """What makes a room unsafe for ``kind`` (None for a kind the run did not name)."""
    record = KIND_DEFAULTS.get(kind or "")
    return record.hazard if record is not None else None
