"""Agent-to-room assignment: Eq. 1 of the paper, minimum-weight full matching, Table IV.

Pure functions on plain data; the mission timeline calls them, and so can a study.
"""

from astralis_des.assignment import baselines  # noqa: F401  (they register)
from astralis_des.assignment.eq1 import Agent, RoomInfo, Weights, eq1_costs
from astralis_des.assignment.matching import match
from astralis_des.assignment.rules import table4_action
from astralis_des.assignment.strategies import STRATEGIES, Assignment, Pair, assign

__all__ = [
    "STRATEGIES", "Agent", "Assignment", "Pair", "RoomInfo", "Weights", "assign", "eq1_costs",
    "match", "table4_action",
]
