"""What a chat line may name: the served mission's robots, rooms and segments (its ``info``),
each looked up with a "did you mean" for a typo."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from astralis_des.errors import suggest

UNITS = {"": 1.0, "s": 1.0, "m": 60.0, "min": 60.0, "h": 3600.0}


class ChatError(Exception):
    """A line the chat cannot use; ``str(error)`` is one line saying why and what would do."""


@dataclass(frozen=True)
class Team:
    robots: dict[str, str]  # id -> kind
    actions: dict[str, tuple[str, ...]]  # id -> the actions its kind has
    rooms: tuple[str, ...]
    segments: dict[str, tuple[str, ...]]  # segment -> its rooms

    @classmethod
    def from_info(cls, info: dict[str, Any]) -> Team:
        """From the reply to the API's ``info``."""
        robots = info.get("robots", {})
        return cls(robots={rid: str(r["type"]) for rid, r in robots.items()},
                   actions={rid: tuple(r.get("actions", ())) for rid, r in robots.items()},
                   rooms=tuple(info.get("rooms", ())),
                   segments={sid: tuple(rooms)
                             for sid, rooms in info.get("segments", {}).items()})

    def kinds(self) -> set[str]:
        return set(self.robots.values())

    def robot(self, word: str) -> str:
        if word in self.robots:
            return word
        raise ChatError(f"no robot '{word}'; {suggest(word, self.robots)}")

    def room(self, word: str) -> str:
        found = _folded(word, self.rooms)
        if found is None:
            raise ChatError(f"no room '{word}'; {suggest(word.upper(), self.rooms)}")
        return found

    def segment(self, word: str) -> str:
        found = _folded(word, self.segments)
        if found is None:
            raise ChatError(f"no segment '{word}'; {suggest(word.upper(), self.segments)}")
        return found

    def is_room(self, word: str) -> bool:
        return _folded(word, self.rooms) is not None


def _folded(word: str, names: Any) -> str | None:
    """``a.2.1.3`` is ``A.2.1.3``: room and segment ids regardless of case."""
    if word in names:
        return word
    lower = word.lower()
    return next((name for name in names if name.lower() == lower), None)


def number(word: str) -> float | None:
    """A finite number, or None if the word is not one."""
    try:
        value = float(word)
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def seconds(word: str, what: str) -> float:
    """``30``, ``30s``, ``2m``, ``1.5h``: simulated seconds."""
    text = word.lower()
    unit = next((u for u in sorted(UNITS, key=len, reverse=True) if u and text.endswith(u)), "")
    value = number(text[: len(text) - len(unit)])
    if value is None:
        raise ChatError(f"{what}: '{word}' is not a time like 30, 30s, 2m or 1h")
    return value * UNITS[unit]


def param_value(text: str) -> float | str:
    """A ``key=value`` word's value: a number if it reads as one."""
    value = number(text)
    return value if value is not None else text
