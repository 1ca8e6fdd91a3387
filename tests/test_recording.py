"""The replay: a recording that loads, with the entity tree, one timeline, task lanes,
assignment rounds (graph and cost matrix), metrics and a layout that reads with 16 robots;
the replay command; an interrupted run."""

from __future__ import annotations

import json
import os
import pickle
import re
import signal
import subprocess
import sys
import time
from collections import defaultdict
from pathlib import Path
from typing import Any

import pytest

from astralis_des import RunResult, Simulation, load_mission
from astralis_des.cli import main
from astralis_des.kernel.catalogue import level_of
from astralis_des.outdir import staging_path
from astralis_des.sinks import recording as recording_module
from astralis_des.sinks.recording import describe
from astralis_des.sinks.rounds import cost_text

ROOT = Path(__file__).resolve().parents[1]
RERUN = str(Path(sys.executable).with_name("rerun"))
BIG_TEAM = ROOT / "examples" / "big_team.yaml"  # 16 robots, a round of 16 agents x 18 rooms
LAYOUT = ("/view", "/container", "/viewport", "/time_panel", "/blueprint_panel",
          "/selection_panel", "/top_panel")  # the blueprint's own entities
CHUNK = re.compile(r"^Chunk\(\S+\) with (\d+) rows \([^)]*\) - (\S+) - data columns: \[(.*)\]")


def chunks(path: Path) -> dict[str, dict[str, int]]:
    """Rows per entity and archetype in the recording's data (not its layout), from
    ``rerun rrd print``."""
    out = subprocess.run([RERUN, "rrd", "print", "-v", str(path)], capture_output=True,
                         text=True, check=True).stdout
    rows: dict[str, dict[str, int]] = defaultdict(lambda: defaultdict(int))
    for line in out.splitlines():
        match = CHUNK.match(line)
        if match and not match[2].startswith(LAYOUT):
            n, entity, columns = int(match[1]), match[2], match[3]
            for archetype in {c.split("@")[1].split(":")[0] for c in columns.split()}:
                rows[entity][archetype] += n
    return rows


def logged(path: Path, entity: str) -> list[dict[str, Any]]:
    """The rows logged on ``entity`` over time (not its static ones), each a column -> value
    dict with ``t`` its simulated time in seconds, in time order."""
    from rerun.chunk import RrdReader

    rows: list[dict[str, Any]] = []
    for chunk in RrdReader(path).stream():
        if chunk.entity_path == entity and not chunk.is_static:
            batch = chunk.to_record_batch()
            times = batch.column("sim_time").cast("int64").to_pylist()
            rows += [{**row, "t": ns / 1e9} for ns, row in zip(
                times, batch.drop_columns(["sim_time"]).to_pylist(), strict=True)]
    return sorted(rows, key=lambda row: row["t"])


def layout(path: Path) -> tuple[dict[str, dict[str, Any]], dict[str, dict[str, Any]]]:
    """The views and containers of the recording's blueprint, by id (``view/...``,
    ``container/...``): a view's class, name, origin, contents and time axis; a container's
    kind (1 tabs, 2 horizontal, 3 vertical) and children."""
    from rerun.chunk import RrdReader

    reader = RrdReader(path)
    parts: dict[str, dict[str, Any]] = defaultdict(dict)
    for chunk in reader.stream(store=reader.blueprints()[0]):
        batch = chunk.to_record_batch()
        item = "/".join(chunk.entity_path.strip("/").split("/")[:2])
        for row in batch.select([c for c in batch.schema.names if ":" in c]).to_pylist():
            parts[item].update({k.split(":")[1]: v for k, v in row.items()})
    views = {k: v for k, v in parts.items() if k.startswith("view/")}
    containers = {k: v for k, v in parts.items() if k.startswith("container/")}
    return views, containers


def verify(path: Path) -> None:
    done = subprocess.run([RERUN, "rrd", "verify", str(path)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


@pytest.fixture(scope="module")
def faults_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[RunResult, Path]:
    out = tmp_path_factory.mktemp("faults")
    result = Simulation(load_mission(ROOT / "missions" / "faults.yaml"), out_dir=out).run()
    return result, out / "recording.rrd"


def test_the_recording_loads_with_its_entity_tree(faults_run: tuple[RunResult, Path]) -> None:
    """rerun rrd verify accepts it; world, robots and mission entities are all there."""
    result, rrd = faults_run
    verify(rrd)
    rows = chunks(rrd)
    for entity in ("/world/site/solids", "/world/rooms", "/world/target", "/mission/events",
                   "/mission/assignment/graph", "/mission/assignment/matrix/heat",
                   "/mission/metrics/rooms_searched"):
        assert entity in rows, entity
    for rid, stats in result.robots.items():
        leaves = ("pose", "trail", "state", "task") + (("plan",) if stats.distance else ())
        for leaf in leaves:
            assert f"/robots/{rid}/{leaf}" in rows, (rid, leaf)


def test_a_mission_run_again_in_one_process_records_the_same(tmp_path: Path) -> None:
    """The second run of a mission in a process prepares the world's solids as chunks and
    keeps its layout encoded; the third sends both as they are. Its recording holds the same
    rows, the same views and its blueprint made active, and reads back whole."""
    from astralis_des.sinks import blueprint, prepared
    from astralis_des.sinks.rrd_check import FILE_MAGIC, HEADER, MESSAGE

    prepared._PREPARED.clear()
    blueprint._SEEN.clear()
    mission = load_mission(ROOT / "missions" / "faults.yaml")
    rrds = []
    for n in range(3):
        Simulation(mission, out_dir=tmp_path / str(n)).run()
        rrds.append(tmp_path / str(n) / "recording.rrd")
    verify(rrds[2])
    assert chunks(rrds[2]) == chunks(rrds[0])
    views = [sorted(json.dumps(view, sort_keys=True, default=str) for view in
                     layout(rrd)[0].values()) for rrd in rrds]
    assert views[2] == views[1] == views[0] and len(views[0]) >= 8
    data = rrds[2].read_bytes()
    assert data.startswith(FILE_MAGIC)
    at, kinds = HEADER, []
    while not kinds or kinds[-1] != 0:
        kind, length = MESSAGE.unpack_from(data, at)
        kinds.append(kind)
        at += MESSAGE.size + length
    assert kinds.count(3) == 1  # the blueprint's activation
    # a study sends the mission, world and all, to its workers pickled (Ray): what the runs
    # prepared for their recordings stays off it (Rerun's chunks cannot be pickled)
    assert pickle.loads(pickle.dumps(mission)).world.name == mission.world.name


def test_one_state_change_per_task_start_and_end(faults_run: tuple[RunResult, Path]) -> None:
    """Each lane starts idle, then changes at every task start and end, fault and recovery."""
    result, rrd = faults_run
    rows = chunks(rrd)
    for rid in result.robots:
        changes = sum(1 for e in result.events if e.get("robot") == rid and e["kind"] in
                      ("task_started", "task_finished", "fault", "recover"))
        assert rows[f"/robots/{rid}/state"]["StateChange"] == 1 + changes, rid
    assert any(e["kind"] == "fault" for e in result.events)


def test_one_graph_and_one_matrix_per_assignment_round(
        faults_run: tuple[RunResult, Path]) -> None:
    """A team of 4: each round has its graph (nodes and edges) and its cost matrix, and the
    layout shows the two side by side; every cell of a round of 3 rooms shows its cost."""
    result, rrd = faults_run
    rows = chunks(rrd)
    graph = rows["/mission/assignment/graph"]
    assert graph["GraphNodes"] == graph["GraphEdges"] == len(result.rounds) >= 2
    assert rows["/mission/assignment/matrix/heat"]["Image"] == len(result.rounds)
    first = result.rounds[0]
    costs = logged(rrd, "/mission/assignment/matrix/costs")[0]["Points2D:labels"]
    assert costs == [cost_text(c) for row in first["costs"] for c in row]
    assert len(costs) == len(first["agents"]) * len(first["rooms"]) == 4 * 3
    views, containers = layout(rrd)
    side_by_side = [[views[c]["class_identifier"][0] for c in box["contents"] if c in views]
                    for box in containers.values() if box["container_kind"] == [2]]
    assert ["Graph", "2D"] in side_by_side


def test_metrics_count_the_rooms_searched(faults_run: tuple[RunResult, Path]) -> None:
    """rooms_searched has one point per search that succeeded; every robot that moved has a
    distance series."""
    result, rrd = faults_run
    rows = chunks(rrd)
    searches = [e for e in result.events if e["kind"] == "task_finished"
                and e["status"] == "succeeded" and "coverage" in e]
    assert rows["/mission/metrics/rooms_searched"]["Scalars"] == len(searches) > 0
    moved = {rid for rid, s in result.robots.items() if s.tasks_succeeded + s.tasks_failed}
    assert {e.split("/")[-1] for e in rows if e.startswith("/mission/metrics/distance/")} == moved


def test_everything_is_on_the_sim_time_timeline(faults_run: tuple[RunResult, Path]) -> None:
    """The data has one timeline, sim_time (no wall-clock log_time)."""
    _, rrd = faults_run
    out = subprocess.run([RERUN, "rrd", "print", "-vv", str(rrd)], capture_output=True,
                         text=True, check=True).stdout
    timelines: set[str] = set()
    for block in out.split("Chunk(")[1:]:
        entity = block.split(" - ")[1] if " - " in block else ""
        if not entity.startswith(LAYOUT):
            timelines.update(re.findall(r"index_name: (\w+)", block))
    assert timelines == {"sim_time"}


def test_a_physics_recording_has_the_finders_frames(tmp_path: Path) -> None:
    """In physics the robot that found the target has camera frames (RGB, depth,
    segmentation) under a pinhole, and the detection is drawn; the layout shows its camera."""
    mission = load_mission(ROOT / "missions" / "fig7.yaml").with_changes(fidelity="physics")
    result = Simulation(mission, out_dir=tmp_path).run()
    assert result.found_by is not None
    rows = chunks(tmp_path / "recording.rrd")
    camera = f"/robots/{result.found_by}/camera"
    assert rows[camera]["Pinhole"] == 1 and rows[camera]["Transform3D"] >= 1
    for image, archetype in (("rgb", "EncodedImage"), ("depth", "DepthImage"),
                             ("segmentation", "SegmentationImage")):
        assert rows[f"{camera}/{image}"][archetype] == rows[camera]["Transform3D"]
    assert rows["/mission/detections"]["Points3D"] == 1
    out = subprocess.run([RERUN, "rrd", "print", "-vvv", str(tmp_path / "recording.rrd")],
                         capture_output=True, text=True, check=True).stdout
    assert f"found by {result.found_by}" in out
    # not black before its first frame: that frame, dimmed, captioned with its time, from 0 s
    preview = logged(tmp_path / "recording.rrd", f"{camera}/preview")
    first = logged(tmp_path / "recording.rrd", f"{camera}/rgb")[0]["t"]
    assert [row["t"] for row in preview] == [0.0, first] and first > 0.0
    assert preview[0]["Points2D:labels"] == [f"first frame at {first:.1f} s"]
    assert preview[0]["EncodedImage:blob"] and preview[1]["Clear:is_recursive"] == [False]


def test_replay_refuses_what_is_not_a_recording(tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    """A missing file, an empty one and a text file: one line each, exit 2."""
    text = tmp_path / "notes.rrd"
    text.write_text("hello\n", encoding="utf-8")
    empty = tmp_path / "empty.rrd"
    empty.write_bytes(b"")
    for path, says in ((tmp_path / "missing.rrd", "no such recording"),
                       (empty, "empty"), (text, "not a Rerun recording")):
        assert main(["replay", str(path)]) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and str(path) in err and says in err, err


def test_replay_opens_the_viewer_on_a_recording(faults_run: tuple[RunResult, Path],
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    """On a recording, replay runs the rerun viewer on it and returns its exit code."""
    _, rrd = faults_run
    calls: list[list[str]] = []
    monkeypatch.setenv("DISPLAY", ":0")  # a desktop's (tests/test_cli.py: one without)
    monkeypatch.setattr(subprocess, "call", lambda cmd: calls.append(cmd) or 0)
    assert main(["replay", str(rrd)]) == 0
    assert calls and calls[0][0].endswith("rerun") and calls[0][-1] == str(rrd)


def test_view_streams_to_a_viewer_as_the_run_goes(tmp_path: Path,
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    """--view connects a viewer and sends the event log in pieces during the run, and the
    file still gets all of it."""
    connected: list[Path] = []
    monkeypatch.setenv("DISPLAY", ":0")  # a desktop's (tests/test_cli.py: one without)
    monkeypatch.setattr(recording_module.RerunRecorder, "connect_viewer",
                        lambda self, path: connected.append(path))
    assert main(["run", str(ROOT / "missions" / "fig7.yaml"), "--out", str(tmp_path),
                 "--quiet", "--view"]) == 0
    assert connected == [staging_path(tmp_path) / "recording.rrd"]  # written there, then put
    # in place
    out = subprocess.run([RERUN, "rrd", "print", str(tmp_path / "recording.rrd")],
                         capture_output=True, text=True, check=True).stdout
    pieces = [int(m[1]) for m in map(CHUNK.match, out.splitlines())
              if m and m[2] == "/mission/events"]
    events = (tmp_path / "events.jsonl").read_text(encoding="utf-8").splitlines()
    assert len(pieces) > 1 and sum(pieces) == len(events)


def test_ctrl_c_leaves_a_recording_and_an_event_log_that_load(tmp_path: Path) -> None:
    """SIGINT in the middle of a physics run: exit 130, the recording verifies, every line of
    the event log is JSON, and the last says the mission was interrupted."""
    out = tmp_path / "run"
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    proc = subprocess.Popen([sys.executable, "-m", "astralis_des.cli", "run",
                             str(ROOT / "missions" / "urban_search.yaml"), "--fidelity",
                             "physics", "--out", str(out), "--quiet"], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    growing = staging_path(out) / "events.jsonl"  # the run's folder until it ends
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None:
        if growing.exists() and growing.read_text(encoding="utf-8").count("task_started") >= 3:
            break
        time.sleep(0.05)
    assert proc.poll() is None, "the run ended before it could be interrupted"
    proc.send_signal(signal.SIGINT)
    assert proc.wait(timeout=60) == 130
    verify(out / "recording.rrd")
    events = out / "events.jsonl"
    records = [json.loads(line) for line in events.read_text(encoding="utf-8").splitlines()]
    assert records[0]["kind"] == "mission_start"
    assert records[-1] == {**records[-1], "kind": "mission_end", "outcome": "interrupted"}
    assert "/robots/uav1/state" in chunks(out / "recording.rrd")


def static_colors(rrd: Path, entity: str, component: str) -> list[int]:
    """The packed RGBA colours of ``entity``'s static ``component`` (e.g. Points3D:colors)."""
    out = subprocess.run([RERUN, "rrd", "print", "-vvv", str(rrd)], capture_output=True,
                         text=True, check=True).stdout
    for block in out.split("Chunk(")[1:]:
        head = block.splitlines()[0]
        if not head.endswith(f" - {entity} - ") or "with 1 rows" not in head:
            continue
        lines = block.splitlines()
        header = next(line for line in lines if f"component: {component}" in line)
        column = [c.strip() for c in header.split("┆")].index(f"component: {component}")
        row = next(line for line in lines if "row_" in line)
        cell = [c.strip() for c in row.split("┆")][column]
        if cell.startswith("["):
            return [int(v) for v in cell.strip("[]").split(",")]
    raise AssertionError(f"no static {component} on {entity}")


def test_storeys_are_entities_and_each_robot_has_its_colour(
        faults_run: tuple[RunResult, Path]) -> None:
    """Issue 24: walls and slabs by building and storey (so that the storeys above can be
    hidden), the furniture of the rooms looked into likewise; one colour per robot, the same
    on its pose, trail and body."""
    result, rrd = faults_run
    rows = chunks(rrd)
    for storey in ("1", "2", "3", "roof"):
        assert f"/world/A/{storey}/solids" in rows, storey
    assert "/world/A/1/furniture" in rows and "/world/solids" not in rows
    colors = {rid: static_colors(rrd, f"/robots/{rid}/pose", "Points3D:colors")
              for rid in result.robots}
    assert len({tuple(c) for c in colors.values()}) == len(result.robots)  # one each
    for rid, color in colors.items():
        assert static_colors(rrd, f"/robots/{rid}/trail", "LineStrips3D:colors") == color
        assert f"/robots/{rid}/body" in rows  # its shape, moved and turned along its trail
    assert static_colors(rrd, "/robots/uav1/body/arms", "LineStrips3D:colors") == \
        colors["uav1"]


@pytest.fixture(scope="module")
def big_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[RunResult, Path]:
    out = tmp_path_factory.mktemp("big_team")
    result = Simulation(load_mission(BIG_TEAM), out_dir=out).run()
    return result, out / "recording.rrd"


def test_a_team_of_16_has_every_lane_in_view(big_run: tuple[RunResult, Path]) -> None:
    """Issue 41: each of the 16 robots has a task lane, and the layout shows them all at once:
    a view per kind (UAVs, UGVs, humans), side by side, none of more than 6 lanes (each lane
    is 40 px: the panel holds 6), each spanning the whole mission."""
    result, rrd = big_run
    assert len(result.robots) == 16
    rows = chunks(rrd)
    for rid in result.robots:
        assert rows[f"/robots/{rid}/state"]["StateChange"] >= 1, rid
    views, containers = layout(rrd)
    lanes = {vid: view for vid, view in views.items()
             if view["class_identifier"] == ["StateTimeline"]}
    assert sorted(v["display_name"][0] for v in lanes.values()) == \
        ["UAV lanes", "UGV lanes", "human lanes"]
    shown = [q for view in lanes.values() for q in view["query"]]
    assert sorted(shown) == sorted(f"+ /robots/{rid}/state" for rid in result.robots)
    assert all(len(view["query"]) <= 6 for view in lanes.values())
    assert any(sorted(box["contents"]) == sorted(lanes) for box in containers.values()
               if box["container_kind"] == [2])  # side by side
    for view in lanes.values():
        assert view["view_range"][0]["end"] >= result.end_time * 1e9  # ns


def test_a_round_of_16_agents_and_18_rooms_is_a_matrix(big_run: tuple[RunResult, Path]) -> None:
    """The round's costs are a heat map of 16 rows (agents) by 18 columns (rooms), named in
    the round's order, a green box on each chosen pair labelled with its cost; the graph, a
    tangle at this size, is left out of the recording and the layout."""
    result, rrd = big_run
    first = result.rounds[0]
    agents, rooms = first["agents"], first["rooms"]
    assert (len(agents), len(rooms)) == (16, 18)
    heat = logged(rrd, "/mission/assignment/matrix/heat")
    assert len(heat) == len(result.rounds)
    assert heat[0]["Image:format"][0]["width"] == 18 and heat[0]["Image:format"][0]["height"] == 16
    names = logged(rrd, "/mission/assignment/matrix/names")[0]["Points2D:labels"]
    assert names[:16] == agents and names[16:34] == rooms
    assert names[34] == f"round 1, {first['segment']} (16 x 18)"
    chosen = logged(rrd, "/mission/assignment/matrix/chosen")[0]["Boxes2D:centers"]
    costs = logged(rrd, "/mission/assignment/matrix/costs")[0]["Points2D:labels"]
    assert len(chosen) == len(costs) == len(first["matching"]) == 18
    cell = {(a, r): first["costs"][i][j] for i, a in enumerate(agents)
            for j, r in enumerate(rooms)}
    assert costs == [cost_text(cell[m["agent"], m["room"]]) for m in first["matching"]]
    assert "/mission/assignment/graph" not in chunks(rrd)
    views, _ = layout(rrd)
    classes = {v["space_origin"][0]: v["class_identifier"][0] for v in views.values()}
    assert classes["mission/assignment/matrix"] == "2D" and "Graph" not in classes.values()


@pytest.mark.parametrize("run", ["faults_run", "big_run"])
def test_the_event_log_shows_each_event_at_its_catalogue_level(
        run: str, request: pytest.FixtureRequest) -> None:
    """The replay's event log has a line per event, in order, each at the level the event
    catalogue gives its kind (mission_start and assignment INFO, task_queued DEBUG, a failed
    task WARN, a fault ERROR, the detection CRITICAL); a robot's task text too."""
    result, rrd = request.getfixturevalue(run)
    rows = logged(rrd, "/mission/events")
    assert [r["TextLog:text"] for r in rows] == [[describe(e)] for e in result.events]
    assert [r["TextLog:level"] for r in rows] == [[level_of(e)] for e in result.events]
    levels = {(e["kind"], r["TextLog:level"][0]) for e, r in zip(result.events, rows,
                                                                  strict=True)}
    assert {("mission_start", "INFO"), ("assignment", "INFO"), ("task_queued", "DEBUG"),
            ("task_started", "INFO"), ("detection", "CRITICAL")} <= levels
    if run == "faults_run":
        assert {("fault", "ERROR"), ("task_finished", "WARN")} <= levels
    robot = next(iter(result.robots))
    tasks = [e for e in result.events if e.get("robot") == robot
             and e["kind"] in ("task_started", "task_finished")]
    assert [r["TextLog:level"] for r in logged(rrd, f"/robots/{robot}/task")] == \
        [[level_of(e)] for e in tasks]


@pytest.mark.parametrize("run", ["faults_run", "big_run"])
def test_view_titles_fit_their_panels(run: str, request: pytest.FixtureRequest) -> None:
    """In a 1600 x 900 window a view three to a row shows about 12 characters of its name:
    the metrics and lanes are named that short ("progress", "coverage", "distance (m)"); no
    name is longer than its panel shows; the event log leaves out the entity path column
    (every line is mission/events)."""
    _, rrd = request.getfixturevalue(run)
    views, containers = layout(rrd)
    rows = [box["contents"] for box in containers.values() if box["container_kind"] == [2]]
    for row in rows:
        named = [views[c]["display_name"][0] for c in row if c in views]
        if len(named) >= 3:
            assert all(len(name) <= 12 for name in named), named
    assert all(len(v["display_name"][0]) <= 60 for v in views.values())
    metrics = sorted(v["display_name"][0] for v in views.values()
                     if v["class_identifier"] == ["TimeSeries"])
    assert metrics == ["coverage", "distance (m)", "progress"]
    log = next(v for v in views.values() if v["class_identifier"] == ["TextLog"])
    assert {c["kind"]: c["visible"] for c in log["text_log_columns"]} == \
        {1: False, 2: True, 3: True}  # entity path hidden; level and text shown
