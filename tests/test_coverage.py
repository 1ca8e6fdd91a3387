"""Coverage paths and the geometric sensor: spacing, coverage shares, detection by sight."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from astralis_des.actions.common import footprint_spacing
from astralis_des.actions.uav import WALL_MARGIN
from astralis_des.detection import predict_pixels, swath
from astralis_des.kernel.robot import Motion, Robot
from astralis_des.kinds import TARGET_SIZE
from astralis_des.sensing import GeometricSensor
from astralis_des.view import View
from astralis_des.world import coverage as cov
from astralis_des.world.catalogue import default_catalogue
from astralis_des.world.geometry import Box, cross2
from astralis_des.world.model import World
from astralis_des.world.scene import Scene

ROOM = Box((0.0, 0.0, 0.0), (4.0, 7.0, 3.0))


def sensor(world: World, target: tuple[float, float, float] | None = None,
           room: str = "B.1.1.1", messiness: float = 0.0, seed: int = 0) -> GeometricSensor:
    """A sensor in ``world`` furnished at ``messiness``, the target in ``room`` (at ``target``)."""
    scene = Scene(world, dict.fromkeys(world.rooms, messiness), seed, default_catalogue())
    return GeometricSensor(scene, scene.place_target(room, {"activity": "idle"}, target))


def robot(kind: str = "uav", height: float = 1.5, heading: float = 0.0) -> Robot:
    """A robot with its kind's camera (UAV: 75 degrees down; UGV: ahead; no range cap)."""
    return Robot("r", kind, 1.0, View.of_kind(kind), height, np.zeros(3), heading=heading)


def test_spiral_rings_are_spacing_apart_and_inside_the_room() -> None:
    """An inward spiral starts on the outer ring, half a spacing from the walls, ends inside."""
    path = cov.spiral(ROOM, 1.0, inward=True)
    assert path[0] == pytest.approx([0.5, 0.5])
    assert np.all((path >= [0.5, 0.5]) & (path <= [3.5, 6.5]))
    assert np.linalg.norm(path[-1] - [2.0, 3.5]) < np.linalg.norm(path[0] - [2.0, 3.5])


def test_outward_spiral_is_the_inward_one_reversed() -> None:
    """Outward starts where inward ends."""
    inward, outward = cov.spiral(ROOM, 1.2, True), cov.spiral(ROOM, 1.2, False)
    assert np.allclose(inward[::-1], outward)


@pytest.mark.parametrize("axis", [0, 1])
def test_lawnmower_lanes_follow_their_axis(axis: int) -> None:
    """Horizontal sweep lanes run along x, vertical along y, ``spacing`` or less apart."""
    path = cov.lawnmower(ROOM, 1.0, axis)
    lanes = path.reshape(-1, 2, 2)
    assert np.allclose(lanes[:, 0, 1 - axis], lanes[:, 1, 1 - axis])  # each lane is straight
    offsets = np.sort(lanes[:, 0, 1 - axis])
    assert np.all(np.diff(offsets) <= 1.0 + 1e-9)


def test_spacing_follows_the_footprint() -> None:
    """Passes are 80% of the strip a UAV camera 1 m above the target's centre searches: a
    sitting target 1 cm inside half of it across the track shows 40 pixels somewhere along a
    pass, one 5 cm outside never does (90 x 106 degrees, 75 down, 320 x 240: about 5.5 m)."""
    view = View.of_kind("uav")
    strip = swath(view, 1.0)
    assert 5.0 < strip < 6.0
    assert footprint_spacing(robot(), 0.2) == pytest.approx(0.8 * strip)
    along = np.arange(-4.0, 4.0, 0.01)

    def most(across: float) -> float:
        centres = np.column_stack([along, np.full(len(along), across), np.full(len(along), -1.0)])
        return float(predict_pixels(view, np.zeros((len(along), 3)), np.zeros(len(along)),
                                    centres, np.array(TARGET_SIZE), None).max())

    assert most(strip / 2 - 0.01) >= 40 > most(strip / 2 + 0.05)


def test_the_uav_camera_sees_ahead_and_below_not_behind() -> None:
    """Facing east at 1.5 m: a point 1 m ahead on the target plane is seen, 1 m behind or
    beyond the 2 m reach is not (the view reaches 0.58 m behind, 30 degrees past the
    vertical); facing west, the one ahead is behind."""
    view = View.of_kind("uav")
    eye = np.array([[0.0, 0.0, 1.5]] * 4)
    points = np.array([[1.0, 0.0, 0.5], [-1.0, 0.0, 0.5], [2.5, 0.0, 0.5], [0.0, 0.0, 0.5]])
    assert view.sees(eye, np.zeros(4), points).tolist() == [True, False, False, True]
    assert view.sees(eye, np.full(4, np.pi), points).tolist() == [False, True, False, True]


def test_the_ugv_camera_sees_a_75_degree_wedge_ahead() -> None:
    """A 60 degree vertical field of view at 4:3 is 75.2 degrees across: 37 degrees off the
    axis is in, 39 is out; with a 6 m range cap, 5.9 m is in, 6.1 m is out."""
    view = View.of_kind("ugv", range=6.0)
    eye = np.zeros((4, 3))
    angles = np.radians([37.0, 39.0, 0.0, 0.0])
    reach = np.array([3.0, 3.0, 5.9, 6.1])
    points = np.column_stack([reach * np.cos(angles), reach * np.sin(angles), np.zeros(4)])
    assert view.sees(eye, np.zeros(4), points).tolist() == [True, False, True, False]


@pytest.mark.parametrize("pattern", ["spiral_in", "spiral_out", "sweep_x", "sweep_y"])
def test_uav_patterns_cover_at_least_90_percent(world: World, pattern: str) -> None:
    """Each UAV search pattern (its outer pass at most 1 m from the walls) sees >= 90% of an
    empty room's floor."""
    room = world.rooms["A.2.1.2"]
    r = robot()
    spacing = footprint_spacing(r, 0.2)
    plane = {
        "spiral_in": lambda: cov.spiral(room.box, spacing, True, WALL_MARGIN),
        "spiral_out": lambda: cov.spiral(room.box, spacing, False, WALL_MARGIN),
        "sweep_x": lambda: cov.lawnmower(room.box, spacing, 0, WALL_MARGIN),
        "sweep_y": lambda: cov.lawnmower(room.box, spacing, 1, WALL_MARGIN),
    }[pattern]()
    pts = np.column_stack([plane, np.full(len(plane), room.box.lo[2] + r.height)])
    share = sensor(world).coverage(r, pts, room)
    assert share >= 0.9


def test_a_peek_from_the_door_sees_part_of_the_room_only(world: World) -> None:
    """From the corridor side of the door the walls hide the room's near corners."""
    room = world.rooms["A.1.1.1"]
    eye = np.array([room.door_point("corridor", 0.15)]) + [0, 0, 0.5]
    into = np.arctan2(room.center[1] - eye[0, 1], room.center[0] - eye[0, 0])
    share = sensor(world).coverage(robot("ugv", 0.5, into), eye, room)
    assert 0.4 < share < 0.95
    away = sensor(world).coverage(robot("ugv", 0.5, into + np.pi), eye, room)
    assert away == 0.0


def test_the_target_is_seen_through_the_door_not_through_the_wall(world: World) -> None:
    """A UGV facing a target in a room sees it from the door, not from behind its wall; a
    UAV flying past the door inside the corridor does not look in (it looks ahead)."""
    room = world.rooms["A.1.1.2"]
    target = (room.center[0], room.center[1], room.box.lo[2] + 0.5)
    seer = sensor(world, target, room.id)
    door = np.array(room.door_point("corridor", 0.5)) + [0, 0, 0.5]
    into = float(np.arctan2(target[1] - door[1], target[0] - door[0]))
    seen = seer.sighting_from(robot("ugv", 0.5, into), door, 0.0)
    assert seen is not None and seen.distance == pytest.approx(np.linalg.norm(door - target))
    neighbour = world.rooms["A.1.1.1"]
    behind = np.array([neighbour.box.hi[0] - 0.5, target[1], 0.5])
    assert seer.sighting_from(robot("ugv", 0.5, 0.0), behind, 0.0) is None
    assert np.linalg.norm(behind - target) < 6.0  # in reach: the wall hides it
    corridor_y = room.door_point("corridor", 1.0)[1]
    past_door = Motion(np.array([[62.5, corridor_y, 1.5], [79.0, corridor_y, 1.5]]), 1.0)
    assert seer.first_sighting(robot("uav"), past_door) is None


def test_a_detection_estimates_the_position_with_seeded_noise(world: World) -> None:
    """The estimate is off by about the camera's position_noise times the distance, and the
    same generator seed gives the same estimate."""
    room = world.rooms["A.1.1.2"]
    target = (room.center[0], room.center[1], room.box.lo[2] + 0.5)
    door = np.array(room.door_point("corridor", 0.5)) + [0, 0, 0.5]
    into = float(np.arctan2(target[1] - door[1], target[0] - door[0]))
    r = Robot("r", "ugv", 1.0, View.of_kind("ugv", position_noise=0.05), 0.5, door,
              heading=into)

    def estimate(seed: int) -> tuple[float, ...]:
        scene = Scene(world, dict.fromkeys(world.rooms, 0.0), 0, default_catalogue())
        seer = GeometricSensor(scene, scene.place_target(room.id, {"activity": "idle"}, target),
                               np.random.default_rng(seed))
        hit = seer.sighting_from(r, door, 0.0)
        assert hit is not None
        assert hit.error == pytest.approx(np.linalg.norm(np.subtract(hit.estimate, target)))
        assert hit.error < 4 * 0.05 * hit.distance * np.sqrt(3)
        return hit.estimate

    assert estimate(1) == estimate(1) != estimate(2)


def test_an_inspect_point_under_a_table_is_skipped_not_failed() -> None:
    """The operator's inspection loop has a corner under a table (the walker's planner, on
    its floor grid, cannot stand there): the search succeeds without that corner, says so,
    and walks the other corners; it does not fail the whole room."""
    from conftest import MISSIONS

    from astralis_des import Simulation, load_mission
    from astralis_des.world.clutter import Clutter, Placed

    base = load_mission(MISSIONS / "fig7.yaml")
    sim = Simulation(base.with_changes(
        team=[{"id": "op1", "kind": "human", "start": [70.0, 78.25, 0.0]}],
        planning={"method": "map"}, scene={"clutter": False}, time_limit=500,
        target={"room": "A.1.2.1"},
        assignment={**base.spec.assignment.model_dump(), "start_at": 400.0}))
    room = sim.world.rooms["A.1.1.3"]
    loop = cov.start_near(cov.loop(room.box, 1.0), room.box, np.array(room.door_point("room")))
    far = loop[int(np.argmax(np.linalg.norm(loop - np.array(room.door.center[:2]), axis=1)))]
    table = Placed("table", room.id, (float(far[0]), float(far[1]), 0.375), (1.2, 0.8, 0.75),
                   0.0)
    sim.scene.set_clutter(room.id, Clutter((table,)))
    sim.start()
    done = sim.enqueue("op1", "inspect", room.id)
    sim.advance(300.0)
    assert done.triggered
    result = done.value
    assert result.ok, result.message
    assert result.message.endswith("(1 of 5 points out of reach)")
    walked = np.array(sim.robots["op1"].trail_p)[:, :2]
    assert np.linalg.norm(walked - far, axis=1).min() > 0.5  # never stood at that corner
    others = [p for p in loop if np.linalg.norm(p - far) > 0.1]
    assert all(np.linalg.norm(walked - p, axis=1).min() < 0.3 for p in others)


@pytest.mark.parametrize("kind", ["uav", "ugv", "human"])
def test_coverage_judges_pairs_as_the_detection_model_does(kind: str) -> None:
    """Coverage judges eye-cell pairs in the camera frame and culls boxes outside the frame
    first: on random eyes and cells it says exactly what the frustum test (``in_frame``) and
    the unhidden pixel count (``predict_pixels``) say, pair by pair."""
    from astralis_des.detection import cull, shows_unhidden
    from astralis_des.sensing import in_frame
    from astralis_des.view import pick

    rng = np.random.default_rng(7)
    view, size = View.of_kind(kind), np.asarray(TARGET_SIZE)
    eyes = np.column_stack([rng.uniform(-3, 3, (40, 2)), rng.uniform(0.3, 2.5, 40)])
    heads = rng.uniform(-np.pi, np.pi, 40)
    cells = np.column_stack([rng.uniform(-8, 8, (300, 2)), np.full(300, 0.5)])
    axes = view.axes(heads)
    m, n = np.repeat(np.arange(40), 300), np.tile(np.arange(300), 40)
    pi, ci = in_frame(view, eyes, heads, cells, size, m, n, axes)
    big = predict_pixels(view, eyes[pi], heads[pi], cells[ci], size, None) >= view.min_pixels
    expected = np.zeros((40, 300), dtype=bool)
    expected[pi[big], ci[big]] = True
    assert 0 < expected.sum() < expected.size
    judged = shows_unhidden(view, eyes, axes, cells, size, m, n).reshape(40, 300)
    assert np.array_equal(judged, expected)
    sure, maybe = cull(view, eyes, pick(axes, np.arange(40)), cells, size)
    assert expected[sure].all()  # sure: never one the model rejects
    culled = np.ones((40, 300), dtype=bool)
    culled[sure] = culled[maybe] = False
    assert not expected[culled].any()  # culled: never one the model accepts


@pytest.mark.parametrize("kind", ["uav", "ugv", "human"])
def test_a_few_pairs_counted_without_culling_are_the_pairs_culling_finds(kind: str) -> None:
    """A few pairs of point and cell are all counted, many are culled first: both ways give
    the same pairs, on random eyes and cells."""
    from astralis_des import sensing

    rng = np.random.default_rng(11)
    view, size = View.of_kind(kind), np.asarray(TARGET_SIZE)
    eyes = np.column_stack([rng.uniform(-3, 3, (60, 2)), rng.uniform(0.3, 2.5, 60)])
    cells = np.column_stack([rng.uniform(-6, 6, (400, 2)), np.full(400, 0.5)])
    axes = view.axes(rng.uniform(-np.pi, np.pi, 60))
    found = 0
    for _ in range(40):
        rows = np.sort(rng.choice(60, int(rng.integers(1, 20)), replace=False))
        todo = np.sort(rng.choice(400, int(rng.integers(1, 40)), replace=False))
        few = sensing._shown(view, eyes, axes, cells, size, rows, todo)
        many = sensing.FEW_PAIRS
        try:
            sensing.FEW_PAIRS = 0
            culled = sensing._shown(view, eyes, axes, cells, size, rows, todo)
        finally:
            sensing.FEW_PAIRS = many
        assert set(zip(*few, strict=True)) == set(zip(*culled, strict=True))
        found += len(few[0])
    assert found > 0


@pytest.mark.parametrize(("kind", "drop"), [("uav", 1.475), ("uav", 0.8), ("human", 1.1)])
def test_swath_culls_nothing_the_pixel_count_would_see(kind: str, drop: float) -> None:
    """The swath skips the pixel count where the box is surely in or out of the frame: the
    width is the one a pixel count over the whole grid gives."""
    from astralis_des.detection import _swath

    view = View.of_kind(kind)
    reach = min(view.reach, 4.0 * max(drop, 0.5))
    xs = np.arange(-reach, reach + 1e-9, 0.05)

    def widest(ys: np.ndarray) -> float:  # the pixel count at every point of the grid
        gx, gy = np.meshgrid(xs, ys, indexing="ij")
        centres = np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, -drop)])
        pixels = predict_pixels(view, np.zeros((len(centres), 3)), np.zeros(len(centres)),
                                centres, np.asarray(TARGET_SIZE), None).reshape(gx.shape)
        return float(ys[(pixels >= view.min_pixels).any(axis=0)].max())

    coarse = widest(np.arange(0.0, reach + 1e-9, 0.1))
    fine = widest(np.arange(coarse, coarse + 0.1, 0.01))
    assert _swath.__wrapped__(view, drop) == round(2 * fine, 2)


def test_a_sweep_flown_again_in_a_room_furnished_anew_covers_what_it_would_afresh(
        world: World) -> None:
    """What the first pass of a sweep would show is kept per room and path, whatever the
    furniture: the same sweep in the room furnished by other seeds covers exactly what it
    covers when nothing is kept."""
    room_id, r = "B.1.1.1", robot()
    room = world.rooms[room_id]
    plane = cov.spiral(room.box, footprint_spacing(r, 0.2), True, WALL_MARGIN)
    pts = np.column_stack([plane, np.full(len(plane), room.box.lo[2] + r.height)])
    shares = {}
    for kept in (True, False):
        for seed in range(4):
            world.__dict__.pop("_memo_coverage", None)  # the answers, not the first passes
            if not kept:
                world.__dict__.pop("_memo_first_pass", None)
            shares[kept, seed] = sensor(world, room=room_id, messiness=1.0,
                                        seed=seed).coverage(r, pts, room)
    assert len({shares[True, s] for s in range(4)}) > 1  # the furniture differs by seed
    assert all(shares[True, s] == shares[False, s] for s in range(4))


def test_the_2d_cross_product_is_numpys_to_the_bit() -> None:
    """``cross2`` (what coverage's turns and an interior's reflex corners use, since NumPy 2
    deprecates ``np.cross`` of 2-D vectors) gives ``np.cross``'s bits."""
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=(500, 2)), rng.normal(size=(500, 2))
    a[:5] = 0.0  # signed zeros too
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        expected = np.cross(a, b)
    assert cross2(a, b).tobytes() == expected.tobytes()
