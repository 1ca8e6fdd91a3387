"""Table IV: the action an assigned agent takes in a room, by its risk and messiness."""

from __future__ import annotations

# (kind, high risk, high messiness) -> action. Risk comes first: a high-risk room gets an
# inward spiral from a UAV and corridor observation from the UGV, whatever its messiness.
TABLE4: dict[tuple[str, bool, bool], str] = {
    ("uav", False, False): "spiral_outward",
    ("uav", True, False): "spiral_inward",
    ("uav", False, True): "sweep_horizontal",
    ("uav", True, True): "spiral_inward",
    ("ugv", False, False): "sneak_peek",
    ("ugv", True, False): "observe_corridor",
    ("ugv", False, True): "observe_corridor",
    ("ugv", True, True): "observe_corridor",
}
# Table IV has no human row; an assigned operator walks in and looks (our choice).
TABLE4.update({("human", r, m): "inspect" for r in (False, True) for m in (False, True)})


def table4_action(kind: str, risk: float, messiness: float, high_risk: float = 0.5,
                  high_messiness: float = 0.5) -> str:
    """High means >= the threshold (the paper: 0.5)."""
    return TABLE4[(kind, risk >= high_risk, messiness >= high_messiness)]
