"""Sensor benchmark on the default world: camera captures, lidar scans, rays started inside.

    python tools/bench/bench_sensors.py [--repeat 200]

Measured in one run, on this machine, each figure the median over ``--repeat`` calls:
- ``Camera.capture()`` (TinyRenderer) at 320 x 240 and 160 x 120, 1.5 m up in front of
  building A, looking at it (RGB, metric depth and segmentation);
- one 360-beam ``Lidar2D.scan()`` (goal < 1 ms) in building A's ground-floor corridor and
  outdoors between the buildings (near parked vehicles and lamp posts), beside the same beams
  as one full-length ``rayTestBatch`` against every body (Bullet alone);
- the same scan on open ground from a Husky with its rays starting at its centre (inside its
  mesh hulls) against starting 0.6 m out, and the same for a 0.4 m box body.

- one 3-D lidar sweep (16 channels x 1,800 azimuths, 100 m; goal: median <= 15 ms and at
  least 3x faster than Bullet) in building A's corridor and in a second-floor room, beside
  the same beams as full-length ``rayTestBatch`` calls (Bullet alone);
- the pose sensors (GNSS, barometer, magnetometer on both UAVs and the UGV, ``--missions``
  kinematic missions of the default mission, seeds 0..N-1): the missions' wall time with them
  and without, in one process, alternating (goal: <= 5% more), the first pass (the open sky
  over new grid cells) and again (kept on the world).

Each world-dependent figure is given for the world as ``PhysicsClient`` builds it and with
every solid present: PyBullet keeps at most 16 shapes in one ``createCollisionShapeArray``,
so a single compound body holds only the first 16 of the world's solids.
"""

from __future__ import annotations

import argparse
import logging
import statistics
import sys
import time
from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from astralis_des.physics.client import PhysicsClient  # noqa: E402
from astralis_des.physics.husky import Husky  # noqa: E402
from astralis_des.physics.sensors import Camera, Intrinsics, Lidar2D  # noqa: E402
from astralis_des.world.build import load_world  # noqa: E402
from astralis_des.world.model import World  # noqa: E402

CORRIDOR = (72.0, 78.25, 0.5)
OUTDOORS = (105.0, 75.0, 0.5)
OPEN_GROUND = (30.0, 30.0)  # nothing within 30 m: a scan's cost is the rays' own
FACING_A = (50.0, 78.25, 1.5)


def median_ms(call: Callable[[], Any], repeat: int) -> float:
    call()  # warm-up
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        call()
        times.append(time.perf_counter() - t0)
    return statistics.median(times) * 1e3


def client_for(world: World) -> tuple[PhysicsClient, int]:
    """A client on the world, and how many solids its static bodies hold."""
    client = PhysicsClient(world, 1 / 240, 4, 20)
    held = sum(len(client.call("getCollisionShapeData", body, -1)) for body in client.static)
    return client, held


def measure(world: World, repeat: int) -> None:
    client, held = client_for(world)
    rng = np.random.default_rng(0)
    print(f"default world ({held} of {len(world.solids)} solids):")
    viewer = client.add_box(FACING_A, (0.4, 0.4, 0.4))
    for width, height in ((320, 240), (160, 120)):
        camera = Camera(client, viewer, Intrinsics(width, height, 60.0))
        print(f"  camera capture {width} x {height}, TinyRenderer: "
              f"{median_ms(camera.capture, max(repeat // 4, 10)):.1f} ms")
    for name, at in (("corridor of A", CORRIDOR), ("outdoors", OUTDOORS)):
        lidar = Lidar2D(client, client.add_box(at, (0.4, 0.4, 0.4)), rng=rng)
        hits = int((lidar.scan().hit_ids >= 0).sum())
        centre, directions = lidar._frame()
        starts = (centre + lidar.start_offset * directions).tolist()
        ends = (centre + lidar.range_max * directions).tolist()
        ours = median_ms(lidar.scan, repeat)
        bullet = median_ms(partial(client.call, "rayTestBatch", starts, ends), repeat)
        print(f"  lidar 360 beams, {name} ({hits} returns): {ours:.3f} ms (goal < 1 ms); "
              f"Bullet alone {bullet:.3f} ms ({bullet / ours:.1f}x)")
    client.close()


def inside_the_body(world: World, repeat: int) -> None:
    client, _ = client_for(world)
    husky = Husky(client, np.array([OPEN_GROUND[0], OPEN_GROUND[1], 0.0]))
    client.step(30)
    box = client.add_box((OPEN_GROUND[0], OPEN_GROUND[1] - 3.0, 0.5), (0.4, 0.4, 0.4))
    rng = np.random.default_rng(0)
    logging.getLogger("astralis_des.physics.sensors").setLevel(logging.ERROR)  # inside on purpose
    print("rays started inside the body against outside it (360 beams, open ground):")
    for name, body, mount, outside in (("Husky", husky.body, (0.0, 0.0, 0.1), 0.6),
                                       ("0.4 m box", box, (0.0, 0.0, 0.0), 0.5)):
        ms = [median_ms(Lidar2D(client, body, mount, rng=rng, start_offset=offset).scan, repeat)
              for offset in (0.0, outside)]
        print(f"  {name}: from its centre {ms[0]:.3f} ms, from {outside} m out {ms[1]:.3f} ms "
              f"({ms[0] / ms[1]:.1f}x)")
    client.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=200)
    parser.add_argument("--missions", type=int, default=40)
    args = parser.parse_args()
    world = load_world((ROOT / "worlds" / "urban_default.yaml").resolve())
    measure(world, args.repeat)
    inside_the_body(world, args.repeat)
    lidar3d(world, max(5, args.repeat // 10))
    pose_sensors(args.missions)


def lidar3d(world: World, repeat: int) -> None:
    from astralis_des.physics.lidar3d import Lidar3D

    client = PhysicsClient(world, 1 / 240, 1, 50)
    box = client.call("createCollisionShape", 3, halfExtents=[0.2, 0.2, 0.1])
    corridor, room = world.spaces["A.1.corridor"].box, world.rooms["A.2.1.2"].box
    for name, at in (("corridor", (*corridor.center[:2], corridor.lo[2] + 1.2)),
                     ("second-floor room", (*room.center[:2], room.lo[2] + 1.5))):
        body = client.call("createMultiBody", 0, box, basePosition=list(at))
        lidar = Lidar3D(client, body, noise_std=0.0)
        ours = []
        for _ in range(repeat):
            t0 = time.perf_counter()
            lidar.scan()
            ours.append(time.perf_counter() - t0)
        centre, heading = lidar.pose()
        dirs = lidar.directions(heading).reshape(-1, 3)
        raw = []
        for _ in range(max(3, repeat // 4)):
            t0 = time.perf_counter()
            for i in range(0, len(dirs), 4000):
                client.call("rayTestBatch", (centre + 0.5 * dirs[i:i + 4000]).tolist(),
                            (centre + 100.0 * dirs[i:i + 4000]).tolist())
            raw.append(time.perf_counter() - t0)
        mine, bullet = statistics.median(ours), statistics.median(raw)
        print(f"3-D lidar, {len(dirs):,} beams, building A's {name}: median {mine * 1e3:.1f} ms "
              f"(goal <= 15 ms); rayTestBatch alone {bullet * 1e3:.1f} ms; "
              f"{bullet / mine:.1f}x faster (goal >= 3x)")
        client.call("removeBody", body)
    client.close()


def pose_sensors(missions: int) -> None:
    from astralis_des import Simulation, load_mission

    base = load_mission(ROOT / "missions" / "urban_search.yaml")
    team = base.spec.model_dump(mode="json")["team"]
    for member in team:
        if member["kind"] in ("uav", "ugv"):
            member["sensors"] = {"gnss": {}, "barometer": {}, "magnetometer": {}}
    sensed = base.with_changes(team=team)

    def run_all(mission: Any) -> float:
        t0 = time.perf_counter()
        for seed in range(missions):
            Simulation(mission.with_changes(seed=seed)).run()
        return time.perf_counter() - t0

    run_all(base)  # the rooms furnished and judged: what stays the same either way
    first, without = run_all(sensed), run_all(base)
    again = statistics.median(run_all(sensed) for _ in range(3))
    without = statistics.median([without, *(run_all(base) for _ in range(2))])
    print(f"pose sensors (GNSS, barometer, magnetometer on 3 robots), {missions} kinematic "
          f"missions: without {without:.2f} s; with {first:.2f} s the first time "
          f"({first / without - 1:+.1%}: the open sky over new cells), {again:.2f} s again "
          f"({again / without - 1:+.1%}; goal <= +5%)")


if __name__ == "__main__":
    main()
