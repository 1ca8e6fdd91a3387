"""A comparison as rows a person reads: sections of (what, A, B, B - A) text, which the command
line prints as tables and the diff recording shows as a Markdown document."""

from __future__ import annotations

from dataclasses import dataclass
from itertools import zip_longest
from typing import Any

from astralis_des.compare.decisions import Comparison, EventDiff, Pair, difference
from astralis_des.compare.runs import Run

Row = tuple[str, str, str, str]  # what, A, B, B - A (or a note)
BRIEF_KEYS = ("round", "segment", "strategy", "op", "action", "room", "status", "message",
              "outcome", "reason", "at")
BRIEF = 90  # characters of an event's brief text


@dataclass(frozen=True)
class Section:
    title: str
    rows: list[Row]


def sections(c: Comparison) -> list[Section]:
    return [Section("runs", _runs(c)), Section("first difference", _first(c)),
            Section("rooms in the order searched", _rooms(c.a, c.b)),
            Section("failed tasks", [(str(n), a, b, "") for n, (a, b) in enumerate(
                zip_longest(c.failed_a, c.failed_b, fillvalue="-"), start=1)]),
            Section("metrics", [(name, number(a), number(b), delta(a, b))
                                for name, a, b in c.metrics])]


def number(value: Any) -> str:
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return f"{value:.1f}" if abs(value) >= 10 else f"{value:.3g}"
    return str(value)


def delta(a: Any, b: Any) -> str:
    d = difference(a, b)
    if d is None:
        return "" if a == b else "differs"
    if d == 0:
        return "0"
    return ("+" if d > 0 else "") + number(d)


def found(run: Run) -> str:
    s = run.summary
    if s.found_by is not None and s.time_to_find is not None:
        return f"{s.found_by} at {s.time_to_find:.1f} s"
    return s.outcome.replace("_", " ")


def _runs(c: Comparison) -> list[Row]:
    a, b = c.a.summary, c.b.summary
    return [("target", a.target.get("room", "-"), b.target.get("room", "-"), ""),
            ("found by", found(c.a), found(c.b), delta(a.time_to_find, b.time_to_find)),
            ("ended", f"{a.end_time:.1f} s, {rounds(len(a.rounds))}",
             f"{b.end_time:.1f} s, {rounds(len(b.rounds))}", delta(a.end_time, b.end_time))]


def rounds(n: int) -> str:
    return f"{n} round" + ("" if n == 1 else "s")


def decided(pairs: list[Pair]) -> str:
    return ", ".join(f"{agent}->{room} {action}" for agent, room, action in pairs) or "-"


def _round_side(number: int, mine: Any, only: list[Pair]) -> str:
    """What one run decided in the round that differs: the pairs the other did not choose."""
    if mine is None:
        return f"no round {number}"
    return f"t = {mine.t:.1f} s: " + (decided(only) if only else "no pair the other lacks")


def _first(c: Comparison) -> list[Row]:
    rows: list[Row] = []
    d = c.round
    if d is None:
        rows.append(("round", "every round's matching is the same", "", ""))
    else:
        rows.append((f"round {d.number}", _round_side(d.number, d.a, d.only_a),
                     _round_side(d.number, d.b, d.only_b), ""))
    e = c.event
    if e is None:
        rows.append(("event", "the event logs are the same", "", ""))
    else:
        rows.append((f"event line {e.line}", brief(e.a), brief(e.b), _keys(e)))
    return rows


def _keys(e: EventDiff) -> str:
    if e.a is None or e.b is None:
        return "one log ended"
    if e.a["kind"] != e.b["kind"]:
        return "another event"
    keys = e.keys
    return ("differs in " + ", ".join(keys[:4]) + (", ..." if len(keys) > 4 else "")) if keys \
        else ""


def brief(record: dict[str, Any] | None) -> str:
    """``t = 84.0 s uav1 task_started move A.1.2.1``, short (``-`` for none)."""
    if record is None:
        return "- (the log had ended)"
    parts = [f"t = {round(float(record['t']), 3):g} s", str(record.get("robot") or ""),
             record["kind"]]
    parts += [str(record[k]) for k in BRIEF_KEYS if record.get(k) not in (None, "")]
    text = " ".join(p for p in parts if p)
    return text if len(text) <= BRIEF else text[:BRIEF - 3] + "..."


def _rooms(a: Run, b: Run) -> list[Row]:
    ra, rb = a.summary.rooms_searched, b.summary.rooms_searched
    return [(str(n), x, y, "" if x == y else "differs")
            for n, (x, y) in enumerate(zip_longest(ra, rb, fillvalue="-"), start=1)]


def markdown(c: Comparison) -> str:
    """The comparison as Markdown tables (the diff recording's summary panel)."""
    lines = [f"**A**: {c.a.folder} ({c.a.summary.mission}: {c.a.label})  ",
             f"**B**: {c.b.folder} ({c.b.summary.mission}: {c.b.label})", ""]
    for section in sections(c):
        lines += [f"**{section.title}**", "", "| | A | B | B - A |", "|---|---|---|---|"]
        lines += ["| " + " | ".join(cell.replace("|", "/") for cell in row) + " |"
                  for row in section.rows] or ["| - | | | |"]
        lines.append("")
    return "\n".join(lines)
