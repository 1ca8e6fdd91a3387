"""Issue 24: the UAV's Table I patterns look like their names, and a UAV takes off, flies
over the heads of standing people, and lands."""

from __future__ import annotations

import itertools
import json
from pathlib import Path

import numpy as np
import pytest

from astralis_des import Simulation, load_mission
from astralis_des.actions.common import footprint_spacing
from astralis_des.actions.uav import WALL_MARGIN
from astralis_des.kernel.robot import Robot
from astralis_des.kinds import KIND_DEFAULTS, UAV_BODY_HALF_HEIGHT, UAV_REST
from astralis_des.view import View
from astralis_des.world import coverage as cov
from astralis_des.world.catalogue import AVATAR_HEIGHTS, default_catalogue
from astralis_des.world.flight import flight_height
from astralis_des.world.geometry import Box

ROOT = Path(__file__).resolve().parents[1]
ROOM = Box((10.0, 20.0, 0.0), (13.8, 26.8, 3.3))  # 3.8 x 6.8 m, as building A's rooms
CENTRE = np.array([11.9, 23.4])
HEIGHT = KIND_DEFAULTS["uav"].height


def turns(path: np.ndarray) -> float:
    """How many times the path turns round: its heading's total signed change / 2 pi."""
    legs = np.diff(path, axis=0)
    heading = np.unwrap(np.arctan2(legs[:, 1], legs[:, 0]))
    return float(abs(heading[-1] - heading[0]) / (2 * np.pi))


def crosses_itself(path: np.ndarray) -> bool:
    def ccw(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> float:
        return float((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))

    legs = list(itertools.pairwise(path))
    for i, (a, b) in enumerate(legs):
        for c, d in legs[i + 2:]:
            if ccw(a, b, c) * ccw(a, b, d) < 0 and ccw(c, d, a) * ccw(c, d, b) < 0:
                return True
    return False


def spacing() -> float:
    uav = Robot("u", "uav", 1.5, View.of_kind("uav"), HEIGHT, np.zeros(3))
    return footprint_spacing(uav, 0.2)


@pytest.mark.parametrize("inward", [True, False], ids=["inward", "outward"])
def test_a_spiral_turns_twice_and_closes_in_or_opens_out(inward: bool) -> None:
    """In a 3.8 x 6.8 m room, with the footprint's spacing (it alone would give one ring):
    at least two turns, each corner nearer the centre than the one before (inward) or
    farther (outward), never crossing itself, within the wall margin."""
    path = cov.spiral(ROOM, spacing(), inward=inward, margin=WALL_MARGIN)
    assert turns(path) >= 2.0
    d = np.linalg.norm(path - CENTRE, axis=1)
    steps = np.diff(d)
    assert np.all(steps < 0) if inward else np.all(steps > 0)
    assert d[-1 if inward else 0] == pytest.approx(0.0)  # ends (starts) at the centre
    assert not crosses_itself(path)
    lo, hi = np.array(ROOM.lo[:2]), np.array(ROOM.hi[:2])
    inset = min(WALL_MARGIN, 3.8 / 4)  # the margin, or half way to the centre if nearer
    assert np.all(path >= lo + inset - 1e-9) and np.all(path <= hi - inset + 1e-9)
    assert np.isclose(path - lo, inset).all(axis=1).any()  # the first side, at the inset


def test_a_wide_room_gets_rings_a_footprint_apart() -> None:
    """In a 20 x 20 m hall the rings are the footprint's spacing apart, not closer."""
    hall = Box((0.0, 0.0, 0.0), (20.0, 20.0, 4.0))
    s = spacing()
    path = cov.spiral(hall, s, inward=True, margin=WALL_MARGIN)
    assert turns(path) >= 2.0
    bottoms = path[::4, 1]  # the corners that start each turn, on the south side
    gaps = np.diff(bottoms[:3])
    assert np.all(gaps <= s + 1e-9) and np.all(gaps > 0.5 * s)


@pytest.mark.parametrize(("axis", "width", "lanes"), [(0, 6.8, 7), (1, 3.8, 4), (0, 3.8, 4)])
def test_a_sweep_has_a_lane_per_footprint_width(axis: int, width: float, lanes: int) -> None:
    """Boustrophedon lanes across the room, as many as the spacing needs (width / spacing,
    rounded up, at least two), turning back at each end."""
    room = Box((0.0, 0.0, 0.0), (width, 10.0, 3.0)) if axis == 1 else \
        Box((0.0, 0.0, 0.0), (10.0, width, 3.0))
    path = cov.lawnmower(room, 1.0, axis)
    offsets = np.unique(np.round(path[:, 1 - axis], 6))
    assert len(offsets) == lanes
    along = path[:, axis].reshape(-1, 2)
    assert np.all(np.sign(along[:, 1] - along[:, 0])[::2] > 0)  # there and back
    assert np.all(np.sign(along[:, 1] - along[:, 0])[1::2] < 0)
    s = spacing()  # the footprint's, wider than the room: two lanes still, not one
    assert s > 3.8 and len(np.unique(np.round(cov.lawnmower(ROOM, s, 1)[:, 0], 6))) == 2
    assert len(np.unique(np.round(cov.lawnmower(ROOM, s, 0)[:, 1], 6))) == max(
        2, int(np.ceil(6.8 / s)))


def test_the_flight_height_clears_a_standing_person_and_passes_the_doors() -> None:
    """Halfway between the tallest standing bystander's head and the doors' lintels, each
    less the craft's half-height: 1.975 m in the default world."""
    world = load_mission(ROOT / "missions" / "urban_search.yaml").world
    height = flight_height(world, default_catalogue())
    assert height == HEIGHT == pytest.approx(1.975)
    assert height - UAV_BODY_HALF_HEIGHT > max(AVATAR_HEIGHTS.values())
    lintel = min(r.door.height for r in world.rooms.values())
    assert height + UAV_BODY_HALF_HEIGHT < lintel
    sitting_only = default_catalogue().model_copy(update={"avatars": default_catalogue()
                                                          .avatars.model_copy(update={
                                                              "attributes": default_catalogue()
                                                              .avatars.attributes.model_copy(
                                                                  update={"activity": (
                                                                      "sitting",)})})})
    assert flight_height(world, sitting_only) < height  # lower: only sitting people, plants


@pytest.fixture(scope="module")
def default_run(tmp_path_factory: pytest.TempPathFactory) -> list[dict]:
    out = tmp_path_factory.mktemp("run")
    Simulation(load_mission(ROOT / "missions" / "urban_search.yaml"), out_dir=out).run()
    return [json.loads(line) for line in (out / "events.jsonl").read_text().splitlines()]


def test_uavs_take_off_first_and_land_at_the_end(default_run: list[dict]) -> None:
    """Each UAV starts on the ground, climbs to its flight height before it goes anywhere,
    and lands when the mission ends; the mission ends when the last has landed."""
    kinds = [e["kind"] for e in default_run]
    found = kinds.index("detection")
    for uav in ("uav1", "uav2"):
        mine = [e for e in default_run if e.get("robot") == uav]
        up = next(e for e in mine if e["kind"] == "took_off")
        assert up["t"] == pytest.approx(2.405) and up["height"] == HEIGHT
        assert not [e for e in mine if e["kind"] == "task_finished" and e["t"] < up["t"]]
        down = next(e for e in mine if e["kind"] == "landed")
        assert default_run.index(down) > found
        assert down["position"][2] == pytest.approx(UAV_REST)
    assert default_run[-1]["kind"] == "mission_end"
    assert default_run[-1]["t"] == max(e["t"] for e in default_run if e["kind"] == "landed")


def test_a_uav_searches_a_room_over_the_heads_of_standing_people() -> None:
    """In a search, the UAV's path is at its flight height over the floor: above the head of
    the tallest standing avatar (by the craft's half-height and more)."""
    sim = Simulation(load_mission(ROOT / "missions" / "urban_search.yaml"))
    result = sim.run()
    searched = [e for e in result.events if e["kind"] == "task_finished"
                and e["action"].startswith(("spiral", "sweep"))]
    assert searched
    uav = sim.robots[searched[0]["robot"]]
    points = np.concatenate([p for _, p in uav.plans])
    doors = sim.world.doorways[:, :2]  # (where it ducks under a lintel)
    away = np.linalg.norm(points[:, None, :2] - doors[None], axis=2).min(axis=1) > 1.5
    inside = np.array([sim.world.room_at(p - [0, 0, 1.0]) is not None for p in points])
    z = np.array([p[2] - sim.world.floor_below(p) for p in points[away & inside]])
    assert len(z) > 20
    standing = [p for p in sim.scene.furnish_all()
                if dict(p.attributes).get("activity") in ("idle", "patrolling")]
    assert standing
    tallest = max(p.box.hi[2] - p.box.lo[2] for p in standing)
    assert np.all(z - UAV_BODY_HALF_HEIGHT > tallest)
