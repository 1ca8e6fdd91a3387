"""Honest contracts (issue 40): a co-simulation, a driver, a trajectory and a perception are
used through the Protocols that declare them, optional capabilities included, never probed
with ``hasattr``/``getattr`` nor waved through with ``type: ignore``."""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path
from typing import Any, cast

import numpy as np
import pytest
from conftest import MISSIONS

from astralis_des import Simulation, load_mission
from astralis_des.kernel.contracts import CoSim
from astralis_des.kernel.robot import Motion, Trajectory
from astralis_des.physics.track import Track

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "astralis_des"
CONTRACTED = ("cosim", "driver", "motion", "track", "perception")
CAPABILITIES = {"perception", "body_pose", "recover", "close", "turn_to", "course_z",
                "blocked_by", "driver", "clock", "heading_at"}


def _names(node: ast.AST) -> Iterator[str]:
    for sub in ast.walk(node):
        if isinstance(sub, ast.Name):
            yield sub.id.lower()
        elif isinstance(sub, ast.Attribute):
            yield sub.attr.lower()


def _probes(source: str) -> Iterator[str]:
    """Each ``hasattr``/``getattr`` on a contracted object, or for a declared capability."""
    for node in ast.walk(ast.parse(source)):
        if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                and node.func.id in ("hasattr", "getattr") and len(node.args) >= 2):
            continue
        on_contract = any(word in name for name in _names(node.args[0]) for word in CONTRACTED)
        asked = node.args[1]
        for_capability = isinstance(asked, ast.Constant) and asked.value in CAPABILITIES
        if on_contract or for_capability:
            yield f"{node.lineno}: {ast.unparse(node)}"


def test_no_contracted_object_is_probed() -> None:
    found = [f"{path.relative_to(ROOT)}:{probe}" for path in sorted(PACKAGE.rglob("*.py"))
             for probe in _probes(path.read_text(encoding="utf-8"))]
    assert found == []


def test_the_probe_scan_finds_the_probes_this_issue_removed() -> None:
    source = ('a = hasattr(driver, "turn_to")\nb = getattr(sim.cosim, "x", None)\n'
              'c = getattr(thing, "body_pose", None)\nd = getattr(spec, "name")\n')
    assert list(_probes(source)) == [
        "1: hasattr(driver, 'turn_to')", "2: getattr(sim.cosim, 'x', None)",
        "3: getattr(thing, 'body_pose', None)"]


def test_no_type_ignore_on_a_contracted_object() -> None:
    found = [f"{path.relative_to(ROOT)}:{n}"
             for path in sorted(PACKAGE.rglob("*.py"))
             for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
             if "type: ignore" in line and any(word in line.lower() for word in CONTRACTED)]
    assert found == []


def test_a_motion_and_a_track_are_trajectories() -> None:
    motion = Motion(np.array([[0.0, 0.0, 1.0], [3.0, 4.0, 1.0]]), speed=1.0)
    track = Track(driver=cast(Any, None), t0=0.0, cap=10.0)
    assert isinstance(motion, Trajectory)
    assert isinstance(track, Trajectory)
    assert motion.heading_at(5.0, 0.0) == pytest.approx(np.arctan2(4.0, 3.0))


def test_the_kinematic_fidelity_keeps_the_contract_without_a_body() -> None:
    sim = Simulation(load_mission(MISSIONS / "fig7.yaml"))
    assert isinstance(sim.cosim, CoSim)
    assert sim.cosim.body_pose is None
    assert sim.cosim.perception is None
    assert sim.run().sensor_calls == {}


def test_the_physics_fidelity_keeps_the_contract_and_declares_its_capabilities() -> None:
    mission = load_mission(MISSIONS / "fig7.yaml").with_changes(fidelity="physics")
    sim = Simulation(mission)
    try:
        cosim = sim.cosim
        assert isinstance(cosim, CoSim)
        assert cosim.perception is not None
        assert cosim.body_pose is not None
        position, attitude = cosim.body_pose(sim.robots["ugv1"])
        assert position.shape == (3,) and attitude.shape == (3, 3)
        drivers = cast(Any, cosim).drivers
        assert {rid: d.blocked_by for rid, d in drivers.items()} == dict.fromkeys(drivers, ())
        assert {rid: d.course_z() for rid, d in drivers.items() if rid != "uav1"
                and rid != "uav2"} == {"ugv1": None, "op1": None}
        assert [drivers[rid].turn_to(0.5) for rid in ("uav1", "op1", "ugv1")] == \
            [False, False, True]
    finally:
        sim.cosim.close()
