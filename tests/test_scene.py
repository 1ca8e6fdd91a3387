"""A mission's scene: the target among the furniture, patrols and movers in both fidelities,
furniture blocking sight, determinism, and custom catalogues."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from astralis_des import Mission, Simulation, load_mission
from astralis_des.cli import main
from astralis_des.kernel.robot import Robot
from astralis_des.mission.draws import AVATAR_VALUES
from astralis_des.sensing import GeometricSensor
from astralis_des.view import View
from astralis_des.world.catalogue import default_catalogue
from astralis_des.world.clutter import Clutter, Placed
from astralis_des.world.model import World
from astralis_des.world.scene import Scene

ROOT = Path(__file__).resolve().parents[1]


def overlaps(a: Placed | tuple, b: Placed) -> bool:
    lo, hi = (a.box.lo, a.box.hi) if isinstance(a, Placed) else a
    return all(lo[k] < b.box.hi[k] and b.box.lo[k] < hi[k] for k in range(2))


def target_box(sim: Simulation) -> tuple[tuple[float, ...], tuple[float, ...]]:
    w, d = (1.8, 0.6) if sim.target.avatar["activity"] == "laying" else (0.5, 0.5)
    x, y, _ = sim.target.start
    return (x - w / 2, y - d / 2), (x + w / 2, y + d / 2)


def test_the_target_stands_on_free_floor(urban_search: Mission) -> None:
    """Over 25 seeds the target never overlaps furniture and stays inside its room."""
    for seed in range(25):
        sim = Simulation(urban_search.with_changes(seed=seed))
        room = sim.world.rooms[sim.target.room]
        assert room.box.contains(sim.target.start)
        box = target_box(sim)
        assert not any(overlaps(box, p) for p in sim.scene.clutter(sim.target.room).placed)


def test_target_attributes_come_from_table_ii(urban_search: Mission) -> None:
    """Drawn attributes are always among the paper's Table II values."""
    for seed in range(25):
        avatar = Simulation(urban_search.with_changes(seed=seed)).target.avatar
        assert all(avatar[key] in values for key, values in AVATAR_VALUES.items())


def test_a_fixed_target_moves_furniture_aside(world: World) -> None:
    """A target put where furniture would stand displaces it; the report says so."""
    scene = Scene(world, dict.fromkeys(world.rooms, 1.0), 3, default_catalogue())
    scene.furnish(["A.2.1.2"])
    first = scene.clutter("A.2.1.2").placed[0]
    scene2 = Scene(world, dict.fromkeys(world.rooms, 1.0), 3, default_catalogue())
    scene2.place_target("A.2.1.2", {"activity": "idle"}, first.center)
    scene2.furnish(["A.2.1.2"])
    placed = scene2.clutter("A.2.1.2").placed
    assert first not in placed
    assert ("A.2.1.2", first.kind, "moved aside for the target") in scene2.skipped()


def test_the_same_seed_furnishes_the_same_way(world: World) -> None:
    """Same seed and messiness: identical furniture; another seed: different furniture."""
    def furniture(seed: int) -> list[Placed]:
        return Scene(world, dict.fromkeys(world.rooms, 0.7), seed,
                     default_catalogue()).furnish_all()

    assert furniture(5) == furniture(5)
    assert furniture(5) != furniture(6)
    assert len(furniture(5)) > 50


def test_furniture_counts_grow_with_messiness(urban_search: Mission) -> None:
    """A mission at messiness 0 has empty rooms; at 1 it has plenty."""
    def count(messiness: float) -> int:
        mission = urban_search.with_changes(rooms={"set": {
            rid: {"messiness": messiness} for rid in urban_search.world.rooms}})
        return len(Simulation(mission).scene.furnish_all())

    assert count(0.0) == 0
    assert count(1.0) > 150


def test_a_cabinet_between_robot_and_target_hides_it(world: World) -> None:
    """The target behind a cabinet is not seen; without the cabinet it is."""
    room = world.rooms["A.1.1.2"]  # north side: door at y=79.5, room y 79.6..86.4
    target = (room.center[0], 85.0, room.box.lo[2] + 0.5)
    eye = np.array([room.center[0], 81.0, room.box.lo[2] + 0.5])
    cabinet = Placed("cabinet", room.id, (room.center[0], 83.0, 1.0), (1.2, 0.5, 2.0), 0.0)
    robot = Robot("r", "ugv", 1.0, View.of_kind("ugv"), 0.5, eye, heading=np.pi / 2)

    def seen(with_cabinet: bool) -> bool:
        scene = Scene(world, dict.fromkeys(world.rooms, 0.0), 0, default_catalogue())
        scene.set_clutter(room.id, Clutter((cabinet,) if with_cabinet else (), ()))
        sensor = GeometricSensor(scene, scene.place_target(room.id, {"activity": "idle"},
                                                           target))
        return sensor.sighting_from(robot, eye, 0.0) is not None

    assert seen(False) and not seen(True)


def patrolling(fidelity: str) -> Mission:
    mission = load_mission(ROOT / "missions" / "fig7.yaml")
    return mission.with_changes(fidelity=fidelity, target={
        "room": "A.1.1.2", "avatar": {"activity": "patrolling", "color": "red"}},
        scene={"movers": 2})


@pytest.mark.parametrize("fidelity", ["kinematic", "physics"])
def test_patrolling_avatars_and_movers_move(fidelity: str) -> None:
    """A patrolling target walks its room's loop at 1 m/s, movers pace their corridors; in
    physics their bodies move with them."""
    sim = Simulation(patrolling(fidelity))
    target = sim.target
    room = sim.world.rooms["A.1.1.2"]
    track = target.positions_at(np.arange(0.0, 20.0, 0.5))
    assert all(room.box.contains(p) for p in track)
    assert np.linalg.norm(np.diff(track, axis=0), axis=1).sum() == pytest.approx(19.5, abs=0.6)
    for mover in sim.scene.movers:
        corridor = next(s.box for s in sim.world.spaces.values() if s.kind == "corridor"
                        and s.box.contains(mover.position_at(0.0)))
        path = mover.positions_at(np.arange(0.0, 20.0, 0.5))
        assert all(corridor.contains(p) for p in path)
        assert np.ptp(path[:, 0]) > 0.5
    if fidelity == "physics":  # each body is where its loop says, at the physics time
        bodies = sim.cosim.movers
        assert {m.id for m, _ in bodies} >= {"target", "obstacle:0", "obstacle:1"}
        sim.start()
        for until in (2.0, 6.0):
            sim.advance(until)
            near = sim.cosim.local.near  # the movers near a moving robot are kept moving
            assert near
            for mover, body in (bodies[i] for i in near):
                where = sim.cosim.client.call("getBasePositionAndOrientation", body)[0]
                assert np.allclose(where, mover.position_at(sim.cosim.movers_time), atol=1e-6)
            assert sim.cosim.t - sim.cosim.movers_time < 0.04  # updated at 30 Hz
        sim.finish()


def test_a_custom_catalogue_is_used(tmp_path: Path) -> None:
    """A mission's scene.catalogue replaces the packaged catalogue."""
    catalogue = tmp_path / "only_plants.yaml"
    catalogue.write_text("items:\n  potted_plant: {size_min: [0.3, 0.3, 0.6], "
                         "size_max: [0.4, 0.4, 1.0], per_10m2_at_full: 3}\n"
                         "avatars: {per_room_at_full: 0}\n", encoding="utf-8")
    text = (ROOT / "missions" / "fig7.yaml").read_text(encoding="utf-8").replace(
        "world: ../worlds/urban_default.yaml", f"world: {ROOT / 'worlds/urban_default.yaml'}")
    mission_file = tmp_path / "mission.yaml"
    mission_file.write_text(text + f"scene:\n  catalogue: {catalogue.name}\n", encoding="utf-8")
    sim = Simulation(load_mission(mission_file))
    sim.scene.furnish(["A.1.1.2"])
    kinds = {p.kind for p in sim.scene.clutter("A.1.1.2").placed}
    assert kinds == {"potted_plant"}


def test_a_bad_catalogue_is_one_line_naming_its_key(tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    """An unknown furniture type in a mission's catalogue: exit 2, file, line and key."""
    catalogue = tmp_path / "bad.yaml"
    catalogue.write_text("items:\n  sofa: {size_min: [1, 1, 1], size_max: [2, 1, 1], "
                         "per_10m2_at_full: 1}\n", encoding="utf-8")
    text = (ROOT / "missions" / "fig7.yaml").read_text(encoding="utf-8").replace(
        "world: ../worlds/urban_default.yaml", f"world: {ROOT / 'worlds/urban_default.yaml'}")
    mission_file = tmp_path / "mission.yaml"
    mission_file.write_text(text + "scene:\n  catalogue: bad.yaml\n", encoding="utf-8")
    assert main(["validate", str(mission_file)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"error: {catalogue}:2: items.sofa: unknown key 'sofa'")


def test_world_show_writes_a_furnished_recording(tmp_path: Path,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    """`astralis world show` furnishes every room and writes a recording that loads."""
    out = tmp_path / "offices.rrd"
    code = main(["world", "show", str(ROOT / "worlds" / "fig4_offices.yaml"),
                 "--messiness", "0", "0.5", "1", "-o", str(out)])
    printed = capsys.readouterr().out
    assert code == 0 and out.is_file()
    assert printed.startswith(f"{out}: 3 rooms furnished: ")
    assert "chair" in printed
    if shutil.which("rerun"):
        assert subprocess.run(["rerun", "rrd", "verify", str(out)],
                              capture_output=True).returncode == 0


def test_world_show_refuses_a_messiness_outside_0_1(tmp_path: Path,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    """Messiness 1.5: one line naming --messiness, exit 2, nothing written."""
    out = tmp_path / "w.rrd"
    code = main(["world", "show", str(ROOT / "worlds" / "fig4_offices.yaml"),
                 "--messiness", "1.5", "-o", str(out)])
    assert code == 2
    assert capsys.readouterr().err.strip() == "error: --messiness: 1.5 is outside [0, 1]"
    assert not out.exists()


def test_items_a_room_has_no_place_for_are_events(urban_search: Mission, tmp_path: Path) -> None:
    """At messiness 1 some avatars find no spot: each is a clutter_skipped event, logged
    after mission_start and written to events.jsonl like any other."""
    mission = urban_search.with_changes(rooms={"set": {
        rid: {"messiness": 1.0} for rid in urban_search.world.rooms}})
    result = Simulation(mission, out_dir=tmp_path).run()
    skipped = [e for e in result.events if e["kind"] == "clutter_skipped"]
    assert skipped and all(e["reason"] and e["item"] and e["room"] for e in skipped)
    assert result.events[0]["kind"] == "mission_start"
    lines = (tmp_path / "events.jsonl").read_text(encoding="utf-8").splitlines()
    assert len(lines) == len(result.events)


def test_a_query_never_furnishes_a_room(world: World) -> None:
    """Furnishing is an explicit step: asking about a room not furnished yet is refused and
    changes nothing; furnishing tells the listeners once, however often it is asked."""
    told: list[str] = []
    scene = Scene(world, dict.fromkeys(world.rooms, 1.0), 3, default_catalogue())
    scene.listeners.append(lambda room, clutter: told.append(room))
    with pytest.raises(LookupError, match=r"room A\.2\.1\.2 is not furnished yet"):
        scene.clutter("A.2.1.2")
    with pytest.raises(LookupError):
        scene.still_boxes(["A.2.1.2"])
    assert scene.furnished_rooms() == [] and told == []
    scene.furnish(["A.2.1.2", "A.1.1.1"])
    scene.furnish(["A.2.1.2"])
    assert told == ["A.2.1.2", "A.1.1.1"]
    assert scene.furnished_rooms() == ["A.1.1.1", "A.2.1.2"]
    assert len(scene.clutter("A.2.1.2").placed) > 0
