"""Hypothesis strategies for what users write: world, mission and study files, and API requests.

Three sources, mixed:

- **sane documents** (:func:`worlds`, :func:`missions`, :func:`studies`): small worlds and
  missions that refer to each other correctly, so that most of them run to a result;
- **schema documents** (:func:`from_schema`): anything the JSON Schema of ``astralis schema``
  allows, field by field (it follows the schema as it changes);
- **mutations** (:func:`mutated`, :func:`serialised`): a key deleted, a value of another type, an
  extreme number, a string too long, a value nested thousands deep, an unknown key; then the
  YAML text cut, spliced with YAML's own syntax, aliased into a bomb, or made invalid UTF-8;
- **bad values in their place** (:func:`world_values`, :func:`bad_points`): NaN, infinite,
  negative or tiny sizes and origins, rooms smaller than a robot, a building off the site,
  and starts and move commands inside a wall, a tree or a closed space, or off the site;
- **output paths** (:func:`output_paths`): nested, with a trailing slash, accents and spaces,
  a symbolic link, the case's own folder, and ones that cannot be written (under a file, a
  file, a name too long, ``/proc``).

``hypothesis-jsonschema`` would give the schema part, but its 0.23 does not run on Hypothesis
6.1xx (``'many' object has no attribute 'more'``); the schema here uses a dozen keywords.
"""

from __future__ import annotations

import copy
import functools
import json
import re
from typing import Any

import yaml
from hypothesis import strategies as st

# -- JSON Schema -> strategy --------------------------------------------------------------------
Schema = dict[str, Any]


def from_schema(schema: Schema) -> st.SearchStrategy[Any]:
    """Values the schema allows (with small sizes); ``$ref`` is looked up in its ``$defs``."""
    return _strategy(schema, schema.get("$defs", {}))


def _strategy(schema: Schema, defs: dict[str, Schema]) -> st.SearchStrategy[Any]:
    if "$ref" in schema:
        name = schema["$ref"].rsplit("/", 1)[-1]
        return st.deferred(lambda: _strategy(defs[name], defs))
    for key in ("anyOf", "oneOf"):
        if key in schema:
            return st.one_of([_strategy(s, defs) for s in schema[key]])
    if "const" in schema:
        return st.just(schema["const"])
    if "enum" in schema:
        return st.sampled_from(schema["enum"])
    kind = schema.get("type")
    if isinstance(kind, list):
        return st.one_of([_strategy({**schema, "type": k}, defs) for k in kind])
    return _TYPES.get(kind, lambda s, d: json_values())(schema, defs)


def _object(schema: Schema, defs: dict[str, Schema]) -> st.SearchStrategy[Any]:
    props: dict[str, Schema] = schema.get("properties", {})
    if not props:
        extra = schema.get("additionalProperties", True)
        values = _strategy(extra, defs) if isinstance(extra, dict) else json_values()
        return st.dictionaries(names(), values, max_size=3)
    required = set(schema.get("required", ()))
    return st.fixed_dictionaries(
        {k: _strategy(v, defs) for k, v in props.items() if k in required},
        optional={k: _strategy(v, defs) for k, v in props.items() if k not in required})


def _array(schema: Schema, defs: dict[str, Schema]) -> st.SearchStrategy[Any]:
    if "prefixItems" in schema:
        return st.tuples(*[_strategy(s, defs) for s in schema["prefixItems"]]).map(list)
    low = schema.get("minItems", 0)
    items = _strategy(schema.get("items", {}), defs)
    return st.lists(items, min_size=low, max_size=schema.get("maxItems", low + 3))


def _bounds(schema: Schema, step: float) -> tuple[float | None, float | None]:
    low = schema.get("minimum", schema.get("exclusiveMinimum"))
    high = schema.get("maximum", schema.get("exclusiveMaximum"))
    if "exclusiveMinimum" in schema:
        low = low + step
    if "exclusiveMaximum" in schema:
        high = high - step
    return low, high


def _integer(schema: Schema, _defs: dict[str, Schema]) -> st.SearchStrategy[Any]:
    low, high = _bounds(schema, 1)
    low = int(low) if low is not None else -1000
    return st.integers(low, int(high) if high is not None else low + 1000)


def _number(schema: Schema, _defs: dict[str, Schema]) -> st.SearchStrategy[Any]:
    low, high = _bounds(schema, 1e-6)
    low = -1e4 if low is None else low
    return st.floats(low, 1e4 + max(low, 0) if high is None else high,
                     allow_nan=False, allow_infinity=False)


def _string(schema: Schema, _defs: dict[str, Schema]) -> st.SearchStrategy[Any]:
    if "pattern" in schema:
        return st.from_regex(schema["pattern"], fullmatch=True).filter(lambda s: len(s) < 40)
    return st.text(max_size=min(schema.get("maxLength", 12), 12))


_TYPES = {
    "object": _object, "array": _array, "integer": _integer, "number": _number,
    "string": _string, "boolean": lambda s, d: st.booleans(), "null": lambda s, d: st.none(),
}


# -- plain JSON and names -----------------------------------------------------------------------
def names() -> st.SearchStrategy[str]:
    return st.from_regex(r"[a-z][a-z0-9_]{0,8}", fullmatch=True)


EXTREMES: tuple[Any, ...] = (
    0, -1, -0.0, 1e308, -1e308, 10**30, 2**63, 1e-320, float("nan"), float("inf"),
    float("-inf"), "", " ", "\x00", "é", "\u202e", "..", "/", "~", "NaN", "1e999", True, False,
    None, [], {}, [[]], {"": None})


def extremes() -> st.SearchStrategy[Any]:
    """One of :data:`EXTREMES`, a fresh copy: a mutation changes lists and dicts in place, and
    a shared one would make the next example differ (Hypothesis: FlakyStrategyDefinition)."""
    return st.sampled_from(EXTREMES).map(copy.deepcopy)


def json_values() -> st.SearchStrategy[Any]:
    """Any JSON-like value, small: what a careless hand or a broken generator writes."""
    leaves = st.one_of(st.none(), st.booleans(), st.integers(-10**6, 10**6),
                       st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=12),
                       extremes())
    return st.recursive(leaves, lambda inner: st.one_of(
        st.lists(inner, max_size=3), st.dictionaries(names(), inner, max_size=3)),
        max_leaves=8)


# -- sane documents ----------------------------------------------------------------------------
@st.composite
def worlds(draw: st.DrawFn) -> dict[str, Any]:
    """A small world of one or two buildings (each 1-2 floors, 1-2 rooms a segment)."""
    buildings = []
    for i, letter in enumerate(draw(st.sampled_from(["A", "A", "AB", "C", "HQ"]).map(
            lambda s: [s] if s in ("HQ",) else list(s)))):
        building: dict[str, Any] = {
            "id": letter, "origin": [20 + 45 * i, 20],
            "floors": draw(st.integers(1, 2)),
            "segments": [{"side": side, "rooms": draw(st.integers(1, 2))}
                         for side in draw(st.sampled_from([["north"], ["south"],
                                                           ["north", "south"]]))]}
        if draw(st.booleans()):
            building["room_size"] = [draw(st.sampled_from([3.0, 4.0, 5.0])),
                                     draw(st.sampled_from([5.0, 7.0]))]
        if draw(st.integers(0, 4)) == 0:
            building["stairs_passable_by"] = draw(st.lists(
                st.sampled_from(["uav", "ugv", "human"]), unique=True, min_size=1))
        buildings.append(building)
    world: dict[str, Any] = {"name": draw(names()), "site": {"size": [110, 70]},
                             "buildings": buildings}
    if draw(st.booleans()):
        world["obstacles"] = [{"kind": "tree", "center": [10, 60], "size": [1, 1, 6]}]
    if draw(st.booleans()):
        world["roads"] = [{"start": [0, 8], "end": [110, 8], "width": 6}]
    return world


BAD_NUMBERS = (float("nan"), float("inf"), float("-inf"), -1.0, 0.0, 1e-9, 1e300)


@st.composite
def world_values(draw: st.DrawFn, world: dict[str, Any]) -> dict[str, Any]:
    """``world`` with a bad value a hand or a converter writes: a NaN, infinite, negative, zero
    or tiny size or origin, rooms smaller than a robot (or just big enough), walls thicker
    than the rooms, a building off the site."""
    world = copy.deepcopy(world)
    building = world["buildings"][0]
    bad = draw(st.sampled_from(BAD_NUMBERS))
    how = draw(st.sampled_from(["origin", "site", "room", "walls", "off_site", "obstacle",
                                "height"]))
    if how == "origin":
        building["origin"][draw(st.integers(0, 1))] = bad
    elif how == "site":
        world["site"]["size"][draw(st.integers(0, 1))] = bad
    elif how == "room":  # 1.21 m holds the Husky (1.01 m) inside 0.2 m walls: it runs
        width = draw(st.sampled_from([1e-9, 0.5, 1.2, 1.21, 1.5]))
        building["room_size"] = [width, draw(st.sampled_from([1e-9, 2.0, 7.0]))]
        building["door_width"] = min(0.9, width / 2)
    elif how == "walls":
        building["wall_thickness"] = draw(st.sampled_from([1e-9, 3.0, 10.0, bad]))
    elif how == "off_site":
        building["origin"] = [draw(st.sampled_from([-10.0, 100.0, 1e6])), 20]
    elif how == "obstacle":
        world["obstacles"] = [{"kind": "tree", "center": [10, bad], "size": [1, 1, 6]}
                              if draw(st.booleans()) else
                              {"kind": "car", "center": [10, 60], "size": [bad, 1, 1.5]}]
    else:
        building["floor_height"] = bad
    return world


def bad_points(world: dict[str, Any]) -> list[list[float]]:
    """Points a robot cannot stand at in a sane world: in a building's south wall, on its
    corner, in the tree, in the closed space beside the lobby, off the site."""
    x, y = world["buildings"][0]["origin"]
    points = [[x + 5.0, y, 0.0], [x, y, 0.0], [x + 5.0, y + 0.1, 0.0], [-3.0, 12.0, 0.0],
              [200.0, 12.0, 0.0], [5.0, 1e5, 0.0], [5.0, -0.5, 0.0]]
    if "obstacles" in world:
        points.append([10.0, 60.0, 0.0])
    return points


def rooms_of(world: dict[str, Any]) -> list[str]:
    """Room ids of a sane world: building.floor.segment.room."""
    out = []
    for b in world["buildings"]:
        for floor in range(1, b["floors"] + 1):
            for s, seg in enumerate(b["segments"], 1):
                out += [f"{b['id']}.{floor}.{s}.{r}" for r in range(1, seg["rooms"] + 1)]
    return out


@st.composite
def missions(draw: st.DrawFn, world: dict[str, Any],
             world_file: str = "world.yaml") -> dict[str, Any]:
    """A mission of a few robots on ``world``, with events and settings that refer to it."""
    rooms = rooms_of(world)
    kinds = draw(st.lists(st.sampled_from(["uav", "ugv", "human"]), min_size=1, max_size=4))
    team = []
    for i, kind in enumerate(kinds):
        member: dict[str, Any] = {"id": f"{kind}{i + 1}", "kind": kind,
                                  "start": [5 + 3 * i, 12 + draw(st.integers(0, 4)), 0]}
        if draw(st.integers(0, 5)) == 0:
            member["speed"] = draw(st.floats(0.3, 4.0))
        if kind != "human" and draw(st.integers(0, 5)) == 0:
            member["sensors"] = {"lidar": {"beams": draw(st.integers(8, 360))}}
        team.append(member)
    buildings = [b["id"] for b in world["buildings"]]
    mission: dict[str, Any] = {
        "name": draw(names()), "world": world_file, "seed": draw(st.integers(0, 2**32)),
        "fidelity": draw(st.sampled_from(["kinematic"] * 9 + ["physics"])),
        "time_limit": draw(st.sampled_from([60, 300, 600])),
        "team": team,
        "assignment": {"strategy": draw(st.sampled_from(["mixed", "naive", "greedy"])),
                       "search": draw(st.lists(st.sampled_from(buildings), min_size=1,
                                               max_size=2, unique=True))}}
    if draw(st.booleans()):
        mission["target"] = {"room": draw(st.sampled_from(rooms)),
                              "avatar": {"activity": draw(st.sampled_from(
                                  ["sitting", "laying", "patrolling", "idle"]))}}
    if draw(st.booleans()):
        mission["rooms"] = {"set": {draw(st.sampled_from(rooms)): {
            "risk": draw(st.floats(0, 1)), "messiness": draw(st.floats(0, 1))}}}
    if draw(st.integers(0, 3)) == 0:
        robot = draw(st.sampled_from([m["id"] for m in team]))
        mission["timeline"] = draw(st.lists(st.sampled_from([
            {"at": 5, "event": "fault", "robot": robot},
            {"at": 20, "event": "recover", "robot": robot},
            {"at": 3, "event": "room_change", "room": rooms[0], "risk": 0.9},
            {"at": 1, "event": "command", "robot": robot, "action": "observe",
             "room": rooms[-1]}]), min_size=1, max_size=3))
    if draw(st.integers(0, 4)) == 0:
        mission["assignment"]["auto"] = False
    if draw(st.integers(0, 5)) == 0:  # a start inside a solid or off the site
        draw(st.sampled_from(team))["start"] = draw(st.sampled_from(bad_points(world)))
    if draw(st.integers(0, 7)) == 0:  # a move to such a point
        x, y, z = draw(st.sampled_from(bad_points(world)))
        mission.setdefault("timeline", []).append(
            {"at": 2, "event": "command", "robot": team[0]["id"], "action": "move",
             "params": {"x": x, "y": y, "z": z}})
    return mission


@st.composite
def studies(draw: st.DrawFn, mission_file: str = "mission.yaml") -> dict[str, Any]:
    """A small study of a mission file: an assignment study or one of whole missions."""
    study: dict[str, Any] = {"name": draw(names()), "mission": mission_file,
                             "seed": draw(st.integers(0, 100)),
                             "scenarios": draw(st.integers(1, 2)),
                             "evaluate": draw(st.sampled_from(["assignment", "mission"]))}
    if draw(st.booleans()):
        study["vary"] = {"strategy": draw(st.lists(st.sampled_from(["naive", "mixed", "greedy"]),
                                                   min_size=1, max_size=2, unique=True))}
    if draw(st.booleans()):
        study["draw"] = {"positions": {"type": "outdoor", "radius": draw(st.integers(1, 20))}}
    if draw(st.booleans()):
        study["set"] = {"fidelity": "kinematic"}
    return study


# -- mutations -----------------------------------------------------------------------------------
NEST = "@@NEST{}@@"  # a placeholder the serialiser expands to a value nested N deep


def _paths(doc: Any, path: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    out = [path]
    if isinstance(doc, dict):
        for k, v in doc.items():
            out += _paths(v, (*path, k))
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            out += _paths(v, (*path, i))
    return out


def _at(doc: Any, path: tuple[Any, ...]) -> Any:
    for part in path:
        doc = doc[part]
    return doc


def _long_string() -> st.SearchStrategy[str]:
    return st.sampled_from([201, 256, 4096, 70_000, 1_000_000]).map(lambda n: "n" * n)


def _replacement(draw: st.DrawFn, old: Any) -> Any:
    how = draw(st.sampled_from(["junk", "extreme", "nest", "long", "retype"]))
    if how == "junk":
        return draw(json_values())
    if how == "extreme":
        return draw(extremes())
    if how == "nest":
        return NEST.format(draw(st.sampled_from([2, 40, 63, 64, 65, 200, 5000])))
    if how == "long":
        return draw(_long_string())
    if isinstance(old, bool | int | float):
        return str(old)
    if isinstance(old, str):
        return [old]
    return json.dumps(old)


@st.composite
def mutated(draw: st.DrawFn, doc: Any, max_changes: int = 3) -> Any:
    """``doc`` with up to ``max_changes`` random changes (none, a third of the time)."""
    doc = json.loads(json.dumps(doc))
    for _ in range(draw(st.sampled_from([0, 0, 1, 1, 2, max_changes]))):
        path = draw(st.sampled_from(_paths(doc)))
        if not path:
            doc = _replacement(draw, doc) if draw(st.integers(0, 9)) == 0 else doc
            continue
        parent, key = _at(doc, path[:-1]), path[-1]
        action = draw(st.sampled_from(["replace", "replace", "delete", "add"]))
        if action == "delete":
            del parent[key]
        elif action == "add" and isinstance(parent, dict):
            parent[draw(names())] = draw(json_values())
        elif action == "add":
            parent.append(json.loads(json.dumps(parent[key])))
        else:
            parent[key] = _replacement(draw, parent[key])
    return doc


_SPLICES = (":", ": ", "- ", "[", "]", "{", "}", "&a ", "*a", "*b", "!!python/object:os.system ",
            "!!binary ", "\t", "%YAML 1.1\n", "---\n", "...\n", "'", '"', "\x00", "\ufeff", "? ",
            "|\n", "<<: *a\n", "\\", "#", "\n  ", "0x", "~")
BOMB = ("a: &a [x, x, x, x, x, x, x, x, x]\nb: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a]\n"
        "c: &c [*b, *b, *b, *b, *b, *b, *b, *b, *b]\nd: &d [*c, *c, *c, *c, *c, *c, *c, *c, *c]\n"
        "e: &e [*d, *d, *d, *d, *d, *d, *d, *d, *d]\nf: &f [*e, *e, *e, *e, *e, *e, *e, *e, *e]\n")


def _expand_nests(text: str) -> str:
    return re.sub(r"""["']?@@NEST(\d+)@@["']?""",
                  lambda m: "[" * int(m.group(1)) + "1" + "]" * int(m.group(1)), text)


@st.composite
def serialised(draw: st.DrawFn, doc: Any) -> bytes:
    """``doc`` as the bytes of a file: YAML (block or flow) or JSON, sometimes broken as text."""
    style = draw(st.sampled_from(["block", "flow", "json"]))
    if style == "json":
        text = json.dumps(doc, indent=draw(st.sampled_from([None, 2])))
    else:
        text = yaml.dump(doc, Dumper=yaml.CSafeDumper, default_flow_style=style == "flow",
                         sort_keys=False, allow_unicode=True, width=2**31 - 1)
    text = _expand_nests(text)
    damage = draw(st.sampled_from(["none"] * 12 + ["cut", "splice", "bomb", "bytes", "empty"]))
    if damage == "cut":
        text = text[:draw(st.integers(0, len(text)))]
    elif damage == "splice":
        at = draw(st.integers(0, len(text)))
        text = text[:at] + draw(st.sampled_from(_SPLICES)) + text[at:]
    elif damage == "bomb":
        text = BOMB + text
    elif damage == "empty":
        text = draw(st.sampled_from(["", "\n", "# nothing\n", "---\n", "null\n", "[]\n", "42\n"]))
    data = text.encode("utf-8")
    if damage == "bytes":
        at = draw(st.integers(0, len(data)))
        data = data[:at] + draw(st.binary(min_size=1, max_size=4)) + data[at:]
    return data


# -- whole cases ---------------------------------------------------------------------------------
def output_paths() -> st.SearchStrategy[str]:
    """The ``--out`` of a case: ``out`` three times in four, else one of ``OUTPUT_PATHS``."""
    from fuzzing.cases import OUTPUT_PATHS

    return st.one_of(st.just("out"), st.just("out"), st.just("out"),
                     st.sampled_from(OUTPUT_PATHS))


@functools.cache
def _schema(model: str) -> st.SearchStrategy[Any]:
    """Documents the JSON Schema of ``astralis schema`` (``--world``) allows."""
    from astralis_des.mission.spec import MissionSpec
    from astralis_des.world.spec import WorldSpec

    return from_schema({"mission": MissionSpec, "world": WorldSpec}[model].model_json_schema())


def _plain(doc: Any) -> bytes:
    return yaml.dump(doc, Dumper=yaml.CSafeDumper, sort_keys=False).encode()


@st.composite
def mission_cases(draw: st.DrawFn) -> Any:
    """A world and a mission on it: mostly sane, a fifth anything the schema allows, then
    mutated and serialised; a sixth of the worlds broken too."""
    from fuzzing.cases import Case

    world = draw(worlds())
    if draw(st.integers(0, 4)) == 0:
        mission = {**draw(_schema("mission")), "world": "world.yaml"}
        mission.setdefault("assignment", {})["search"] = [b["id"] for b in world["buildings"]]
    else:
        mission = draw(missions(world))
    if draw(st.integers(0, 19)) == 0:
        world_bytes = draw(serialised(draw(_schema("world"))))
    elif draw(st.integers(0, 9)) == 0:
        world_bytes = draw(serialised(draw(mutated(world))))
    elif draw(st.integers(0, 7)) == 0:
        world_bytes = _plain(draw(world_values(world)))
    else:
        world_bytes = _plain(world)
    return Case(draw(serialised(draw(mutated(mission)))), world_bytes,
                stale=draw(st.booleans()), recording=draw(st.integers(0, 9)) == 0,
                out=draw(output_paths()))


@st.composite
def study_cases(draw: st.DrawFn) -> Any:
    """A sane kinematic mission on a sane world, and a study of it, mutated and serialised."""
    from fuzzing.cases import Case

    world = draw(worlds())
    mission = {**draw(missions(world)), "fidelity": "kinematic", "time_limit": 300}
    return Case(_plain(mission), _plain(world), draw(serialised(draw(mutated(draw(studies()))))),
                stale=draw(st.booleans()), out=draw(output_paths()))


@functools.cache
def _op_args(name: str) -> st.SearchStrategy[Any]:
    from astralis_des.api.ops import OPS

    return from_schema(OPS.get(name).args.model_json_schema())


@st.composite
def requests(draw: st.DrawFn) -> list[bytes]:
    """The frames of one API request: an operation with arguments its schema allows (then
    mutated), or junk a careless client sends; at most ZeroMQ's hard limit (above it the
    server drops the connection, by design: ``test_api_safety.py``)."""
    from astralis_des.api.ops import OPS
    from astralis_des.api.protocol import HARD_LIMIT

    ops = sorted(name for name in OPS if name != "shutdown")
    how = draw(st.sampled_from(["op"] * 6 + ["junk", "bytes", "frames"]))
    if how == "bytes":
        return [draw(st.binary(max_size=200))]
    if how == "frames":
        return [b'{"op": "info"}', draw(st.binary(max_size=20))]
    if how == "junk":
        doc = draw(json_values())
    else:
        name = draw(st.sampled_from(ops))
        args = draw(_op_args(name))
        doc = draw(mutated({"op": name, "id": draw(st.integers(0, 10**6)), **args}, 2))
    text = _expand_nests(json.dumps(doc, allow_nan=True))
    return [text.encode("utf-8")[:HARD_LIMIT]]
