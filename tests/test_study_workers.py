"""Issue 39: a study's workers can die (the OOM killer's SIGKILL) and its process group can be
signalled at any moment: the study goes on, or ends at once with the rows it finished; it
never waits for ever.

Before: a killed pool worker stopped the study at 15/16 for good; SIGTERM to the group left
the parent waiting; SIGINT before the first result ended in a ``KeyError: 'variant'``
traceback from the plots and no folder.
"""

from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import pytest
from fake_backends import Interrupted

from astralis_des.studies import load_study, pool, run_study
from astralis_des.studies.backends import LocalBackend
from astralis_des.studies.scenarios import ChunkResult

ROOT = Path(__file__).resolve().parents[1]
OUTCOMES = ROOT / "studies" / "outcomes.yaml"
TABLE5 = ROOT / "studies" / "table5.yaml"
ENV = {**os.environ, "PYTHONUNBUFFERED": "1"}
KILLED = "worker killed by signal 9 (SIGKILL) (twice)"


def children(pid: int) -> list[int]:
    """The processes whose parent is ``pid`` (from /proc: no psutil needed)."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text(encoding="ascii", errors="replace")
        except OSError:
            continue
        if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
            found.append(int(entry.name))
    return found


def study_cli(out: Path, *args: str) -> subprocess.Popen[str]:
    """``astralis study`` in a session of its own (a group to signal, as a terminal would)."""
    return subprocess.Popen([sys.executable, "-m", "astralis_des.cli", "study", str(OUTCOMES),
                             "--workers", "2", "--out", str(out), *args], env=ENV, cwd=ROOT,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)


def workers_of(proc: subprocess.Popen[str], count: int = 2) -> list[int]:
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and proc.poll() is None:
        found = children(proc.pid)
        if len(found) >= count:
            return found
        time.sleep(0.02)
    raise AssertionError("the study's workers never started")


def table(folder: Path) -> list[dict[str, str]]:
    with (folder / "table.csv").open(encoding="utf-8") as f:
        return list(csv.DictReader(f))


def test_a_worker_killed_mid_study_is_replaced_and_the_table_is_unchanged(
        tmp_path: Path) -> None:
    """SIGKILL to one of two workers while they run: the study finishes (exit 0) with every
    row ok, the same table as a study no one disturbed."""
    killed = study_cli(tmp_path / "killed", "--scenarios", "8", "--quiet")
    victim = workers_of(killed)[0]
    time.sleep(0.5)
    os.kill(victim, signal.SIGKILL)
    _, err = killed.communicate(timeout=120)
    assert killed.returncode == 0, err
    calm = study_cli(tmp_path / "calm", "--scenarios", "8", "--quiet")
    calm.communicate(timeout=120)
    rows = table(tmp_path / "killed")
    assert len(rows) == 24 and {r["status"] for r in rows} == {"ok"}
    assert rows == table(tmp_path / "calm")


@pytest.fixture
def poisoned(monkeypatch: pytest.MonkeyPatch) -> None:
    """Scenario 3 kills the worker that runs it, every time (the workers are forked from
    this process, patch included)."""
    run_chunk = pool.run_chunk

    def deadly(study: Any, indices: Sequence[int], recordings: Path | None) -> ChunkResult:
        if 3 in indices:
            os.kill(os.getpid(), signal.SIGKILL)
        return run_chunk(study, indices, recordings)

    monkeypatch.setattr(pool, "run_chunk", deadly)


def check_poisoned(rows: list[dict[str, Any]], scenarios: int, variants: int) -> None:
    assert len(rows) == scenarios * variants
    failed = [r for r in rows if r["status"] == "failed"]
    assert {r["scenario"] for r in failed} == {3} and len(failed) == variants
    assert all(r["error"] == KILLED for r in failed)
    assert all(r["status"] == "ok" for r in rows if r["scenario"] != 3)


def test_a_scenario_that_kills_its_worker_again_is_a_failed_row(poisoned: None,
                                                                 tmp_path: Path) -> None:
    """Scenario 3 is run again in a fresh worker, dies again, and its rows are failed with the
    reason; the other scenarios' rows are ok and the folder is written."""
    study = load_study(TABLE5).with_changes(scenarios=8)
    result = run_study(study, workers=2, out=tmp_path / "study")
    check_poisoned(result.rows, 8, len(study.variants))
    meta = json.loads((tmp_path / "study" / "meta.json").read_text(encoding="utf-8"))
    assert meta["rows"] == 8 * len(study.variants) and not result.interrupted


def test_a_held_pool_replaces_its_dead_worker_for_the_next_run(poisoned: None) -> None:
    """A tune's held workers: a study made from the held one loses a worker on scenario 3 and
    fails it; the next study runs on the replaced workers."""
    base = load_study(TABLE5).with_changes(scenarios=6)
    backend = LocalBackend(2)
    backend.hold(base)
    try:
        first = run_study(base.with_changes(seed=11), backend=backend)
        check_poisoned(first.rows, 6, len(base.variants))
        second = run_study(base.with_changes(seed=12, scenarios=3), backend=backend)
        assert {r["status"] for r in second.rows} == {"ok"}
    finally:
        backend.close()


def test_sigterm_to_the_process_group_ends_the_study_in_5_s(tmp_path: Path) -> None:
    """What ``timeout``, ``docker stop`` and systemd send: the workers die, and the parent
    writes the rows it has and exits 130 within 5 s (it used to wait for ever)."""
    proc = study_cli(tmp_path / "study", "--scenarios", "1000", "--quiet")
    workers_of(proc)
    time.sleep(6.0)
    os.killpg(proc.pid, signal.SIGTERM)
    began = time.monotonic()
    _, err = proc.communicate(timeout=60)
    assert time.monotonic() - began < 5.0
    assert proc.returncode == 130, err
    meta = json.loads((tmp_path / "study" / "meta.json").read_text(encoding="utf-8"))
    rows = table(tmp_path / "study")
    assert meta["interrupted"] is True and 0 < len(rows) == meta["rows"] < 3000


def test_workers_end_when_the_study_is_killed(tmp_path: Path) -> None:
    """SIGKILL to the study alone (the OOM killer picks the biggest process): its workers
    end within seconds. (Before: each held both ends of its pipe, so it never saw its parent
    go and waited for a scenario for ever, holding the terminal's output open: a caller
    reading it to the end, as CI does, hung.)"""
    proc = study_cli(tmp_path / "study", "--scenarios", "1000", "--quiet")
    workers = workers_of(proc)
    os.kill(proc.pid, signal.SIGKILL)
    proc.communicate(timeout=60)  # the workers hold its stdout and stderr until they end
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline and any(Path(f"/proc/{w}").exists() for w in workers):
        time.sleep(0.05)
    assert not [w for w in workers if Path(f"/proc/{w}").exists()]
    assert not (tmp_path / "study").exists()


def test_ctrl_c_before_the_first_result_writes_an_empty_folder(tmp_path: Path) -> None:
    """SIGINT to the group as soon as the workers start: exit 130, nothing on stderr under
    --quiet (no traceback), a folder of no rows marked interrupted (before: a ``KeyError:
    'variant'`` from the plots, and no folder)."""
    proc = study_cli(tmp_path / "study", "--scenarios", "100", "--quiet")
    workers_of(proc)
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert err == "", err
    meta = json.loads((tmp_path / "study" / "meta.json").read_text(encoding="utf-8"))
    assert (meta["interrupted"], meta["rows"]) == (True, 0)


def test_an_interrupted_mission_study_writes_its_folder_without_plots(tmp_path: Path) -> None:
    """The plots of a mission study (time to find, outcomes) with no rows: none drawn, the
    folder written (the in-process form of the case above)."""
    study = load_study(OUTCOMES).with_changes(scenarios=4)
    result = run_study(study, backend=Interrupted(),  # type: ignore[arg-type]
                       out=tmp_path / "study")
    assert result.interrupted and result.rows == []
    assert not list((tmp_path / "study" / "plots").glob("*.png"))


def ray_workers() -> list[int]:
    """Ray's worker processes running the study's actor."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                cmdline = (entry / "cmdline").read_bytes()
            except OSError:
                continue
            if b"_RayWorker" in cmdline:
                found.append(int(entry.name))
    return found


def test_a_lost_ray_actor_is_replaced_and_the_table_is_unchanged() -> None:
    """A Ray actor killed mid-study: its chunk runs again on fresh actors, and the table is
    the one process's."""
    ray = pytest.importorskip("ray")
    study = load_study(OUTCOMES).with_changes(scenarios=6, vary={"strategy": ["naive"]})
    killed: list[int] = []

    def kill_one() -> None:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not killed:
            found = ray_workers()
            if found:
                time.sleep(0.3)
                os.kill(found[0], signal.SIGKILL)
                killed.append(found[0])
            time.sleep(0.05)

    ray.init(num_cpus=2, include_dashboard=False, logging_level="ERROR", log_to_driver=False)
    try:
        killer = threading.Thread(target=kill_one, daemon=True)
        killer.start()
        on_ray = run_study(study, workers=2, backend="ray")
        killer.join(timeout=5)
    finally:
        ray.shutdown()
    assert killed, "no actor was found to kill"
    assert {r["status"] for r in on_ray.rows} == {"ok"}
    assert on_ray.table.equals(run_study(study, workers=1).table)
