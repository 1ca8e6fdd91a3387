"""The fundamental actions (the paper's Table I, plus human move and inspect), by registry.

``ACTIONS`` maps ``(kind, name)`` to a generator function ``action(ctx, robot, task)`` that
returns an :class:`~astralis_des.kernel.tasks.ActionResult`. New ones plug in with
``@ACTIONS.register(("uav", "my_action"))``.
"""

from __future__ import annotations

from collections.abc import Callable

from astralis_des.actions.common import ActionGen, Context
from astralis_des.kernel.robot import Robot
from astralis_des.kernel.tasks import Task
from astralis_des.plugins import ACTIONS as _ACTIONS
from astralis_des.plugins import actions_for
from astralis_des.registry import Registry

Action = Callable[[Context, Robot, Task], ActionGen]
ACTIONS: Registry[tuple[str, str], Action] = _ACTIONS  # held in the foundations, by name

from astralis_des.actions import human, move, uav, ugv  # noqa: E402,F401  (they register)

# Actions that take no room (the others search, peek into or go to one; ``move`` also takes
# a point: ``x`` and ``y`` params).
ROOMLESS = frozenset({"hover", "take_off", "land"})

__all__ = ["ACTIONS", "ROOMLESS", "Action", "actions_for"]
