"""Plug-ins without an edit to the package (issue 40): a mission names a module (a .py file
beside it, or a module on the path), or an installed package declares an entry point in the
group ``astralis_des.plugins``; its actions and strategies are then names the mission uses,
through ``astralis run`` as through the API. A plug-in that cannot be imported, or fails as it
is, is one line naming the file, line and key."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]
WORLD = ROOT / "worlds" / "urban_default.yaml"

PLUGIN = '''
"""A plug-in of a user's: a UAV action, and a strategy that costs rooms by their order."""
import numpy as np
from pydantic import Field

from astralis_des.action_spec import ActionParams, Number
from astralis_des.assignment.strategies import register_strategy
from astralis_des.kernel.tasks import ActionResult, TaskStatus
from astralis_des.plugins import action


class CircleParams(ActionParams):
    seconds: Number = Field(3.0, ge=0.0, le=60.0, description="s circling")


@action("circle", ("uav",), params=CircleParams, room=False)
def circle(ctx, robot, task):
    """Circle where it is for a while."""
    yield ctx.env.timeout(float(task.param("seconds", 3.0)))
    return ActionResult(TaskStatus.SUCCEEDED, "circled")


@register_strategy("in_order")
def in_order(agents, rooms, weights):
    return np.add.outer(np.arange(len(agents), dtype=float), np.arange(len(rooms)))
'''


def mission(folder: Path, plugins: list[str], **extra: object) -> Path:
    doc = {"name": "plugged", "world": str(WORLD), "plugins": plugins, "seed": 3,
           "time_limit": 400,
           "team": [{"id": "uav1", "kind": "uav", "start": [60, 60, 0]},
                    {"id": "op1", "kind": "human", "start": [62, 60, 0]}],
           "assignment": {"strategy": "in_order", "search": ["A.1.1"]},
           "timeline": [{"at": 1, "event": "command", "robot": "uav1", "action": "circle",
                         "params": {"seconds": 4}, "preempt": True}], **extra}
    path = folder / "mission.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
    return path


def astralis(*args: str, env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "astralis_des.cli", *args], cwd=ROOT,
                          capture_output=True, text=True, timeout=300,
                          env={**os.environ, **(env or {})})


def circled(out: Path) -> list[dict[str, object]]:
    events = [json.loads(line) for line in (out / "events.jsonl").read_text().splitlines()]
    assert any(e["kind"] == "assignment" and e["strategy"] == "in_order" for e in events)
    return [e for e in events if e["kind"] == "task_finished" and e["action"] == "circle"]


def test_a_plug_in_file_the_mission_names(tmp_path: Path) -> None:
    (tmp_path / "my_robots.py").write_text(PLUGIN, encoding="utf-8")
    path = mission(tmp_path, ["my_robots.py"])
    done = astralis("run", str(path), "--out", str(tmp_path / "out"), "--quiet",
                    "--no-recording")
    assert done.returncode == 0, done.stderr
    [finished] = circled(tmp_path / "out")
    assert (finished["status"], finished["message"]) == ("succeeded", "circled")
    bad = mission(tmp_path, ["my_robots.py"], timeline=[
        {"at": 1, "event": "command", "robot": "uav1", "action": "circle",
         "params": {"secs": 4}}])
    refused = astralis("validate", str(bad))
    assert refused.returncode == 2
    assert refused.stderr.strip().endswith("timeline[0].params.secs: circle has no parameter "
                                           "'secs' (its parameters: seconds)")


def test_a_plug_in_module_on_the_path_and_an_installed_entry_point(tmp_path: Path) -> None:
    """The same module, named by the mission as a module; then declared by an installed
    package (a dist-info with an entry point), with the mission naming nothing."""
    site = tmp_path / "site"
    (site / "userbots").mkdir(parents=True)
    (site / "userbots" / "__init__.py").write_text(PLUGIN, encoding="utf-8")
    env = {"PYTHONPATH": os.pathsep.join([str(site), str(ROOT)])}
    named = astralis("run", str(mission(tmp_path, ["userbots"])), "--out",
                     str(tmp_path / "a"), "--quiet", "--no-recording", env=env)
    assert named.returncode == 0, named.stderr
    assert len(circled(tmp_path / "a")) == 1
    info = site / "userbots-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: userbots\nVersion: 1.0\n",
                                   encoding="utf-8")
    (info / "entry_points.txt").write_text("[astralis_des.plugins]\nbots = userbots\n",
                                           encoding="utf-8")
    installed = astralis("run", str(mission(tmp_path, [])), "--out", str(tmp_path / "b"),
                         "--quiet", "--no-recording", env=env)
    assert installed.returncode == 0, installed.stderr
    assert len(circled(tmp_path / "b")) == 1


@pytest.mark.parametrize(("plugin", "says"), [
    ("nowhere_to_be_found", "cannot import the plug-in 'nowhere_to_be_found': not on the path"),
    ("missing.py", "no such plug-in file: "),
    ("broken.py", "the plug-in 'broken.py' failed as it was imported: ZeroDivisionError: "
                  "division by zero"),
    ("typo.py", "the plug-in 'typo.py' failed as it was imported: SyntaxError: "),
])
def test_a_plug_in_that_cannot_be_had_is_one_line(tmp_path: Path, plugin: str,
                                                  says: str) -> None:
    (tmp_path / "broken.py").write_text("x = 1 / 0\n", encoding="utf-8")
    (tmp_path / "typo.py").write_text("def f(:\n", encoding="utf-8")
    path = mission(tmp_path, [plugin])
    done = astralis("validate", str(path))
    assert done.returncode == 2
    line = done.stderr.strip()
    assert "\n" not in line
    assert line.startswith(f"error: {path}:4: plugins[0]: {says}"), line
