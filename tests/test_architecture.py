"""The package's import graph flows one way (docs/architecture.md): no module imports
another that imports it back, the layers of ``[tool.importlinter]`` hold, and a new action
and a new sensor plug in from outside the package, as the architecture's table says."""

from __future__ import annotations

import math
import shutil
import subprocess
from collections.abc import Generator, Iterator
from pathlib import Path
from typing import Any

import grimp
import networkx as nx
import numpy as np
import pytest
import simpy
from conftest import MISSIONS

from astralis_des import Simulation, load_mission
from astralis_des.kernel.contracts import Context, Host
from astralis_des.kernel.robot import Robot
from astralis_des.kernel.tasks import ActionResult, Task, TaskStatus
from astralis_des.plugins import ACTIONS, SENSORS

ROOT = Path(__file__).resolve().parents[1]


def test_no_module_imports_one_that_imports_it_back() -> None:
    """Counting every import grimp sees (type-only and inside functions too): the graph of
    the package's modules has no cycle."""
    graph = grimp.build_graph("astralis_des")
    edges = nx.DiGraph()
    for module in graph.modules:
        for imported in graph.find_modules_directly_imported_by(module):
            edges.add_edge(module, imported)
    cycles = [sorted(c) for c in nx.strongly_connected_components(edges) if len(c) > 1]
    assert cycles == []


def test_the_layers_contract_holds() -> None:
    """``lint-imports`` (import-linter) keeps the layers and the fidelities' independence."""
    exe = shutil.which("lint-imports")
    assert exe is not None
    done = subprocess.run([exe], cwd=ROOT, capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stdout[-2000:]
    assert "0 broken" in done.stdout


# -- a toy action: a UAV climbs on the spot to a given height and comes back ------------------
def bob(ctx: Context, robot: Robot, task: Task) -> Generator[simpy.Event, Any, ActionResult]:
    """Wait ``seconds`` where it is, then report its height."""
    yield ctx.env.timeout(float(task.param("seconds", 2.0)))
    here = robot.position(ctx.env.now)
    return ActionResult(TaskStatus.SUCCEEDED, f"bobbed at {here[2]:.1f} m")


@pytest.fixture
def toy_action() -> Iterator[None]:
    ACTIONS.register(("uav", "bob"))(bob)
    yield
    ACTIONS.remove(("uav", "bob"))


def test_a_new_action_plugs_in_from_outside_the_package(toy_action: None) -> None:
    """Registered in this test (no module of the package changed), the action is checked by
    the mission loader, commanded from the timeline and logged like the built-in ones."""
    base = load_mission(MISSIONS / "urban_search.yaml")
    mission = base.with_changes(timeline=[
        {"at": 1.0, "event": "command", "robot": "uav1", "action": "bob",
         "params": {"seconds": 3.0}, "preempt": True}])
    result = Simulation(mission).run()
    done = [e for e in result.events if e["kind"] == "task_finished" and e["action"] == "bob"]
    assert len(done) == 1 and done[0]["status"] == "succeeded"
    assert done[0]["message"].startswith("bobbed at ")
    started = next(e for e in result.events if e["kind"] == "task_started"
                   and e["action"] == "bob")
    assert done[0]["t"] - started["t"] == pytest.approx(3.0)


# -- a toy sensor: an odometer reading the distance travelled at a rate ---------------------
class Odometer:
    """Distance along the robot's pose, sampled ``rate`` times a second (either fidelity)."""

    def __init__(self, host: Host, robot: Robot, params: dict[str, Any]) -> None:
        self.env, self.robot = host.env, robot
        self.period = 1.0 / float(params.get("rate", 2.0))
        self.readings: list[tuple[float, float]] = []  # (t, metres so far)

    def run(self) -> Generator[simpy.Event, Any, None]:
        last, total = self.robot.position(self.env.now), 0.0
        while True:
            yield self.env.timeout(self.period)
            here = self.robot.position(self.env.now)
            total += float(np.linalg.norm(here - last))
            last = here
            self.readings.append((self.env.now, total))


@pytest.fixture
def toy_sensor() -> Iterator[None]:
    SENSORS.register("odometer")(Odometer)
    yield
    SENSORS.remove("odometer")


def test_a_new_sensor_plugs_in_from_outside_the_package(toy_sensor: None) -> None:
    """Registered in this test, the sensor is named in a member's ``sensors.plugins``,
    built and run by the simulation: it reads at its rate for the whole mission, and the
    distance it sums is the robot's (sampled at 4 Hz, it cuts corners: within 3%)."""
    base = load_mission(MISSIONS / "urban_search.yaml")
    team = [m.model_dump() for m in base.spec.team]
    team[0]["sensors"] = {"camera": {}, "imu": {}, "plugins": {"odometer": {"rate": 4.0}}}
    sim = Simulation(base.with_changes(team=team))
    result = sim.run()
    odometer = sim.sensors[team[0]["id"]]["odometer"]
    assert isinstance(odometer, Odometer)
    times = [t for t, _ in odometer.readings]
    assert len(times) == math.floor(result.end_time * 4.0 + 1e-9)
    travelled = odometer.readings[-1][1]
    robot = sim.robots[team[0]["id"]]
    assert travelled == pytest.approx(robot.distance, rel=0.03)


def test_an_unknown_plug_in_sensor_is_a_one_line_error(tmp_path: Path) -> None:
    """A mission file naming a sensor nobody registered: exit 2, one line with the file,
    line and key."""
    path = tmp_path / "sonar.yaml"
    path.write_text(f"""name: sonar
world: {ROOT / "worlds" / "urban_default.yaml"}
team:
  - id: uav1
    kind: uav
    start: [60, 60, 0]
    sensors:
      plugins:
        sonar: {{rate: 2}}
""", encoding="utf-8")
    done = subprocess.run([shutil.which("astralis") or "astralis", "run", str(path), "--quiet"],
                          capture_output=True, text=True, check=False, cwd=tmp_path)
    assert done.returncode == 2
    assert done.stderr.strip() == (f"error: {path}:9: team[0].sensors.plugins.sonar: no sensor "
                                   "'sonar'; none is registered (astralis_des.plugins.SENSORS)")


def test_the_architecture_page_draws_the_contracts_layers() -> None:
    """docs/architecture.md's diagram names the layers of ``[tool.importlinter]``, in order."""
    import re
    import tomllib

    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    contract = next(c for c in config["tool"]["importlinter"]["contracts"]
                    if c["type"] == "layers")
    layers = [" ".join(part.replace("astralis_des.", "") for part in layer.split())
              for layer in contract["layers"]]
    page = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    drawn = re.findall(r'^\s+L\d+\["([^<"]+)<br/>', page, flags=re.MULTILINE)
    assert drawn == layers
