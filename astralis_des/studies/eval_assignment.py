"""``evaluate: assignment``: one assignment problem per scenario, as in the paper's Table V.

The team, at its drawn starts, is matched to the rooms of the scenario's segment (each room's
risk and messiness drawn), with no simulation: a thousand problems take a fraction of a second.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from astralis_des.assignment import Agent, RoomInfo, Weights, assign
from astralis_des.kinds import KIND_DEFAULTS, KINDS
from astralis_des.streams import stream
from astralis_des.studies.evaluation import Metric, evaluation
from astralis_des.studies.teams import team_ids

if TYPE_CHECKING:
    from astralis_des.studies.draws import Point, Scenario
    from astralis_des.studies.spec import Study, Variant

METRICS = (
    Metric("human_high_risk", "human -> high-risk room", "rate"),
    Metric("ugv_high_mess", "UGV -> high-messiness room", "rate"),
    *(Metric(f"{kind}_unassigned", f"{KIND_DEFAULTS[kind].label or kind} unassigned", "rate")
      for kind in sorted(KINDS)),
)


@evaluation("assignment", METRICS, tradeoff=("human_high_risk", "ugv_high_mess"),
            headline=("human_high_risk", "ugv_high_mess"))
def evaluate_assignment(study: Study, scenario: Scenario, variant: Variant,
                        out_dir: Path | None) -> dict[str, Any]:
    s = variant.setting
    world = study.mission.world
    room_ids = world.segments[scenario.segment].rooms
    values = scenario.values(s.risk, s.messiness)
    agents = [Agent(ident, kind, _where(study, scenario.start(kind, k)))
              for ident, kind, k in team_ids(s.team)]
    rooms = [RoomInfo(r, world.rooms[r].center, *values[r], world.rooms[r].area)
             for r in room_ids]
    plan = assign(agents, rooms, Weights(s.weights["risk"], s.weights["messiness"]),
                  strategy=s.strategy, solver=study.mission.spec.assignment.solver,
                  high_risk=s.high_risk, high_messiness=s.high_messiness,
                  rng=stream(scenario.seed, "assignment", 1), options=s.options)
    kind_of = {a.id: a.kind for a in agents}
    high_risk = {r.id for r in rooms if r.risk >= s.high_risk}
    high_mess = {r.id for r in rooms if r.messiness >= s.high_messiness}
    row: dict[str, Any] = {"segment": scenario.segment}
    for j, room in enumerate(rooms, 1):
        row[f"risk_{j}"] = room.risk
        row[f"messiness_{j}"] = room.messiness
    hazard = {a.id: KIND_DEFAULTS[a.kind].hazard for a in agents}
    row["human_high_risk"] = any(hazard[p.agent] == "risk" and p.room in high_risk
                                 for p in plan.pairs)
    row["ugv_high_mess"] = any(hazard[p.agent] == "messiness" and p.room in high_mess
                               for p in plan.pairs)
    for kind in sorted(KINDS):
        row[f"{kind}_unassigned"] = any(kind_of[a] == kind for a in plan.unassigned)
    row["total_cost"] = plan.total_cost
    row["assignment"] = " ".join(f"{p.agent}>{p.room}" for p in plan.pairs)
    return row


def _where(study: Study, start: Point | str) -> Point:
    """A start as a point: a room id stands for the room's centre."""
    return study.mission.world.rooms[start].center if isinstance(start, str) else start
