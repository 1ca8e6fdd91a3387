"""Large generated worlds and missions, for the limits' tests and ``tools/bench/bench_world.py``:
a world of N rooms (buildings of 5 storeys of 4 segments of 25 rooms) and a mission of N
scheduled timeline events."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

ROOMS_PER_BUILDING = 500  # 5 storeys x 4 segments x 25 rooms
FLOORS, SEGMENT_ROOMS = 5, 25
FOOTPRINT = (4.0 + 2 * SEGMENT_ROOMS * 4.0 + 4.0, 7.0 + 2.5 + 7.0)  # m: the defaults' plan
GAP = 12.0  # m of open ground round each building
COLUMNS = 4


def big_world(rooms: int) -> dict[str, Any]:
    """A world of ``rooms`` rooms (a multiple of 500): a grid of identical buildings."""
    if rooms % ROOMS_PER_BUILDING:
        raise ValueError(f"rooms must be a multiple of {ROOMS_PER_BUILDING}")
    count = rooms // ROOMS_PER_BUILDING
    rows = -(-count // COLUMNS)
    step_x, step_y = FOOTPRINT[0] + 2 * GAP, FOOTPRINT[1] + 2 * GAP
    buildings = [{
        "id": f"B{i + 1}", "origin": [GAP + (i % COLUMNS) * step_x, GAP + (i // COLUMNS) * step_y],
        "floors": FLOORS,
        "segments": [{"side": side, "rooms": SEGMENT_ROOMS}
                     for side in ("north", "north", "south", "south")]}
        for i in range(count)]
    return {"name": f"big_{rooms}",
            "site": {"size": [min(count, COLUMNS) * step_x, rows * step_y]},
            "buildings": buildings,
            "obstacles": [{"kind": "tree", "center": [GAP / 2, GAP / 2], "size": [1, 1, 6]}]}


def write_big_world(path: Path, rooms: int) -> Path:
    path.write_text(yaml.safe_dump(big_world(rooms), sort_keys=False), encoding="utf-8")
    return path


def write_timeline_mission(path: Path, world: Path, events: int) -> Path:
    """A mission on ``world`` (the default one, or any with a room A.1.1.1 and A.1.1.2) with
    ``events`` scheduled events of every kind, written a line each as a person would."""
    kinds = ("fault", "recover", "room_change", "command", "cancel")
    lines = [f"name: timeline_{events}", f"world: {world}", f"time_limit: {events + 10}",
             "team:", "  - {id: uav1, kind: uav, start: [90, 60, 0]}",
             "  - {id: op1, kind: human, start: [96, 66, 0]}", "timeline:"]
    for i in range(events):
        kind = kinds[i % len(kinds)]
        if kind == "room_change":
            lines.append(f"  - {{at: {i * 0.5:g}, event: room_change, room: A.1.1.2, risk: 0.5}}")
        elif kind == "command":
            lines.append(f"  - {{at: {i * 0.5:g}, event: command, robot: op1, action: move, "
                         f"params: {{x: {90 + i % 7}, y: 60}}}}")
        else:
            lines.append(f"  - {{at: {i * 0.5:g}, event: {kind}, robot: uav1}}")
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path
