"""An output folder has one writer at a time: a second is refused in one line naming the
first (exit 2), a dead writer's lock is taken over with a note, and a killed writer leaves
only dot-names beside the folder, never a folder that looks like a result."""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from astralis_des.cli import main

ROOT = Path(__file__).resolve().parents[1]
MISSION = ROOT / "missions" / "urban_search.yaml"
ENV = {**os.environ, "PYTHONUNBUFFERED": "1"}


def astralis(*args: str) -> subprocess.Popen[str]:
    return subprocess.Popen([sys.executable, "-m", "astralis_des.cli", *args], env=ENV,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)


def seeds(out: Path) -> tuple[int, int]:
    """The seed the event log's run had, and the one the summary's had."""
    first = json.loads((out / "events.jsonl").read_text(encoding="utf-8").splitlines()[0])
    return first["seed"], json.loads((out / "summary.json").read_text(encoding="utf-8"))["seed"]


def wait_for_staged(out: Path, proc: subprocess.Popen[str], started: int = 2) -> None:
    """Until the run writing ``out`` has ``started`` tasks started in its staging folder."""
    from astralis_des.outdir import staging_path

    events = staging_path(out) / "events.jsonl"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None:
        if events.exists() and events.read_text(encoding="utf-8").count("task_started") >= \
                started:
            return
        time.sleep(0.05)
    raise AssertionError("the run ended (or never started) before it could be caught")


def test_two_runs_at_once_into_one_folder_never_mix_their_files(tmp_path: Path) -> None:
    """The issue's reproduction, made sure to overlap: a second ``astralis run`` with the
    same --out while the first is under way. (Before: both exit 0, and the folder holds the
    second run's event log beside the first run's summary.) Now the second is refused in one
    line naming the first, and the folder is the first run's alone."""
    out = tmp_path / "out"
    first = astralis("run", str(MISSION), "--seed", "1", "--fidelity", "physics", "--out",
                     str(out), "--quiet")
    wait_for_staged(out, first)
    second = astralis("run", str(MISSION), "--seed", "2", "--out", str(out), "--quiet")
    _, err = second.communicate(timeout=300)
    assert second.returncode == 2, err
    assert err.startswith(f"error: {out}: being written by pid {first.pid} (astralis run ")
    assert len(err.splitlines()) == 1
    os.killpg(first.pid, signal.SIGTERM)  # the first keeps what it recorded
    assert first.wait(timeout=120) == 130
    assert seeds(out) == (1, 1)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no lock, no staging


@contextlib.contextmanager
def held(target: Path) -> Iterator[int]:
    """Another process holding the lock of ``target`` (as a writer does); its pid."""
    code = ("import time; from astralis_des.outdir import holding\n"
            f"with holding({str(target)!r}):\n"
            "    print('held', flush=True); time.sleep(120)\n")
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout is not None and proc.stdout.readline().strip() == "held"
        yield proc.pid
    finally:
        proc.kill()
        proc.wait()


@pytest.mark.parametrize("command", ["run", "study", "tune", "falsify", "world import"])
def test_a_second_writer_is_refused_in_one_line_naming_the_first(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str) -> None:
    from test_outputs_disk import commands

    out = tmp_path / "out"
    target = out.with_name("out.yaml") if command == "world import" else out
    with held(target) as pid:
        t0 = time.perf_counter()
        code = main(commands(out, tmp_path)[command])
        seconds = time.perf_counter() - t0
    err = capsys.readouterr().err
    assert code == 2, err
    assert err == f"error: {target}: being written by pid {pid} (astralis): wait for it to " \
                  "end, or write elsewhere\n"
    assert seconds < 30  # refused before the work, not after it
    assert not target.exists()


def test_a_dead_writers_lock_is_taken_over_with_a_note(tmp_path: Path) -> None:
    """A lock left by a process that is gone (killed, the machine rebooted) does not stop
    the next run: it says so and goes on."""
    from astralis_des.outdir import lock_path

    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True)
    out = tmp_path / "out"
    lock_path(out).write_text(f"{dead.stdout.strip()} astralis run old.yaml\n",
                              encoding="utf-8")
    proc = astralis("run", str(MISSION), "--out", str(out), "--no-recording")
    _, err = proc.communicate(timeout=300)
    assert proc.returncode == 0, err
    assert f"took over from pid {dead.stdout.strip()}, which ended without finishing" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_a_killed_run_leaves_only_dot_names_and_the_earlier_result(tmp_path: Path) -> None:
    """SIGKILL (the OOM killer) mid-run: the earlier result is as it was, beside it only a
    dot-named staging folder (whole event-log lines) and lock; the next run takes over."""
    out = tmp_path / "run"
    first = astralis("run", str(MISSION), "--seed", "1", "--out", str(out), "--quiet",
                     "--no-recording")
    assert first.wait(timeout=300) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    proc = astralis("run", str(MISSION), "--seed", "2", "--fidelity", "physics", "--out",
                    str(out), "--quiet")
    wait_for_staged(out, proc)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait(timeout=60)
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert sorted(p.name for p in tmp_path.iterdir()) == [".run.lock", ".run.partial", "run"]
    for line in (tmp_path / ".run.partial" / "events.jsonl").read_text().splitlines():
        json.loads(line)
    again = astralis("run", str(MISSION), "--seed", "3", "--out", str(out))
    _, err = again.communicate(timeout=300)
    assert again.returncode == 0, err
    assert f"took over from pid {proc.pid}" in err
    assert seeds(out) == (3, 3)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]


def test_a_run_replaces_its_own_files_and_keeps_the_others(tmp_path: Path) -> None:
    """A run into a folder with other files replaces its outputs, removes those of an
    earlier run it does not write again (run.mcap), and leaves the rest alone."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine", encoding="utf-8")
    (out / "run.mcap").write_bytes(b"an earlier run's")
    assert main(["run", str(MISSION), "--out", str(out), "--quiet", "--no-recording"]) == 0
    assert sorted(p.name for p in out.iterdir()) == ["events.jsonl", "notes.txt",
                                                     "summary.json"]
    assert (out / "notes.txt").read_text(encoding="utf-8") == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_a_study_into_a_runs_folder_leaves_none_of_the_runs_files(tmp_path: Path) -> None:
    """Found by the fuzzer: a folder holding a result (a key file: a run's summary.json) is
    replaced as a whole result, so a study's folder never holds a run's event log."""
    out = tmp_path / "out"
    assert main(["run", str(MISSION), "--out", str(out), "--quiet", "--no-recording"]) == 0
    (out / "notes.txt").write_text("mine", encoding="utf-8")
    assert main(["study", str(ROOT / "studies" / "table5.yaml"), "--scenarios", "4",
                 "--workers", "1", "--out", str(out), "--quiet"]) == 0
    names = sorted(p.name for p in out.iterdir())
    assert "meta.json" in names and "notes.txt" in names
    assert not {"events.jsonl", "summary.json"} & set(names)


def test_a_run_into_a_users_folder_touches_only_its_own_files(tmp_path: Path) -> None:
    """``--out .`` in a folder of the user's files (a study file among them, which is also a
    name a study writes): only the run's files are added; nothing of the user's goes."""
    mine = {"study.yaml": "name: mine\n", "report.md": "# my notes\n", "notes.txt": "mine"}
    for name, text in mine.items():
        (tmp_path / name).write_text(text, encoding="utf-8")
    assert main(["run", str(MISSION), "--out", str(tmp_path), "--quiet",
                 "--no-recording"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        [*mine, "events.jsonl", "summary.json"])
    assert all((tmp_path / n).read_text(encoding="utf-8") == t for n, t in mine.items())


def test_a_killed_tune_resumes_from_the_trials_it_left(tmp_path: Path) -> None:
    """A tune's journal grows in its staging folder; killed, ``--resume`` goes on from the
    trials it left there, and ends with the trials of a tune never killed."""
    import yaml
    from test_outputs_disk import small_tune

    from astralis_des.outdir import staging_path

    path = small_tune(tmp_path)
    path.write_text(yaml.safe_dump({**yaml.safe_load(path.read_text()), "trials": 8},
                                   sort_keys=False), encoding="utf-8")
    out = tmp_path / "out"
    proc = astralis("tune", str(path), "--workers", "1", "--out", str(out), "--quiet")
    journal = staging_path(out) / "trials.jsonl"
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline and proc.poll() is None and \
            len(journal.read_text().splitlines() if journal.exists() else ()) < 3:
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait(timeout=60)
    assert not out.exists()
    resumed = astralis("tune", str(path), "--workers", "1", "--out", str(out), "--resume")
    _, err = resumed.communicate(timeout=600)
    assert resumed.returncode == 0, err
    assert f"took over from pid {proc.pid}, which ended without finishing (killed?); going " \
           "on from what it left" in err
    assert main(["tune", str(path), "--workers", "1", "--out", str(tmp_path / "ref"),
                 "--quiet"]) == 0

    def trials(folder: Path) -> list[dict[str, object]]:
        rows = [json.loads(line)["row"] for line in
                (folder / "trials.jsonl").read_text().splitlines()[1:]]
        return [{k: v for k, v in r.items() if k != "seconds"} for r in rows]

    assert trials(out) == trials(tmp_path / "ref") and len(trials(out)) == 8
