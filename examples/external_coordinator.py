"""An external coordination algorithm, on the API only: each free robot takes the nearest room
still to search, and a room a robot could not search goes to a robot of another kind.

    astralis serve missions/urban_search.yaml --manual --stepped &
    python examples/external_coordinator.py [--connect tcp://127.0.0.1:5555] [--step 2]

``--manual`` keeps the mission's own assignment rounds out of the way; ``--stepped`` lets
this script move time on, so that the run is reproducible. It stops when the target is found,
the rooms run out or the mission ends, and prints what happened.
"""

from __future__ import annotations

import argparse
import math
from typing import Any

from astralis_des.api import Client

SEARCH = {"uav": "spiral_inward", "ugv": "sneak_peek", "human": "inspect"}


class Nearest:
    """The coordinator's state: rooms to search, what each robot is on, what failed where."""

    def __init__(self, client: Client) -> None:
        self.client = client
        info = client.info()
        self.kinds = {rid: r["type"] for rid, r in info["robots"].items()}
        self.rooms = {room: client.location(room)["location"] for room in info["rooms"]}
        self.pending = sorted(self.rooms)
        self.working: dict[str, tuple[str, int]] = {}  # robot -> (room, search task id)
        self.tried: dict[str, set[str]] = {}  # room -> kinds that failed it
        self.searched: list[str] = []
        self.cursor = client.events(last=1)["next"]

    def tick(self) -> None:
        """Book the searches that ended, then give each free robot its nearest room."""
        news = self.client.events(after=self.cursor, kinds=["task_finished"])
        self.cursor = news["next"]
        for event in news["events"]:
            room, task = self.working.get(event["robot"], (None, None))
            if event["task"] != task or room is None:
                continue
            del self.working[event["robot"]]
            if event["status"] == "succeeded":
                self.searched.append(room)
            else:  # another kind may get there
                self.tried.setdefault(room, set()).add(self.kinds[event["robot"]])
                self.pending.append(room)
        robots = self.client.status()["robots"]
        for rid, robot in robots.items():
            if rid in self.working or robot["state"] != "idle" or robot["queued"]:
                continue
            kind = self.kinds[rid]
            options = [r for r in self.pending if kind not in self.tried.get(r, set())]
            if not options:
                continue
            room = min(options, key=lambda r: math.dist(self.rooms[r][:2], robot["pose"][:2]))
            self.pending.remove(room)
            self.client.enqueue(rid, "move", room, params={"point": "door"})
            task = self.client.enqueue(rid, SEARCH[kind], room)["task"]
            self.working[rid] = (room, task)

    def run(self, step: float, limit: float = 3600.0) -> dict[str, Any]:
        while True:
            status = self.client.status()
            if status["found"] or status["ended"] or status["t"] >= limit:
                return status
            if not self.pending and not self.working:
                return status
            self.tick()
            self.client.step(by=step)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--connect", default="tcp://127.0.0.1:5555")
    parser.add_argument("--step", type=float, default=2.0, help="simulated s per tick")
    args = parser.parse_args()
    with Client(args.connect, timeout=10.0) as client:
        coordinator = Nearest(client)
        status = coordinator.run(args.step)
        found = f"found by {status['found_by']}" if status["found"] else "not found"
        print(f"t = {status['t']:.1f} s: target {found}; rooms searched: "
              f"{', '.join(coordinator.searched) or 'none'}")


if __name__ == "__main__":
    main()
