"""SIGTERM (what docker stop, systemd, Kubernetes and CI time-outs send) and SIGHUP end a
command as Ctrl-C does: the outputs say the run was interrupted, load, and never sit beside
an earlier run's files; a study keeps the rows of the scenarios it finished."""

from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from fake_backends import Interrupted
from test_api_safety import free_port
from test_recording import verify

from astralis_des.outdir import staging_path

ROOT = Path(__file__).resolve().parents[1]
MISSION = ROOT / "missions" / "urban_search.yaml"
ENV = {**os.environ, "PYTHONUNBUFFERED": "1"}


def astralis(*args: str) -> subprocess.Popen[str]:
    return subprocess.Popen([sys.executable, "-m", "astralis_des.cli", *args], env=ENV,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def wait_for(events: Path, proc: subprocess.Popen[str], started: int) -> None:
    """Until the event log shows ``started`` tasks started (the run is well under way); it
    grows in the staging folder beside the output folder until the run ends."""
    events = staging_path(events.parent) / events.name
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None:
        if events.exists() and events.read_text(encoding="utf-8").count("task_started") >= started:
            return
        time.sleep(0.05)
    raise AssertionError("the run ended (or never started) before it could be interrupted")


def check_interrupted(out: Path) -> None:
    records = [json.loads(line)
               for line in (out / "events.jsonl").read_text(encoding="utf-8").splitlines()]
    assert records[0]["kind"] == "mission_start"
    assert records[-1]["kind"] == "mission_end" and records[-1]["outcome"] == "interrupted"
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    assert summary["outcome"] == "interrupted"
    verify(out / "recording.rrd")


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP], ids=["SIGTERM", "SIGHUP"])
def test_a_terminated_physics_run_keeps_what_it_recorded(tmp_path: Path,
                                                          sig: signal.Signals) -> None:
    """A physics run sent SIGTERM (or SIGHUP) mid-mission: exit 130, the event log ends with
    ``mission_end`` ``interrupted``, summary.json says interrupted, the recording verifies.
    (Before: no summary.json, the event log cut mid-mission, the recording unreadable.)"""
    out = tmp_path / "run"
    out.mkdir()
    (out / "summary.json").write_text('{"outcome": "found"}', encoding="utf-8")  # an old run
    proc = astralis("run", str(MISSION), "--fidelity", "physics", "--out", str(out), "--quiet")
    wait_for(out / "events.jsonl", proc, 3)
    proc.send_signal(sig)
    assert proc.wait(timeout=60) == 130
    check_interrupted(out)


def test_a_kinematic_run_terminated_at_once_keeps_a_consistent_folder(tmp_path: Path) -> None:
    """A kinematic run is over in a fraction of a second; terminated as soon as its event log
    appears it either finished or was interrupted, and its folder agrees with itself: never
    an earlier run's summary beside a new event log."""
    out = tmp_path / "run"
    out.mkdir()
    (out / "summary.json").write_text('{"outcome": "not_found"}', encoding="utf-8")
    proc = astralis("run", str(MISSION), "--out", str(out), "--quiet")
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and proc.poll() is None and \
            not (staging_path(out) / "events.jsonl").exists():
        time.sleep(0.005)
    proc.send_signal(signal.SIGTERM)
    code = proc.wait(timeout=60)
    assert code in (0, 130), proc.stderr.read() if proc.stderr else ""
    last = json.loads((out / "events.jsonl").read_text(encoding="utf-8").splitlines()[-1])
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    assert last["kind"] == "mission_end" and summary["outcome"] == last["outcome"]
    assert (last["outcome"] == "interrupted") == (code == 130)


def test_a_terminated_server_keeps_what_it_recorded(tmp_path: Path) -> None:
    """``astralis serve`` sent SIGTERM: exit 130 and the same outputs as after Ctrl-C, with no
    earlier run's summary left beside them."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "summary.json").write_text('{"outcome": "found"}', encoding="utf-8")
    port = free_port()
    proc = astralis("serve", str(MISSION), "--bind", f"tcp://127.0.0.1:{port}", "--pace",
                    "5x", "--out", str(out))
    wait_for(out / "events.jsonl", proc, 3)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "interrupted at t = " in err
    check_interrupted(out)


def test_a_terminated_study_keeps_the_rows_it_finished(tmp_path: Path) -> None:
    """``astralis study`` sent SIGTERM after a few seconds: exit 130, and the folder holds
    the rows of the scenarios finished (whole scenarios: every variant), its meta.json
    marked interrupted."""
    out = tmp_path / "study"
    proc = astralis("study", str(ROOT / "studies" / "outcomes.yaml"), "--scenarios", "1000",
                    "--workers", "2", "--out", str(out), "--quiet")
    time.sleep(12.0)
    assert proc.poll() is None, "the study ended before it could be interrupted"
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    meta = json.loads((out / "meta.json").read_text(encoding="utf-8"))
    assert meta["interrupted"] is True
    with (out / "table.csv").open(encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert 0 < len(rows) == meta["rows"] < 3000 and len(rows) % 3 == 0


def test_a_signal_while_the_study_folder_is_written_keeps_it_whole(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """SIGTERM after the last scenario, while the folder is being written: the folder is
    finished and put in place with every row, and the result says it was interrupted."""
    from astralis_des.exits import interrupt_on_termination
    from astralis_des.studies import output, runner
    from astralis_des.studies.spec import load_study

    study = load_study(ROOT / "studies" / "table5.yaml").with_changes(scenarios=20)
    fill = output.fill_folder

    def fill_and_terminate(result: runner.StudyResult, folder: Path) -> None:
        os.kill(os.getpid(), signal.SIGTERM)  # held until the folder is in place
        fill(result, folder)

    before = {sig: signal.getsignal(sig) for sig in (signal.SIGTERM, signal.SIGHUP)}
    interrupt_on_termination()
    monkeypatch.setattr(runner, "fill_folder", fill_and_terminate)
    try:
        result = runner.run_study(study, workers=1, out=tmp_path / "study")
    finally:
        for sig, handler in before.items():
            signal.signal(sig, handler)
    assert result.interrupted
    assert len(result.rows) == 40
    with (tmp_path / "study" / "table.csv").open(encoding="utf-8") as f:
        assert len(list(csv.DictReader(f))) == 40
    assert sorted(p.name for p in tmp_path.iterdir()) == ["study"]  # no staging, no lock


def test_a_study_interrupted_before_its_first_scenario_writes_an_empty_folder(
        tmp_path: Path) -> None:
    """Interrupted before any scenario ended: a folder with no rows, marked interrupted (it
    crashed in the summary before: the empty table had no variant column)."""
    from astralis_des.studies import runner
    from astralis_des.studies.spec import load_study

    study = load_study(ROOT / "studies" / "table5.yaml").with_changes(scenarios=10)
    result = runner.run_study(study, backend=Interrupted(),  # type: ignore[arg-type]
                              out=tmp_path / "study")
    assert result.interrupted and result.rows == []
    meta = json.loads((tmp_path / "study" / "meta.json").read_text(encoding="utf-8"))
    assert (meta["interrupted"], meta["rows"]) == (True, 0)
