"""Ctrl-C and SIGTERM at any moment, from the first line of ``main`` (before the heavy
imports) to the last write: exit 130, at most one line, no traceback; and a signal in the
wind-down or while the outputs are written still leaves them whole and in place.

Each command starts in a session of its own and the signal goes to its process group, as a
terminal's Ctrl-C does (a background job of a non-interactive shell ignores SIGINT)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from astralis_des.cli import main

ROOT = Path(__file__).resolve().parents[1]
MISSION = ROOT / "missions" / "urban_search.yaml"
ENV = {**os.environ, "PYTHONUNBUFFERED": "1"}
DELAYS = (0.0, 0.03, 0.1, 0.2, 0.35, 0.6, 1.0)  # s after main began: its imports, then work
pytestmark = pytest.mark.skipif(not Path("/proc/self/status").exists(),
                                reason="reads the signals a process catches from /proc")


def catches_sigterm(pid: int) -> bool:
    """Whether the process has a handler for SIGTERM: main's first line sets it."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except (FileNotFoundError, ProcessLookupError):
        return False
    mask = next(int(line.split()[1], 16) for line in status.splitlines()
                if line.startswith("SigCgt:"))
    return bool(mask & (1 << (signal.SIGTERM - 1)))


def interrupted(args: list[str], sig: signal.Signals, delay: float) -> tuple[int, str, str]:
    """Start ``astralis ARGS``, send ``sig`` to its group ``delay`` s after main began."""
    proc = subprocess.Popen([sys.executable, "-m", "astralis_des.cli", *args], env=ENV,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    deadline = time.monotonic() + 60
    while not catches_sigterm(proc.pid) and proc.poll() is None:
        assert time.monotonic() < deadline, "main never began"
        time.sleep(0.001)
    time.sleep(delay)
    os.killpg(proc.pid, sig)
    out, err = proc.communicate(timeout=120)
    return proc.returncode, out, err


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_a_run_signalled_at_any_moment_of_its_start_exits_130_in_one_line(
        tmp_path: Path, sig: signal.Signals) -> None:
    """A physics run (its imports take about a second, its mission ten): at each moment,
    exit 130 and one line. (Before: a KeyboardInterrupt traceback during the imports.)"""
    for delay in DELAYS:
        code, _, err = interrupted(["run", str(MISSION), "--fidelity", "physics", "--out",
                                    str(tmp_path / "run")], sig, delay)
        assert code == 130, (delay, err)
        lines = err.splitlines()
        assert len(lines) <= 2 and lines[-1].startswith("interrupted"), (delay, err)
        if len(lines) == 2:  # the progress bar, if the run was under way, then the line
            assert lines[0].startswith("mission "), (delay, err)


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_validate_signalled_at_any_moment_is_one_line(sig: signal.Signals) -> None:
    """``validate`` either ends first (``ok:``) or says ``interrupted``, exit 130. (Before:
    a KeyboardInterrupt traceback at any time.)"""
    for delay in DELAYS[:-1]:
        code, out, err = interrupted(["validate", str(MISSION)], sig, delay)
        if code == 0:
            assert out.startswith("ok:") and err == "", (delay, err)
        else:
            assert (code, err) == (130, "interrupted\n"), (delay, err)


def test_a_signal_during_the_wind_down_still_puts_the_outputs_in_place(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    """The target is found and the UAVs land when SIGTERM comes: the landings end there, and
    the event log, the summary and the recording are whole and in place. (Before: the
    interrupt left the wind-down with no mission_end and no summary.)"""
    from astralis_des.simulation.core import Simulation

    wind_down = Simulation._wind_down

    def terminated(self: Simulation) -> None:
        os.kill(os.getpid(), signal.SIGTERM)
        wind_down(self)

    monkeypatch.setattr(Simulation, "_wind_down", terminated)
    out = tmp_path / "run"
    assert main(["run", str(MISSION), "--out", str(out)]) == 130
    said = "".join(capsys.readouterr().err.split())  # rich wraps the line at 80 columns
    assert said.endswith("".join(f"interrupted; what was recorded is in {out}/".split()))
    check_whole(out, "found")


def test_a_signal_while_the_outputs_are_written_keeps_them_whole(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """SIGINT as the summary is written, and again as the folder is put in place: both
    wait until the folder is in place, then exit 130."""
    from astralis_des import outdir
    from astralis_des.sinks import files as sinks

    close, place = sinks.SummaryWriter.close, outdir.Staging._place

    def close_interrupted(self: sinks.SummaryWriter, result: object) -> None:
        os.kill(os.getpid(), signal.SIGINT)
        close(self, result)  # type: ignore[arg-type]

    def place_interrupted(self: outdir.Staging) -> list[Path]:
        os.kill(os.getpid(), signal.SIGTERM)
        return place(self)

    monkeypatch.setattr(sinks.SummaryWriter, "close", close_interrupted)
    monkeypatch.setattr(outdir.Staging, "_place", place_interrupted)
    out = tmp_path / "run"
    assert main(["run", str(MISSION), "--out", str(out), "--quiet"]) == 130
    check_whole(out, "found")


def check_whole(out: Path, outcome: str) -> None:
    from test_recording import verify

    records = [json.loads(line) for line in
               (out / "events.jsonl").read_text(encoding="utf-8").splitlines()]
    assert records[-1] == {**records[-1], "kind": "mission_end", "outcome": outcome}
    assert json.loads((out / "summary.json").read_text(encoding="utf-8"))["outcome"] == outcome
    verify(out / "recording.rrd")
    assert sorted(p.name for p in out.parent.iterdir()) == [out.name]  # no staging left
