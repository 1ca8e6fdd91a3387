"""Bad input: one line on stderr naming file, line and key; exit code 2; no traceback; no outputs.

Each case edits a copy of ``missions/urban_search.yaml`` (with ``world:`` made absolute, since the
copy lives in ``tmp_path``) and runs ``astralis run`` / ``astralis validate`` on it in-process.
Library bugs are strict xfails whose reason starts with ``BUG:``.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pytest

from astralis_des.cli import main

ROOT = Path(__file__).parents[1]
WORLD = ROOT / "worlds" / "urban_default.yaml"
MISSION = ROOT / "missions" / "urban_search.yaml"


def base_text() -> str:
    """urban_search.yaml with ``world:`` pointing at the absolute default world."""
    text = MISSION.read_text(encoding="utf-8")
    new, count = re.subn(r"(?m)^world:.*$", f"world: {json.dumps(str(WORLD))}", text)
    assert count == 1
    return new


def line_of(text: str, needle: str, nth: int = 1) -> int:
    """1-based line of the ``nth`` line of ``text`` containing ``needle``."""
    hits = [i for i, line in enumerate(text.splitlines(), 1) if needle in line]
    assert len(hits) >= nth, f"{needle!r} not in the test mission"
    return hits[nth - 1]


def replace(old: str, new: str) -> Callable[[str], str]:
    def edit(text: str) -> str:
        assert text.count(old) == 1, f"{old!r} should occur once in the mission"
        return text.replace(old, new)

    return edit


def append(block: str) -> Callable[[str], str]:
    return lambda text: text.rstrip("\n") + "\n" + block


UAV2 = "{id: uav2, kind: uav, start: [92, 60, 0]}"
OP1_START = "start: [96, 66, 0]"


def member(**extra: object) -> Callable[[str], str]:
    """Add ``key: value`` pairs to uav2, the second team member (``team[1]``)."""
    fields = "".join(f", {k}: {v}" for k, v in extra.items())
    return replace(UAV2, UAV2[:-1] + fields + "}")


@dataclass(frozen=True)
class Case:
    id: str
    edit: Callable[[str], str] | None  # None: the mission file is not written at all
    marker: str | None = None  # the error's line is the line holding this text (None: no line)
    nth: int = 1  # ... its nth occurrence
    alt_markers: tuple[str, ...] = ()  # other lines that are also acceptable
    key: str | None = None  # the key named after FILE:LINE:
    key_prefix: bool = False  # accept a deeper key under ``key`` (team -> team[1].id)
    line_in_message: bool = False  # also accept the line named as "line N" in the message
    says: tuple[str, ...] = ()  # substrings of the message
    absent: tuple[str, ...] = ()  # substrings the message must not contain
    world: str | None = None  # text of a world file the mission uses instead of the default
    names_world: bool = False  # the error names the world file, not the mission file
    bug: str | None = None  # a known library bug: strict xfail with this reason

    def write(self, folder: Path) -> tuple[Path, str]:
        """Write the mission (and world) into ``folder``; the file the error should name."""
        path = folder / "mission.yaml"
        text = base_text()
        if self.world is not None:
            world = folder / "bad_world.yaml"
            world.write_text(self.world, encoding="utf-8")
            text = re.sub(r"(?m)^world:.*$", f"world: {json.dumps(str(world))}", text)
        if self.edit is None:
            return path, ""
        text = self.edit(text)
        path.write_text(text, encoding="utf-8")
        return (folder / "bad_world.yaml" if self.names_world else path), text


TIMELINE_CMD = "timeline:\n  - {at: 10, event: command, robot: uav1, action: %s}\n"

CASES = [
    Case("missing_file", None, says=("no such file",)),
    Case("empty_file", lambda _: "", says=("empty",)),
    Case("comments_only_file", lambda _: "# nothing here\n\n", says=("empty",)),
    Case("yaml_syntax_error", replace("seed: 42", "seed: 42: 43"), marker="seed: 42: 43",
         says=("YAML syntax error",)),
    Case("yaml_two_documents", append("---\nname: other\n"), marker="---",
         says=("YAML syntax error",)),
    Case("yaml_unclosed_bracket", replace("search: [A]", "search: [A"), marker="search: [A",
         says=("YAML syntax error",), line_in_message=True),
    Case("yaml_unclosed_brace", replace("start: [90, 60, 0]}", "start: [90, 60, 0]"),
         marker="start: [90, 60, 0]", says=("YAML syntax error",), line_in_message=True),
    Case("yaml_python_tag_on_scalar", replace("seed: 42", "seed: !!python/name:os.system 42"),
         marker="seed: !!python", says=("python/name:os.system",)),
    Case("yaml_python_tag_on_sequence",
         replace("search: [A]", "search: !!python/object/apply:os.system [A]"),
         marker="search: !!python", says=("python/object/apply",)),
    Case("yaml_recursive_alias", replace("search: [A]", "search: &s [A, *s]"),
         marker="search: &s"),
    Case("duplicate_key", replace("seed: 42\n", "seed: 42\nseed: 7\n"), marker="seed: 7",
         key="seed", says=("duplicate key 'seed'", f"line {line_of(base_text(), 'seed: 42')}")),
    Case("wrong_type", member(speed="fast"), marker=UAV2[:-1], key="team[1].speed",
         says=("'fast'",)),
    Case("unknown_member_key", member(sped=2), marker=UAV2[:-1], key="team[1].sped",
         says=("unknown key 'sped'", "did you mean 'speed'?")),
    Case("unknown_top_level_key", replace("seed: 42", "seeds: 3"), marker="seeds: 3",
         key="seeds", says=("unknown key 'seeds'", "did you mean 'seed'?")),
    Case("unknown_nested_key", replace("strategy: mixed", "stratgy: mixed"),
         marker="stratgy", key="assignment.stratgy", says=("did you mean 'strategy'?",)),
    Case("unknown_kind", replace("{id: uav2, kind: uav,", "{id: uav2, kind: robot,"),
         marker="id: uav2", key="team[1].kind", says=("robot", "'uav'", "'ugv'", "'human'")),
    Case("unknown_action", append(TIMELINE_CMD % "fly"), marker="action: fly",
         key="timeline[0].action", says=("a uav has no action 'fly'", "hover", "sweep_horizontal")),
    Case("unknown_action_close", append(TIMELINE_CMD % "hovr"), marker="action: hovr",
         key="timeline[0].action", says=("did you mean 'hover'?",)),
    Case("negative_hover", append(TIMELINE_CMD % "hover, params: {duration: -5}"),
         marker="duration: -5", key="timeline[0].params.duration",
         says=("hover: duration must be at least 0 (got -5)",)),
    Case("hover_duration_not_a_number", append(TIMELINE_CMD % "hover, params: {duration: abc}"),
         marker="duration: abc", key="timeline[0].params.duration",
         says=("hover: duration must be a number (got 'abc')",)),
    Case("unknown_action_parameter", append(TIMELINE_CMD % "hover, params: {seconds: 3}"),
         marker="seconds: 3", key="timeline[0].params.seconds",
         says=("hover has no parameter 'seconds' (its parameters: duration)",)),
    Case("unknown_strategy", replace("strategy: mixed", "strategy: mixd"),
         marker="strategy: mixd", key="assignment.strategy", says=("did you mean 'mixed'?",)),
    Case("unknown_search_segment", replace("search: [A]", "search: [C]"), marker="search: [C]",
         key="assignment.search[0]", says=("'C'",)),
    Case("room_in_rooms_set", append("rooms:\n  set:\n    A.1.1.9: {risk: 0.5}\n"),
         marker="A.1.1.9", key="rooms.set.A.1.1.9", says=("no room 'A.1.1.9'", "did you mean")),
    Case("room_in_target", append("target:\n  room: Z9\n"), marker="room: Z9",
         key="target.room", says=("no room 'Z9'",)),
    Case("room_in_timeline_room_change",
         append("timeline:\n  - {at: 10, event: room_change, room: Z9, risk: 0.2}\n"),
         marker="room: Z9", key="timeline[0].room", says=("no room 'Z9'",)),
    Case("room_in_timeline_command",
         append("timeline:\n  - at: 10\n    event: command\n    robot: uav1\n"
                "    action: hover\n    room: A.1.1.9\n"),
         marker="room: A.1.1.9", key="timeline[0].room", says=("no room 'A.1.1.9'",)),
    Case("room_as_team_start", replace(OP1_START, "start: lobby"), marker="start: lobby",
         key="team[3].start", says=("no room 'lobby'",)),
    Case("negative_speed", member(speed=-1), marker=UAV2[:-1], key="team[1].speed",
         says=("greater than 0", "-1")),
    Case("empty_team", lambda t: re.sub(r"(?ms)^team:\n(  - .*?\n)+", "team: []\n", t),
         marker="team: []", key="team", says=("at least 1",)),
    Case("missing_required_key", replace("{id: uav2, kind: uav, ", "{id: uav2, "),
         marker="id: uav2", key="team[1].kind", says=("required",)),
    Case("missing_world_file", lambda t: re.sub(r"(?m)^world:.*$", "world: nowhere.yaml", t),
         marker="world: nowhere.yaml", key="world", says=("no such world file", "nowhere.yaml")),
    Case("bad_world_file", lambda t: t,
         world=WORLD.read_text(encoding="utf-8").replace("buildings:", "buildngs:"),
         names_world=True, key="buildngs", says=("did you mean 'buildings'?",)),
    Case("unknown_timeline_event",
         append("timeline:\n  - {at: 10, event: explode, robot: uav1}\n"),
         marker="event: explode", key="timeline[0].event",
         says=("unknown event 'explode'", "fault", "command")),
    Case("unknown_timeline_event_block",
         append("timeline:\n  - at: 10\n    event: explode\n    robot: uav1\n"),
         marker="event: explode", key="timeline[0].event", says=("'explode'",)),
    Case("timeline_event_after_time_limit",
         append("timeline:\n  - {at: 99999, event: fault, robot: uav1}\n"),
         marker="at: 99999", key="timeline[0].at", says=("time_limit",)),
    Case("start_outside_world", replace(OP1_START, "start: [500, 500, 0]"),
         marker="start: [500, 500, 0]", key="team[3].start", says=("outside the world",)),
    Case("start_outside_world_plain_numbers", replace(OP1_START, "start: [500, 500, 0]"),
         marker="start: [500, 500, 0]", key="team[3].start", absent=("np.float64",)),
    Case("timeline_robot_not_in_team",
         append("timeline:\n  - {at: 10, event: fault, robot: uav9}\n"),
         marker="robot: uav9", key="timeline[0].robot", says=("no robot 'uav9'",)),
    Case("duplicate_team_ids", replace("{id: uav2,", "{id: uav1,"), marker="id: uav1", nth=2,
         alt_markers=("team:",), key="team", key_prefix=True, says=("uav1",)),
    # issue 19: each was a traceback (RecursionError, OSError, ValueError) or numpy warnings
    Case("nested_5000_deep", append("extra: " + "[" * 5000 + "]" * 5000 + "\n"),
         marker="extra: [[[", key="extra", says=("nested more than 64 levels deep",)),
    Case("name_of_a_million_characters", replace("name: urban_search", "name: " + "a" * 1_000_000),
         marker="name: aaa", key="name", says=("at most 200 characters", "1,000,000 characters")),
    Case("negative_seed", replace("seed: 42", "seed: -1"), marker="seed: -1", key="seed",
         says=("greater than or equal to 0",)),
    Case("coordinate_1e308", replace("start: [90, 60, 0]", "start: [1e308, 60, 0]"),
         marker="start: [1e308", key="team[0].start[0]", says=("less than or equal to",)),
    # issue 27: the pose sensors' keys and the site's geodetic origin
    Case("latitude_beyond_90", append("site: {latitude: 95, longitude: 4}\n"),
         marker="site: {latitude: 95", key="site.latitude", says=("less than or equal to 90",)),
    Case("unknown_sensor", member(sensors="{gps: {}}"), marker=UAV2[:-1],
         key="team[1].sensors.gps", says=("unknown key 'gps'",)),
    Case("gnss_rate_zero", member(sensors="{gnss: {rate: 0}}"), marker=UAV2[:-1],
         key="team[1].sensors.gnss.rate", says=("greater than 0",)),
    Case("lidar3d_no_channels", member(sensors="{lidar3d: {channels: 0}}"), marker=UAV2[:-1],
         key="team[1].sensors.lidar3d.channels", says=("greater than or equal to 1",)),
    Case("lidar3d_negative_range", member(sensors="{lidar3d: {range: -5}}"), marker=UAV2[:-1],
         key="team[1].sensors.lidar3d.range", says=("greater than 0",)),
    Case("lidar3d_field_of_view_over_180",
         member(sensors="{lidar3d: {vertical_fov: [-100, 90]}}"), marker=UAV2[:-1],
         key="team[1].sensors.lidar3d", key_prefix=True,
         says=("-90 <= low < high <= 90",)),
    Case("human_with_a_barometer", replace(OP1_START, OP1_START + ", sensors: {barometer: {}}"),
         marker=OP1_START, key="team[3]", key_prefix=True,
         says=("a human cannot carry a barometer",)),
]


def _params() -> list[object]:
    marks = {c.id: [pytest.mark.xfail(reason=c.bug, strict=True)] if c.bug else [] for c in CASES}
    return [pytest.param(c, id=c.id, marks=marks[c.id]) for c in CASES]


ERROR = re.compile(r"^error: (?P<file>.+?\.yaml)(?::(?P<line>\d+))?: (?P<rest>.*)$")


def check_error(err: str, case: Case, named: Path, text: str) -> None:
    """``err`` is one line ``error: FILE[:LINE]: [KEY: ]message`` as ``case`` expects."""
    assert "Traceback" not in err
    lines = err.splitlines()
    assert len(lines) == 1, f"expected one line on stderr, got:\n{err}"
    match = ERROR.match(lines[0])
    assert match, f"not 'error: FILE:LINE: KEY: message': {lines[0]!r}"
    assert Path(match["file"]) == named or Path(match["file"]).resolve() == named.resolve()
    if case.marker is not None:
        expected = {line_of(text, case.marker, case.nth)}
        expected |= {line_of(text, m) for m in case.alt_markers}
        reported = {int(match["line"])} if match["line"] else set()
        if case.line_in_message:
            reported |= {int(n) for n in re.findall(r"\bline (\d+)", match["rest"])}
        assert reported & expected, lines[0]
    elif case.names_world:
        assert match["line"] is not None, lines[0]
    rest = match["rest"]
    if case.key is not None:
        deeper = r"(?:[\[.][^ ]*)?" if case.key_prefix else ""
        assert re.match(re.escape(case.key) + deeper + ": ", rest), lines[0]
    for part in case.says:
        assert part in rest, lines[0]
    for part in case.absent:
        assert part not in rest, lines[0]


@pytest.mark.parametrize("case", _params())
def test_run_rejects_bad_input(case: Case, tmp_path: Path, capsys: pytest.CaptureFixture[str]):
    named, text = case.write(tmp_path)
    mission = tmp_path / "mission.yaml"
    out = tmp_path / "out"
    code = main(["run", str(mission), "--out", str(out), "--quiet"])
    captured = capsys.readouterr()
    assert code == 2, captured.err
    assert captured.out == ""
    check_error(captured.err, case, named, text)
    assert not out.exists(), "bad input must write nothing under the output folder"


@pytest.mark.parametrize("case", _params())
def test_validate_rejects_bad_input(case: Case, tmp_path: Path,
                                    capsys: pytest.CaptureFixture[str]):
    named, text = case.write(tmp_path)
    code = main(["validate", str(tmp_path / "mission.yaml")])
    captured = capsys.readouterr()
    assert code == 2, captured.err
    assert "ok:" not in captured.out
    check_error(captured.err, case, named, text)


def test_validate_accepts_the_example_mission(capsys: pytest.CaptureFixture[str]):
    assert main(["validate", str(MISSION)]) == 0
    captured = capsys.readouterr()
    assert captured.out.startswith("ok:")
    assert "urban_search" in captured.out
    assert captured.err == ""


def test_validate_accepts_the_copy_with_absolute_world(tmp_path: Path,
                                                       capsys: pytest.CaptureFixture[str]):
    """The copy the bad cases start from is itself good: their errors come from the edits."""
    mission = tmp_path / "mission.yaml"
    mission.write_text(base_text(), encoding="utf-8")
    assert main(["validate", str(mission)]) == 0
    assert capsys.readouterr().out.startswith("ok:")


def test_subprocess_bad_input_exits_2_without_traceback(tmp_path: Path):
    case = next(c for c in CASES if c.id == "unknown_member_key")
    named, text = case.write(tmp_path)
    out = tmp_path / "out"
    proc = subprocess.run(
        [sys.executable, "-m", "astralis_des.cli", "run", str(named), "--out", str(out),
         "--quiet"],
        capture_output=True, text=True, timeout=60, cwd=tmp_path,
    )
    assert proc.returncode == 2, proc.stderr
    assert proc.stdout == ""
    check_error(proc.stderr, case, named, text)
    assert not out.exists()


def test_out_that_is_a_file_is_a_one_line_error(tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]):
    mission = tmp_path / "mission.yaml"
    mission.write_text(base_text(), encoding="utf-8")
    out = tmp_path / "out"
    out.write_text("keep me", encoding="utf-8")
    code = main(["run", str(mission), "--out", str(out), "--quiet", "--no-recording"])
    err = capsys.readouterr().err
    assert code == 2
    assert len(err.splitlines()) == 1 and err.startswith("error: ")
    assert str(out) in err
    assert out.read_text(encoding="utf-8") == "keep me"
