"""A study's team: the ids of a team mix, and how the mission's own members map onto them."""

from __future__ import annotations

from typing import TYPE_CHECKING

from astralis_des.kinds import KINDS

if TYPE_CHECKING:
    from astralis_des.mission.spec import MissionSpec


def team_ids(team: dict[str, int]) -> list[tuple[str, str, int]]:
    """``(id, kind, k)`` of a team mix: uav1, uav2, ugv1, human1, in kind order."""
    return [(f"{kind}{k + 1}", kind, k) for kind in KINDS for k in range(team.get(kind, 0))]


def renamed_robots(mission: MissionSpec, team: dict[str, int]) -> dict[str, str]:
    """The mission's robot ids -> the ids the team mix gives the same members (the k-th of
    each kind): uav1, uav2, ugv1, human1 in kind order."""
    by_kind = {kind: [m.id for m in mission.team if m.kind == kind] for kind in KINDS}
    return {by_kind[kind][k]: ident for ident, kind, k in team_ids(team)
            if k < len(by_kind[kind])}


def unmatched_robots(mission: MissionSpec, team: dict[str, int]) -> list[str]:
    """The robots the mission's timeline names that the team mix has no member for."""
    renamed = renamed_robots(mission, team)
    named = [getattr(e, "robot", None) for e in mission.timeline]
    return sorted({r for r in named if r is not None and r not in renamed})
