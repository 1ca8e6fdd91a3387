"""What the chat says back: an API reply to a short reply a person reads, by registry
(``@shows("status")``). Plain :class:`~rich.text.Text`, never markup, so that a room like
``[A.1.1.1]`` in a message is shown as it is."""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Iterable
from typing import Any

from rich.console import Group, RenderableType
from rich.table import Table
from rich.text import Text

from astralis_des.chat.language import Parsed
from astralis_des.registry import Registry

log = logging.getLogger(__name__)

Show = Callable[[Parsed, Any], RenderableType]
SHOWS: Registry[str, Show] = Registry("reply")


def shows(op: str) -> Callable[[Show], Show]:
    return SHOWS.register(op)


def reply(parsed: Parsed, result: Any) -> RenderableType:
    """The reply to ``parsed``, as shown; an op without its own form as key: value lines."""
    if parsed.op in SHOWS:
        try:
            return SHOWS.get(parsed.op)(parsed, result)
        except (KeyError, TypeError, ValueError):  # a reply of another version's shape
            log.warning("cannot show the reply to %s", parsed.op, exc_info=True)
    if isinstance(result, dict):
        return Text("\n".join(f"{k}: {v}" for k, v in result.items()))
    return Text(str(result))


def where(pose: Iterable[float] | None) -> str:
    if pose is None:
        return "-"
    return "(" + ", ".join(f"{v:.1f}" for v in pose) + ")"


def fmt(value: Any) -> str:
    """A value of a reply as a person reads it: floats to 2 decimals."""
    if isinstance(value, float):
        return f"{value:.2f}".rstrip("0").rstrip(".")
    return str(value)


def task_text(task: dict[str, Any]) -> str:
    """``spiral_inward A.2.1.3`` or ``move to (70.0, 60.0)``."""
    params = dict(task.get("params") or {})
    target = task.get("room")
    if target is None and "x" in params and "y" in params:
        target = f"to ({params.pop('x'):.1f}, {params.pop('y'):.1f})"
        params.pop("z", None)
        params.pop("look", None)
    extra = " ".join(f"{k}={fmt(v)}" for k, v in params.items())
    return " ".join(str(p) for p in (task["action"], target, extra) if p)


def clock_line(result: dict[str, Any]) -> str:
    mission = (f"mission ended: {result['outcome']}" if result.get("ended")
               else "mission running")
    found = (f"; target found by {result['found_by']}" if result.get("found")
             and result.get("found_by") else "")
    rounds, searched = result.get("rounds", 0), len(result.get("rooms_searched", []))
    return (f"t = {result['t']:.1f} s, clock {result['clock']}; {mission}{found}; "
            f"{plural(rounds, 'assignment round')}, {plural(searched, 'room')} searched")


def plural(n: int, what: str) -> str:
    return f"{n} {what}{'' if n == 1 else 's'}"


@shows("status")
def _status(parsed: Parsed, result: dict[str, Any]) -> RenderableType:
    table = Table(box=None, pad_edge=False, header_style="bold")
    for name in ("robot", "type", "state", "command", "queued", "position"):
        table.add_column(name, justify="right" if name == "queued" else "left")
    for rid, r in result["robots"].items():
        table.add_row(rid, r["type"], r["state"], r["command"] or "-", str(r["queued"]),
                      where(r["pose"]))
    return Group(Text(clock_line(result)), table)


@shows("robot")
def _robot(parsed: Parsed, r: dict[str, Any]) -> RenderableType:
    doing = f"doing {r['command']} (task {r['task']})" if r["command"] else "idle"
    heading = math.degrees(r["heading"] or 0.0)
    return Text(f"{r['id']} ({r['type']}): {r['state']}, {doing}, {r['queued']} queued; at "
                f"{where(r['pose'])} heading {heading:.0f} deg; {r['distance']:.1f} m "
                "travelled")


@shows("location")
def _location(parsed: Parsed, r: dict[str, Any]) -> RenderableType:
    return Text(f"{r['room']} (segment {r['segment']}) at {where(r['location'])}: messiness "
                f"{fmt(r['messiness_level'])}, risk {fmt(r['risk'])}, sound {fmt(r['sound'])}; "
                f"{'searched' if r['searched'] else 'not searched yet'}")


@shows("avatar")
def _avatar(parsed: Parsed, r: dict[str, Any]) -> RenderableType:
    looks = ", ".join(f"{k} {fmt(v)}" for k, v in r.items()
                      if k not in ("found", "location", "room"))
    found = (f"found in {r['room']} at {where(r['location'])}" if r.get("found")
             else "not found yet")
    return Text(f"target: {looks}; {found}")


@shows("queue")
def _queue(parsed: Parsed, r: dict[str, Any]) -> RenderableType:
    return Text(queue_text(r))


def queue_text(r: dict[str, Any]) -> str:
    current = r["current"]
    running = (f"running task {current['id']}: {task_text(current)}" if current
               else "nothing running")
    if not r["queued"]:
        return f"{r['robot']}: {running}, nothing queued"
    lines = [f"{r['robot']}: {running}; queued, in order:"]
    lines += [f"  task {t['id']}: {task_text(t)}" for t in r["queued"]]
    return "\n".join(lines)


@shows("events")
def _events(parsed: Parsed, r: dict[str, Any]) -> RenderableType:
    events = r["events"]
    if not events:
        return Text(f"no events since t = {parsed.args.get('since', 0):g} s")
    more = parsed.args.get("limit") == len(events)
    last = f"\n(more: events since {events[-1]['t']:g})" if more else ""
    return unwrapped(events_text(events) + last)


def unwrapped(text: str) -> Table:
    """Lines cut at the terminal's edge (with an ellipsis) instead of wrapped."""
    table = Table(box=None, show_header=False, pad_edge=False, padding=0)
    table.add_column(no_wrap=True, overflow="ellipsis")
    table.add_row(Text(text))
    return table


def events_text(events: list[dict[str, Any]]) -> str:
    """One line per event."""
    return "\n".join(event_line(e) for e in events)


def event_line(e: dict[str, Any]) -> str:
    rest = " ".join(f"{k}={_short(v)}" for k, v in e.items() if k not in ("t", "kind", "robot")
                    and v is not None)
    return f"t = {e['t']:8.1f}  {e['kind']:<12} {e.get('robot') or '':<6} {rest}".rstrip()


def _short(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, list) and all(isinstance(v, float) for v in value):
        return "(" + ", ".join(f"{v:.1f}" for v in value) + ")"
    text = str(value)
    return text if len(text) <= 60 else text[:57] + "..."


@shows("enqueue")
def _enqueue(parsed: Parsed, r: dict[str, Any]) -> RenderableType:
    what = task_text(parsed.args)
    ahead = int(r["position"])  # the API's position: how many queued tasks run before it
    where = "next to run" if ahead == 0 else f"{ahead} queued ahead of it"
    return Text(f"queued task {r['task']} for {r['robot']}: {what} ({where})")


@shows("preempt")
def _preempt(parsed: Parsed, r: dict[str, Any]) -> RenderableType:
    what = task_text(parsed.args)
    stopped = (f"; task {r['interrupted']} interrupted" if r.get("interrupted") is not None
               else "")
    return Text(f"task {r['task']} for {r['robot']} runs now: {what}{stopped}")


@shows("cancel")
def _cancel(parsed: Parsed, r: dict[str, Any]) -> RenderableType:
    if not r["cancelled"]:
        return Text(f"{r['robot']} had no tasks to cancel")
    tasks = ", ".join(map(str, r["cancelled"]))
    return Text(f"cancelled {r['robot']}'s task{'s' if len(r['cancelled']) > 1 else ''} "
                f"{tasks}")


@shows("pause")
def _pause(parsed: Parsed, r: dict[str, Any]) -> RenderableType:
    return Text(f"clock paused at t = {r['t']:.1f} s (step moves it on, resume runs it)")


@shows("resume")
def _resume(parsed: Parsed, r: dict[str, Any]) -> RenderableType:
    return Text(f"clock {r['clock']} from t = {r['t']:.1f} s")


@shows("step")
def _step(parsed: Parsed, r: dict[str, Any]) -> RenderableType:
    ended = f"; mission ended: {r['outcome']}" if r["ended"] else ""
    return Text(f"t = {r['t']:.1f} s{ended}")


@shows("assign")
def _assign(parsed: Parsed, r: dict[str, Any]) -> RenderableType:
    pairs = [f"{m['agent']} -> {m['action']} {m['room']}" for m in r["matching"]]
    lines = [f"round {r['round']} over {parsed.args['segment']}: "
             f"{plural(len(pairs), 'task')} queued"]
    lines += [f"  {p}" for p in pairs]
    if r["unassigned"]:
        lines.append(f"  unassigned: {', '.join(r['unassigned'])}")
    return Text("\n".join(lines))


@shows("shutdown")
def _shutdown(parsed: Parsed, r: dict[str, Any]) -> RenderableType:
    return Text(f"the server stops at t = {r['t']:.1f} s; the mission's outputs are written")
