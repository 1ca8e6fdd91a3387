"""examples/plugins/: a legged robot kind, its action, planner, physics body and look, and a
strategy, added by a plug-in module the mission names, with no edit to the package. Each run
is its own process, as a user's is, so the plug-in's kind never leaks into other tests."""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from pathlib import Path

import pytest
from terminal import cli

ROOT = Path(__file__).resolve().parents[1]
MISSION = ROOT / "examples" / "plugins" / "legged_search.yaml"
FLOOR_HEIGHT = 3.5  # m: the default world's storeys


def _run(tmp_path: Path, *args: str) -> tuple[dict, list[dict]]:
    out = tmp_path / "out"
    done = subprocess.run(cli("run", str(MISSION), "--out", str(out), "--quiet",
                              "--no-recording", *args),
                          capture_output=True, text=True, timeout=600, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""
    events = [json.loads(line) for line in (out / "events.jsonl").read_text().splitlines()]
    return json.loads((out / "summary.json").read_text()), events


@pytest.mark.parametrize("fidelity", ["kinematic", "physics"])
def test_the_legged_robot_searches_takes_the_stairs_and_finds_the_target(
        tmp_path: Path, fidelity: str) -> None:
    summary, events = _run(tmp_path, "--fidelity", fidelity)
    assert summary["robots"]["dog1"]["kind"] == "legged"
    assert summary["robots"]["dog1"]["tasks_failed"] == 0
    rounds = [e for e in events if e["kind"] == "assignment"]
    assert rounds and {r["strategy"] for r in rounds} == {"timed"}  # the plug-in's strategy
    sweeps = [e for e in events if e["kind"] == "task_finished" and e["robot"] == "dog1"
              and e["action"] == "trot_sweep"]  # the plug-in's action, by Table IV
    done = [e for e in sweeps if e["status"] == "succeeded"]
    assert len(done) >= 2 and all(e["coverage"] > 0.5 for e in done)
    assert all(e["message"] == "mission ended" for e in sweeps if e not in done)
    # the target is upstairs (A.2.2.3): the dog climbed the stairs and saw it there
    assert summary["outcome"] == "found" and summary["found_by"] == "dog1"
    seen = next(e for e in events if e["kind"] == "detection")
    assert seen["robot_position"][2] > FLOOR_HEIGHT


def test_the_package_ships_no_legged_robot() -> None:
    """The kind, its action, planner, look and the strategy exist only once the plug-in is
    imported: nothing in the package names them."""
    probe = ("from astralis_des.kinds import KINDS; from astralis_des.plugins import ACTIONS, "
             "STRATEGIES; from astralis_des.planning.planners import PLANNERS; "
             "from astralis_des.sinks.looks import LOOKS; "
             "print(list(KINDS), 'timed' in STRATEGIES, 'trot' in PLANNERS, "
             "'quadruped' in LOOKS, any(k == 'legged' for k, _ in ACTIONS))")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=120, check=True)
    assert done.stdout.split() == ["['uav',", "'ugv',", "'human']", "False", "False", "False",
                                   "False"]
    named = [f"{path.relative_to(ROOT)}:{line}" for path in (ROOT / "astralis_des").rglob("*.py")
             for line, text in _strings(path) if "legged" in text or "quadruped" in text]
    assert named == []


def _strings(path: Path) -> list[tuple[int, str]]:
    """The string literals of a module's code (its docstrings left out: they may point to
    the example)."""
    tree = ast.parse(path.read_text())
    docs = {id(node.body[0].value) for node in ast.walk(tree)
            if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef))
            and node.body and isinstance(node.body[0], ast.Expr)}
    return [(node.lineno, node.value) for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and isinstance(node.value, str)
            and id(node) not in docs]


def test_a_mission_without_the_plug_in_names_the_unknown_kind(tmp_path: Path) -> None:
    text = MISSION.read_text().replace("plugins: [legged.py]\n", "")
    bare = tmp_path / "bare.yaml"
    bare.write_text(text.replace("../../worlds/", str(ROOT / "worlds") + "/"))
    done = subprocess.run(cli("validate", str(bare)), capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 2
    line = next(n for n, t in enumerate(text.splitlines(), 1) if "kind: legged" in t)
    assert done.stderr.strip() == (
        f"error: {bare}:{line}: team[1].kind: unknown robot kind 'legged'; known: 'uav', "
        "'ugv', 'human' (a plug-in adds others: plugins: [file.py])")
