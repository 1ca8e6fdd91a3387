"""The registries whose entries plug in from above: a lower layer may name and look up what a
higher one provides (the mission file checks action and strategy names; the actions, which
need the kernel, register them). Each names the modules whose import fills it, imported on
the first look-up (:class:`~astralis_des.registry.Registry`'s ``plugins``).

To add an action, a strategy, a fidelity or a sensor, register it in a module of your own
and import that module before running (or add it to the ``plugins`` here). An action is one
record (:class:`~astralis_des.action_spec.ActionSpec`), its parameters a pydantic model::

    from astralis_des.action_spec import ActionParams, Number
    from astralis_des.plugins import action

    class ZigzagParams(ActionParams):
        width: Number = Field(2.0, ge=0.5, le=20.0, description="m")

    @action("zigzag", ("uav",), params=ZigzagParams)
    def zigzag(ctx, robot, task): ...

A bare function registered with ``@ACTIONS.register(("uav", "zigzag"))`` takes any params.

A robot kind is one record (:class:`~astralis_des.kinds.KindDefaults`), added with
:func:`robot_kind`; ``examples/plugins/legged.py`` adds a legged robot with its own action,
planner, physics driver and look.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar

from astralis_des.action_spec import ActionSpec, AnyParams
from astralis_des.kinds import KINDS, KindDefaults, register_kind
from astralis_des.registry import Registry

F = TypeVar("F", bound=Callable[..., Any])


class ActionRegistry(Registry[tuple[str, str], ActionSpec]):
    """``(kind, name)`` -> the action's record; a record serving several kinds is registered
    under each."""

    def register(self, key: tuple[str, str]) -> Callable[[Any], Any]:
        add = super().register(key)

        def wrap(entry: Any) -> Any:
            add(entry if isinstance(entry, ActionSpec) else
                ActionSpec(key[1], (key[0],), entry, params=AnyParams))
            return entry

        return wrap

    def add(self, spec: ActionSpec) -> ActionSpec:
        for kind in spec.kinds:
            self.register((kind, spec.name))(spec)
        return spec

    def specs(self) -> list[ActionSpec]:
        """Each record once, in the order they were registered."""
        return list({id(s): s for _, s in self.registered()}.values())


ACTIONS = ActionRegistry("action", plugins=("astralis_des.actions",))
# name -> strategy(agents, rooms, weights, ...) -> Assignment
STRATEGIES: Registry[str, Any] = Registry("assignment strategy",
                                          plugins=("astralis_des.assignment.strategies",
                                                   "astralis_des.assignment.baselines"))

# fidelity -> co-simulation class (the physics one is imported only when asked for)
COSIMS: Registry[str, Any] = Registry("fidelity", plugins=("astralis_des.cosim.kinematic",))

# name -> sensor(host, robot, params): a sensor a mission adds to a member by name
# (``sensors: {plugins: {name: {...}}}``); see astralis_des.kernel.contracts.PluginSensor
SENSORS: Registry[str, Any] = Registry("sensor")


def action(name: str, kinds: tuple[str, ...], **about: Any) -> Callable[[F], F]:
    """Register ``run`` as the action ``name`` of ``kinds``; ``about``: the record's other
    fields (``params``, ``room``, ``search``, ...)."""
    def add(run: F) -> F:
        ACTIONS.add(ActionSpec(name, kinds, run, doc=" ".join((run.__doc__ or "").split()),
                               **about))
        return run

    return add


def robot_kind(name: str, record: KindDefaults,
               share: dict[str, str] | None = None) -> KindDefaults:
    """Register the robot kind ``name``. It runs ``move`` as every kind does, and each action
    ``share`` names (``{action: kind}``) with that kind's record; its own actions register
    with :func:`action`."""
    register_kind(name, record)
    for verb, like in {"move": KINDS[0], **(share or {})}.items():
        if (name, verb) not in ACTIONS:
            ACTIONS.register((name, verb))(ACTIONS.get((like, verb)))
    return record


def actions_for(kind: str) -> list[str]:
    """The names of the actions a kind has."""
    return [name for k, name in ACTIONS if k == kind]


def check_params(kind: str, action: str, params: dict[str, Any]) -> dict[str, Any]:
    """``params`` checked against the record of ``kind``'s ``action`` (numbers as floats); a
    ``ValueError`` with one line naming the parameter otherwise. An action the kind does not
    have is refused where it is looked up, not here."""
    if (kind, action) not in ACTIONS:
        return dict(params)
    return ACTIONS.get((kind, action)).check(params)
