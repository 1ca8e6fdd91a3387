"""How the ``astralis`` program ends: as Python's exit does (the threads, the ``atexit``
handlers, stdout and stderr flushed) less its finalization, which took apart every module
and walked the million objects of the package's imports (0.3-0.6 s of a 1.5-2 s run); and
what it prints meets a full disk or a closed pipe with one line or nothing, never a
traceback."""

from __future__ import annotations

import subprocess
import sys
from importlib.metadata import entry_points
from pathlib import Path

import pytest
from terminal import cli

ROOT = Path(__file__).resolve().parents[1]
MISSION = ROOT / "missions" / "urban_search.yaml"

ENDING = """
import atexit, sys, threading, time
from concurrent.futures import ThreadPoolExecutor

atexit.register(lambda: print("atexit handler ran", file=sys.stderr))
pool = ThreadPoolExecutor(1)  # left open: its exit hook ends its worker
pool.submit(time.sleep, 0.01)

def late(mark: str) -> None:  # not a daemon: Python's exit waits for it
    time.sleep(0.3)
    with open(mark, "w") as f:
        f.write("joined")

threading.Thread(target=late, args=(sys.argv[1],)).start()
sys.argv = ["astralis", *sys.argv[2:]]
from astralis_des.cli import entry
entry()
print("never here", file=sys.stderr)
"""


@pytest.mark.parametrize(("argv", "code"), [
    (["validate", str(MISSION)], 0),
    (["validate", str(ROOT / "pyproject.toml")], 2),
])
def test_the_program_ends_as_pythons_exit_would(tmp_path: Path, argv: list[str],
                                                code: int) -> None:
    mark = tmp_path / "thread"
    done = subprocess.run([sys.executable, "-c", ENDING, str(mark), *argv], capture_output=True,
                          text=True, cwd=ROOT, timeout=120, check=False)
    assert done.returncode == code, done.stderr
    assert done.stderr.splitlines()[-1] == "atexit handler ran"
    assert "never here" not in done.stderr and "Traceback" not in done.stderr
    assert mark.read_text() == "joined"
    if code == 0:  # what it printed is out
        assert done.stdout.startswith(f"ok: {MISSION}: mission 'urban_search'")


def test_the_installed_program_is_the_entry_that_ends_so() -> None:
    (script,) = [e for e in entry_points(group="console_scripts") if e.name == "astralis"]
    assert script.value == "astralis_des.cli:entry"


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="no /dev/full")
@pytest.mark.parametrize("argv", [["--version"], ["schema"], ["validate", str(MISSION)]])
def test_printing_to_a_full_disk_is_one_line_and_exit_74(argv: list[str]) -> None:
    with open("/dev/full", "w") as full:
        done = subprocess.run(cli(*argv), stdout=full, stderr=subprocess.PIPE, text=True,
                              cwd=ROOT, timeout=120, check=False)
    assert done.returncode == 74
    assert done.stderr == "error: No space left on device\n"


@pytest.mark.parametrize("argv", [["--version"], ["schema"]])
def test_a_reader_gone_away_is_no_error(argv: list[str]) -> None:
    """``astralis schema | head -0``: the pipe closed before anything was written."""
    with subprocess.Popen(cli(*argv), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          cwd=ROOT) as proc:
        assert proc.stdout is not None and proc.stderr is not None
        proc.stdout.close()
        errors = proc.stderr.read()
        assert proc.wait(timeout=120) == 0
    assert errors == b""
