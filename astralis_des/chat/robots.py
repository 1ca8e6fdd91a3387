"""Robot lines: ``<robot> <verb> [ROOM | X Y] [VARIANT] [key=value ...] [now]``.

Each kind's verbs come from the actions' records (their ``verbs``), keyed by (kind, verb): a
UAV's ``search ROOM inward`` is ``spiral_inward``, a UGV's ``observe ROOM`` is
``observe_corridor``. Every action
a robot has also answers to its own name (``sweep-horizontal``, ``sweep_horizontal``), so a
kind this module has never heard of can still be commanded.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, Literal

from astralis_des.action_spec import ActionSpec, Verb
from astralis_des.chat.team import ChatError, Team, number, param_value, seconds
from astralis_des.errors import suggest
from astralis_des.kinds import KINDS
from astralis_des.plugins import ACTIONS
from astralis_des.registry import Registry

ANY_KIND = "*"
NOW = "now"
RoomUse = Literal["required", "optional", "none"]


@dataclass(frozen=True)
class RobotVerb:
    name: str
    action: str  # what it runs without a variant word
    help: str
    variants: dict[str, str] = field(default_factory=dict)  # word after the room -> action
    room: RoomUse = "required"
    point: bool = False  # X Y will do instead of a room
    number: str | None = None  # an optional number in the room's place: this param

    def usage(self, robot: str = "ROBOT") -> str:
        where = {"required": " ROOM", "optional": " [ROOM]", "none": ""}[self.room]
        if self.point:
            where = " ROOM|X Y"
        if self.number:
            where += f" [{self.number.upper()}]"
        if self.variants:
            where += f" [{'|'.join(self.variants)}]"
        return f"{robot} {self.name}{where}"

    def actions(self) -> set[str]:
        return {self.action, *self.variants.values()}


VERBS: Registry[tuple[str, str], RobotVerb] = Registry("robot verb")
_ORDER: list[tuple[str, str]] = []  # as registered: the order help and messages list them in


def robot_verb(kind: str, verb: RobotVerb) -> None:
    VERBS.register((kind, verb.name))(verb)
    _ORDER.append((kind, verb.name))


def _help(spec: ActionSpec, verb: Verb) -> str:
    if verb.number is None or not verb.help:
        return verb.help
    return f"{verb.help} (default {spec.default(verb.number):g} s)"


def _from_actions() -> None:
    """Each action record's chat words: the records of a kind that share a word make one
    verb (the first the action run without a variant word); a verb every kind has alike is
    registered once for any kind."""
    built: dict[tuple[str, str], RobotVerb] = {}
    for spec in ACTIONS.specs():
        for verb in spec.verbs:
            variant = {verb.variant: spec.name} if verb.variant else {}
            for kind in spec.kinds:
                had = built.get((kind, verb.word))
                built[(kind, verb.word)] = RobotVerb(
                    verb.word, spec.name, _help(spec, verb), variant,
                    room="required" if spec.room else "none", point=spec.point,
                    number=verb.number) if had is None else replace(
                    had, help=had.help or _help(spec, verb), variants={**had.variants, **variant})
    for (kind, word), made in built.items():
        if all(built.get((k, word)) == made for k in KINDS):
            if (ANY_KIND, word) not in VERBS:
                robot_verb(ANY_KIND, made)
        else:
            robot_verb(kind, made)


_from_actions()

# ``uav1 queue`` is ``queue uav1``: the robot-first form of the commands about one robot.
ROBOT_COMMANDS = ("status", "queue", "cancel")


def verbs_of(robot: str, team: Team) -> dict[str, RobotVerb]:
    """The verbs a robot answers to: its kind's, then its actions by their own names."""
    kind, has = team.robots[robot], set(team.actions[robot])
    out = {name: v for (k, name), v in _registered() if k in (kind, ANY_KIND)
           and v.actions() <= has}
    for action in team.actions[robot]:
        dashed = action.replace("_", "-")
        out.setdefault(dashed, RobotVerb(dashed, action, f"the action {action}",
                                         room="optional"))
    return out


def friendly_verbs(robot: str, team: Team) -> list[str]:
    """The registered verbs only (``move, sneak-peek, observe``), for messages and help."""
    verbs = verbs_of(robot, team)
    named = [name for name in verbs if (team.robots[robot], name) in VERBS
             or (ANY_KIND, name) in VERBS]
    return named or list(verbs)


def parse_robot_line(robot: str, words: list[str], team: Team) -> tuple[str, dict[str, Any]]:
    """The words after a robot id to an API op and its arguments."""
    if not words:
        raise ChatError(f"{robot} what? it can {', '.join(friendly_verbs(robot, team))} "
                        f"(help {robot})")
    word, rest = words[0].lower(), words[1:]
    verbs = verbs_of(robot, team)
    verb = verbs.get(word.replace("_", "-"))
    if verb is None:
        raise ChatError(_not_a_verb(robot, word, team))
    preempt = bool(rest) and rest[-1].lower() == NOW
    if preempt:
        rest = rest[:-1]
    params = {k: param_value(v) for k, _, v in (w.partition("=") for w in rest if "=" in w)}
    if any(not k for k in params):
        raise ChatError(f"a parameter is key=value, e.g. spacing=2 (usage: {verb.usage(robot)})")
    action, room, more = _place(robot, verb, [w for w in rest if "=" not in w], team)
    params.update(more)
    args: dict[str, Any] = {"robot": robot, "action": action}
    if room is not None:
        args["room"] = room
    if params:
        args["params"] = params
    return ("preempt" if preempt else "enqueue"), args


def _place(robot: str, verb: RobotVerb, rest: list[str],
           team: Team) -> tuple[str, str | None, dict[str, Any]]:
    """The room (or point, or number) and the variant of a robot line."""
    room: str | None
    action, room, params = verb.action, None, dict[str, Any]()
    chosen = [w.lower() for w in rest if w.lower() in verb.variants]
    if len(chosen) > 1:
        raise ChatError(f"{robot} {verb.name}: one of {', '.join(verb.variants)}, not "
                        f"{' and '.join(chosen)}")
    if chosen:
        action = verb.variants[chosen[0]]
        rest = [w for w in rest if w.lower() not in verb.variants]
    if verb.number and rest and _is_time(rest[0]):
        params[verb.number] = seconds(rest.pop(0), f"{robot} {verb.name}")
    if verb.point and len(rest) >= 2 and None not in (number(rest[0]), number(rest[1])):
        params["x"], params["y"] = float(rest[0]), float(rest[1])
        rest = rest[2:]
    elif rest and verb.room != "none":
        room = team.room(rest.pop(0))
    if room is None and "x" not in params and verb.room == "required":
        raise ChatError(f"{robot} {verb.name} needs {'a room or x y' if verb.point else 'a room'}"
                        f": {verb.usage(robot)}")
    if rest:
        raise ChatError(f"'{rest[0]}' makes no sense here; {verb.usage(robot)}")
    return action, room, params


def _not_a_verb(robot: str, word: str, team: Team) -> str:
    kind = team.robots[robot]
    can = ", ".join(friendly_verbs(robot, team))
    known = {name for _, name in VERBS} | {
        a.replace("_", "-") for acts in team.actions.values() for a in acts}
    if word.replace("_", "-") in known:
        return f"{robot} is a {kind}: it cannot {word}; it can {can}"
    options = [*verbs_of(robot, team), *ROBOT_COMMANDS]
    return f"{robot} has no command '{word}'; {suggest(word, options)} (it can {can})"


def _registered() -> list[tuple[tuple[str, str], RobotVerb]]:
    return [(key, VERBS.get(key)) for key in _ORDER]


def _is_time(word: str) -> bool:
    try:
        seconds(word, "")
    except ChatError:
        return False
    return True


def completions(robot: str, words: list[str], team: Team) -> list[str]:
    """Candidates for the next word of a robot line, given the words after the robot id."""
    verbs = verbs_of(robot, team)
    if not words:
        return [*verbs, *ROBOT_COMMANDS]
    verb = verbs.get(words[0].lower().replace("_", "-"))
    if verb is None:
        return []
    given = words[1:]
    if given and given[-1].lower() == NOW:
        return []
    if not given and verb.room != "none":
        return list(team.rooms)
    options = [NOW]
    if given and any(w.lower() in verb.variants for w in given):
        return options
    return [*verb.variants, *options]
