"""Clutter by messiness: no overlaps, door kept clear, every region reachable, deterministic."""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence

import numpy as np
import pytest
from scipy import ndimage

from astralis_des.world.build import build_world
from astralis_des.world.catalogue import AVATAR_HEIGHTS, default_catalogue
from astralis_des.world.clutter import (
    Clutter,
    Placed,
    free_spot,
    furnish,
    place_room,
    place_world,
)
from astralis_des.world.geometry import Box
from astralis_des.world.model import Room, World
from astralis_des.world.spec import WorldSpec

SEEDS = range(60)
LEVELS = (0.0, 0.25, 0.5, 0.75, 1.0)
ROOMS = ("A.1.1.1", "A.1.2.2", "B.2.1.3")  # doors on the south and north walls, two buildings
EPS = 1e-9
TABLE_II = {
    "activity": {"sitting", "laying", "patrolling", "idle"},
    "color": {"yellow", "red", "purple", "blue"},
    "gender": {"male", "female"},
    "height": {"tall", "medium", "short"},
    "tied_to_chair": {True, False},
}


def room_of(seed: int) -> str:
    return ROOMS[seed % len(ROOMS)]


@pytest.fixture(scope="module")
def runs(world: World) -> dict[tuple[int, float], Clutter]:
    """Every (seed, messiness) placed once for all the property tests."""
    return {(seed, level): place_room(world, room_of(seed), level, np.random.default_rng(seed))
            for seed in SEEDS for level in LEVELS}


def overlap(a: Box, b: Box, gap: float = 0.0) -> bool:
    """Do the x, y footprints overlap, or come closer than ``gap`` along every axis?"""
    return all(a.lo[k] < b.hi[k] + gap - EPS and b.lo[k] < a.hi[k] + gap - EPS for k in (0, 1))


def keepout(room: Room) -> Box:
    """The 1.2 m deep, 1.4 m wide rectangle inside the room in front of its door."""
    axis, door = room.door.normal_axis, room.door
    lo_side, hi_side = room.box.lo[axis], room.box.hi[axis]
    face_lo = abs(lo_side - door.center[axis]) < abs(hi_side - door.center[axis])
    face = lo_side if face_lo else hi_side
    span = sorted((face, face + (1.2 if face_lo else -1.2)))
    lo, hi = [0.0, 0.0, 0.0], [0.0, 0.0, 10.0]
    lo[axis], hi[axis] = span
    lo[1 - axis], hi[1 - axis] = door.center[1 - axis] - 0.7, door.center[1 - axis] + 0.7
    return Box((lo[0], lo[1], lo[2]), (hi[0], hi[1], hi[2]))


def clearance(kind: str) -> float:
    items = default_catalogue().items.present()
    return items[kind].clearance if kind in items else default_catalogue().avatars.clearance


def unreachable_wide_cells(room: Room, placed: Sequence[Placed], passage: float) -> int:
    """Cells with room for a robot ``passage + 0.3`` wide that a ``passage - 0.1`` wide robot
    cannot reach from the door, on an exact 5 cm raster (the margins absorb the 10 cm grid)."""
    cell = 0.05
    lo = np.array(room.box.lo[:2]) - 0.3
    shape = tuple(np.round((np.array(room.box.hi[:2]) + 0.3 - lo) / cell).astype(int))
    gx, gy = np.meshgrid(*(lo[k] + (np.arange(shape[k]) + 0.5) * cell for k in (0, 1)),
                         indexing="ij")

    def inside(box: Box, grow: float = 0.0) -> np.ndarray:
        return (gx > box.lo[0] - grow) & (gx < box.hi[0] + grow) & \
            (gy > box.lo[1] - grow) & (gy < box.hi[1] + grow)

    door, axis = room.door, room.door.normal_axis
    gap = [door.center[0], door.center[1]]
    doorway = Box((gap[0] - 0.5 if axis else gap[0] - 0.4, gap[1] - 0.4 if axis else gap[1] - 0.5,
                   0), (gap[0] + 0.5 if axis else gap[0] + 0.4,
                        gap[1] + 0.4 if axis else gap[1] + 0.5, 0))
    walk = inside(room.box) | inside(doorway)
    for item in placed:
        walk &= ~inside(item.box)
    room_side = inside(room.box)
    free_width = ndimage.distance_transform_edt(walk) * cell
    r = passage / 2
    wide, narrow = (free_width >= r + 0.15) & room_side, free_width >= r - 0.05
    labels, _ = ndimage.label(narrow)
    seed = np.floor((np.array(room.door_point("room", 0.4)[:2]) - lo) / cell).astype(int)
    assert narrow[seed[0], seed[1]], "the door itself is blocked"
    return int((wide & (labels != labels[seed[0], seed[1]])).sum())


def test_footprints_never_overlap(world: World, runs: dict[tuple[int, float], Clutter]) -> None:
    """No two footprints overlap, nor come closer than the larger of their clearances (but a
    sitting avatar, who sits on a chair: issue 24)."""
    for clutter in runs.values():
        chairs = {p.center[:2] for p in clutter.placed if p.kind == "chair"}
        for a, b in itertools.combinations(clutter.placed, 2):
            if {a.kind, b.kind} == {"chair", "avatar"} and a.center[:2] == b.center[:2]:
                continue  # the avatar on its chair
            seated = [p for p in (a, b) if p.kind == "avatar" and p.center[:2] in chairs]
            # a seated avatar keeps its chair's clearance, less the 5 cm its body may
            # reach past the chair's seat on each side
            gap = max(clearance("chair") - 0.05, 0.0) if seated else \
                max(clearance(a.kind), clearance(b.kind))
            assert not overlap(a.box, b.box, gap), (a, b)


def test_items_stand_inside_the_room_on_its_floor(
        world: World, runs: dict[tuple[int, float], Clutter]) -> None:
    """Every footprint is inside its room's box and stands on the room's floor."""
    for (seed, _), clutter in runs.items():
        room = world.rooms[room_of(seed)]
        for item in clutter.placed:
            box = item.box
            assert item.room == room.id
            assert all(room.box.lo[k] - EPS <= box.lo[k] and box.hi[k] <= room.box.hi[k] + EPS
                       for k in (0, 1)), item
            assert box.lo[2] == pytest.approx(room.box.lo[2])


def test_door_keepout_stays_empty(world: World, runs: dict[tuple[int, float], Clutter]) -> None:
    """No footprint enters the 1.2 x 1.4 m rectangle in front of the door."""
    for (seed, _), clutter in runs.items():
        zone = keepout(world.rooms[room_of(seed)])
        assert not [p for p in clutter.placed if overlap(p.box, zone)]


def test_every_free_region_is_reachable_from_the_door(
        world: World, runs: dict[tuple[int, float], Clutter]) -> None:
    """Open floor where a robot fits stays connected to the door at about the passage width."""
    passage = default_catalogue().passage
    for (seed, level), clutter in runs.items():
        room = world.rooms[room_of(seed)]
        assert unreachable_wide_cells(room, clutter.placed, passage) == 0, (seed, level)


def test_messiness_zero_places_nothing(runs: dict[tuple[int, float], Clutter]) -> None:
    """At messiness 0 a room stays empty and nothing is skipped."""
    for seed in SEEDS:
        assert runs[seed, 0.0] == Clutter((), ())


def test_counts_grow_with_messiness(runs: dict[tuple[int, float], Clutter]) -> None:
    """The mean number of items rises from messiness 0 through 0.5 to 1."""
    mean = {level: np.mean([len(runs[s, level].placed) for s in SEEDS]) for level in LEVELS}
    assert mean[0.0] == 0
    assert mean[0.25] < mean[0.5] < mean[0.75] < mean[1.0]
    assert 10 <= mean[1.0] <= 16  # the default catalogue's ~14 items in a 3.8 x 6.8 m room


def test_against_wall_items_back_onto_a_wall(
        world: World, runs: dict[tuple[int, float], Clutter]) -> None:
    """Cabinets and desks touch a wall with their long side, depth axis across the wall."""
    items = default_catalogue().items.present()
    checked = 0
    for (seed, _), clutter in runs.items():
        room = world.rooms[room_of(seed)]
        for item in clutter.placed:
            if item.kind not in items or not items[item.kind].against_wall:
                continue
            box, tol = item.box, 0.05 + items[item.kind].clearance
            touching = [k for k in (0, 1) if box.lo[k] - room.box.lo[k] <= tol
                        or room.box.hi[k] - box.hi[k] <= tol]
            depth_axis = 1 if item.yaw == 0.0 else 0  # yaw 0: the depth runs along y
            assert item.yaw in (0.0, math.pi / 2)
            assert depth_axis in touching, item
            assert item.size[depth_axis] < item.size[1 - depth_axis], item
            checked += 1
    assert checked > 100


def test_avatars_have_table_ii_attributes(runs: dict[tuple[int, float], Clutter]) -> None:
    """Each bystander has all five Table II attributes and a size that fits its activity."""
    avatars = [p for c in runs.values() for p in c.placed if p.kind == "avatar"]
    assert len(avatars) > 100
    for avatar in avatars:
        attributes = dict(avatar.attributes)
        assert list(attributes) == list(TABLE_II)
        assert all(attributes[k] in allowed for k, allowed in TABLE_II.items()), attributes
        if attributes["activity"] == "laying":
            assert sorted(avatar.size[:2]) == pytest.approx([0.6, 1.8])
            assert avatar.size[2] == pytest.approx(0.35)
        else:
            assert avatar.size[:2] == pytest.approx((0.5, 0.5))
            tall = 1.3 if attributes["activity"] == "sitting" else \
                AVATAR_HEIGHTS[str(attributes["height"])]
            assert avatar.size[2] == pytest.approx(tall)
    assert {dict(a.attributes)["activity"] for a in avatars} == TABLE_II["activity"]


def test_same_seed_same_clutter_other_seed_other_clutter(world: World) -> None:
    """A seed reproduces the placement exactly; another seed changes it."""
    messiness = {"A.1.1.1": 1.0, "A.2.2.3": 0.6, "B.1.1.1": 0.8}
    first = place_world(world, messiness, seed=7)
    assert place_world(world, messiness, seed=7) == first
    assert place_world(world, messiness, seed=8).placed != first.placed
    assert [p.room for p in first.placed] == sorted(p.room for p in first.placed)


def test_a_room_does_not_depend_on_the_others(world: World) -> None:
    """A room's clutter is the same whether or not other rooms are placed with it."""
    alone = place_world(world, {"A.2.2.3": 0.6}, seed=3)
    together = place_world(world, {"A.1.1.1": 1.0, "A.2.2.3": 0.6, "B.2.1.1": 1.0}, seed=3)
    assert together.in_room("A.2.2.3") == alone.placed
    assert len(together.placed) > len(alone.placed)


def tiny_world() -> World:
    return build_world(WorldSpec.model_validate({
        "name": "tiny", "site": {"size": [30, 30]},
        "buildings": [{"id": "T", "origin": [5, 5], "floors": 1, "room_size": [1.5, 1.5],
                       "segments": [{"side": "north", "rooms": 1}]}],
    }))


def test_a_tiny_room_reports_what_does_not_fit() -> None:
    """A 1.5 x 1.5 m room at messiness 1 lists its two bystanders as skipped, not raising
    (and the chair brought for a sitting one)."""
    world = tiny_world()
    clutter = place_room(world, "T.1.1.1", 1.0, np.random.default_rng(0))
    assert clutter.placed == ()
    skipped = [(room, kind) for room, kind, _ in clutter.skipped]
    assert skipped.count(("T.1.1.1", "avatar")) == 2
    assert set(skipped) <= {("T.1.1.1", "avatar"), ("T.1.1.1", "chair")}
    assert all(reason.startswith("no ") and "spot on the free floor" in reason
               for _, _, reason in clutter.skipped)


def test_free_spot_avoids_clutter_and_the_door(world: World) -> None:
    """A target's spot in a cluttered room overlaps no item and keeps out of the door zone."""
    room = world.rooms["A.1.1.1"]
    for seed in range(10):
        clutter = place_world(world, {room.id: 1.0}, seed=seed)
        spot = free_spot(world, room.id, clutter, (0.5, 0.5), np.random.default_rng(seed))
        assert spot is not None
        target = Box((spot[0] - 0.25, spot[1] - 0.25, 0.0), (spot[0] + 0.25, spot[1] + 0.25, 1.0))
        assert room.box.contains((*spot, room.box.lo[2]))
        assert not [p for p in clutter.placed if overlap(target, p.box)]
        assert not overlap(target, keepout(room))


def test_free_spot_is_none_when_nothing_fits() -> None:
    """No 1 x 1 m spot exists in a 1.5 x 1.5 m room beside its door zone."""
    world = tiny_world()
    assert free_spot(world, "T.1.1.1", Clutter(), (1.0, 1.0), np.random.default_rng(0)) is None


def test_bad_messiness_and_unknown_rooms_are_refused(world: World) -> None:
    """Messiness outside [0, 1] and an unknown room id are refused with what is valid."""
    with pytest.raises(ValueError, match=r"messiness must be in \[0, 1\], got 1.5"):
        place_room(world, "A.1.1.1", 1.5, np.random.default_rng(0))
    with pytest.raises(ValueError, match=r"unknown room 'A\.1\.1\.7'; did you mean"):
        place_world(world, {"A.1.1.7": 0.5}, seed=0)


def test_a_room_furnished_again_comes_from_memory_and_is_the_room_placed_anew(
        world: World) -> None:
    """A study's next variant or a tune's next trial furnishes the same room with the same
    seed: the world keeps it, and it is what placing it again gives."""
    from astralis_des.streams import stream

    catalogue = default_catalogue()
    first = furnish(world, "A.1.2.2", 0.8, 11, 4, catalogue)
    assert first == place_room(world, "A.1.2.2", 0.8, stream(11, "clutter", 4), catalogue)
    assert furnish(world, "A.1.2.2", 0.8, 11, 4, catalogue) is first
    other = furnish(world, "A.1.2.2", 0.8, 12, 4, catalogue)
    assert other == place_room(world, "A.1.2.2", 0.8, stream(12, "clutter", 4), catalogue)
    assert other != first  # another seed, another room


def test_erosion_near_a_new_footprint_equals_eroding_the_whole_floor() -> None:
    """Placing a footprint re-erodes the floor only around it: on random floors and random
    footprints (at the grid's edges too) the result is the whole floor eroded again."""
    from astralis_des.world.grids import erode, erode_near

    rng = np.random.default_rng(3)
    for _ in range(200):
        walk = rng.random((int(rng.integers(5, 40)), int(rng.integers(5, 40)))) > 0.15
        radius = float(rng.choice([1.5, 2.5, 3.5]))
        before = erode(walk, radius)
        i, j = int(rng.integers(walk.shape[0])), int(rng.integers(walk.shape[1]))
        changed = (slice(i, i + int(rng.integers(1, 6))), slice(j, j + int(rng.integers(1, 6))))
        after = walk.copy()
        after[changed] = False
        assert np.array_equal(erode_near(after, radius, changed, before), erode(after, radius))


def test_summed_area_tables_count_the_cells_of_every_window() -> None:
    """A summed-area table (accumulated in place) gives, for any window, the number of set
    cells numpy counts in it."""
    from astralis_des.world.grids import summed, window

    rng = np.random.default_rng(5)
    for _ in range(50):
        mask = rng.random((int(rng.integers(1, 30)), int(rng.integers(1, 30)))) > 0.4
        kx, ky = int(rng.integers(1, mask.shape[0] + 1)), int(rng.integers(1, mask.shape[1] + 1))
        counts = window(summed(mask), kx, ky)
        i, j = int(rng.integers(counts.shape[0])), int(rng.integers(counts.shape[1]))
        assert counts[i, j] == mask[i:i + kx, j:j + ky].sum()
        assert summed(mask)[-1, -1] == mask.sum()


def test_cells_near_a_set_one_by_shifts_are_those_a_summed_area_table_finds() -> None:
    """The cells within a few cells (a square) of a set one, found by shifted copies, are
    those whose window in a summed-area table of the padded grid holds a set cell."""
    from astralis_des.world.grids import near, padded, summed, window

    rng = np.random.default_rng(6)
    for _ in range(60):
        mask = rng.random((int(rng.integers(1, 25)), int(rng.integers(1, 25)))) > 0.9
        grow = int(rng.integers(0, 5))
        table = summed(padded(mask, grow, False))
        assert np.array_equal(near(mask, grow), window(table, 2 * grow + 1, 2 * grow + 1) > 0)


def test_cells_near_a_taken_one_kept_up_to_date_are_those_found_afresh(world: World) -> None:
    """What a footprint's window must avoid (cells within its clearance of a taken one) is
    kept up to date as footprints are stamped: at every step, on random rectangles (at the
    room's edges too), the cells found afresh from what is taken."""
    from astralis_des.world.clutter import Occupancy
    from astralis_des.world.freespace import room_free_space

    space = room_free_space(world, ROOMS[0])
    rng = np.random.default_rng(9)
    occupancy = Occupancy.empty(space, np.zeros(space.shape, dtype=bool), 0.7)
    for grow in (0, 2, 3):
        occupancy.near_taken(grow)
    (x0, y0), (nx, ny) = space.origin[:2], space.shape
    for _ in range(40):
        lo = (x0 + rng.uniform(-0.5, nx * space.cell), y0 + rng.uniform(-0.5, ny * space.cell))
        size = rng.uniform(0.05, 1.5, 2)
        occupancy.stamp(space, Box((*lo, 0.0), (lo[0] + size[0], lo[1] + size[1], 0.0)), 0.2)
        afresh = Occupancy.empty(space, occupancy.keepout, 0.7)
        afresh.taken = occupancy.taken
        for grow in (0, 2, 3):
            assert np.array_equal(occupancy.near[grow], afresh.near_taken(grow))
    assert occupancy.taken.any() and not occupancy.taken.all()


def test_an_items_size_is_drawn_as_rng_uniform_draws_it() -> None:
    """An item's size is the very draw ``rng.uniform(size_min, size_max)`` makes, and leaves
    the generator where it leaves it (furnishing's placements depend on both)."""
    from astralis_des.world.clutter import _size

    low, high = (0.45, 0.45, 0.8), (0.55, 0.55, 1.0)
    for seed in range(200):
        ours, numpys = np.random.default_rng(seed), np.random.default_rng(seed)
        for _ in range(20):
            assert _size(ours, low, high) == tuple(numpys.uniform(low, high).tolist())
        assert ours.random() == numpys.random()
