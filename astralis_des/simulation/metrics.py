"""A finished mission's metrics: ``RunResult.metrics``, written in ``summary.json`` and read
by the studies (a column each), ``astralis falsify`` and ``astralis diff``.

- ``found``, ``time_to_find``, ``rooms_searched``, ``tasks_failed``, ``distance``: the run's
  outcome in numbers;
- ``human_high_risk_s`` and ``ugv_high_mess_s``: seconds people spent searching high-risk rooms
  and UGVs high-messiness ones (:func:`search_time`; the paper's Table V trade-off), with the
  counts of such rooms (``high_risk_rooms``, ``high_mess_rooms``);

The metrics of the multi-robot task allocation field (issue 21):

- ``makespan``: when the last search of the run ended (a mission stops when the target is
  seen, so this is the makespan of what was executed, not of the whole plan);
  ``completion_sum``: the sum of the end times of the rooms searched (Sadcher's and
  MRTA-Benchmark's two objectives, on executed searches);
- ``infeasible_rounds``: rounds a planner reported infeasible (``hard``);
- ``rooms_per_robot`` and ``workload_gini``: rooms each robot searched, and the Gini
  coefficient of those counts over the team (0: even; near 1: one robot did all);
- ``human_high_risk_rounds`` and ``ugv_high_mess_rounds``: the share of rounds that gave a
  person a high-risk room, or the UGV a high-messiness room (Table V's violations, per round);
- ``human_min_distance`` and ``human_close_s``: the closest a moving robot came to a person,
  and the seconds a person spent within ``CLOSE`` metres of one (HuNavSim's social metrics),
  from the robots' trails sampled every ``STEP`` seconds.

A round's wall compute time is no column (the table stays the same byte for byte on any
machine): ``RunResult.allocation_time`` holds it per round, and
``tools/bench/bench_allocation.py`` measures it per strategy.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from astralis_des.kinds import KIND_DEFAULTS

if TYPE_CHECKING:
    from astralis_des.simulation.contracts import Run

CLOSE = 1.2  # m: a robot this near a person is too near (HuNavSim)
STEP = 0.1  # s between the samples of the trails
MOVING = 0.05  # m/s: slower is standing still


def run_metrics(sim: Run, rounds: list[dict[str, Any]], end: float,
                tasks_failed: int, found_at: float | None) -> dict[str, Any]:
    """The metrics of a finished run, rooms judged high by the mission's thresholds (on the
    rooms' values at the end of the run)."""
    cfg = sim.mission.spec.assignment
    high_risk = {r for r, st in sim.rooms.items() if st.risk >= cfg.high_risk}
    high_mess = {r for r, st in sim.rooms.items() if st.messiness >= cfg.high_messiness}
    return {
        "found": found_at is not None, "time_to_find": found_at,
        "rooms_searched": len(sim.searched), "tasks_failed": tasks_failed,
        "distance": sum(r.distance for r in sim.robots.values()),
        "human_high_risk_s": search_time(sim, "human", high_risk),
        "ugv_high_mess_s": search_time(sim, "ugv", high_mess),
        "high_risk_rooms": len(high_risk), "high_mess_rooms": len(high_mess),
        **allocation_metrics(sim, rounds, end, cfg.high_risk, cfg.high_messiness),
    }


def search_time(sim: Run, kind: str, rooms: set[str]) -> float:
    """Seconds robots of ``kind`` spent searching ``rooms`` (their Table IV actions, however
    they ended; the way to the door is not counted). A UGV searches from the door or the
    corridor, so this, not time inside, is what it is exposed to."""
    return float(sum(res.end - res.start for task, res in sim.finished
                     if task.room in rooms and task.action != "move"
                     and sim.robots[task.robot].kind == kind))


def allocation_metrics(sim: Run, rounds: list[dict[str, Any]], end: float,
                       high_risk: float, high_messiness: float) -> dict[str, Any]:
    searches = [(task, res) for task, res in sim.finished
                if task.room and task.action != "move" and res.ok]
    ends = {task.room: res.end for task, res in searches}
    counts = np.array([sum(1 for task, _ in searches if task.robot == rid)
                       for rid in sim.robots], dtype=float)
    human, ugv = _round_shares(sim, rounds, high_risk, high_messiness)
    return {
        "makespan": max((res.end for _, res in searches), default=None),
        "completion_sum": float(sum(ends.values())) if ends else None,
        "infeasible_rounds": sum(1 for r in rounds if r.get("info", {}).get("infeasible")),
        "rooms_per_robot": float(counts.mean()) if len(counts) else 0.0,
        "workload_gini": gini(counts),
        "human_high_risk_rounds": human,
        "ugv_high_mess_rounds": ugv,
        **social(sim, end),
    }


def gini(values: np.ndarray) -> float:
    """The Gini coefficient of non-negative ``values`` (0 when all are equal or all zero)."""
    v = np.sort(np.asarray(values, dtype=float))
    n, total = len(v), float(v.sum())
    if n == 0 or total == 0:
        return 0.0
    ranks = np.arange(1, n + 1)
    return float((2 * (ranks * v).sum()) / (n * total) - (n + 1) / n)


def _round_shares(sim: Run, rounds: list[dict[str, Any]], high_risk: float,
                  high_messiness: float) -> tuple[float | None, float | None]:
    """Shares of the rounds with an agent in a room high in its hazard: a person in a
    high-risk room, a UGV in a high-messiness one (None where the team has no agent with that
    hazard or there were no rounds)."""
    hazard = {rid: KIND_DEFAULTS[r.kind].hazard for rid, r in sim.robots.items()}
    shares: list[float | None] = []
    for column, threshold in (("risk", high_risk), ("messiness", high_messiness)):
        if column not in hazard.values() or not rounds:
            shares.append(None)
            continue
        bad = 0
        for record in rounds:
            value = dict(zip(record["rooms"], record[column], strict=True))
            bad += any(hazard.get(p["agent"]) == column and value[p["room"]] >= threshold
                       for p in record["matching"])
        shares.append(bad / len(rounds))
    return shares[0], shares[1]


def social(sim: Run, end: float) -> dict[str, float | None]:
    """The closest approach of a moving robot to a person, and seconds within ``CLOSE``."""
    people = [rid for rid, r in sim.robots.items() if KIND_DEFAULTS[r.kind].person]
    others = [rid for rid, r in sim.robots.items() if not KIND_DEFAULTS[r.kind].person]
    times = np.arange(0.0, end + STEP / 2, STEP)
    if not people or not others or len(times) < 2:  # a speed needs two samples
        return {"human_min_distance": None, "human_close_s": None}
    where = {rid: _track(sim, rid, times, end) for rid in sim.robots}
    moving = {rid: np.linalg.norm(_gradient(where[rid]), axis=1) > MOVING for rid in others}
    nearest, close = np.inf, 0.0
    for person in people:
        near = np.full(len(times), np.inf)
        for rid in others:
            gap = np.linalg.norm(where[rid] - where[person], axis=1)
            near = np.minimum(near, np.where(moving[rid], gap, np.inf))
        nearest = min(nearest, float(near.min()))
        close += float((near < CLOSE).sum() * STEP)
    return {"human_min_distance": nearest if np.isfinite(nearest) else None,
            "human_close_s": close}


def _gradient(path: np.ndarray) -> np.ndarray:
    """``np.gradient(path, STEP, axis=0)`` for two samples or more, the same arithmetic
    without its generality (central differences inside, one-sided at the ends)."""
    out = np.empty_like(path)
    out[1:-1] = (path[2:] - path[:-2]) / (2.0 * STEP)
    out[0] = (path[1] - path[0]) / STEP
    out[-1] = (path[-1] - path[-2]) / STEP
    return out


def _track(sim: Run, rid: str, times: np.ndarray, end: float) -> np.ndarray:
    """Where robot ``rid`` was at ``times``, from its trail (and a motion still under way)."""
    robot = sim.robots[rid]
    tt = np.array(robot.trail_t, dtype=float)
    pp = np.array(robot.trail_p, dtype=float).reshape(-1, 3)
    if robot.motion is not None:
        more_t, more_p = robot.motion.vertices_until(end)
        tt, pp = np.concatenate([tt, more_t]), np.concatenate([pp, more_p])
    if not len(tt):
        return np.repeat(np.asarray(robot.pose, dtype=float)[None, :], len(times), axis=0)
    if len(tt) > 1 and bool((tt[1:] < tt[:-1]).any()):  # a stable sort changes nothing else
        order = np.argsort(tt, kind="stable")
        tt, pp = tt[order], pp[order]
    return np.column_stack([np.interp(times, tt, pp[:, k]) for k in range(3)])
