"""The fundamental actions (the paper's Table I, plus human move and inspect), by registry.

``ACTIONS`` maps ``(kind, name)`` to the action's record
(:class:`~astralis_des.action_spec.ActionSpec`): its generator function
``run(ctx, robot, task)`` returning an :class:`~astralis_des.kernel.tasks.ActionResult`, its
parameters, its room, search, duration, Table IV and chat facts. New ones plug in with
:func:`astralis_des.plugins.action`.
"""

from __future__ import annotations

from collections.abc import Callable

from astralis_des.actions.common import ActionGen, Context
from astralis_des.kernel.robot import Robot
from astralis_des.kernel.tasks import Task
from astralis_des.plugins import ACTIONS, ActionRegistry, actions_for

Action = Callable[[Context, Robot, Task], ActionGen]

# Registered in this order, which is the order the chat lists each kind's verbs in (``move``,
# every kind's, first).
from astralis_des.actions import move, uav, ugv, human  # noqa: E402,F401,I001  (they register)

__all__ = ["ACTIONS", "Action", "ActionRegistry", "actions_for"]
