"""``astralis diff RUN_A RUN_B [-o diff.rrd]``: where two runs part, the table's numbers, the
recording of both, a study's run folders, and bad input in one line."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from conftest import DEFAULT_WORLD, MISSIONS
from terminal import run_cli

from astralis_des import Simulation, load_mission
from astralis_des.compare import Comparison, compare, load_run
from astralis_des.compare.chunks import GHOST_ALPHA, ghost_color, read_chunks
from astralis_des.compare.recording import write_diff
from astralis_des.sinks.rrd_check import broken

FAULT_AT = 60.0  # uav2 fails between round 2 (54.1 s) and round 3 (84.0 s) of the mission


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The default mission as it is, with uav2 failing at 60 s, under greedy, forked at round 3
    to greedy, and a mission of another world: each run's folder, as ``astralis run -o``
    writes it."""
    base = tmp_path_factory.mktemp("diff")
    mission = load_mission(MISSIONS / "urban_search.yaml")
    greedy = mission.spec.assignment.model_dump(mode="json") | {"strategy": "greedy"}
    offices = base / "offices.yaml"
    offices.write_text(
        f"name: offices\nworld: {DEFAULT_WORLD.parent / 'fig4_offices.yaml'}\nseed: 1\n"
        "time_limit: 600\nteam:\n  - {id: uav1, kind: uav, start: [5, 5, 0]}\n"
        "assignment:\n  search: [F]\n", encoding="utf-8")
    missions = {
        "mixed": mission,
        "fault": mission.with_changes(timeline=[
            {"at": FAULT_AT, "event": "fault", "robot": "uav2", "reason": "rotor failure"}]),
        "greedy": mission.with_changes(assignment=greedy),
        "offices": load_mission(offices)}
    for name, m in missions.items():
        Simulation(m, out_dir=base / name).run()
    Simulation(mission, out_dir=base / "fork").fork(at="round:3", changes={
        "assignment.strategy": "greedy"})
    shutil.copytree(base / "mixed", base / "unrecorded")
    (base / "unrecorded" / "recording.rrd").unlink()
    return {name: base / name for name in [*missions, "unrecorded", "fork"]}


@pytest.fixture(scope="module")
def fault(runs: dict[str, Path]) -> Comparison:
    return compare(load_run(runs["mixed"]), load_run(runs["fault"]))


def test_a_fault_between_rounds_parts_the_runs_at_the_next_round(fault: Comparison) -> None:
    """uav2 fails at 60 s: rounds 1 and 2 are the same, round 3 (84.0 s) is the first that
    differs, without uav2 in B; the fault is the first event that differs."""
    ra, rb = fault.a.summary.rounds, fault.b.summary.rounds
    assert [r.matching for r in ra[:2]] == [r.matching for r in rb[:2]]
    assert fault.round is not None and fault.round.number == 3
    assert fault.round.t == ra[2].t == pytest.approx(84.003578)
    assert "uav2" in [agent for agent, _, _ in fault.round.only_a]
    assert "uav2" not in [agent for agent, _, _ in fault.round.only_b]
    line = next(n for n, e in enumerate(fault.b.events, start=1) if e["kind"] == "fault")
    assert fault.a.events[:line - 1] == fault.b.events[:line - 1]
    assert fault.event is not None and fault.event.line == line
    assert fault.event.b is not None and fault.event.b["kind"] == "fault"
    assert fault.event.t == FAULT_AT and fault.first_time == FAULT_AT


def test_a_fork_parts_from_its_original_at_its_fork_event(runs: dict[str, Path]) -> None:
    """Forked at round 3: the logs are the same up to the fork event's line, which is the
    first that differs; round 3, where greedy decides otherwise, is the first decision that
    differs; the fork is named so."""
    code, out, err = run_cli("diff", str(runs["mixed"]), str(runs["fork"]))
    assert (code, err) == (0, "")
    fork = load_run(runs["fork"])
    line = next(n for n, e in enumerate(fork.events, start=1) if e["kind"] == "fork")
    assert fork.summary.rounds[2].strategy == "greedy"
    assert out.splitlines()[1] == (f"B: {runs['fork']} (urban_search: mixed->greedy, seed 42, "
                                   "kinematic, forked at round:3)")
    assert out.splitlines()[2] == (
        "the first decision that differs is round 3 (t = 84.0 s); the first event that differs "
        f"is line {line} (t = 84.0 s, A assignment, B fork)")


def test_a_run_against_itself_does_not_part(runs: dict[str, Path]) -> None:
    code, out, err = run_cli("diff", str(runs["mixed"]), str(runs["mixed"]))
    assert (code, err) == (0, "")
    assert out.splitlines()[2] == ("the runs do not differ: every round and every event is "
                                   "the same")


def test_the_table_says_where_they_part_and_who_found_the_target(
        runs: dict[str, Path]) -> None:
    """mixed against greedy: they part at round 1; who found the target and when, and the
    time to find's difference, are the summaries'."""
    code, out, err = run_cli("diff", str(runs["mixed"]), str(runs["greedy"]))
    assert (code, err) == (0, "")
    a, b = (json.loads((runs[n] / "summary.json").read_text()) for n in ("mixed", "greedy"))
    lines = out.splitlines()
    assert lines[:2] == [f"A: {runs['mixed']} (urban_search: mixed, seed 42, kinematic)",
                         f"B: {runs['greedy']} (urban_search: greedy, seed 42, kinematic)"]
    assert lines[2].startswith("the first decision that differs is round 1 (t = 0.0 s); the "
                               "first event that differs is line 2 (t = 0.0 s, assignment)")
    found = next(line for line in out.splitlines() if "found by" in line)
    assert f"{a['found_by']} at {a['time_to_find']:.1f} s" in found
    assert f"{b['found_by']} at {b['time_to_find']:.1f} s" in found
    rows = {cells[1].strip(): [c.strip() for c in cells[2:5]]
            for cells in (line.split("│") for line in lines) if len(cells) == 6}
    assert rows["time_to_find"] == [f"{a['time_to_find']:.1f}", f"{b['time_to_find']:.1f}",
                                    f"{b['time_to_find'] - a['time_to_find']:+.1f}"]
    assert set(a["metrics"]) <= set(rows)  # every metric of the summaries has its row
    assert rows["human_close_s"][:2] == [f"{a['metrics']['human_close_s']:.3g}",
                                         f"{b['metrics']['human_close_s']:.3g}"]


def test_the_recording_holds_both_runs_and_where_they_part(fault: Comparison,
                                                          tmp_path: Path) -> None:
    """A's entities as they are, B's robots under ghost/ in pale colours, the marker at round
    3's time; the file reads back whole; B's walls are not drawn twice."""
    path = write_diff(fault, tmp_path / "diff.rrd")
    assert broken(path) is None
    assert sorted(p.name for p in tmp_path.iterdir()) == ["diff.rrd"]  # nothing else left
    chunks = read_chunks(path)
    entities = {c.entity_path for c in chunks}
    assert {"/robots/uav2/pose", "/ghost/robots/uav2/pose", "/robots/uav2/state",
            "/ghost/robots/uav2/state", "/ghost/mission/events", "/diff/lane",
            "/diff/round/flags", "/diff/summary", "/world/A/1/solids"} <= entities
    assert not any(e.startswith("/ghost/world/A/") for e in entities)

    def static_colors(entity: str) -> list[int]:
        chunk = next(c for c in chunks if c.entity_path == entity and c.is_static)
        return chunk.to_record_batch().column("Points3D:colors").to_pylist()[0]

    import numpy as np

    a, ghost = static_colors("/robots/uav2/pose"), static_colors("/ghost/robots/uav2/pose")
    assert ghost == ghost_color(np.array(a, dtype=np.uint32)).tolist() != a
    assert all(c & 0xFF == GHOST_ALPHA for c in ghost)
    flags = next(c for c in chunks if c.entity_path == "/diff/round/flags")
    assert flags.to_record_batch().column("sim_time").cast("int64").to_pylist() == [
        round(fault.round.t * 1e9)] if fault.round else False


def test_a_study_recordings_folder_is_a_run_folder(tmp_path: Path) -> None:
    """Two variants of one scenario of a study's --recordings, diffed and drawn."""
    from astralis_des.studies import load_study, run_scenario

    study = load_study(MISSIONS.parent / "studies" / "outcomes.yaml").with_changes(
        scenarios=1, vary={"strategy": ["mixed", "greedy"]})
    run_scenario(study, 0, recordings=tmp_path / "scenarios")
    folder = tmp_path / "scenarios" / "000000"
    code, out, err = run_cli("diff", str(folder / "00_mixed"), str(folder / "01_greedy"),
                             "-o", str(tmp_path / "d.rrd"))
    assert (code, err) == (0, "")
    assert "mixed, seed" in out and "greedy, seed" in out
    assert broken(tmp_path / "d.rrd") is None
    code, _, err = run_cli("diff", str(tmp_path), str(folder / "01_greedy"))
    assert code == 2 and err == (f"error: {tmp_path}: not a run folder (no summary.json): it "
                                 f"holds runs, give one of them, e.g. {folder / '00_mixed'}\n")


def _broken_copy(runs: dict[str, Path], base: Path, name: str, file: str, text: str) -> Path:
    folder = base / name
    shutil.copytree(runs["mixed"], folder)
    (folder / file).write_text(text, encoding="utf-8")
    return folder


def test_bad_input_is_one_line_and_exit_2(runs: dict[str, Path], tmp_path: Path) -> None:
    """Each names its file (and line or key); nothing is written; with a run lacking its
    recording, the table still prints and -o says why it cannot draw."""
    events = (runs["mixed"] / "events.jsonl").read_text().splitlines()
    summary = json.loads((runs["mixed"] / "summary.json").read_text())
    del summary["rounds"]
    cut = _broken_copy(runs, tmp_path, "cut", "recording.rrd", "")
    (cut / "recording.rrd").write_bytes((runs["mixed"] / "recording.rrd").read_bytes()[:5000])
    out = tmp_path / "d.rrd"
    cases = {
        "nowhere": ((str(tmp_path / "nowhere"),), f"{tmp_path / 'nowhere'}: no such folder"),
        "file": ((str(runs["mixed"] / "summary.json"),), "summary.json: is a file"),
        "json": ((str(_broken_copy(runs, tmp_path, "j", "summary.json", '{"mission":\n')),),
                 "j/summary.json:2: not valid JSON"),
        "key": ((str(_broken_copy(runs, tmp_path, "k", "summary.json", json.dumps(summary))),),
                "k/summary.json: rounds: field required"),
        "line": ((str(_broken_copy(runs, tmp_path, "l", "events.jsonl",
                                   "\n".join([*events[:4], "{oops", *events[5:]]))),),
                 "l/events.jsonl:5: not a JSON event"),
        "unrecorded": ((str(runs["unrecorded"]), "-o", str(out)),
                       "unrecorded: no recording.rrd, so -o cannot draw the diff"),
        "world": ((str(runs["offices"]), "-o", str(out)),
                  "offices: of another world than"),
        "cut": ((str(cut), "-o", str(out)), "cut/recording.rrd: not a whole Rerun recording"),
        "suffix": ((str(runs["fault"]), "-o", str(tmp_path / "d.txt")),
                   "d.txt: -o: give a file name ending in .rrd"),
        "input": ((str(runs["fault"]), "-o", str(runs["fault"] / "recording.rrd")),
                  "fault/recording.rrd: -o: is the recording of"),
    }
    for name, (args, message) in cases.items():
        code, stdout, err = run_cli("diff", str(runs["mixed"]), *args)
        assert code == 2, name
        assert err.count("\n") == 1 and err.startswith("error: ") and message in err, (name, err)
        assert not out.exists() and not list(tmp_path.glob(".d.rrd*")), name
        if name in ("unrecorded", "world"):  # the runs were read: their table is printed
            assert "found by" in stdout, name
    assert broken(runs["fault"] / "recording.rrd") is None


def test_a_diff_written_into_a_run_folder_leaves_the_run_as_it_is(
        runs: dict[str, Path], tmp_path: Path) -> None:
    """-o RUN/diff.rrd adds the file: the run's own files stay (a file target is not a
    result folder to clear, even in a process that registered the run's files)."""
    run = tmp_path / "run"
    shutil.copytree(runs["fault"], run)
    before = sorted(p.name for p in run.iterdir())
    code, _, err = run_cli("diff", str(runs["mixed"]), str(run), "-o", str(run / "diff.rrd"))
    assert (code, err) == (0, "")
    assert sorted(p.name for p in run.iterdir()) == sorted([*before, "diff.rrd"])
