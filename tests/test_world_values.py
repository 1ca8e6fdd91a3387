"""World files are checked like missions (issue 39): finite, positive sizes and origins, rooms a
robot fits in, buildings on the site, and starts and timeline points that are neither inside a
solid nor off the site, the error naming the nearest free point. ``validate`` and ``run`` refuse
the same things, with one line ``error: FILE:LINE: KEY: message`` and exit code 2."""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass
from pathlib import Path

import pytest

from astralis_des.cli import main

# building A: x 20-36 (stairwell 20-24, two rooms of 4 m, lobby 32-36), y 20-29.5 (the corridor
# 20-22.5 along its south wall, the rooms north of it); the south wall is y 19.9-20.1
WORLD = """\
name: small
site: {size: [110, 70]}
buildings:
  - id: A
    origin: [20, 20]
    floors: 1
    segments: [{side: north, rooms: 2}]
obstacles:
  - {kind: tree, center: [10, 60], size: [1, 1, 6]}
"""
MISSION = """\
name: m
world: world.yaml
time_limit: 600
team:
  - {id: op1, kind: human, start: [5, 12, 0]}
  - {id: ugv1, kind: ugv, start: [8, 12, 0]}
"""
MOVE = "timeline:\n  - {at: 5, event: command, robot: %s, action: move, params: %s}\n"


@dataclass(frozen=True)
class Bad:
    """A world (or mission) edit that must be refused: the key and words of the one line."""

    id: str
    world: tuple[str, str] | None = None  # (old, new) in WORLD
    mission: tuple[str, str] | None = None  # (old, new) in MISSION
    append: str = ""  # added to the mission
    key: str = ""
    says: tuple[str, ...] = ()
    in_world: bool = True  # the error names the world file (else the mission file)
    marker: str | None = None  # the line the error names holds this text
    point: str = ""  # the point refused, as the mission writes it


BAD = [
    Bad("nan_origin", world=("origin: [20, 20]", "origin: [.nan, 20]"),
        key="buildings[0].origin[0]", says=("finite number",), marker="origin:"),
    Bad("infinite_site", world=("size: [110, 70]", "size: [.inf, 70]"),
        key="site.size[0]", says=("finite number",), marker="site:"),
    Bad("negative_site", world=("size: [110, 70]", "size: [110, -70]"),
        key="site.size[1]", says=("greater than 0",), marker="site:"),
    Bad("huge_site", world=("size: [110, 70]", "size: [1e300, 70]"),
        key="site.size[0]", says=("less than or equal to 1000000",), marker="site:"),
    Bad("nan_floor_height", world=("floors: 1", "floors: 1\n    floor_height: .nan"),
        key="buildings[0].floor_height", says=("finite number",), marker="floor_height"),
    Bad("tiny_room", world=("floors: 1", "floors: 1\n    room_size: [1.0e-9, 7]\n"
                                          "    door_width: 1.0e-10"),
        key="buildings[0].room_size", says=("smaller than a robot", "1.01"),
        marker="room_size"),
    Bad("walls_thicker_than_rooms", world=("floors: 1", "floors: 1\n    wall_thickness: 5"),
        key="buildings[0].room_size", says=("smaller than a robot",), marker="id: A"),
    Bad("building_outside_the_site", world=("origin: [20, 20]", "origin: [100, 20]"),
        key="buildings[0].origin", says=("reaches outside the site",), marker="origin:"),
    Bad("building_west_of_the_site", world=("origin: [20, 20]", "origin: [-5, 20]"),
        key="buildings[0].origin", says=("reaches outside the site",), marker="origin:"),
    Bad("nan_obstacle", world=("center: [10, 60]", "center: [10, .nan]"),
        key="obstacles[0].center[1]", says=("finite number",), marker="kind: tree"),
    Bad("infinite_obstacle", world=("size: [1, 1, 6]", "size: [1, .inf, 6]"),
        key="obstacles[0].size[1]", says=("finite number",), marker="kind: tree"),
    Bad("negative_obstacle", world=("size: [1, 1, 6]", "size: [1, -1, 6]"),
        key="obstacles[0].size[1]", says=("greater than 0",), marker="kind: tree"),
    Bad("start_inside_a_wall", mission=("start: [5, 12, 0]", "start: [25, 20, 0]"),
        key="team[0].start", in_world=False, marker="start: [25, 20, 0]",
        point="[25, 20, 0]", says=("[25, 20, 0] is inside a wall of building A",
                                     "the nearest free point is [25, 19.6, 0]")),
    Bad("start_by_a_wall", mission=("start: [8, 12, 0]", "start: [25, 20.3, 0]"),
        key="team[1].start", in_world=False, marker="start: [25, 20.3, 0]",
        point="[25, 20.3, 0]", says=("too close to a wall of building A", "a ugv",
              "the nearest free point is [25, 20.5, 0]")),
    Bad("start_inside_a_tree", mission=("start: [5, 12, 0]", "start: [10, 60, 0]"),
        key="team[0].start", in_world=False, marker="start: [10, 60, 0]",
        point="[10, 60, 0]", says=("inside a tree", "the nearest free point is [")),
    Bad("start_outside_the_site", mission=("start: [5, 12, 0]", "start: [130, 12, 0]"),
        key="team[0].start", in_world=False, marker="start: [130, 12, 0]",
        point="[130, 12, 0]", says=("outside the world", "the nearest free point is [110, 12, 0]")),
    Bad("move_into_a_wall", append=MOVE % ("op1", "{x: 25, y: 20}"),
        key="timeline[0].params", in_world=False, marker="action: move",
        point="{x: 25, y: 20}", says=("[25, 20, 0] is inside a wall of building A",
                                      "the nearest free point is [25, 19.6, 0]")),
    Bad("move_off_the_site", append=MOVE % ("ugv1", "{x: 5, y: -40}"),
        key="timeline[0].params", in_world=False, marker="action: move",
        point="{x: 5, y: -40}", says=("outside the world", "the nearest free point is [5, 0, 0]")),
]


def write(folder: Path, bad: Bad) -> tuple[Path, Path]:
    world, mission = WORLD, MISSION
    if bad.world is not None:
        assert world.count(bad.world[0]) == 1
        world = world.replace(*bad.world)
    if bad.mission is not None:
        assert mission.count(bad.mission[0]) == 1
        mission = mission.replace(*bad.mission)
    (folder / "world.yaml").write_text(world, encoding="utf-8")
    (folder / "mission.yaml").write_text(mission + bad.append, encoding="utf-8")
    return folder / "mission.yaml", folder / ("world.yaml" if bad.in_world else "mission.yaml")


def refusal(command: str, mission: Path, capsys: pytest.CaptureFixture[str]) -> str:
    """The one line of ``astralis COMMAND`` (exit 2, nothing written)."""
    out = mission.parent / "out"
    argv = ["validate", str(mission)] if command == "validate" else \
        ["run", str(mission), "--out", str(out), "--no-recording", "--quiet"]
    code = main(argv)
    captured = capsys.readouterr()
    assert code == 2, captured.out + captured.err
    assert "Traceback" not in captured.err
    lines = captured.err.splitlines()
    assert len(lines) == 1, captured.err
    assert not out.exists()
    return lines[0]


@pytest.mark.parametrize("command", ["validate", "run"])
@pytest.mark.parametrize("bad", BAD, ids=[b.id for b in BAD])
def test_a_bad_world_value_or_point_is_one_line(bad: Bad, command: str, tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    """validate and run refuse it alike, naming the file, the line and the key."""
    mission, named = write(tmp_path, bad)
    line = refusal(command, mission, capsys)
    match = re.match(r"^error: (.+?):(\d+): (\S+): (.*)$", line)
    assert match, line
    assert Path(match[1]) == named
    assert match[3] == bad.key, line
    if bad.marker is not None:
        text = named.read_text(encoding="utf-8").splitlines()
        assert bad.marker in text[int(match[2]) - 1], line
    for words in bad.says:
        assert words in match[4], line


def test_the_nearest_free_point_is_free(tmp_path: Path,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    """The point an error names as the nearest free one validates in its place."""
    for bad in (b for b in BAD if b.point):
        mission, _ = write(tmp_path, bad)
        line = refusal("validate", mission, capsys)
        found = re.search(r"the nearest free point is \[([^]]*)\]", line)
        assert found is not None, line
        x, y, z = found[1].split(", ")
        text = mission.read_text(encoding="utf-8")
        new = f"[{x}, {y}, {z}]" if bad.point.startswith("[") else f"{{x: {x}, y: {y}, z: {z}}}"
        mission.write_text(text.replace(bad.point, new), encoding="utf-8")
        assert main(["validate", str(mission)]) == 0, (bad.id, capsys.readouterr().err)
        capsys.readouterr()


def test_a_sane_world_and_mission_validate(tmp_path: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    """The cases above differ from a good pair by their one edit."""
    mission, _ = write(tmp_path, Bad("none"))
    assert main(["validate", str(mission)]) == 0
    assert capsys.readouterr().out.startswith("ok:")


def test_a_run_never_writes_nan_into_its_summary(tmp_path: Path,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    """The smallest room a world may have still gives finite coverage (it wrote NaN when a
    room 1e-9 m wide was accepted)."""
    world = WORLD.replace("floors: 1", "floors: 1\n    room_size: [1.21, 2]\n    door_width: 0.9")
    (tmp_path / "world.yaml").write_text(world, encoding="utf-8")
    mission = tmp_path / "mission.yaml"
    mission.write_text(MISSION.replace("kind: human, start: [5, 12, 0]",
                                       "kind: uav, start: [5, 12, 0]"), encoding="utf-8")
    code = main(["run", str(mission), "--out", str(tmp_path / "out"), "--no-recording",
                 "--quiet"])
    assert code == 0, capsys.readouterr().err
    summary = (tmp_path / "out" / "summary.json").read_text(encoding="utf-8")
    assert "NaN" not in summary and "Infinity" not in summary
    values = json.loads(summary)

    def numbers(value: object) -> list[float]:
        if isinstance(value, dict):
            return [n for v in value.values() for n in numbers(v)]
        if isinstance(value, list):
            return [n for v in value for n in numbers(v)]
        return [value] if isinstance(value, float) else []

    assert all(math.isfinite(n) for n in numbers(values))


@pytest.mark.parametrize("name", ["..", ".", "a/b", "../x", "/tmp/x"])
def test_a_mission_name_is_a_plain_file_name(name: str, tmp_path: Path,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    """``name`` becomes the output folder out/NAME: ``..`` wrote into the working folder."""
    mission, _ = write(tmp_path, Bad("name", mission=("name: m", f"name: {json.dumps(name)}")))
    line = refusal("validate", mission, capsys)
    assert re.match(rf"^error: {re.escape(str(mission))}:1: name: ", line), line
    assert "plain file name" in line or "should match pattern" in line, line
