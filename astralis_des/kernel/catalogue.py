"""The one catalogue of events: every kind the event log may hold, its fields and the level a
replay shows it at. The log refuses a kind or a field not catalogued here, so the log, the
sinks (``recording.rrd``'s text log, the MCAP), the API (``events``, ``kinds``) and the
stream (topic ``event.<kind>``) all read one truth, and ``docs/events.md`` is generated from it
(``astralis schema --events``).

A plug-in that emits a kind of its own registers an :class:`EventKind` in :data:`EVENTS`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Any, Literal

from astralis_des.registry import Registry

Level = Literal["CRITICAL", "ERROR", "WARN", "INFO", "DEBUG"]  # Rerun's text-log levels
Robot = Literal["always", "never", "maybe"]


@dataclass(frozen=True)
class EventKind:
    """One kind of event: what it means, the payload it carries, how a replay shows it.

    ``fields`` are always in its payload, ``optional`` ones when they apply; ``robot`` says
    whether it names a robot. ``raised``: ``(field, value, level)``, a higher level when the
    field has that value (a failed task is a warning, a finished one is not)."""

    name: str
    what: str
    fields: tuple[str, ...] = ()
    optional: tuple[str, ...] = ()
    robot: Robot = "never"
    level: Level = "DEBUG"
    raised: tuple[tuple[str, Any, Level], ...] = ()

    def level_of(self, record: dict[str, Any]) -> Level:
        """The level a replay shows ``record`` at."""
        for field, value, level in self.raised:
            if record.get(field) == value:
                return level
        return self.level

    @cached_property
    def _fields(self) -> frozenset[str]:
        return frozenset(self.fields)

    @cached_property
    def _allowed(self) -> frozenset[str]:
        return frozenset(self.fields) | frozenset(self.optional)

    def check(self, robot: str | None, payload: dict[str, Any]) -> None:
        """Refuse (``ValueError``) a payload this kind does not declare: a field missing or
        unknown, a robot where none goes or none where one must."""
        if (robot is None and self.robot == "always") or \
                (robot is not None and self.robot == "never"):
            says = "names a robot" if self.robot == "always" else "names no robot"
            raise ValueError(f"a {self.name} event {says}")
        keys = payload.keys()
        if self._fields <= keys <= self._allowed:  # the usual case, at every event
            return
        missing = [f for f in self.fields if f not in keys]
        unknown = [k for k in keys if k not in self.fields and k not in self.optional]
        if missing or unknown:
            raise ValueError(f"a {self.name} event " + "; ".join(
                [f"lacks {', '.join(missing)}"] * bool(missing)
                + [f"has no field {', '.join(unknown)} (kernel/catalogue.py)"] * bool(unknown)))


EVENTS: Registry[str, EventKind] = Registry("event kind")


def event(kind: EventKind) -> EventKind:
    """Register ``kind`` in :data:`EVENTS` (twice is refused)."""
    return EVENTS.register(kind.name)(kind)


def level_of(record: dict[str, Any]) -> Level:
    """The level a replay shows ``record`` at (its kind's)."""
    return EVENTS.get(record["kind"]).level_of(record)


TASK = ("task", "action", "room")
COMMAND_ARGS = ("action", "room", "params", "preempt",  # a timeline's command
                "op", "source", "task", "pace", "until", "segment", "rooms", "robots",
                "direction", "distance")  # the API's (``op``), with what each op was given

for _kind in (
    EventKind("mission_start", "the mission begins: its name, seed, fidelity, target's room "
              "and team", ("mission", "seed", "fidelity", "target_room", "team"),
              level="INFO"),
    EventKind("mission_end", "the mission ends: found, searched_out, team_lost, time_limit "
              "or interrupted", ("outcome",), level="INFO"),
    EventKind("assignment", "an assignment round: the segment's pending rooms, the agents, "
              "Eq. 1's costs and the matching", ("round", "segment", "strategy", "agents",
                                                 "rooms", "risk", "messiness", "costs",
                                                 "matching", "unassigned"),
              ("info",), level="INFO"),
    EventKind("task_queued", "a task joins a robot's FIFO queue (from an assignment, the "
              "timeline, the API or the chat)", (*TASK, "origin"), robot="always"),
    EventKind("task_started", "a robot starts the task at the head of its queue", TASK,
              robot="always", level="INFO"),
    EventKind("task_finished", "a task ends: succeeded, failed or cancelled, with the "
              "distance travelled (and a search's coverage)",
              (*TASK, "status", "message", "distance"), ("coverage",), robot="always",
              level="INFO", raised=(("status", "failed", "WARN"),)),
    EventKind("took_off", "a UAV leaves the ground to its flight height", ("height",),
              robot="always"),
    EventKind("landed", "a UAV is down where it landed", ("position",), robot="always"),
    EventKind("fault", "a robot is down (injected, or it crashed): its task fails",
              ("reason",), robot="always", level="ERROR"),
    EventKind("recover", "a faulted robot is back in service", robot="always", level="INFO"),
    EventKind("detection", "a sensor sees the target: the mission is won",
              ("sensor", "target_room", "estimate", "error", "target_position",
               "robot_position", "distance", "avatar"), ("pixels",), robot="always",
              level="CRITICAL"),
    EventKind("command", "a command from the timeline or the API (its op)", (),
              COMMAND_ARGS, robot="maybe", level="INFO"),
    EventKind("cancel", "the timeline cancels a robot's queued tasks", ("tasks",),
              robot="always", level="INFO"),
    EventKind("room_change", "the timeline changes a room's risk, messiness or sound",
              ("room",), ("risk", "messiness", "sound"), level="INFO"),
    EventKind("room_undercovered", "a search saw less of a room than the threshold: another "
              "kind may take it", ("room", "coverage", "threshold", "requeued", "kinds_left"),
              robot="always", level="INFO"),
    EventKind("room_searched_undercovered", "no kind left to search a room better: it "
              "counts as searched, undercovered", ("room", "reason"), level="WARN"),
    EventKind("room_given_up", "no agent reached a room after its attempts: it is left",
              ("room", "attempts"), ("reason",), level="WARN"),
    EventKind("team_lost", "no agent is left to search a segment: the mission ends",
              ("segment",), level="ERROR"),
    EventKind("fork", "the run forks here (astralis run --fork-at): the mission's settings "
              "changed from this point on, the events added to its timeline, and how many "
              "rounds were decided and lines logged before it", ("point", "changes",
                                                                 "timeline", "rounds", "lines"),
              level="WARN"),
    EventKind("clutter_skipped", "an item of furniture found no free spot in its room",
              ("room", "item", "reason")),
    EventKind("make_way", "physics: a robot steps aside for another", ("for_robot", "to"),
              robot="always"),
    EventKind("contact", "physics: a robot touches another body", ("other", "impulse"),
              robot="always"),
):
    event(_kind)


def markdown() -> str:
    """``docs/events.md``: the catalogue as a table."""
    lines = ["# Event kinds", "",
             "Generated from the catalogue (`astralis_des/kernel/catalogue.py`; "
             "`astralis schema --events -o docs/events.md`, a test checks that it is up to date).",
             "Each line of a run's `events.jsonl` is one event: `t` (simulated seconds), `kind`, "
             "`robot` where it names one, and the fields below. The level is how the replay's "
             "text log shows it; the API's `events` op filters by kind, and the stream's topic "
             "is `event.<kind>`.", "",
             "| kind | robot | fields | optional fields | level | what |",
             "| --- | --- | --- | --- | --- | --- |"]
    for name in EVENTS:
        kind = EVENTS.get(name)
        level = kind.level + "".join(f" ({f} {v}: {lv})" for f, v, lv in kind.raised)
        lines.append(f"| `{name}` | {kind.robot} | {', '.join(kind.fields) or '-'} | "
                     f"{', '.join(kind.optional) or '-'} | {level} | {kind.what} |")
    return "\n".join(lines) + "\n"
