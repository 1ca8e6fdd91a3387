"""The chat's line language: a line to an API request (or to something the chat answers
itself), and the candidates for the word being typed. No sockets: it needs only the served
mission's ``info`` (as a :class:`~astralis_des.chat.team.Team`).

Commands are registered with ``@command(name, usage)``; the lines about one robot
(``uav1 search A.2.1.3 inward``) are :mod:`astralis_des.chat.robots`'s.
"""

from __future__ import annotations

import difflib
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from astralis_des.api.protocol import read_pace
from astralis_des.chat import robots
from astralis_des.chat.team import ChatError, Team, number, seconds
from astralis_des.errors import suggest
from astralis_des.registry import Registry

LAST_EVENTS = 10  # events shown by a bare ``events``
SINCE_EVENTS = 50  # at most this many from ``events since T``
MAX_EVENTS = 1000  # the most ``events N`` shows


@dataclass(frozen=True)
class Parsed:
    """An API request (``op`` and its arguments), or, with ``local``, something the chat
    answers itself: help, quit, robots, rooms, the last events."""

    op: str
    args: dict[str, Any] = field(default_factory=dict)
    local: bool = False


Parse = Callable[[list[str], Team], Parsed]
Next = Callable[[list[str], Team], list[str]]


@dataclass(frozen=True)
class Command:
    name: str
    usage: str
    help: str
    parse: Parse
    next_words: Next  # completion: candidates for the word after ``words``
    aliases: tuple[str, ...] = ()


COMMANDS: Registry[str, Command] = Registry("chat command")
ALIASES: dict[str, str] = {}


def _nothing(words: list[str], team: Team) -> list[str]:
    return []


def _first_robot(words: list[str], team: Team) -> list[str]:
    return list(team.robots) if not words else []


def command(name: str, usage: str, *, aliases: tuple[str, ...] = (),
            next_words: Next = _nothing) -> Callable[[Parse], Parse]:
    """Register a command; its docstring's first line is its help."""
    def add(fn: Parse) -> Parse:
        text = (fn.__doc__ or "").strip().splitlines()
        COMMANDS.register(name)(Command(name, usage, text[0] if text else "", fn, next_words,
                                        aliases))
        for alias in aliases:
            ALIASES[alias] = name
        return fn

    return add


# -- the whole line ------------------------------------------------------------------------
def parse(line: str, team: Team) -> Parsed:
    """One line to what to do; :class:`ChatError` says what is wrong with it."""
    words = line.split()
    if not words:
        return Parsed("nothing", local=True)
    first = words[0]
    if first in team.robots and first.lower() not in COMMANDS:
        if len(words) > 1 and words[1].lower() in robots.ROBOT_COMMANDS:
            return parse(" ".join([words[1], first, *words[2:]]), team)
        op, args = robots.parse_robot_line(first, words[1:], team)
        return Parsed(op, args)
    name = ALIASES.get(first.lower(), first.lower())
    if name not in COMMANDS:
        raise ChatError(_unknown(first, team))
    return COMMANDS.get(name).parse(words[1:], team)


def _unknown(word: str, team: Team) -> str:
    options = [*COMMANDS, *ALIASES, *team.robots]
    close = difflib.get_close_matches(word, options, n=1, cutoff=0.6)
    if close and close[0] in team.robots:
        return f"no robot '{word}'; did you mean '{close[0]}'?"
    if close:
        return f"unknown command '{word}'; did you mean '{close[0]}'?"
    return f"unknown command '{word}'; type help for the commands ({suggest(word, options)})"


def complete(line: str, team: Team) -> list[str]:
    """The candidates for the word being typed at the end of ``line``."""
    words = line.split()
    partial = words.pop() if words and not line[-1].isspace() else ""
    options = _next_words(words, team)
    return sorted({o for o in options if o.lower().startswith(partial.lower())})


def _next_words(words: list[str], team: Team) -> list[str]:
    if not words:
        return [*COMMANDS, *ALIASES, *team.robots]
    first = words[0]
    if first in team.robots and first.lower() not in COMMANDS:
        return robots.completions(first, words[1:], team)
    name = ALIASES.get(first.lower(), first.lower())
    return COMMANDS.get(name).next_words(words[1:], team) if name in COMMANDS else []


def _at_most(words: list[str], n: int, usage: str) -> None:
    if len(words) > n:
        raise ChatError(f"'{words[n]}' makes no sense here; usage: {usage}")


def _one_robot(words: list[str], team: Team, usage: str) -> str:
    if not words:
        raise ChatError(f"which robot? usage: {usage} (robots: {', '.join(team.robots)})")
    return team.robot(words[0])


# -- the commands ----------------------------------------------------------------------------
@command("help", "help [COMMAND | ROBOT | VERB]", aliases=("?",),
         next_words=lambda w, t: ([*COMMANDS, *t.robots, *(n for _, n in robots.VERBS)]
                                  if not w else []))
def _help(words: list[str], team: Team) -> Parsed:
    """The commands, or what one command, robot or verb does."""
    _at_most(words, 1, "help [WORD]")
    return Parsed("help", {"word": words[0]} if words else {}, local=True)


@command("quit", "quit", aliases=("exit",))
def _quit(words: list[str], team: Team) -> Parsed:
    """Leave the chat (a mission served by the chat ends and its outputs are written)."""
    return Parsed("quit", local=True)


@command("status", "status [ROBOT]", next_words=_first_robot)
def _status(words: list[str], team: Team) -> Parsed:
    """The mission's time, clock and outcome, and each robot's state and position."""
    _at_most(words, 1, "status [ROBOT]")
    return Parsed("status", {"robot": team.robot(words[0])} if words else {})


@command("robot", "robot ROBOT", next_words=_first_robot)
def _robot(words: list[str], team: Team) -> Parsed:
    """One robot: its type, pose, heading, command and queue (Table II)."""
    _at_most(words, 1, "robot ROBOT")
    return Parsed("robot", {"robot": _one_robot(words, team, "robot ROBOT")})


@command("room", "room ROOM", aliases=("location",),
         next_words=lambda w, t: list(t.rooms) if not w else [])
def _room(words: list[str], team: Team) -> Parsed:
    """A room: where it is, its messiness, risk and sound (Table II), searched or not."""
    _at_most(words, 1, "room ROOM")
    if not words:
        raise ChatError("which room? usage: room ROOM (rooms lists them)")
    return Parsed("location", {"room": team.room(words[0])})


@command("avatar", "avatar")
def _avatar(words: list[str], team: Team) -> Parsed:
    """The target avatar (Table II): what it looks like; where, once found."""
    _at_most(words, 0, "avatar")
    return Parsed("avatar")


@command("robots", "robots")
def _robots(words: list[str], team: Team) -> Parsed:
    """The team: each robot's kind and what it can be told to do."""
    _at_most(words, 0, "robots")
    return Parsed("robots", local=True)


@command("rooms", "rooms [SEGMENT]", aliases=("segments",),
         next_words=lambda w, t: list(t.segments) if not w else [])
def _rooms(words: list[str], team: Team) -> Parsed:
    """The segments and their rooms (or one segment's)."""
    _at_most(words, 1, "rooms [SEGMENT]")
    return Parsed("rooms", {"segment": team.segment(words[0])} if words else {}, local=True)


@command("queue", "queue [ROBOT]", next_words=_first_robot)
def _queue(words: list[str], team: Team) -> Parsed:
    """A robot's running task and those waiting (every robot's, without one)."""
    _at_most(words, 1, "queue [ROBOT]")
    if not words:
        return Parsed("queues", local=True)
    return Parsed("queue", {"robot": team.robot(words[0])})


@command("events", "events [N] | events since T",
         next_words=lambda w, t: ["since"] if not w else [])
def _events(words: list[str], team: Team) -> Parsed:
    """The last N events of the mission's log (10), or those since a time."""
    usage = "events [N] | events since T"
    if words and words[0].lower() == "since":
        _at_most(words, 2, usage)
        if len(words) < 2:
            raise ChatError(f"since when? usage: {usage}")
        return Parsed("events", {"since": seconds(words[1], "events since"),
                                 "limit": SINCE_EVENTS})
    _at_most(words, 1, usage)
    last = number(words[0]) if words else LAST_EVENTS
    if last is None or not 1 <= last <= MAX_EVENTS or last != int(last):
        raise ChatError(f"events: '{words[0]}' is not a count from 1 to {MAX_EVENTS}; "
                        f"usage: {usage}")
    return Parsed("tail", {"last": int(last)}, local=True)


@command("pause", "pause")
def _pause(words: list[str], team: Team) -> Parsed:
    """Stop the clock: time then moves only on step (or resume)."""
    _at_most(words, 0, "pause")
    return Parsed("pause")


@command("resume", "resume [PACE, e.g. 10x]")
def _resume(words: list[str], team: Team) -> Parsed:
    """Start the clock again, at a pace (simulated s per wall s) or the one it had."""
    _at_most(words, 1, "resume [PACE]")
    if not words:
        return Parsed("resume")
    try:
        pace = read_pace(words[0])
    except ValueError as exc:
        raise ChatError(f"resume: {exc}") from None
    return Parsed("resume", {"pace": pace})


@command("step", "step SECONDS | step to T", next_words=lambda w, t: ["to"] if not w else [])
def _step(words: list[str], team: Team) -> Parsed:
    """With the clock paused: run the mission on for a while, or to a time."""
    usage = "step SECONDS | step to T (e.g. step 30, step 2m, step to 600)"
    if words and words[0].lower() in ("to", "until"):
        _at_most(words, 2, usage)
        if len(words) < 2:
            raise ChatError(f"to when? usage: {usage}")
        return Parsed("step", {"until": seconds(words[1], "step to")})
    _at_most(words, 1, usage)
    if not words:
        raise ChatError(f"for how long? usage: {usage}")
    by = seconds(words[0], "step")
    if by <= 0:
        raise ChatError(f"step: {words[0]} is not a while; usage: {usage}")
    return Parsed("step", {"by": by})


@command("cancel", "cancel ROBOT [TASK]", next_words=_first_robot)
def _cancel(words: list[str], team: Team) -> Parsed:
    """Cancel a robot's tasks, running and queued, or one task by its number."""
    usage = "cancel ROBOT [TASK]"
    _at_most(words, 2, usage)
    args: dict[str, Any] = {"robot": _one_robot(words, team, usage)}
    if len(words) == 2:
        task = number(words[1].lstrip("#"))
        if task is None or task != int(task):
            raise ChatError(f"cancel: '{words[1]}' is not a task number (queue "
                            f"{args['robot']} lists them)")
        args["task"] = int(task)
    return Parsed("cancel", args)


def _assign_next(words: list[str], team: Team) -> list[str]:
    given = words[1:] if words and words[0].lower() == "segment" else words
    if not given:
        return [*(["segment"] if not words else []), *team.segments]
    segment = next((s for s in team.segments if s.lower() == given[0].lower()), None)
    rooms = team.segments.get(segment, ()) if segment else ()
    return [*rooms, *team.robots]


@command("assign", "assign [segment] SEGMENT [ROOM ...] [ROBOT ...]", next_words=_assign_next)
def _assign(words: list[str], team: Team) -> Parsed:
    """Run an assignment round over a segment's rooms (or some) with the team (or some)."""
    given = words[1:] if words and words[0].lower() == "segment" else words
    if not given:
        raise ChatError("which segment? usage: assign segment SEGMENT (rooms lists them)")
    segment = team.segment(given[0])
    rooms = [w for w in given[1:] if w not in team.robots]
    agents = [w for w in given[1:] if w in team.robots]
    args: dict[str, Any] = {"segment": segment}
    if rooms:
        args["rooms"] = [team.room(w) for w in rooms]
    if agents:
        args["robots"] = agents
    return Parsed("assign", args)


@command("shutdown", "shutdown")
def _shutdown(words: list[str], team: Team) -> Parsed:
    """End the mission where it is, write its outputs and stop the server."""
    _at_most(words, 0, "shutdown")
    return Parsed("shutdown")


# -- help ------------------------------------------------------------------------------------
def help_rows(word: str | None, team: Team) -> list[tuple[str, str]]:
    """(usage, what it does) rows: every command, or those a word names."""
    if word is None:
        rows = [(c.usage, c.help) for c in map(COMMANDS.get, COMMANDS)]
        return [*rows, ("ROBOT VERB ...", "a task for a robot: help ROBOT lists its verbs")]
    if word in team.robots:
        verbs = robots.verbs_of(word, team)
        named = robots.friendly_verbs(word, team)
        actions = [name for name in verbs if name not in named]
        rows = [(verbs[name].usage(word), verbs[name].help) for name in named]
        if actions:
            rows.append((f"{word} ACTION [ROOM]", f"its actions by name: {', '.join(actions)}"))
        return rows
    name = ALIASES.get(word.lower(), word.lower())
    if name in COMMANDS:
        found = COMMANDS.get(name)
        return [(found.usage, found.help)]
    rows = [(v.usage(kind.upper() if kind != robots.ANY_KIND else "ROBOT"), v.help)
            for (kind, name), v in ((k, robots.VERBS.get(k)) for k in robots.VERBS)
            if name == word.lower()]
    if not rows:
        options = [*COMMANDS, *ALIASES, *team.robots, *(n for _, n in robots.VERBS)]
        raise ChatError(f"no help on '{word}'; {suggest(word, options)}")
    return rows
