"""Sleeping robots are woken as a scripted mover comes near them (a placed body pushes only a
body that is awake); a mission whose idle UGVs sleep runs to its end."""

from __future__ import annotations

import numpy as np

from astralis_des.cosim.physics_bodies import WAKE_RANGE, SceneBodies
from astralis_des.physics.client import PhysicsClient
from astralis_des.world.scene import Mover


class Sleeper:
    """A robot's driver standing at ``xy``, counting the times it is woken."""

    def __init__(self, body: int, xy: tuple[float, float]) -> None:
        self.body, self.xy, self.woken = body, np.array([*xy, 0.5]), 0

    def position(self) -> np.ndarray:
        return self.xy

    def wake(self) -> None:
        self.woken += 1


def test_a_mover_wakes_the_sleepers_within_range_only(physics_client: PhysicsClient) -> None:
    """A walker heading along y = 30 wakes the robot beside its way, not the one 5 m off."""
    near, far = Sleeper(-10, (31.0, 31.0)), Sleeper(-11, (31.0, 35.0))
    drivers = {"ugv1": near, "ugv2": far}
    bodies = SceneBodies(physics_client, drivers, [], scene=None, log=None,  # type: ignore[arg-type]
                         clock=lambda: 0.0, sleepers=["ugv1", "ugv2"])
    loop = np.array([[30.0, 30.0, 0.85], [40.0, 30.0, 0.85], [30.0, 30.0, 0.85]])
    bodies.add_movers([Mover("avatar1", "avatar", loop, 1.0, (0.5, 0.5, 1.7))])
    bodies.move_movers([0], 0.5)
    assert np.linalg.norm(near.xy[:2] - [30.5, 30.0]) < WAKE_RANGE
    assert (near.woken, far.woken) == (1, 0)


def test_a_team_whose_idle_ugvs_sleep_finds_the_target() -> None:
    """The default mission with two UGVs that sleep while idle ends with the target found."""
    from conftest import MISSIONS

    from astralis_des import Simulation, load_mission

    base = load_mission(MISSIONS / "urban_search.yaml")
    team = [*base.spec.team, {"id": "ugv2", "kind": "ugv", "start": [97.0, 66.0, 0.0]}]
    mission = base.with_changes(fidelity="physics", team=[
        m if isinstance(m, dict) else m.model_dump() for m in team],
        physics={**base.spec.physics.model_dump(), "sleep_idle": True})
    result = Simulation(mission).run()
    assert result.outcome == "found"
