"""``--quiet`` means nothing on stderr but errors: no library warnings, no PyBullet banner."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
MISSION = ROOT / "missions" / "urban_search.yaml"


CROWDED = """
import sys
from astralis_des.actions import landing
from astralis_des.cli import main

way = landing.landing_way


def crowded(ctx, robot):  # as where furniture takes every spot
    landing.log.warning("%s: no free spot to land on near %s: it comes down where it is",
                        robot.id, robot.position(ctx.env.now).round(2).tolist())
    landing.log.error("%s: an error still shows", robot.id)
    return way(ctx, robot)


landing.landing_way = crowded
sys.exit(main())
"""


@pytest.mark.parametrize("quiet", [True, False], ids=["quiet", "loud"])
def test_a_library_warning_is_not_shown_with_quiet(tmp_path: Path, quiet: bool) -> None:
    """A UAV that finds no free spot to land on says so in the log: on stderr without
    ``--quiet``, not with it (before: with it too). Errors still show."""
    flags = ["--quiet"] if quiet else []
    done = subprocess.run([sys.executable, "-c", CROWDED, "run", str(MISSION), "--out",
                           str(tmp_path / "run"), *flags], capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr
    lines = done.stderr.splitlines()
    assert ("uav1: no free spot to land on near [" in done.stderr) is not quiet
    assert "uav1: an error still shows" in lines
    if quiet:
        assert lines == ["uav1: an error still shows", "uav2: an error still shows"]


def test_a_quiet_physics_run_prints_nothing_on_stderr(tmp_path: Path) -> None:
    """Not PyBullet's build time either (it prints it on stderr as it loads): a quiet
    physics run, stopped with SIGTERM once under way, has an empty stderr (and exit 130)."""
    from astralis_des.outdir import staging_path

    proc = subprocess.Popen([sys.executable, "-m", "astralis_des.cli", "run", str(MISSION),
                             "--fidelity", "physics", "--out", str(tmp_path / "run"),
                             "--quiet"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True)
    events = staging_path(tmp_path / "run") / "events.jsonl"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None and \
            "task_started" not in (events.read_text() if events.exists() else ""):
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGTERM)
    out, err = proc.communicate(timeout=120)
    assert (proc.returncode, out, err) == (130, "", "")
