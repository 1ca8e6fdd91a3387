"""``astralis run`` starts without Python's cyclic garbage collector walking what it imports.

Its imports and the mission's load make about a million objects that all stay alive; left
on, the collector sets off 280-odd collections over them (two of them full), 0.1-0.2 s of a
1.5-2 s process. The command holds the collector off until the run's first event, freezes
what was made by then and collects as usual from there on. A caller of ``main`` (a test, a
notebook) gets its collector back as it was."""

from __future__ import annotations

import gc
import json
import subprocess
import sys
from pathlib import Path

import pytest
from terminal import run_cli

ROOT = Path(__file__).resolve().parents[1]
MISSION = ROOT / "missions" / "urban_search.yaml"

COUNTED = """
import gc, json, sys
seen = []
gc.callbacks.append(lambda phase, info: seen.append(info["generation"]) if phase == "start"
                    else None)
from astralis_des.cli import main
code = main(sys.argv[1:])
print(json.dumps({"code": code, "collections": len(seen), "full": seen.count(2),
                  "enabled": gc.isenabled(), "frozen": gc.get_freeze_count()}))
"""


def test_a_run_in_its_own_process_is_not_slowed_by_collections(tmp_path: Path) -> None:
    done = subprocess.run([sys.executable, "-c", COUNTED, "run", str(MISSION), "--out",
                           str(tmp_path / "out"), "--quiet", "--no-recording"],
                          capture_output=True, text=True, cwd=ROOT, timeout=300, check=False)
    assert done.returncode == 0, done.stderr
    counted = json.loads(done.stdout.strip().splitlines()[-1])
    assert counted["code"] == 0
    assert counted["full"] == 0  # none over the million objects of its start
    assert counted["collections"] < 100  # the run's own (about 20), not its start's (280)
    assert counted["enabled"] and counted["frozen"] == 0  # given back, nothing left frozen


@pytest.mark.parametrize("argv", [
    ["--no-recording"],  # a whole run
    ["--seed", "-1"],  # bad input: exit 2 before anything runs
])
def test_the_callers_collector_is_given_back(tmp_path: Path, argv: list[str]) -> None:
    assert gc.isenabled()
    code, _, stderr = run_cli("run", str(MISSION), "--out", str(tmp_path / "out"), "--quiet",
                              *argv)
    assert code == (0 if argv == ["--no-recording"] else 2), stderr
    assert gc.isenabled()
    assert gc.get_freeze_count() == 0


def test_a_caller_without_a_collector_is_left_without_one(tmp_path: Path) -> None:
    gc.disable()
    try:
        code, _, stderr = run_cli("run", str(MISSION), "--out", str(tmp_path / "out"),
                                  "--quiet", "--no-recording")
        assert code == 0, stderr
        assert not gc.isenabled()
        assert gc.get_freeze_count() == 0
    finally:
        gc.enable()


def test_a_callers_own_frozen_objects_stay_frozen(tmp_path: Path) -> None:
    """A server that froze its objects before forking calls ``main``: they stay frozen."""
    gc.freeze()
    try:
        frozen = gc.get_freeze_count()
        code, _, stderr = run_cli("run", str(MISSION), "--out", str(tmp_path / "out"),
                                  "--quiet", "--no-recording")
        assert code == 0, stderr
        assert gc.isenabled()
        assert 0 < gc.get_freeze_count() <= frozen  # not unfrozen (some died meanwhile)
    finally:
        gc.unfreeze()
