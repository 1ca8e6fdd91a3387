"""``--set KEY=VALUE``: a change to a mission file, by the dotted path of a key.

``KEY`` is a path of the mission file: ``assignment.strategy``, ``assignment.weights.risk.
human``, ``team.0.speed``; a key that holds dots goes in brackets, ``rooms.set[A.1.2.1].risk``
(without them where the file has that key already). ``KEY+=VALUE`` appends to a list
(``timeline+={event: fault, robot: uav2, at: 120}``; a list appends each of its items).
``VALUE`` is read as YAML. The changed mission is checked as a file is, and an error is one
line naming the option: ``--set assignment.strategy=cbbb: no strategy 'cbbb'; did you mean
'cbba'?``.
"""

from __future__ import annotations

import copy
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import yaml

from astralis_des.errors import InputError
from astralis_des.mission.loader import Mission
from astralis_des.yamlio import format_path

Part = str | int
Changes = Mapping[str, Any] | Iterable[str]  # {KEY: value}, or "KEY=VALUE" strings
_PART = re.compile(r"\[([^\]]+)\]|([^.\[\]]+)")
_EXAMPLE = ("KEY is a dotted path such as assignment.weights.risk.human (a key with dots in "
            "brackets: rooms.set[A.1.2.1].risk)")


@dataclass(frozen=True)
class Change:
    """One ``--set``: the path it names, its value, whether it appends, and how it was said."""

    path: tuple[Part, ...]
    value: Any
    append: bool
    said: str  # "KEY=VALUE", for errors

    def error(self, message: str) -> InputError:
        return InputError(message, key=f"--set {self.said}")


def parse_changes(changes: Changes) -> list[Change]:
    """``{KEY: value}`` (values as they are) or ``["KEY=VALUE", ...]`` (values read as YAML)."""
    if isinstance(changes, Mapping):
        return [_change(str(k), v, f"{k}={v}") for k, v in changes.items()]
    parsed = []
    for said in changes:
        key, eq, text = said.partition("=")
        if not eq:
            raise InputError("give KEY=VALUE (e.g. assignment.strategy=cbba)",
                             key=f"--set {said}")
        try:
            value = yaml.safe_load(text)
        except yaml.YAMLError as exc:
            problem = " ".join(str(getattr(exc, "problem", None) or exc).split())
            raise InputError(f"the value is not YAML: {problem}", key=f"--set {said}") from None
        parsed.append(_change(key, value, said))
    return parsed


def _change(key: str, value: Any, said: str) -> Change:
    append = key.endswith("+")
    key = key.removesuffix("+").strip()
    parts: list[Part] = []
    pos = 0
    for match in _PART.finditer(key):
        between = key[pos:match.start()]
        allowed = ("",) if not parts else ((".",) if match.group(2) else ("", "."))
        if between not in allowed:
            raise InputError(_EXAMPLE, key=f"--set {said}")
        word = match.group(1) if match.group(1) is not None else match.group(2)
        parts.append(int(word) if match.group(2) and word.isdigit() else word)
        pos = match.end()
    if not parts or pos != len(key):
        raise InputError(_EXAMPLE, key=f"--set {said}")
    return Change(tuple(parts), value, append, said)


def show_path(path: Iterable[Part]) -> str:
    """A path as ``--set`` spells it: ``rooms.set[A.1.2.1].risk``, ``team.0.speed``."""
    text = ""
    for part in path:
        word = str(part)
        if "." in word:
            text += f"[{word}]"
        else:
            text += f".{word}" if text else word
    return text


def apply_changes(data: dict[str, Any], changes: Iterable[Change]) -> dict[str, Any]:
    """A deep copy of a mission file's ``data`` with each change made, in order."""
    data = copy.deepcopy(data)
    for change in changes:
        _apply(data, change)
    return data


def _apply(data: dict[str, Any], change: Change) -> None:
    node: Any = data
    parts = list(change.path)
    done: list[Part] = []
    while True:
        key, parts = _next_key(node, parts, done, change)
        done.append(key)
        if not parts:
            break
        if isinstance(node, dict) and node.get(key) is None:
            node[key] = {}  # a mapping the file leaves out (rooms.set[R])
        node = node[key]
    if not change.append:
        node[key] = change.value
        return
    target = node.get(key) if isinstance(node, dict) else node[key]
    if target is None and isinstance(node, dict):
        target = node[key] = []
    if not isinstance(target, list):
        raise change.error(f"{show_path(done)} is not a list: += appends to a list")
    target.extend(change.value if isinstance(change.value, list) else [change.value])


def _next_key(node: Any, parts: list[Part], done: list[Part],
              change: Change) -> tuple[Part, list[Part]]:
    """The key of ``node`` that ``parts`` start with, and the parts left: a list takes an
    index; a mapping the longest run of parts that names one of its keys (dots and all)."""
    where = show_path(done) or "the mission"
    if isinstance(node, list):
        index = parts[0]
        if not isinstance(index, int) or not 0 <= index < len(node):
            raise change.error(f"{where} is a list of {len(node)} items: give an index from 0 "
                               f"to {len(node) - 1}" + ("" if change.append else
                                                        ", or append with +="))
        return index, parts[1:]
    if not isinstance(node, dict):
        raise change.error(f"{where} is a value, not a mapping of keys")
    for n in range(len(parts), 1, -1):
        joined = ".".join(str(p) for p in parts[:n])
        if joined in node:
            return joined, parts[n:]
    return str(parts[0]), parts[1:]


def changed_mission(mission: Mission, changes: Iterable[Change]) -> Mission:
    """``mission`` with ``changes`` made, checked as a file is (any key); an error is that of
    the ``--set`` it concerns."""
    changes = list(changes)
    if not changes:
        return mission
    return check_changed(mission, apply_changes(mission.spec.model_dump(mode="json"), changes),
                         changes)


def check_changed(mission: Mission, data: dict[str, Any], changes: list[Change]) -> Mission:
    """The mission of ``data`` (its file's data changed by ``changes``), or the one-line
    error of the change the first problem concerns."""
    try:
        return mission.with_changes(**data)
    except InputError as exc:
        raise blame(changes, exc.key or "", exc.message) from None


def blame(changes: list[Change], key: str, message: str) -> InputError:
    """``message``, about the file's ``key``, as the error of the last change that touched
    it (the last change if none did)."""
    culprit = next((c for c in reversed(changes) if _overlaps(format_path(c.path), key)),
                   changes[-1])
    return culprit.error(message if not key or key == format_path(culprit.path)
                         else f"{key}: {message}")


def _overlaps(a: str, b: str) -> bool:
    """Is one key path within the other (``team[0]`` and ``team[0].speed``)?"""
    short, long = sorted((a, b), key=len)
    return long.startswith(short) and long[len(short):][:1] in ("", ".", "[")
