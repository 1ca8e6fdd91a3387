"""``evaluate: mission``: a full mission per scenario and variant, in either fidelity.

The scenario's mission is the base mission with the scenario's seed (its target, clutter and
sounds), the variant's team at the drawn starts, each room's drawn risk and messiness, and the
variant's strategy, weights, thresholds, fidelity and time limit.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from astralis_des.kinds import KINDS
from astralis_des.studies.evaluation import Metric, evaluation
from astralis_des.studies.teams import renamed_robots, team_ids

if TYPE_CHECKING:
    from astralis_des.mission.loader import Mission
    from astralis_des.studies.draws import Scenario
    from astralis_des.studies.factors import Setting
    from astralis_des.studies.spec import Study, Variant

METRICS = (
    Metric("found", "found", "rate"),
    Metric("time_to_find", "time to find", "mean", "s"),
    Metric("human_high_risk_s", "human searching high-risk rooms", "mean", "s"),
    Metric("ugv_high_mess_s", "UGV searching high-messiness rooms", "mean", "s"),
    Metric("rooms_searched", "rooms searched", "mean"),
    Metric("distance", "distance (team)", "mean", "m"),
    Metric("makespan", "makespan (last search ends)", "mean", "s"),
    Metric("completion_sum", "sum of completion times", "mean", "s"),
    Metric("infeasible_rounds", "infeasible rounds", "mean"),
    Metric("workload_gini", "workload Gini (rooms per robot)", "mean"),
    Metric("human_high_risk_rounds", "rounds: human to a high-risk room", "mean"),
    Metric("ugv_high_mess_rounds", "rounds: UGV to a high-messiness room", "mean"),
    Metric("human_min_distance", "closest moving robot to the human", "mean", "m"),
    Metric("human_close_s", "human within 1.2 m of a moving robot", "mean", "s"),
)


def _timeline(study: Study, s: Setting) -> list[dict[str, Any]] | None:
    """The mission's timeline with its robots under the team's ids (None: unchanged)."""
    renamed = renamed_robots(study.mission.spec, s.team)
    events = [e.model_dump(mode="json") for e in study.mission.spec.timeline]
    moved = [e for e in events if e.get("robot") is not None and renamed[e["robot"]] != e["robot"]]
    for event in moved:
        event["robot"] = renamed[event["robot"]]
    return events if moved else None


def scenario_mission(study: Study, scenario: Scenario, s: Setting, outputs: bool) -> Mission:
    """The mission a scenario runs under a variant's setting (checked like a file). The team
    takes the ids of the variant's mix (uav1, ..., human1), and the timeline's fault, recover,
    command and cancel events follow the members they named."""
    base = study.mission.spec
    by_kind = {kind: [m for m in base.team if m.kind == kind] for kind in KINDS}
    timeline = _timeline(study, s)
    team = []
    for ident, kind, k in team_ids(s.team):
        like = by_kind[kind][k % len(by_kind[kind])] if by_kind[kind] else None
        member = like.model_dump(mode="json", exclude_unset=True) if like else {}
        start = scenario.start(kind, k)
        team.append({**member, "id": ident, "kind": kind,
                     "start": start if isinstance(start, str) else list(start)})
    rooms = base.rooms.model_dump(mode="json", exclude_none=True)
    for room, (risk, mess) in scenario.values(s.risk, s.messiness).items():
        rooms["set"][room] = {**rooms["set"].get(room, {}), "risk": risk, "messiness": mess}
    assignment = base.assignment.model_dump(mode="json")
    assignment.update(strategy=s.strategy, weights=s.weights, high_risk=s.high_risk,
                      high_messiness=s.high_messiness, options=s.options)
    changes: dict[str, Any] = {} if timeline is None else {"timeline": timeline}
    return study.mission.with_changes(
        seed=scenario.seed, fidelity=s.fidelity, time_limit=s.time_limit, team=team,
        rooms=rooms, assignment=assignment,
        outputs={"dir": None, "events": outputs, "summary": outputs, "recording": outputs},
        **changes)


@evaluation("mission", METRICS, tradeoff=("human_high_risk_s", "ugv_high_mess_s"),
            headline=("found", "time_to_find"))
def evaluate_mission(study: Study, scenario: Scenario, variant: Variant,
                     out_dir: Path | None) -> dict[str, Any]:
    from astralis_des.simulation import Simulation

    s = variant.setting
    sim = Simulation(scenario_mission(study, scenario, s, out_dir is not None), out_dir=out_dir)
    result = sim.run()
    m = result.metrics  # the run's own (summary.json's), in the table's column order
    row: dict[str, Any] = {
        "outcome": result.outcome, "found": m["found"], "time_to_find": m["time_to_find"],
        "found_by": result.found_by, "end_time": result.end_time,
        "target_room": result.target["room"], "rooms_searched": m["rooms_searched"],
        "rounds": len(result.rounds), "tasks_failed": m["tasks_failed"],
        "distance": m["distance"],
    }
    for kind in KINDS:
        row[f"distance_{kind}"] = sum(st.distance for st in result.robots.values()
                                      if st.kind == kind)
    firsts = ("found", "time_to_find", "rooms_searched", "tasks_failed", "distance")
    row.update((k, v) for k, v in m.items() if k not in firsts)
    return row
