"""What a run returns, and the ``summary.json`` it writes."""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import TYPE_CHECKING, Any

from astralis_des.kernel.events import Record, plain
from astralis_des.simulation.metrics import run_metrics

if TYPE_CHECKING:
    from astralis_des.simulation.contracts import Run


@dataclass(frozen=True)
class RobotStats:
    kind: str
    distance: float
    busy_time: float
    idle_time: float
    tasks_succeeded: int
    tasks_failed: int
    tasks_cancelled: int
    tasks_preempted: int
    faulted: bool


# what summary.json leaves out: the events (events.jsonl has them) and what the wall clock
# measured (so that the file is reproducible)
UNSUMMED = frozenset({"events", "wall_time", "sensor_time", "allocation_time"})


@dataclass(frozen=True)
class RunResult:
    """The outcome of one mission run, with everything a study needs to tabulate it."""

    mission: str
    seed: int
    fidelity: str
    outcome: str  # found | not_found | team_lost | time_limit | interrupted
    end_time: float
    time_to_find: float | None
    found_by: str | None
    target: dict[str, Any]
    robots: dict[str, RobotStats]
    rounds: list[dict[str, Any]]
    rooms_searched: list[str]
    coverage: dict[str, float]
    events: list[Record] = field(repr=False)
    # per searched room: its status, the most of it one search saw, and each search
    rooms: dict[str, dict[str, Any]] = field(default_factory=dict)
    sensor_calls: dict[str, int] = field(default_factory=dict)  # physics: looks, renders, scans
    wall_time: float = 0.0
    sensor_time: dict[str, float] = field(default_factory=dict)  # wall s per sensor (physics)
    allocation_time: list[float] = field(default_factory=list)  # wall s of each round's plan
    # the run's metrics (astralis_des.simulation.metrics): summary.json's last entry, where
    # floats are rounded to 1e-6 as everywhere in it (``plain(metrics)`` is what it holds)
    metrics: dict[str, Any] = field(default_factory=dict)
    # a forked run's ``fork`` event (astralis_des.simulation.fork); summary.json has it then
    fork: Record | None = None

    @property
    def found(self) -> bool:
        return self.outcome == "found"

    @property
    def realtime_factor(self) -> float:
        return self.end_time / self.wall_time if self.wall_time > 0 else float("inf")

    def summary(self) -> dict[str, Any]:
        """JSON-ready summary; wall time is left out so that the file is reproducible."""
        data = {f.name: getattr(self, f.name) for f in fields(self) if f.name not in UNSUMMED}
        data["robots"] = {rid: {f.name: getattr(stats, f.name) for f in fields(stats)}
                          for rid, stats in self.robots.items()}
        if data["fork"] is None:  # a run that did not fork: its summary as before forks
            data.pop("fork")
        summary: dict[str, Any] = plain(data)  # plain copies: no dataclass is left inside
        return summary


def build_result(sim: Run, outcome: str, wall_time: float) -> RunResult:
    now = float(sim.env.now)
    stats = {}
    for rid, robot in sim.robots.items():
        mine = [res.status.value for task, res in sim.finished if task.robot == rid]
        stats[rid] = RobotStats(
            robot.kind, robot.distance, robot.busy_time, max(now - robot.busy_time, 0.0),
            mine.count("succeeded"), mine.count("failed"), mine.count("cancelled"),
            mine.count("preempted"), robot.faulted)
    coverage = {task.room: float(res.coverage) for task, res in sim.finished
                if task.room and res.coverage is not None and res.ok}
    detection = next((r for r in sim.log.records if r["kind"] == "detection"), None)
    rooms = room_report(sim)
    target = {"room": sim.target.room, "position": list(sim.target.position),
              **sim.target.avatar}
    time_to_find = detection["t"] if detection else None
    failed = sum(s.tasks_failed for s in stats.values())
    perception = sim.cosim.perception
    clock = perception.clock if perception is not None else None
    return RunResult(
        mission=sim.mission.spec.name, seed=sim.mission.spec.seed,
        fidelity=sim.mission.spec.fidelity, outcome=outcome, end_time=now,
        time_to_find=time_to_find,
        found_by=detection["robot"] if detection else None, target=target, robots=stats,
        rounds=sim.rounds, rooms_searched=list(sim.searched), coverage=coverage,
        events=sim.log.records, rooms=rooms, wall_time=wall_time,
        sensor_calls=dict(sorted(clock.calls.items())) if clock is not None else {},
        sensor_time=dict(sorted(clock.seconds.items())) if clock is not None else {},
        allocation_time=list(sim.allocation_time),
        metrics=run_metrics(sim, sim.rounds, now, failed, time_to_find),
        fork=next((r for r in sim.log.records if r["kind"] == "fork"), None))


def room_report(sim: Run) -> dict[str, dict[str, Any]]:
    """Each room of the searched segments: ``searched`` (seen at least ``min_coverage``),
    ``undercovered`` (counted searched though no search saw that much: no agent of another
    kind was left), ``given_up``, or ``not_searched``; the most of it one search saw, and who
    searched it how (so that "hidden by furniture" can be told from "never looked")."""
    given_up = {r["room"] for r in sim.log.records if r["kind"] == "room_given_up"}
    threshold = sim.mission.spec.assignment.min_coverage
    report: dict[str, dict[str, Any]] = {}
    for room in sim.mission.searched_rooms():
        searches = [{"robot": task.robot, "kind": sim.robots[task.robot].kind,
                     "action": task.action, "status": res.status.value,
                     "coverage": res.coverage}
                    for task, res in sim.finished if task.room == room and task.action != "move"]
        seen = [float(s["coverage"]) for s in searches if s["coverage"] is not None]
        best = max(seen) if seen else None
        if room in sim.searched:
            status = "searched" if best is None or best >= threshold else "undercovered"
        else:
            status = "given_up" if room in given_up else "not_searched"
        report[room] = {"status": status, "coverage": best, "searches": searches}
    return report
