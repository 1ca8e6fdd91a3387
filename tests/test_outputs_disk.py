"""A full disk, an I/O error, a folder that cannot be written: one line, a non-zero exit (74
for the machine, 2 for a path), and nothing half-written left to look like a result.

The full and read-only file systems are small tmpfs mounts (the tests run as root here; they
skip where mounting is not permitted)."""

from __future__ import annotations

import errno
import json
import math
import os
import shutil
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
import yaml

from astralis_des.cli import main

ROOT = Path(__file__).resolve().parents[1]
MISSION = ROOT / "missions" / "urban_search.yaml"
SCAN = ROOT / "data" / "real" / "autzen_trim.laz"
ENV = {**os.environ, "PYTHONUNBUFFERED": "1"}
EXIT_OUTPUT = 74  # the machine could not write the outputs (astralis_des.exits)
Disk = Callable[..., Path]


def astralis(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "astralis_des.cli", *args], env=ENV,
                          capture_output=True, text=True, timeout=600)


def one_line(err: str) -> str:
    """The one line a failed command prints (no traceback, no library's log lines)."""
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    return lines[0]


@pytest.fixture
def disk(tmp_path: Path) -> Iterator[Disk]:
    """``disk("64k")``: a fresh tmpfs of that size (``ro=True``: read-only), unmounted after."""
    mounted: list[Path] = []

    def mount(size: str, *, ro: bool = False) -> Path:
        where = tmp_path / f"disk{len(mounted)}"
        where.mkdir()
        if shutil.which("mount") is None:
            pytest.skip("no mount command")
        options = f"size={size}" + (",ro" if ro else "")
        done = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(where)],
                              capture_output=True, text=True)
        if done.returncode != 0:
            pytest.skip(f"mounting a tmpfs is not permitted here: {done.stderr.strip()}")
        mounted.append(where)
        return where

    yield mount
    for where in mounted:
        subprocess.run(["umount", "-l", str(where)], capture_output=True)


def fill(folder: Path, leave: int) -> None:
    """Fill the file system of ``folder`` until ``leave`` bytes are free."""
    free = shutil.disk_usage(folder).free - leave
    if free > 0:
        (folder / "filler").write_bytes(b"\0" * free)


def snapshot(folder: Path) -> dict[str, bytes]:
    return {p.relative_to(folder).as_posix(): p.read_bytes()
            for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.mark.parametrize(("size", "extra", "what"), [
    ("200k", [], "the recording (Rerun's file sink only logs it)"),
    ("12k", ["--no-recording"], "the summary"),
    ("8k", ["--no-recording"], "the event log, mid-run"),
], ids=["recording", "summary", "event-log"])
def test_a_run_on_a_full_disk_is_one_line_exit_74_and_leaves_nothing(
        disk: Disk, size: str, extra: list[str], what: str) -> None:
    """The disk fills while the run writes ``what``. (Before: exit 0 with a recording that
    fails ``rerun rrd verify``; with --no-recording an OSError traceback and an event log
    cut mid-line.)"""
    full = disk(size)
    done = astralis("run", str(MISSION), "--out", str(full / "run"), "--quiet", *extra)
    assert done.returncode == EXIT_OUTPUT, done.stderr
    assert "no space left on device" in one_line(done.stderr)
    assert list(full.iterdir()) == []  # no folder, no staging folder, no lock


def test_a_full_disk_leaves_the_earlier_result_as_it_was(disk: Disk) -> None:
    """A run that cannot be written leaves the earlier run's folder untouched: never the
    new event log beside the old summary."""
    folder = disk("64k")
    out = folder / "run"
    assert astralis("run", str(MISSION), "--out", str(out), "--quiet",
                    "--no-recording").returncode == 0
    before = snapshot(out)
    fill(folder, 10_000)
    done = astralis("run", str(MISSION), "--out", str(out), "--seed", "7", "--quiet",
                    "--no-recording")
    assert done.returncode == EXIT_OUTPUT, done.stderr
    one_line(done.stderr)
    assert snapshot(out) == before
    assert sorted(p.name for p in folder.iterdir()) == ["filler", "run"]


@pytest.mark.parametrize("command", ["study", "tune", "falsify", "world import"])
def test_a_study_tune_or_import_on_a_full_disk_is_one_line_exit_74(
        disk: Disk, tmp_path: Path, command: str) -> None:
    full = disk("32k")
    args = {"study": ["study", str(ROOT / "studies" / "table5.yaml"), "--scenarios", "20",
                      "--workers", "1", "--out", str(full / "out"), "--quiet"],
            "tune": ["tune", str(small_tune(tmp_path)), "--workers", "1", "--out",
                     str(full / "out"), "--quiet"],
            "falsify": FALSIFY + ["--out", str(full / "out")],
            "world import": ["world", "import", str(SCAN), "-o", str(full / "w.yaml")]}
    done = astralis(*args[command])
    assert done.returncode == EXIT_OUTPUT, done.stderr
    assert "no space left on device" in one_line(done.stderr)
    assert list(full.iterdir()) == []


FALSIFY = ["falsify", str(MISSION), "--trials", "2", "--batch", "2", "--no-baseline",
           "--workers", "1", "--quiet"]


def small_tune(folder: Path) -> Path:
    study = {"name": "t", "mission": str(MISSION), "seed": 3, "scenarios": 60,
             "evaluate": "assignment", "draw": {"positions": "building", "segment": "random"},
             "vary": {"strategy": ["mixed"]}}
    (folder / "study.yaml").write_text(yaml.safe_dump(study), encoding="utf-8")
    tune = {"name": "fit", "study": "study.yaml", "seed": 1, "trials": 3, "sampler": "random",
            "params": {"w1.ugv": {"low": 0, "high": 10}},
            "targets": {"mixed.ugv_high_mess": 0.06}}
    path = folder / "tune.yaml"
    path.write_text(yaml.safe_dump(tune, sort_keys=False), encoding="utf-8")
    return path


def commands(out: Path, tmp_path: Path) -> dict[str, list[str]]:
    return {"run": ["run", str(MISSION), "--out", str(out), "--quiet", "--no-recording"],
            "study": ["study", str(ROOT / "studies" / "table5.yaml"), "--scenarios", "4",
                      "--workers", "1", "--out", str(out), "--quiet"],
            "tune": ["tune", str(small_tune(tmp_path)), "--workers", "1", "--out", str(out),
                     "--quiet"],
            "falsify": FALSIFY + ["--out", str(out)],
            "world import": ["world", "import", str(SCAN), "-o", str(out) + ".yaml"]}


@pytest.mark.parametrize("command", ["run", "study", "tune", "falsify", "world import"])
@pytest.mark.parametrize("place", ["read-only", "under a file", "/proc"])
def test_an_output_folder_that_cannot_be_written_is_one_line_exit_2(
        disk: Disk, tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str,
        place: str) -> None:
    """(Before: an OSError traceback from each command.)"""
    if place == "read-only":
        out, says = disk("64k", ro=True) / "out", "read-only file system"
    elif place == "under a file":
        (tmp_path / "a-file").write_text("keep me", encoding="utf-8")
        out, says = tmp_path / "a-file" / "out", "a-file is a file, not a folder"
    else:
        out, says = Path("/proc/astralis-test/out"), "cannot write there"
    code = main(commands(out, tmp_path)[command])
    err = capsys.readouterr().err
    assert code == 2, err
    line = one_line(err)
    assert str(out) in line and says in line
    if place == "under a file":
        assert (tmp_path / "a-file").read_text(encoding="utf-8") == "keep me"


def test_an_io_error_mid_run_is_one_line_and_leaves_nothing(
        tmp_path: Path, capsys: pytest.CaptureFixture[str],
        monkeypatch: pytest.MonkeyPatch) -> None:
    """EIO (a failing disk) while the event log is written: exit 74, one line."""
    from astralis_des.sinks import files as sinks

    written = [0]
    on_event = sinks.JsonlWriter.on_event

    def failing(self: sinks.JsonlWriter, record: dict[str, object]) -> None:
        written[0] += 1
        if written[0] == 50:
            raise OSError(errno.EIO, os.strerror(errno.EIO))
        on_event(self, record)

    monkeypatch.setattr(sinks.JsonlWriter, "on_event", failing)
    code = main(["run", str(MISSION), "--out", str(tmp_path / "run"), "--quiet"])
    assert code == EXIT_OUTPUT
    assert "input/output error" in one_line(capsys.readouterr().err)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", ["events.jsonl", "summary.json", "recording.rrd"])
def test_an_io_error_putting_a_file_on_disk_is_one_line_and_leaves_nothing(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
        name: str) -> None:
    """EIO when a finished file is put on disk (``fsync``, which runs on a thread of its own
    while the other files are written): exit 74, one line naming the run's folder, and no
    result in place, whichever file it is."""
    from astralis_des import outdir

    sync = outdir.sync
    synced: list[str] = []

    def failing(path: Path) -> None:
        synced.append(path.name)
        if path.name == name:
            raise OSError(errno.EIO, os.strerror(errno.EIO), str(path))
        sync(path)

    monkeypatch.setattr(outdir, "sync", failing)
    code = main(["run", str(MISSION), "--out", str(tmp_path / "run"), "--quiet"])
    assert code == EXIT_OUTPUT
    line = one_line(capsys.readouterr().err)
    assert "input/output error" in line and str(tmp_path / "run") in line
    assert sorted(synced) == ["events.jsonl", "recording.rrd", "summary.json"]
    assert list(tmp_path.iterdir()) == []


def test_a_recording_that_does_not_read_back_is_an_error(tmp_path: Path) -> None:
    """Rerun's file sink logs a failed write and goes on: the recording is read back."""
    from astralis_des import Simulation, load_mission
    from astralis_des.sinks.rrd_check import check_recording

    Simulation(load_mission(MISSION), out_dir=tmp_path / "run").run()
    whole = tmp_path / "run" / "recording.rrd"
    check_recording(whole)  # no error
    cut = tmp_path / "cut.rrd"
    cut.write_bytes(whole.read_bytes()[: whole.stat().st_size // 2])
    with pytest.raises(OSError, match="does not read back"):
        check_recording(cut)


@pytest.mark.parametrize("keep", [0, 4, 12, 20, 400, -40, -32, -1, 1])
def test_a_recording_cut_anywhere_does_not_read_back(tmp_path: Path, keep: int) -> None:
    """Its framing is read back: the header, each message's length up to the end message,
    and the footer that points at the manifest. A file cut at any byte (or with a byte too
    many, ``keep`` 1) is refused, naming why."""
    from astralis_des import Simulation, load_mission
    from astralis_des.sinks.rrd_check import broken, check_recording

    Simulation(load_mission(MISSION), out_dir=tmp_path / "run").run()
    whole = (tmp_path / "run" / "recording.rrd").read_bytes()
    cut = tmp_path / "cut.rrd"
    cut.write_bytes(whole + b"\0" if keep == 1 else whole[:keep] if keep else b"")
    assert broken(cut) is not None
    with pytest.raises(OSError, match=r"does not read back \((no |cut short|a message|its "
                                      r"footer|bytes after)"):
        check_recording(cut)


def test_a_nan_never_reaches_a_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """JSON is written strict: a NaN in a summary is an error naming where it is, and the
    run's folder is not put in place."""
    from astralis_des import Simulation, load_mission
    from astralis_des.outdir import dumps
    from astralis_des.simulation.result import RunResult

    with pytest.raises(ValueError, match=r"rooms\[1\] = nan is not a number JSON can hold"):
        dumps({"rooms": [1.0, math.nan]})
    summary = RunResult.summary
    monkeypatch.setattr(RunResult, "summary",
                        lambda self: {**summary(self), "coverage": math.nan})
    with pytest.raises(ValueError, match="coverage = nan"):
        Simulation(load_mission(MISSION), out_dir=tmp_path / "run").run()
    assert list(tmp_path.iterdir()) == []


def test_a_tune_journal_reads_back_its_infinities() -> None:
    """A tune's journal holds infinite scores (a trial that failed a target) as strict JSON
    that reads back as they were; its best.json says null."""
    from astralis_des.outdir import finite, journal_dumps, journal_loads

    record = {"row": {"score": math.inf, "z": [-math.inf, 1.5]}, "values": None}
    line = journal_dumps(record)
    json.loads(line, parse_constant=lambda c: pytest.fail(f"{c} in strict JSON"))
    back = journal_loads(line)
    assert back["row"]["score"] == math.inf and back["row"]["z"][0] == -math.inf
    assert finite(record) == {"row": {"score": None, "z": [None, 1.5]}, "values": None}
