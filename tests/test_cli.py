"""``astralis run | validate | schema``: the outputs a good mission writes, and the CLI surface.

Full mission runs are shared through module-scoped fixtures (each takes about half a second).
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from importlib.metadata import version
from pathlib import Path
from typing import Any

import pytest
from terminal import run_cli

import astralis_des
from astralis_des.cli import main

ROOT = Path(__file__).parents[1]
MISSION = ROOT / "missions" / "urban_search.yaml"
WORLD = ROOT / "worlds" / "urban_default.yaml"
TEAM = ["uav1", "uav2", "ugv1", "op1"]


def read_events(folder: Path) -> list[dict[str, Any]]:
    lines = (folder / "events.jsonl").read_text(encoding="utf-8").splitlines()
    return [json.loads(line) for line in lines]


def read_summary(folder: Path) -> dict[str, Any]:
    return json.loads((folder / "summary.json").read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def quiet_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, int, str, str]:
    """``astralis run missions/urban_search.yaml --out DIR --quiet`` (with the recording)."""
    out = tmp_path_factory.mktemp("quiet") / "out"
    code, stdout, stderr = run_cli("run", str(MISSION), "--out", str(out), "--quiet")
    return out, code, stdout, stderr


@pytest.fixture(scope="module")
def loud_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, int, str, str]:
    """A run without ``--quiet`` and with ``--no-recording``."""
    out = tmp_path_factory.mktemp("loud") / "out"
    code, stdout, stderr = run_cli("run", str(MISSION), "--out", str(out), "--no-recording")
    return out, code, stdout, stderr


def test_quiet_run_succeeds_silently(quiet_run: tuple[Path, int, str, str]) -> None:
    out, code, stdout, stderr = quiet_run
    assert code == 0, stderr
    assert stdout == ""
    assert stderr == ""
    assert sorted(p.name for p in out.iterdir()) == ["events.jsonl", "recording.rrd",
                                                      "summary.json"]


def test_events_jsonl(quiet_run: tuple[Path, int, str, str]) -> None:
    out = quiet_run[0]
    events = read_events(out)
    assert len(events) >= 2
    for event in events:
        assert isinstance(event, dict)
        assert {"t", "kind"} <= event.keys()
        assert isinstance(event["t"], int | float)
        assert isinstance(event["kind"], str)
    assert events[0]["kind"] == "mission_start"
    assert events[-1]["kind"] == "mission_end"
    assert [e["kind"] for e in events].count("mission_start") == 1
    assert [e["kind"] for e in events].count("mission_end") == 1
    times = [e["t"] for e in events]
    assert times == sorted(times), "events are written in simulated-time order"
    assert events[0]["t"] == 0
    assert events[0]["seed"] == 42
    assert events[0]["team"] == TEAM


def test_summary_json(quiet_run: tuple[Path, int, str, str]) -> None:
    out = quiet_run[0]
    summary = read_summary(out)
    assert {"outcome", "time_to_find", "robots", "rounds"} <= summary.keys()
    assert isinstance(summary["outcome"], str) and summary["outcome"]
    assert summary["seed"] == 42
    assert summary["mission"] == "urban_search"
    assert list(summary["robots"]) == TEAM
    for rid, robot in summary["robots"].items():
        for key in ("distance", "busy_time", "idle_time"):
            assert isinstance(robot[key], int | float), (rid, key)
            assert robot[key] >= 0, (rid, key)
    assert summary["rounds"], "the mission makes at least one assignment round"
    for round_ in summary["rounds"]:
        assert "costs" in round_ and "matching" in round_
        assert isinstance(round_["costs"], list)
        assert isinstance(round_["matching"], list)
    if summary["outcome"] == "found":
        assert isinstance(summary["time_to_find"], int | float)
        assert summary["time_to_find"] > 0


def test_summary_agrees_with_events(quiet_run: tuple[Path, int, str, str]) -> None:
    out = quiet_run[0]
    events, summary = read_events(out), read_summary(out)
    assert events[-1]["outcome"] == summary["outcome"]
    assert summary["end_time"] == pytest.approx(events[-1]["t"])


def test_recording_rrd(quiet_run: tuple[Path, int, str, str]) -> None:
    rrd = quiet_run[0] / "recording.rrd"
    assert rrd.is_file()
    assert rrd.stat().st_size > 0


@pytest.mark.skipif(shutil.which("rerun") is None, reason="no rerun executable on PATH")
def test_recording_rrd_verifies(quiet_run: tuple[Path, int, str, str]) -> None:
    rrd = quiet_run[0] / "recording.rrd"
    rerun = shutil.which("rerun")
    assert rerun is not None
    proc = subprocess.run([rerun, "rrd", "verify", str(rrd)], capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_no_recording_writes_no_rrd(loud_run: tuple[Path, int, str, str]) -> None:
    out, code, _, stderr = loud_run
    assert code == 0, stderr
    assert (out / "events.jsonl").is_file()
    assert (out / "summary.json").is_file()
    assert not list(out.rglob("*.rrd"))


def test_summary_output_names_outcome_and_every_robot(
        loud_run: tuple[Path, int, str, str]) -> None:
    out, code, stdout, _ = loud_run
    assert code == 0
    summary = read_summary(out)
    outcome = summary["outcome"]
    assert (outcome.replace("_", " ") in stdout
            or (outcome == "found" and f"found by {summary['found_by']}" in stdout)), stdout
    for rid in TEAM:
        assert re.search(rf"\b{re.escape(rid)}\b", stdout), (rid, stdout)
    assert str(out) in stdout


def test_seed_override_is_recorded(tmp_path: Path) -> None:
    out = tmp_path / "out"
    code, _, stderr = run_cli("run", str(MISSION), "--out", str(out), "--quiet", "--seed", "5",
                              "--no-recording")
    assert code == 0, stderr
    assert read_summary(out)["seed"] == 5
    assert read_events(out)[0]["seed"] == 5


def test_default_output_folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Without --out (and no outputs.dir) the outputs go to out/<mission name> under the cwd."""
    monkeypatch.chdir(tmp_path)
    code, _, stderr = run_cli("run", str(MISSION), "--quiet", "--no-recording")
    assert code == 0, stderr
    assert (tmp_path / "out" / "urban_search" / "summary.json").is_file()


def test_summary_output_shows_long_robot_ids(tmp_path: Path,
                                             monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("COLUMNS", "80")
    long_ids = {"uav1": "quadrotor_alpha_one", "op1": "search_and_rescue_operator"}
    text = MISSION.read_text(encoding="utf-8")
    text = re.sub(r"(?m)^world:.*$", f"world: {json.dumps(str(WORLD))}", text)
    for old, new in long_ids.items():
        text = text.replace(f"id: {old},", f"id: {new},")
    mission = tmp_path / "mission.yaml"
    mission.write_text(text, encoding="utf-8")
    code, stdout, stderr = run_cli("run", str(mission), "--out", str(tmp_path / "out"),
                                   "--no-recording")
    assert code == 0, stderr
    for rid in long_ids.values():
        assert rid in stdout.split("team")[-1], stdout


def test_schema_mission(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["schema"]) == 0
    schema = json.loads(capsys.readouterr().out)
    assert "properties" in schema
    assert "team" in schema["properties"]
    assert "world" in schema["properties"]


def test_schema_world(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["schema", "--world"]) == 0
    schema = json.loads(capsys.readouterr().out)
    assert "buildings" in schema["properties"]
    assert "team" not in schema["properties"]


def test_schema_to_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    target = tmp_path / "mission.schema.json"
    assert main(["schema", "-o", str(target)]) == 0
    assert capsys.readouterr().out == ""
    assert "team" in json.loads(target.read_text(encoding="utf-8"))["properties"]


def test_help_lists_commands(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["--help"])
    assert exc.value.code == 0
    text = capsys.readouterr().out
    for name in ("run", "validate", "schema"):
        assert re.search(rf"\b{name}\b", text), name


def test_run_help_lists_options(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["run", "--help"])
    assert exc.value.code == 0
    text = capsys.readouterr().out
    for option in ("--out", "--seed", "--no-recording", "--quiet"):
        assert option in text


def test_no_command_prints_help(capsys: pytest.CaptureFixture[str]) -> None:
    assert main([]) == 0
    assert "validate" in capsys.readouterr().out


def test_version(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--version"]) == 0
    text = capsys.readouterr().out.strip()
    assert text == f"astralis-des {astralis_des.__version__}"
    assert astralis_des.__version__ == version("astralis-des")


def test_unknown_command_is_a_usage_error(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["fly"])
    assert exc.value.code == 2
    assert "invalid choice" in capsys.readouterr().err


def test_console_script_is_installed() -> None:
    script = shutil.which("astralis") or shutil.which("astralis", path=str(Path(sys.executable)
                                                                            .parent))
    if script is None:
        pytest.skip("the astralis console script is not on PATH")
    proc = subprocess.run([script, "--help"], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert "validate" in proc.stdout


def test_validate_says_what_will_really_be_searched(tmp_path: Path) -> None:
    """Issue 24: it said "18 rooms to search" for a mission with ``auto: false``."""
    code, out, _ = run_cli("validate", str(MISSION))
    assert code == 0 and "18 rooms to search in world 'urban_default'" in out
    manual = tmp_path / "manual.yaml"
    text = MISSION.read_text()
    manual.write_text(text.replace("world: ../worlds/urban_default.yaml", f"world: {WORLD}")
                      .replace("assignment:\n", "assignment:\n  auto: false\n", 1))
    code, out, _ = run_cli("validate", str(manual))
    assert code == 0 and "no rooms searched but those commanded (assignment.auto is false)" in out


def test_world_rooms_lists_what_a_mission_can_name() -> None:
    code, out, _ = run_cli("world", "rooms", str(WORLD))
    assert code == 0
    assert out.splitlines()[0].startswith("world urban_default: site 220 x 175 m; 8 segments, "
                                          "24 rooms; A: 3 storeys of 3.5 m, 18 rooms")
    row = next(line for line in out.splitlines() if line.startswith("A.1.1.1 "))
    assert row.split() == ["A.1.1.1", "A.1.1", "1", "64.1..67.9,", "79.6..86.4", "25.8",
                           "66,", "79.5,", "0", "A.1.corridor"]
    assert sum(line.startswith("A.2.1.") for line in out.splitlines()) == 3
    assert len(out.splitlines()) == 2 + 24


# -- the same options everywhere ---------------------------------------------------------------
COMMANDS = ["run", "replay", "diff", "export", "validate", "world", "study", "tune", "falsify",
            "serve", "keys", "chat", "teleop", "schema"]
WORLD_COMMANDS = ["rooms", "spots", "show", "import"]
WRITERS = [["run"], ["diff"], ["study"], ["tune"], ["falsify"], ["serve"], ["chat"], ["schema"],
           ["world", "show"], ["world", "import"]]


def help_text(capsys: pytest.CaptureFixture[str], *command: str) -> str:
    with pytest.raises(SystemExit) as exc:
        main([*command, "--help"])
    assert exc.value.code == 0
    return capsys.readouterr().out


def test_the_help_lists_every_command(capsys: pytest.CaptureFixture[str]) -> None:
    """The commands the tests below go through are all there are."""
    listed = re.findall(r"^    (\w+) ", help_text(capsys), flags=re.MULTILINE)
    assert listed == COMMANDS
    listed = re.findall(r"^    (\w+) ", help_text(capsys, "world"), flags=re.MULTILINE)
    assert listed == WORLD_COMMANDS


def test_every_command_spells_its_options_the_same(capsys: pytest.CaptureFixture[str]) -> None:
    """What a command writes goes to -o/--out, --output shown nowhere; every --quiet is also
    -q; the top level has -V/--version."""
    for command in [[c] for c in COMMANDS] + [["world", w] for w in WORLD_COMMANDS]:
        text = help_text(capsys, *command)
        writes = re.search(r"^  -o (DIR|FILE), --out (DIR|FILE) ", text, flags=re.MULTILINE)
        assert bool(writes) is (command in WRITERS), command
        assert "--output" not in text, command
        assert ("--quiet" in text) is ("-q, --quiet" in text), command
    assert "-V, --version" in help_text(capsys)


def test_short_options(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``-V`` prints the version; ``run -q -o DIR`` writes the run and prints nothing."""
    assert main(["-V"]) == 0
    assert capsys.readouterr().out == f"astralis-des {astralis_des.__version__}\n"
    assert main(["run", str(MISSION), "-q", "-o", str(tmp_path / "run"), "--no-recording"]) == 0
    assert capsys.readouterr() == ("", "")
    assert sorted(p.name for p in (tmp_path / "run").iterdir()) == ["events.jsonl",
                                                                     "summary.json"]


def test_the_old_output_spelling_still_works(tmp_path: Path,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    """Scripts written for ``--output`` (schema, world show, world import) keep working."""
    target = tmp_path / "world.schema.json"
    assert main(["schema", "--world", "--output", str(target)]) == 0
    assert "buildings" in json.loads(target.read_text(encoding="utf-8"))["properties"]
    code, _, err = run_cli("world", "import", str(tmp_path / "scan.las"), "--output",
                           str(tmp_path / "w.yaml"))  # past argparse: the file is missing
    assert code == 2 and err.startswith(f"error: {tmp_path / 'scan.las'}"), err
    with pytest.raises(SystemExit) as exc:
        main(["world", "import", str(tmp_path / "scan.las")])
    assert exc.value.code == 2
    assert capsys.readouterr().err.splitlines()[-1] == (
        "astralis world import: error: the following arguments are required: -o/--out")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="X11 or Wayland: Linux")
def test_the_viewer_without_a_display_says_to_use_web(
        quiet_run: tuple[Path, int, str, str], tmp_path: Path,
        monkeypatch: pytest.MonkeyPatch) -> None:
    """``replay`` (and ``run --view``) with no DISPLAY nor WAYLAND_DISPLAY: exit 2 and one
    line naming --web, before any viewer starts (before: a winit error from the viewer)."""
    import astralis_des.sinks.viewer as viewer

    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setattr(viewer.subprocess, "call", lambda *a, **k: pytest.fail("spawned"))
    recording = quiet_run[0] / "recording.rrd"
    code, out, err = run_cli("replay", str(recording))
    assert (code, out) == (2, "")
    assert err == ("error: no display to open the Rerun viewer on (DISPLAY and WAYLAND_DISPLAY "
                   "are not set); use --web to serve it to a browser: astralis replay "
                   f"{recording} --web\n")
    code, out, err = run_cli("run", str(MISSION), "--view", "-o", str(tmp_path / "run"))
    assert (code, out, len(err.splitlines())) == (2, "", 1)
    assert "--web" in err and not (tmp_path / "run").exists()


def test_stdout_holds_only_our_lines_with_pybullet(tmp_path: Path) -> None:
    """A physics run and a world import with V-HACD parts load PyBullet, which prints its
    build time and its progress: none of it reaches stdout (a pipe: C buffers it to the end)."""
    import trimesh

    short = tmp_path / "short.yaml"
    short.write_text(MISSION.read_text().replace("../worlds/", f"{WORLD.parent}/")
                     .replace("time_limit: 3600", "time_limit: 10"), encoding="utf-8")
    trimesh.util.concatenate([trimesh.creation.box((10, 10, 3)).apply_translation((0, 0, 1.5)),
                              trimesh.creation.box((4, 4, 6)).apply_translation((12, 0, 3))]
                             ).export(tmp_path / "blocks.obj")
    cli = [sys.executable, "-m", "astralis_des.cli"]
    env = {**os.environ, "COLUMNS": "100"}
    run = subprocess.run([*cli, "run", str(short), "--fidelity", "physics", "--no-recording",
                          "-o", str(tmp_path / "run")], capture_output=True, text=True,
                         timeout=300, env=env)
    imp = subprocess.run([*cli, "world", "import", str(tmp_path / "blocks.obj"), "-o",
                          str(tmp_path / "w" / "blocks.yaml"), "--collision", "convex", "--up",
                          "z"], capture_output=True, text=True, timeout=300, env=env)
    assert run.returncode == 0 and imp.returncode == 0, run.stderr + imp.stderr
    lines = run.stdout.splitlines()
    assert lines[0].startswith("urban_search (seed 42, physics): ")
    assert lines[-1] == f"outputs: {tmp_path / 'run'}/"
    lines = imp.stdout.splitlines()
    words = " ".join(imp.stdout.split())  # a long tmp_path (pytest-xdist's) wraps the line
    assert words.startswith(f"{tmp_path / 'w' / 'blocks.yaml'}: 24 triangles, ")
    assert lines[-1] == "wrote blocks.blocks.npz, blocks.mesh.obj, blocks.parts.obj, blocks.yaml"
    for text in (run.stdout, imp.stdout):
        assert "pybullet" not in text.lower() and "build time" not in text
