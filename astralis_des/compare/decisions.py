"""Two runs compared: where they part (the first assignment round whose matching differs, the
first event whose content differs), what each found and when, the rooms in the order they
were searched, failed tasks and the metrics with their difference. Pure functions of two
:class:`~astralis_des.compare.runs.Run`; nothing is printed or written here."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from astralis_des.compare.runs import Round, Run, Value

# mission_start's keys that say which run it is (shown in the header), not what happened
IDENTITY = {"mission_start": ("mission", "seed", "fidelity")}
Pair = tuple[str, str, str]  # agent, room, action


def pairs(round_: Round | None) -> list[Pair]:
    return [] if round_ is None else [(m.agent, m.room, m.action or "-")
                                      for m in round_.matching]


@dataclass(frozen=True)
class RoundDiff:
    """The first round whose matching differs: its number, each run's round (``None``: that
    run had no such round) and the pairs only one of them chose."""

    number: int
    a: Round | None
    b: Round | None

    @property
    def t(self) -> float:
        return min(r.t for r in (self.a, self.b) if r is not None)

    @property
    def only_a(self) -> list[Pair]:
        return [p for p in pairs(self.a) if p not in pairs(self.b)]

    @property
    def only_b(self) -> list[Pair]:
        return [p for p in pairs(self.b) if p not in pairs(self.a)]

    @property
    def rooms(self) -> list[str]:
        """The rooms the two runs assigned differently (A's first)."""
        return list(dict.fromkeys(p[1] for p in self.only_a + self.only_b))


@dataclass(frozen=True)
class EventDiff:
    """The first event whose content differs: its line in ``events.jsonl`` (1-based), each
    run's event there (``None``: that log had ended) and the keys whose values differ."""

    line: int
    a: dict[str, Any] | None
    b: dict[str, Any] | None

    @property
    def t(self) -> float:
        return min(float(e["t"]) for e in (self.a, self.b) if e is not None)

    @property
    def keys(self) -> list[str]:
        if self.a is None or self.b is None:
            return []
        a, b = _content(self.a), _content(self.b)
        return [k for k in dict.fromkeys([*a, *b]) if a.get(k) != b.get(k)]


@dataclass(frozen=True)
class Comparison:
    """Two runs compared (:func:`compare`): where they part (``round``, ``event``; ``None``
    where they do not), each metric of either run with A's and B's value, each run's failed
    tasks as text."""

    a: Run
    b: Run
    round: RoundDiff | None
    event: EventDiff | None
    metrics: list[tuple[str, Any, Any]]  # name, A's, B's (None: the run has none)
    failed_a: list[str]
    failed_b: list[str]

    @property
    def first_time(self) -> float | None:
        """When the runs first part (the earlier of the round's and the event's)."""
        times = [d.t for d in (self.round, self.event) if d is not None]
        return min(times) if times else None


def compare(a: Run, b: Run) -> Comparison:
    """Run ``b`` against run ``a`` (differences are B - A)."""
    return Comparison(a, b, first_round(a, b), first_event(a, b), metrics_of(a, b),
                      failed_tasks(a), failed_tasks(b))


def first_round(a: Run, b: Run) -> RoundDiff | None:
    """The first round (in order) whose matching differs, or that only one run held."""
    ra, rb = a.summary.rounds, b.summary.rounds
    for i in range(max(len(ra), len(rb))):
        one = ra[i] if i < len(ra) else None
        two = rb[i] if i < len(rb) else None
        if sorted(pairs(one)) != sorted(pairs(two)):
            held = one if one is not None else two
            assert held is not None  # i is below the longer list's length
            return RoundDiff(held.round, one, two)
    return None


def _content(record: dict[str, Any]) -> dict[str, Any]:
    skip = IDENTITY.get(record["kind"], ())
    return {k: v for k, v in record.items() if k not in skip}


def first_event(a: Run, b: Run) -> EventDiff | None:
    """The first line of the two event logs whose events differ (mission_start's seed,
    fidelity and mission name aside: the header shows them)."""
    ea, eb = a.events, b.events
    for i in range(max(len(ea), len(eb))):
        one = ea[i] if i < len(ea) else None
        two = eb[i] if i < len(eb) else None
        if one is None or two is None or _content(one) != _content(two):
            return EventDiff(i + 1, one, two)
    return None


def derived(run: Run) -> dict[str, Value]:
    """What any summary gives, for runs whose summary has no ``metrics``."""
    s = run.summary
    return {"found": s.outcome == "found", "time_to_find": s.time_to_find,
            "rooms_searched": len(s.rooms_searched),
            "distance": round(sum(r.distance for r in s.robots.values()), 6),
            "tasks_failed": sum(r.tasks_failed for r in s.robots.values()),
            "robots_faulted": sum(r.faulted for r in s.robots.values()),
            "rounds": len(s.rounds), "end_time": s.end_time}


def metrics_of(a: Run, b: Run) -> list[tuple[str, Any, Any]]:
    """Each metric of either run, the summary's ``metrics`` first in their order, then those
    derived from the summary that they do not name."""
    ma, mb = a.summary.metrics or {}, b.summary.metrics or {}
    da, db = derived(a), derived(b)
    names = list(dict.fromkeys([*ma, *mb, *da]))
    return [(n, ma.get(n, da.get(n)), mb.get(n, db.get(n))) for n in names]


def difference(a: Any, b: Any) -> float | None:
    """B - A for two numbers (not for flags or text, nor where either has none)."""
    if isinstance(a, bool) or isinstance(b, bool):
        return None
    if isinstance(a, int | float) and isinstance(b, int | float):
        return b - a
    return None


def failed_tasks(run: Run) -> list[str]:
    """``ugv1 move A.1.2.3 at 61.2 s: no path``, for each task that ended failed."""
    return [f"{e.get('robot', '?')} {e.get('action', '?')} {e.get('room') or '-'} at "
            f"{float(e['t']):.1f} s: {e.get('message', '')}".rstrip(": ")
            for e in run.events if e["kind"] == "task_finished" and e.get("status") == "failed"]
