"""An indoor scan or model becomes a world searched room by room (issue 42): ``astralis world
import --indoor`` on a scan of the default world's building A, or on its model as a mesh,
writes its storeys, rooms, doors and stairs; the twin's rooms are the original's, the paper's
team searches it in both fidelities with the same first-round Eq. 1 assignment, and a corrected
world file is checked line by line. A scan whose walls run off its axes is turned back; one
with no storey is refused."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from indoor_scan import write_mesh
from indoor_scenes import building_a, face_cloud
from terminal import run_cli

from astralis_des import Simulation, load_mission
from astralis_des.errors import InputError
from astralis_des.world.build import load_world, read_world

ROOT = Path(__file__).resolve().parents[1]
MARGIN = 40  # m of site round the building: room for the team's starts outside it


def write_ply(path: Path, points: np.ndarray) -> Path:
    """A binary little-endian PLY of ``points`` (float32 x, y, z)."""
    header = ("ply\nformat binary_little_endian 1.0\n"
              f"element vertex {len(points)}\nproperty float x\nproperty float y\n"
              "property float z\nend_header\n")
    path.write_bytes(header.encode("ascii") + points.astype("<f4").tobytes())
    return path


@pytest.fixture(scope="module", params=["cloud", "mesh"])
def twin(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory
         ) -> tuple[Path, str]:
    """Building A imported with --indoor, from a scan (a PLY cloud) or from its model (an OBJ
    mesh): the world file and what the CLI printed."""
    folder = tmp_path_factory.mktemp(request.param)
    if request.param == "cloud":
        source = write_ply(folder / "a.ply", face_cloud(building_a(), 0.07))
    else:
        source = write_mesh(building_a(), folder / "a.obj")
    code, out, err = run_cli("world", "import", str(source), "-o", str(folder / "a.yaml"),
                             "--indoor", "--margin", str(MARGIN))
    assert code == 0, err
    return folder / "a.yaml", out


def offset(world_file: Path) -> np.ndarray:
    """Where the twin's (0, 0) lies in the scan's (the default world's) coordinates."""
    doc = yaml.safe_load(world_file.read_text(encoding="utf-8"))
    return np.array(doc["source"]["offset"][:2])


def test_the_import_finds_building_a(twin: tuple[Path, str]) -> None:
    path, out = twin
    assert "18 rooms" in " ".join(out.split())
    world, original = load_world(path), load_world(ROOT / "worlds" / "urban_default.yaml")
    want = sorted(r for r in original.rooms if r.startswith("A."))
    assert sorted(world.rooms) == want
    shift = offset(path)
    for rid in want:  # each room where the original's is, inside its walls
        mine, theirs = world.rooms[rid].box, original.rooms[rid].box
        assert np.allclose(np.add(mine.lo[:2], shift), theirs.lo[:2], atol=0.15), rid
        assert np.allclose(np.add(mine.hi[:2], shift), theirs.hi[:2], atol=0.15), rid
        assert mine.lo[2] == pytest.approx(theirs.lo[2], abs=0.15)
        door, true_door = world.rooms[rid].door, original.rooms[rid].door
        assert np.allclose(np.add(door.center[:2], shift), true_door.center[:2], atol=0.3)
        assert door.width == pytest.approx(true_door.width, abs=0.2)
    assert world.segment_order("A") == original.segment_order("A")
    assert [s.kind for s in world.spaces.values()].count("passage") == 3  # a corridor a storey
    assert world.interior is not None
    assert world.interior.storeys == pytest.approx((0.0, 3.5, 7.0), abs=0.05)


def mission_in(world_file: Path, tmp: Path, fidelity: str = "kinematic") -> Path:
    """missions/urban_search.yaml with the twin for its world and its team's starts moved by
    the import's offset."""
    doc: dict[str, Any] = yaml.safe_load((ROOT / "missions" / "urban_search.yaml").read_text())
    doc["world"] = str(world_file)
    doc["fidelity"] = fidelity
    shift = offset(world_file)
    for member in doc["team"]:
        member["start"] = [round(float(member["start"][0] - shift[0]), 3),
                           round(float(member["start"][1] - shift[1]), 3), 0]
    path = tmp / f"twin_{fidelity}.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
    return path


def first_round(result: Any) -> list[tuple[str, str, str]]:
    return [(m["agent"], m["room"], m["action"]) for m in result.rounds[0]["matching"]]


def test_the_paper_team_searches_the_twin_as_the_original(twin: tuple[Path, str],
                                                          tmp_path: Path) -> None:
    """Eq. 1's first round is the original world's; the target is found, no task fails: in
    both fidelities on the scan's twin, in the kinematic on the model's (its physics is the
    scan's: walls made from the same places and doors)."""
    original = Simulation(load_mission(ROOT / "missions" / "urban_search.yaml")).run()
    scanned = twin[0].parent.name.startswith("cloud")
    for fidelity in ("kinematic", "physics") if scanned else ("kinematic",):
        result = Simulation(load_mission(mission_in(twin[0], tmp_path, fidelity))).run()
        assert result.rounds[0]["rooms"] == original.rounds[0]["rooms"]
        assert first_round(result) == first_round(original), fidelity
        assert result.found and result.found_by == original.found_by
        failed = [e for e in result.events if e["kind"] == "task_finished"
                  and e["status"] == "failed"]
        assert failed == [], fidelity


def test_routes_take_the_stairs_to_the_top_storey(twin: tuple[Path, str]) -> None:
    """From outside, each kind reaches a room on storey 3 by the entrance and the stairs."""
    world = load_world(twin[0])
    outside = world.interior.footprint.hi[0] + 5.0 if world.interior else 0.0
    start = (outside, world.interior.footprint.center[1] if world.interior else 0.0, 0.0)
    for kind in ("uav", "ugv", "human"):
        route = world.router.route(start, world.rooms["A.3.1.2"].center, kind)
        assert route is not None, kind
        assert route[-1][2] == pytest.approx(world.interior.storeys[2] if world.interior else 0)
        assert np.all(np.diff(route[:, 2]) >= -1e-9)  # up, never down


def edited(world_file: Path, old: str, new: str, tmp: Path) -> Path:
    text = world_file.read_text(encoding="utf-8")
    assert old in text
    path = tmp / world_file.name
    for sidecar in world_file.parent.glob(f"{world_file.stem}.*.*"):
        (tmp / sidecar.name).write_bytes(sidecar.read_bytes())
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    return path


def line_of(path: Path, text: str) -> int:
    return next(n for n, line in enumerate(path.read_text().splitlines(), 1) if text in line)


def test_a_corrected_world_is_checked_line_by_line(twin: tuple[Path, str],
                                                   tmp_path: Path) -> None:
    """A door to a place that is not there, and a room left with no door, are one line that
    names the file, the line and the key."""
    path = twin[0]
    door = re.search(r"between: \[A\.1\.2\.1, (A\.1\.0\.\d)\]", path.read_text())
    assert door is not None
    corridor = door.group(1)
    bad = edited(path, door.group(0), "between: [A.1.2.1, A.1.0.9]", tmp_path)
    with pytest.raises(InputError) as err:
        read_world(bad)
    assert err.value.line == line_of(bad, "A.1.0.9") and "no place 'A.1.0.9'" in str(err.value)
    assert "interior.doors[" in str(err.value)
    lonely = edited(path, door.group(0), f"between: [A.1.2.2, {corridor}]", tmp_path)
    with pytest.raises(InputError, match=r"no door leads into 'A.1.2.1'") as err:
        read_world(lonely)
    assert err.value.line == line_of(lonely, "id: A.1.2.1,")
    code, _, err_text = run_cli("validate", str(lonely))
    assert code == 2 and len(err_text.strip().splitlines()) == 1
    assert f"{lonely}:{err.value.line}: interior.places[" in err_text
    assert "no door leads into 'A.1.2.1'" in err_text
    code, out, _ = run_cli("validate", str(path))
    assert code == 0 and "world 'a', 18 rooms in 6 segments; an interior of 3 storeys" in out


def test_a_scan_with_no_storey_is_refused_in_one_line(tmp_path: Path) -> None:
    """A flat field has no storey: no room is made up."""
    rng = np.random.default_rng(0)
    ground = np.column_stack([rng.uniform(0, 30, 50_000), rng.uniform(0, 30, 50_000),
                              rng.normal(0, 0.02, 50_000)])
    code, _, err = run_cli("world", "import", str(write_ply(tmp_path / "f.ply", ground)),
                           "-o", str(tmp_path / "f.yaml"), "--indoor")
    assert code == 2
    assert "--indoor: no storey found" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "f.yaml").exists()


def test_a_scan_turned_off_the_axes_is_turned_back(tmp_path: Path) -> None:
    """Building A scanned with its walls at 23 degrees to the scan's axes: the import turns it
    back (heading 23), finds the same 18 rooms and ids, and a room's centre in the file's
    frame is the world's turned by the heading, plus the offset."""
    angle = np.radians(23.0)
    turn = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    points = face_cloud(building_a(), 0.08)
    points[:, :2] = points[:, :2] @ turn.T
    code, out, err = run_cli("world", "import", str(write_ply(tmp_path / "t.ply", points)),
                             "-o", str(tmp_path / "t.yaml"), "--indoor")
    assert code == 0, err
    assert "turned by -23.0 degrees" in " ".join(out.split())
    doc = yaml.safe_load((tmp_path / "t.yaml").read_text())
    assert doc["interior"]["heading"] == pytest.approx(23.0, abs=0.1)
    world, original = load_world(tmp_path / "t.yaml"), load_world(ROOT / "worlds" /
                                                                  "urban_default.yaml")
    want = sorted(r for r in original.rooms if r.startswith("A."))
    assert sorted(world.rooms) == want
    for rid in want:
        mine = turn @ np.array(world.rooms[rid].box.center[:2]) + offset(tmp_path / "t.yaml")
        theirs = turn @ np.array(original.rooms[rid].box.center[:2])
        assert np.allclose(mine, theirs, atol=0.2), rid


def test_a_room_that_is_no_rectangle_is_furnished_and_searched_inside_its_outline() -> None:
    """The hospital's stores by the stairs take in the landing, and two rooms have niches:
    rooms that are no rectangle. Their furniture stands inside the outline, and a UAV's spiral
    and a walker's loop keep to it."""
    from astralis_des.world import coverage as cov
    from astralis_des.world.catalogue import default_catalogue
    from astralis_des.world.geometry import inside_polygon
    from astralis_des.world.scene import Scene

    world = load_world(ROOT / "worlds" / "hospital.yaml")
    shaped = [r for r in world.rooms.values() if r.outline]
    assert len(shaped) == 4
    scene = Scene(world, dict.fromkeys(world.rooms, 1.0), 3, default_catalogue())
    scene.furnish([r.id for r in shaped])
    for room in shaped:
        outline = np.asarray(room.outline)
        items = scene.clutter(room.id).in_room(room.id)
        assert len(items) >= 2
        centres = np.array([[*item.box.center[:2]] for item in items])
        assert inside_polygon(centres, outline).all(), room.id
        spiral = cov.within(cov.spiral(room.box, 1.0, margin=0.4), room.outline, 0.4)
        walk = cov.within(cov.loop(room.box, 0.6), room.outline, 0.6)
        for path in (spiral, walk):
            assert len(path) >= 4 and inside_polygon(path, outline).all(), room.id
        assert inside_polygon(np.array([room.center[:2]]), outline)[0]


def test_routes_in_the_hospital_keep_inside_its_walls() -> None:
    """Its hall and corridors are one place that is not convex (round the rooms in its
    middle): from the entrance hall every kind reaches every room, and no leg of a route
    passes through a wall."""
    from astralis_des.world.geometry import segments_hit_boxes
    from astralis_des.world.interior_routes import reflex_corners, visible

    world = load_world(ROOT / "worlds" / "hospital.yaml")
    walls = np.array([[s.box.lo, s.box.hi] for s in world.solids if s.kind == "wall"])
    start = np.array([22.5, 58.0, 0.0])
    for kind in ("uav", "ugv", "human"):
        for room in world.rooms.values():
            route = world.router.route(start, np.array(room.center), kind)
            assert route is not None, (kind, room.id)
            legs = route.copy()
            legs[:, 2] = 0.5  # under the lintels
            assert not segments_hit_boxes(legs[:-1], legs[1:], walls).any(), (kind, room.id)
    square = np.array([(0, 0), (4, 0), (4, 4), (0, 4)], dtype=float)
    ell = np.array([(0, 0), (6, 0), (6, 3), (3, 3), (3, 6), (0, 6)], dtype=float)
    assert len(reflex_corners(square)) == 0 and len(reflex_corners(ell)) == 1
    assert visible(np.array([[1, 1], [5, 1]]), np.array([[5, 1], [1, 5]]), ell).tolist() == \
        [True, False]


@pytest.mark.parametrize("seed", [1, 3, 6])
def test_the_hospital_mission_finds_the_target_with_no_failed_task(seed: int) -> None:
    """Other seeds of missions/hospital_search.yaml, kinematic: a patrolling bystander in a
    room that is no rectangle once ended a run in a traceback."""
    mission = load_mission(ROOT / "missions" / "hospital_search.yaml").with_changes(seed=seed)
    result = Simulation(mission).run()
    assert result.found
    assert not [e for e in result.events if e["kind"] == "task_finished"
                and e["status"] == "failed"]
