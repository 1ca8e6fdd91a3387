"""The environments' action space: what an agent may do when it is asked.

An action is an index into a :class:`Layout`: ``continue`` (only for an agent that is not asked:
its task goes on), ``wait`` (nothing, until the next decision time), ``hold`` (stay where it is
for the environment's ``hold_s`` seconds: a UAV hovers, Table I's ``hover``; a UGV or a person
stands still), then one index per (room, search action): go to the room's door and search it
with that Table I action. The rooms are those of the mission's searched segments, in their
order; the actions the union of the kinds' searches (a mask leaves each agent its own kind's).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache, cached_property

import numpy as np

from astralis_des.actions import ACTIONS
from astralis_des.kinds import KINDS

# The records that search a room, by kind (as in KINDS), then name: the action space's order.
SEARCHES: tuple[str, ...] = tuple(dict.fromkeys(
    spec.name for spec in sorted((s for s in ACTIONS.specs() if s.search),
                                 key=lambda s: (min(KINDS.index(k) for k in s.kinds), s.name))))
CONTINUE, WAIT, HOLD = 0, 1, 2
SPECIAL: tuple[str, ...] = ("continue", "wait", "hold")


@dataclass(frozen=True)
class Layout:
    """The rooms an action can name, and how indices map to (room, action)."""

    rooms: tuple[str, ...]

    @property
    def size(self) -> int:
        return len(SPECIAL) + len(self.rooms) * len(SEARCHES)

    @cached_property
    def room_index(self) -> dict[str, int]:
        return {room: k for k, room in enumerate(self.rooms)}

    @cached_property
    def _search_rows(self) -> dict[str, np.ndarray]:
        return {}  # kind -> searches_by(kind), filled as kinds are asked for

    def searches_by(self, kind: str) -> np.ndarray:
        """``(rooms, the kind's searches)``: the action indices of each room's searches that
        ``kind`` has (for masks)."""
        rows = self._search_rows.get(kind)
        if rows is None:
            actions = np.array([SEARCHES.index(a) for a in searches_of(kind)], dtype=np.intp)
            rows = len(SPECIAL) + np.arange(len(self.rooms))[:, None] * len(SEARCHES) + actions
            self._search_rows[kind] = rows
        return rows

    def index(self, room: str, action: str) -> int:
        """The action that searches ``room`` with ``action``."""
        return len(SPECIAL) + self.room_index[room] * len(SEARCHES) + SEARCHES.index(action)

    def decode(self, index: int) -> tuple[str, str | None]:
        """``(action, room)``: ``("wait", None)``, ``("inspect", "A.1.1.2")``, ..."""
        if not 0 <= index < self.size:
            raise IndexError(f"action {index} is not in 0..{self.size - 1}")
        if index < len(SPECIAL):
            return SPECIAL[index], None
        room, action = divmod(index - len(SPECIAL), len(SEARCHES))
        return SEARCHES[action], self.rooms[room]

    def name(self, index: int) -> str:
        action, room = self.decode(index)
        return action if room is None else f"{action} {room}"


@cache
def searches_of(kind: str) -> tuple[str, ...]:
    """The search actions a kind has (Table I)."""
    return tuple(a for a in SEARCHES if (kind, a) in ACTIONS)
