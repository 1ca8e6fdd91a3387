"""Indoor analysis (issue 42): the storeys, rooms, doors and entrances found in clouds sampled
on the faces of our own buildings (``tests/indoor_scenes.py``), against their truth: building
A of the default world, and a building of irregular rooms."""

from __future__ import annotations

import numpy as np
import pytest
from indoor_scenes import (
    Scene,
    building_a,
    face_cloud,
    irregular,
    oriented_cloud,
    score,
)

from astralis_des.importers.indoor import FoundDoor, Interior, find_interior, find_storeys

SPACING = 0.1  # m between points on a face: about 290,000 points for building A


@pytest.fixture(scope="module")
def found_a() -> tuple[Scene, Interior]:
    scene = building_a()
    return scene, find_interior(face_cloud(scene, SPACING))


@pytest.fixture(scope="module")
def found_irregular() -> tuple[Scene, Interior]:
    scene = irregular()
    return scene, find_interior(face_cloud(scene, SPACING))


def _nearest(interior: Interior, storey: int, xy: tuple[float, float]
             ) -> tuple[float, FoundDoor]:
    doors = [d for d in interior.doors if d.storey == storey]
    gaps = [float(np.hypot(d.centre[0] - xy[0], d.centre[1] - xy[1])) for d in doors]
    k = int(np.argmin(gaps))
    return gaps[k], doors[k]


def test_building_a_has_three_storeys_of_3_5_m(found_a: tuple[Scene, Interior]) -> None:
    """Floors at 0, 3.5 and 7 m; ceilings at the slabs' undersides, 0.2 m under the next
    floor (the roof's for the top one); 3.5 m floor to floor."""
    storeys = found_a[1].storeys
    assert [round(s.z, 2) for s in storeys] == [0.0, 3.5, 7.0]
    assert [round(s.ceiling, 2) for s in storeys] == [3.3, 6.8, 10.3]
    assert [round(s.height, 2) for s in storeys] == [3.5, 3.5, 3.5]


def test_every_room_of_building_a_is_found(found_a: tuple[Scene, Interior]) -> None:
    """Each of the 18 rooms is matched, one to one, by a found room of kind room whose cells
    cover its inner floor with an IoU of at least 0.8 (0.95 with these cells)."""
    scene, interior = found_a
    result = score(scene, interior)
    assert len(result.iou) == 18
    assert min(result.iou.values()) >= 0.8
    assert len(set(result.matched.values())) == 18
    kinds = {r.id: r.kind for r in interior.rooms}
    assert {kinds[f] for f in result.matched.values()} == {"room"}
    areas = {r.id: r.area for r in interior.rooms}
    assert all(abs(areas[f] - 3.8 * 6.8) < 2.0 for f in result.matched.values())


def test_every_door_of_building_a_is_found(found_a: tuple[Scene, Interior]) -> None:
    """Each room's door and the entrance: a found door within 0.3 m of its centre and 0.2 m
    of its width (1 m; the entrance 1.6 m), in a wall across the same axis; a room's door
    joins it to its storey's corridor, the room on the side it is on."""
    scene, interior = found_a
    result = score(scene, interior)
    assert len(result.door_error) == 19
    assert all(c <= 0.3 and w <= 0.2 and same for c, w, same in result.door_error.values())
    for door in scene.doors[:-1]:
        storey = 1 + round(door.floor / 3.5)
        _, found = _nearest(interior, storey, door.centre)
        room = result.matched[door.id]
        corridor = next(r.id for r in interior.rooms if r.storey == storey
                        and r.kind == "corridor")
        south = door.centre[1] < 78.0  # the rooms south of the corridor are on the low side
        assert found.rooms == ((room, corridor) if south else (corridor, room))


def test_building_a_corridors_and_entrance(found_a: tuple[Scene, Interior]) -> None:
    """On each storey the corridor is found as a corridor that the storey's six room doors
    open onto; the one entrance is on the ground floor, in the east wall (x = 80 m),
    1.6 m wide, outside on its high side."""
    _, interior = found_a
    for storey in (1, 2, 3):
        corridors = [r for r in interior.rooms if r.storey == storey and r.kind == "corridor"]
        assert len(corridors) == 1
        rooms = [d for d in interior.doors_of(corridors[0].id) if not d.entrance]
        assert sum(d.normal_axis == 1 and abs(d.width - 1.0) <= 0.2 for d in rooms) == 6
    (entrance,) = interior.entrances
    assert entrance.storey == 1 and entrance.normal_axis == 0
    assert entrance.centre[0] == pytest.approx(80.0, abs=0.3)
    assert entrance.width == pytest.approx(1.6, abs=0.2)
    assert entrance.rooms[1] is None


def test_no_false_rooms_in_building_a(found_a: tuple[Scene, Interior]) -> None:
    """Every found room over 4 m² is a true room or lies in the corridor, the lobby or the
    stairwell (the stairwell's two sides beside the lift's shaft are rooms on the ground
    floor; over it, its void has no floor and is no room)."""
    scene, interior = found_a
    assert score(scene, interior).false_rooms == []
    assert [len([r for r in interior.rooms if r.storey == s]) for s in (1, 2, 3)] == [9, 7, 7]


def test_furniture_stays_free(found_a: tuple[Scene, Interior]) -> None:
    """Tables (0.75 m), chairs and cabinets (0.9 m) in every room: no wall cell under any of
    them, nor under a table's top kept clear of its legs."""
    scene, interior = found_a
    furniture = scene.solids[-scene.furniture:]
    walled = 0
    for (x0, y0, z0), (x1, y1, _) in furniture:
        storey = 1 + round(z0 / 3.5)
        plan = interior.plans[storey - 1]
        lo = plan.cells(np.array([[x0 + 0.1, y0 + 0.1]]))[0]
        hi = plan.cells(np.array([[x1 - 0.1, y1 - 0.1]]))[0]
        walled += int(plan.walls[lo[0]:hi[0] + 1, lo[1]:hi[1] + 1].sum())
    assert scene.furniture == 18 * 18  # a table and two chairs with legs, a cabinet a room
    assert walled == 0


def test_irregular_rooms_are_found(found_irregular: tuple[Scene, Interior]) -> None:
    """Storeys at 12 and 15 m; on each, the L-shaped room, the store, the rooms with two
    doors, the room behind a half-closed door and the L-shaped open-plan space (a partition
    stub, a pillar, desks) each matched with an IoU of at least 0.8; the open plan is one
    hall, the corridor a corridor, and nothing else is found."""
    scene, interior = found_irregular
    assert [(round(s.z, 2), round(s.height, 2)) for s in interior.storeys] == [(12.0, 3.0),
                                                                               (15.0, 3.0)]
    result = score(scene, interior)
    assert len(result.iou) == 12
    assert min(result.iou.values()) >= 0.8
    assert len(set(result.matched.values())) == 12
    kinds = {r.id: r.kind for r in interior.rooms}
    for storey in (1, 2):
        assert kinds[result.matched[f"{storey}.open"]] == "hall"
        assert kinds[result.matched[f"{storey}.L"]] == "room"
        assert sorted(r.kind for r in interior.rooms if r.storey == storey) == \
            ["corridor", "hall", "room", "room", "room", "room", "room"]
    assert result.false_rooms == []


def test_irregular_doors(found_irregular: tuple[Scene, Interior]) -> None:
    """Every door within 0.3 m and 0.2 m of width, the half-closed one's 0.6 m gap too; S1
    and S2 have two doors each, S1 on the low-x side of theirs; two entrances below, none
    above; no door where there is none."""
    scene, interior = found_irregular
    result = score(scene, interior)
    assert len(result.door_error) == 16
    assert all(c <= 0.3 and w <= 0.2 and same for c, w, same in result.door_error.values())
    assert result.extra_doors == 0
    m = result.matched
    for storey in (1, 2):
        assert len(interior.doors_of(m[f"{storey}.S1"])) == 2
        assert len(interior.doors_of(m[f"{storey}.S2"])) == 2
        _, shared = _nearest(interior, storey, (5.0, 3.0))
        assert shared.rooms == (m[f"{storey}.S1"], m[f"{storey}.S2"])
        gap, half_closed = _nearest(interior, storey, (11.8, 6.0))
        assert gap <= 0.3 and half_closed.width == pytest.approx(0.6, abs=0.2)
        assert half_closed.rooms[0] == m[f"{storey}.S3"]
    assert sorted((d.storey, round(d.centre[1])) for d in interior.entrances) == [(1, 3), (1, 7)]


def test_normals_keep_walls_and_floors() -> None:
    """Given the faces' normals (table tops then never count towards walls; storeys come from
    horizontal faces alone), the irregular building's storeys are at the same heights and
    every room still matches with an IoU of at least 0.8."""
    scene = irregular(floors=(12.0,))
    points, normals = oriented_cloud(scene, SPACING, seed=3)
    interior = find_interior(points, normals=normals)
    assert [round(s.z, 2) for s in interior.storeys] == [12.0]
    result = score(scene, interior)
    assert len(result.iou) == 6 and min(result.iou.values()) >= 0.8


def test_a_turned_building_is_planned_along_its_walls() -> None:
    """The irregular building turned 30 degrees about the origin: its walls' heading is found
    (30 degrees), its plan drawn along them finds every room (IoU >= 0.8) and door as unturned,
    and ``to_cloud`` puts a door's centre back where it is in the turned cloud."""
    scene = irregular(floors=(12.0,))
    angle = np.radians(30.0)
    turn = np.array([[np.cos(angle), -np.sin(angle), 0.0],
                     [np.sin(angle), np.cos(angle), 0.0], [0.0, 0.0, 1.0]])
    interior = find_interior(face_cloud(scene, SPACING, seed=4) @ turn.T)
    assert np.degrees(interior.heading) == pytest.approx(30.0, abs=0.1)
    result = score(scene, interior)
    assert len(result.iou) == 6 and min(result.iou.values()) >= 0.8
    assert all(c <= 0.3 and w <= 0.2 and same for c, w, same in result.door_error.values())
    _, shared = _nearest(interior, 1, (5.0, 3.0))  # S1 and S2's door, in the plan's frame
    expected = turn[:2, :2] @ np.array([5.0, 3.0])
    assert interior.to_cloud(shared.centre)[0] == pytest.approx(expected, abs=0.3)


def test_a_cloud_without_a_closed_storey_has_none() -> None:
    """A floor with nothing over it (a car park's top deck, a terrain) is no storey: no
    storeys, no rooms, no doors."""
    rng = np.random.default_rng(0)
    deck = np.column_stack([rng.uniform(0, 20, 5000), rng.uniform(0, 20, 5000),
                            rng.normal(0, 0.01, 5000)])
    assert find_storeys(deck) == []
    interior = find_interior(deck)
    assert (interior.storeys, interior.rooms, interior.doors) == ((), (), ())


def test_a_stray_point_far_away_is_refused() -> None:
    """One point 20 km off the building would make its storey's plan 400 km²: refused, saying
    how far the storey spans and what to do, before any grid is made."""
    points = face_cloud(irregular(floors=(12.0,), furnished=False), 0.2)
    points = np.vstack([points, [[20_000.0, 5.0, 13.0]]])
    with pytest.raises(ValueError, match=r"storey 1 spans 20000 m x 14 m: more than "
                                         r"33,554,432 cells of 0.1 m; crop the cloud"):
        find_interior(points)


def test_bad_input_is_refused() -> None:
    """Points that are not (N, 3), or normals not shaped like them: a ValueError saying the
    shape."""
    with pytest.raises(ValueError, match=r"\(N, 3\) array, not \(4, 2\)"):
        find_interior(np.zeros((4, 2)))
    with pytest.raises(ValueError, match=r"normals must be shaped like the points \(4, 3\)"):
        find_interior(np.zeros((4, 3)), normals=np.zeros((3, 3)))
