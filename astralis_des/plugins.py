"""The registries whose entries plug in from above: a lower layer may name and look up what a
higher one provides (the mission file checks action and strategy names; the actions, which
need the kernel, register them). Each names the modules whose import fills it, imported on
the first look-up (:class:`~astralis_des.registry.Registry`'s ``plugins``).

To add an action, a strategy, a fidelity or a sensor, register it in a module of your own
and import that module before running (or add it to the ``plugins`` here)::

    from astralis_des.plugins import ACTIONS

    @ACTIONS.register(("uav", "zigzag"))
    def zigzag(ctx, robot, task): ...
"""

from __future__ import annotations

from typing import Any

from astralis_des.registry import Registry

# (kind, name) -> action(ctx, robot, task): a generator returning an ActionResult
ACTIONS: Registry[tuple[str, str], Any] = Registry("action", plugins=("astralis_des.actions",))
# name -> strategy(agents, rooms, weights, ...) -> Assignment
STRATEGIES: Registry[str, Any] = Registry("assignment strategy",
                                          plugins=("astralis_des.assignment.strategies",
                                                   "astralis_des.assignment.baselines"))

# fidelity -> co-simulation class (the physics one is imported only when asked for)
COSIMS: Registry[str, Any] = Registry("fidelity", plugins=("astralis_des.cosim.kinematic",))

# name -> sensor(host, robot, params): a sensor a mission adds to a member by name
# (``sensors: {plugins: {name: {...}}}``); see astralis_des.kernel.contracts.PluginSensor
SENSORS: Registry[str, Any] = Registry("sensor")


def actions_for(kind: str) -> list[str]:
    """The names of the actions a kind has."""
    return [name for k, name in ACTIONS if k == kind]
