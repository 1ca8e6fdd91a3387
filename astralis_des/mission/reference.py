"""``docs/missions.md`` and ``docs/world.md``: every key of a mission file and of a world file,
made from the schemas so they cannot drift.

    astralis schema --markdown -o docs/missions.md
    python tools/world_reference.py                  # docs/world.md

A row per key (dotted path; ``[]`` an item of a list, ``{}`` a value of a map): its type, its
default, what it means (units in the description) and, where the default mission sets it, the
value it has there as an example. A key inside a map whose default is given whole (the weights
per kind) shows the default it really has, from the map's. Then each kind's actions with their
params, and the assignment strategies with the options each reads, from their records.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Protocol

import yaml

from astralis_des.kinds import KINDS
from astralis_des.mission.spec import MissionSpec, StrategyOptions
from astralis_des.plugins import ACTIONS, STRATEGIES
from astralis_des.world.spec import WorldSpec

EXAMPLE = "missions/urban_search.yaml"
INTRO = """# Mission file reference

Generated from the schema (`astralis schema --markdown -o docs/missions.md`; a test checks that
it is up to date). A mission is a YAML file (a regular file of at most 50 MB and 2,000,000
values); `astralis validate FILE` checks one and its world (`docs/worlds.md`) as `astralis run`
does: every start, and every point a `move` command of the timeline goes to, must be on the
site and clear of walls, slabs and obstacles by the robot's body (the error names the nearest
free point). `astralis world rooms WORLD` lists the ids of rooms, segments and doors a mission
can name. Keys are dotted paths: `team[]` is an item of the list `team`
(`timeline[event=fault]` one of its events of that kind), `rooms.set{}` a value of the map
`rooms.set`. The example column is the value in `{example}`,
where it sets the key. Timeline events are told apart by `event`
(`fault`, `recover`, `room_change`, `command`, `cancel`); a command's `params` are the
action's own, listed per kind after this table (any other key is refused), and the assignment
strategies with the options each reads after them.

| key | type | default | what | example |
| --- | --- | --- | --- | --- |
"""
WORLD_EXAMPLE = "worlds/urban_default.yaml"
WORLD_INTRO = """# World file reference

Generated from the schema (`python tools/world_reference.py`; a test checks that it is up to
date; `astralis schema --world` prints the JSON Schema, for editors). A world is a YAML file:
the site, buildings laid out from a few numbers (storeys, segments of rooms along a corridor, a
stairwell with a vehicle lift), search areas (boxes on open ground or in an imported scan), an
interior (the storeys, rooms, corridors, doors and stairs found in an indoor scan or model by
`astralis world import --indoor`, searched like a building's rooms), obstacles and roads. An
imported world also has `source` (what was read) and `geometry` (the files beside it): `astralis
world import` writes those, not a person (how-to: import your site). Room ids read building,
storey, segment and room: `A.2.1.3` is building A, storey 2, segment 1, room 3; `astralis world
rooms WORLD` lists a world's buildings, storeys, segments, rooms and doors, the ids a mission
names. What a world may hold (finite numbers, rooms a robot fits in, at most 10,000 rooms) is in
`docs/worlds.md`. Keys are dotted paths as in the mission reference; the example column is the
value in `{example}`.

| key | type | default | what | example |
| --- | --- | --- | --- | --- |
"""


class StrategyRecord(Protocol):
    """What the reference reads of a registered strategy
    (:class:`astralis_des.assignment.strategies.Strategy`)."""

    @property
    def doc(self) -> str: ...
    @property
    def whole_mission(self) -> bool: ...
    @property
    def options(self) -> tuple[str, ...]: ...


def reference(example: Path | None = None) -> str:
    schema = MissionSpec.model_json_schema()
    defs = schema.get("$defs", {})
    values: Any = {}
    if example is not None and example.is_file():
        values = yaml.safe_load(example.read_text(encoding="utf-8")) or {}
    rows: list[str] = []
    _walk(schema, defs, "", rows, values, set())
    return (INTRO.replace("{example}", EXAMPLE) + "\n".join(rows) + "\n" + action_params()
            + strategies())


def world_reference(example: Path | None = None) -> str:
    """``docs/world.md``: every key of a world file."""
    schema = WorldSpec.model_json_schema()
    values: Any = {}
    if example is not None and example.is_file():
        values = yaml.safe_load(example.read_text(encoding="utf-8")) or {}
    rows: list[str] = []
    _walk(schema, schema.get("$defs", {}), "", rows, values, set())
    return WORLD_INTRO.replace("{example}", WORLD_EXAMPLE) + "\n".join(rows) + "\n"


def strategy_names() -> str:
    return ", ".join(f"`{name}`" for name, _ in STRATEGIES.registered())


def strategies() -> str:
    """The assignment strategies (``assignment.strategy``) and the ``assignment.options`` each
    reads, from their records."""
    records: list[tuple[str, StrategyRecord]] = STRATEGIES.registered()
    out = ["", "## Assignment strategies", "",
           "`assignment.strategy` names one of these (a plug-in may register more:",
           "docs/architecture.md). A round's rooms: a strategy matches the free agents to the",
           "pending rooms of one segment, at most a room an agent, or plans a queue for each agent",
           "over every pending room of the mission at once. Options: the keys of",
           "`assignment.options` it reads (the table after this one).", "",
           "| strategy | rooms a round | options | what |", "| --- | --- | --- | --- |"]
    for name, record in records:
        rooms = "the mission's, queued" if record.whole_mission else "a segment's, one an agent"
        options = ", ".join(f"`{o}`" for o in record.options) or "none"
        out.append(f"| `{name}` | {rooms} | {options} | {_cell(_markdown(record.doc))} |")
    out += ["", "### Options", "",
            "| option | type | default | read by | what |", "| --- | --- | --- | --- | --- |"]
    for option, node in StrategyOptions.model_json_schema()["properties"].items():
        by = ", ".join(f"`{n}`" for n, r in records if option in r.options) or "none"
        what = node.get("description", "").split(": ", 1)[-1]  # without "cbba: "
        out.append(f"| `{option}` | {_type(node, {})} | {_cell(json.dumps(node.get('default')))}"
                   f" | {by} | {_cell(what)} |")
    return "\n".join(out) + "\n"


def _markdown(text: str) -> str:
    return text.replace("``", "`")


def action_params() -> str:
    """Each kind's actions and their params (a timeline command's ``params``), from the
    actions' records."""
    out = ["", "## Actions and their params", "",
           "What each kind can be commanded (`timeline[event=command].action`) and the `params`",
           "it takes. `room`: the command names a room (`move`: or params `x` and `y`).", ""]
    for kind in KINDS:
        out += [f"### {kind}", "", "| action | room | param | type | default | what |",
                "| --- | --- | --- | --- | --- | --- |"]
        for key, spec in ACTIONS.registered():
            if key[0] != kind:
                continue
            room = "required" if spec.room and not spec.point else (
                "or x, y" if spec.room else "none")
            props = spec.fields()
            if not props:
                out.append(f"| `{spec.name}` | {room} | | | | takes no params |")
            for name, node in props.items():
                default = "" if node.get("default") is None else _cell(node["default"])
                out.append(f"| `{spec.name}` | {room} | `{name}` | {_type(node, {})} | "
                           f"{default} | {_cell(node.get('description', ''))} |")
        out.append("")
    return "\n".join(out)


def _resolve(node: dict[str, Any], defs: dict[str, Any]) -> dict[str, Any]:
    if "$ref" in node:
        return defs[node["$ref"].split("/")[-1]]
    return node


def _type(node: dict[str, Any], defs: dict[str, Any]) -> str:
    if "$ref" in node:
        return node["$ref"].split("/")[-1].removesuffix("Spec").lower() or "object"
    if "enum" in node:
        return " \\| ".join(json.dumps(v) for v in node["enum"])
    if "const" in node:
        return json.dumps(node["const"])
    for key in ("anyOf", "oneOf"):
        if key in node:
            return " \\| ".join(_type(n, defs) for n in node[key])
    kind = node.get("type", "any")
    if kind == "array":
        items = node.get("items")
        if isinstance(items, dict) and items:
            return f"list of {_type(items, defs)}"
        prefix = node.get("prefixItems")
        if prefix:
            return "[" + ", ".join(_type(n, defs) for n in prefix) + "]"
        return "list"
    if kind == "object" and isinstance(node.get("additionalProperties"), dict):
        return f"map of {_type(node['additionalProperties'], defs)}"
    limits = [f"{op} {node[k]:g}" for k, op in (("minimum", ">="), ("exclusiveMinimum", ">"),
                                                  ("maximum", "<="), ("exclusiveMaximum", "<"))
              if k in node and abs(node[k]) < 1e6]  # not the sanity bounds of coordinates
    return str(kind) + (f" ({', '.join(limits)})" if limits else "")


def _cell(value: Any) -> str:
    text = json.dumps(value) if not isinstance(value, str) else value
    return text.replace("|", "\\|").replace("\n", " ")


# keys whose string names a registry entry: what the reference says they may be
NAMED = {"assignment.strategy": lambda: f"one of {strategy_names()} (Assignment strategies, "
                                        "below)"}


def _walk(node: dict[str, Any], defs: dict[str, Any], path: str, rows: list[str], example: Any,
          seen: set[str], given: Any = None) -> None:
    """``given``: the default of the object at ``path`` as a whole, where it has one: its
    keys' defaults are taken from it (the map's own defaults only apply when it is set)."""
    node = _resolve(node, defs)
    for name, sub in node.get("properties", {}).items():
        key = f"{path}.{name}" if path else name
        here = example.get(name) if isinstance(example, dict) else None
        what = sub.get("description", "") or _resolve(sub, defs).get("description", "")
        if key in NAMED:
            what = f"{what}; {NAMED[key]()}" if what else NAMED[key]()
        default = json.dumps(sub["default"]) if "default" in sub else (
            "required" if name in node.get("required", []) else "")
        if isinstance(given, dict) and name in given:
            if "default" in sub and sub["default"] != given[name]:
                what = (f"{what}; " if what else "") + (
                    f"{json.dumps(sub['default'])} if `{path}` is given without it")
            default = json.dumps(given[name])
        plain = here is not None and not isinstance(here, dict) and not (
            isinstance(here, list) and any(isinstance(v, dict | list) for v in here))
        shown = _cell(here) if plain else ""
        rows.append(f"| `{key}` | {_type(sub, defs)} | {_cell(default)} | "
                    f"{_cell(' '.join(what.split()))} | {shown} |")
        whole = given[name] if isinstance(given, dict) and name in given else sub.get("default")
        _children(sub, defs, key, rows, here, seen, whole)


def _children(sub: dict[str, Any], defs: dict[str, Any], key: str, rows: list[str],
              here: Any, seen: set[str], given: Any = None) -> None:
    options = [sub] + sub.get("anyOf", []) + sub.get("oneOf", [])
    for option in options:
        ref = option.get("$ref")
        if ref and ref not in seen:
            _walk(option, defs, key, rows, here, seen | {ref}, given)
        elif option.get("type") == "array":
            items = option.get("items", {})
            item = here[0] if isinstance(here, list) and here else None
            for choice in [items] + items.get("anyOf", []) + items.get("oneOf", []):
                if "$ref" in choice and choice["$ref"] not in seen:
                    tag = _resolve(choice, defs).get("properties", {}).get("event", {})
                    where = f"{key}[event={tag['const']}]" if "const" in tag else f"{key}[]"
                    _walk(choice, defs, where, rows, item, seen | {choice["$ref"]})
        elif isinstance(option.get("additionalProperties"), dict):
            value = option["additionalProperties"]
            first = next(iter(here.values()), None) if isinstance(here, dict) and here else None
            if "$ref" in value and value["$ref"] not in seen:
                _walk(value, defs, f"{key}{{}}", rows, first, seen | {value["$ref"]})
