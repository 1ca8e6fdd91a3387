"""Sensors at work in physics missions: detection from rendered pixels, occlusion, culling,
kept frames, the lidar slowing the UGV, IMU readings, and the sensor sets of the team."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from astralis_des import Simulation, load_mission
from astralis_des.kernel.robot import Motion
from astralis_des.mission.spec import CameraSpec, LidarSpec
from astralis_des.physics.perception import CREEP, SLOW_AT, STOP_AT

MISSIONS = Path(__file__).resolve().parents[1] / "missions"
ROOM = "A.1.1.2"  # x 68.1..71.9, y 79.6..86.4, ground floor
TARGET = [71.3, 83.0, 0.5]


def sim_with(member: dict[str, Any], target: list[float] = TARGET,
             fidelity: str = "physics", out_dir: Path | None = None) -> Simulation:
    """A one-robot physics mission in an empty room with the target at ``target`` (its
    outputs, the recording among them, in ``out_dir`` if given)."""
    mission = load_mission(MISSIONS / "fig7.yaml").with_changes(
        fidelity=fidelity, team=[member], scene={"clutter": False},
        target={"room": ROOM, "position": target, "avatar": {"activity": "idle"}})
    sim = Simulation(mission, out_dir=out_dir)
    sim.start()
    return sim


UGV = {"id": "ugv1", "kind": "ugv", "start": [68.8, 83.0, 0]}  # facing east, 2.5 m from it


def test_a_ugv_detects_the_target_from_its_pixels() -> None:
    """The target 2.5 m ahead covers thousands of pixels; the estimate (the centroid of its
    visible face) lies within 0.4 m of its centre, on the robot's side of it."""
    sim = sim_with(UGV)
    hit = sim.cosim.look(sim.robots["ugv1"], sim.sensor)
    assert hit is not None and hit.pixels is not None and hit.pixels >= 1000
    assert hit.error < 0.4 and hit.estimate[0] < TARGET[0]
    assert hit.distance == pytest.approx(2.5, abs=0.05)
    sim.finish()


def test_a_cabinet_between_hides_the_target() -> None:
    """A 2 m cabinet between the UGV and the target: no target pixel, no detection; the
    geometric model agrees in the same place when the cabinet is furniture."""
    sim = sim_with(UGV)
    sim.cosim.client.add_box((70.0, 83.0, 1.0), (0.4, 1.2, 2.0))
    assert sim.cosim.look(sim.robots["ugv1"], sim.sensor) is None
    assert sim.cosim.perception.frames == [] or not sim.cosim.perception.frames[-1].detection
    sim.finish()


def test_fewer_pixels_than_min_pixels_is_no_detection() -> None:
    """The same view with min_pixels above what the target covers detects nothing."""
    sim = sim_with({**UGV, "sensors": {"camera": {"min_pixels": 76800}}})
    assert sim.cosim.look(sim.robots["ugv1"], sim.sensor) is None
    sim.finish()


def test_a_target_out_of_view_costs_a_frustum_test_not_a_frame() -> None:
    """Facing away from the target, a look renders nothing (record_rate 0 keeps no frames)."""
    sim = sim_with({**UGV, "start": [71.3, 81.0, 0], "sensors": {"camera": {"record_rate": 0}}},
                   target=[69.0, 85.5, 0.5])
    assert sim.cosim.look(sim.robots["ugv1"], sim.sensor) is None
    clock = sim.cosim.perception.clock
    assert clock.calls.get("camera_cull") == 1 and "camera" not in clock.calls
    sim.finish()


def test_a_hovering_uav_looks_around_and_keeps_the_detection_frame(tmp_path: Path) -> None:
    """The target lies north of a UAV facing east: its gimbal pans a full turn and finds it;
    the frame is kept at half resolution with the target's pixels in it (a run recording)."""
    sim = sim_with({"id": "uav1", "kind": "uav", "start": [70.0, 81.0, 0]},
                   target=[70.0, 82.6, 0.5], out_dir=tmp_path / "out")
    robot = sim.robots["uav1"]
    sim.start()
    sim.enqueue("uav1", "take_off")  # it starts on the ground
    sim.advance(3.0)
    assert robot.airborne and robot.heading == 0.0
    hit = sim.cosim.look(robot, sim.sensor)
    assert hit is not None and hit.pixels is not None and hit.pixels >= 40
    frames = sim.cosim.perception.frames
    kept = frames[-1]
    assert kept.detection and kept.rgb.shape == (120, 160, 3)
    assert (kept.segmentation == sim.cosim.target_body + 1).sum() * 4 == pytest.approx(
        hit.pixels, rel=0.2)
    assert not frames[0].detection  # the frame kept at the record rate, before
    sim.finish()


@pytest.mark.parametrize("recording", [True, False])
def test_frames_at_the_record_rate_are_rendered_only_for_a_recording(
        tmp_path: Path, recording: bool) -> None:
    """A look from the UGV facing the target renders its detection frame; the half-size
    frame kept at the record rate is rendered too when the run records, and not without a
    recording (nothing would read it). The detection is the same either way."""
    sim = sim_with(UGV, out_dir=tmp_path / "out" if recording else None)
    hit = sim.cosim.look(sim.robots["ugv1"], sim.sensor)
    assert hit is not None and hit.pixels is not None and hit.pixels >= 1000
    perception = sim.cosim.perception
    assert perception.clock.calls["camera"] == (2 if recording else 1)
    assert [frame.detection for frame in perception.frames] == \
        ([False, True] if recording else [True])
    sim.finish()


def test_the_lidar_slows_the_ugv_for_what_is_ahead() -> None:
    """A wall 1 m ahead: the lidar reads 1 m and the UGV's speed cap becomes the share of the
    slow-down band that range leaves; with nothing ahead there is no cap."""
    sim = sim_with(UGV, target=[70.0, 86.0, 0.5])
    driver = sim.cosim.drivers["ugv1"]
    perception = sim.cosim.perception
    done, robot = sim.env.event(), sim.robots["ugv1"]
    next(perception._scan(robot, done, robot.motion))
    assert driver.husky.limit == math.inf
    sim.cosim.client.add_box((69.9, 83.0, 0.5), (0.2, 1.0, 1.0))
    next(perception._scan(robot, done, robot.motion))
    points, here = perception.scans[-1].points, driver.position()
    ahead = points[(np.abs(points[:, 1] - here[1]) < 0.3) & (points[:, 0] > here[0])]
    nearest = float(np.min(ahead[:, 0])) - here[0]
    assert nearest == pytest.approx(1.0, abs=0.05)
    share = max((nearest - STOP_AT) / (SLOW_AT - STOP_AT), CREEP)
    assert driver.husky.limit == pytest.approx(share * driver.speed, abs=0.03)
    sim.finish()


def test_a_halted_motion_stops_its_lidar_and_imu() -> None:
    """A motion halted midway (a fault, a new order) ends its lidar and IMU with it: the UGV
    standing there is not scanned at 10 Hz or read at 20 Hz for the rest of the run, and its
    speed cap is lifted (the event of a halted motion never fires)."""
    sim = sim_with(UGV, target=[70.0, 86.0, 0.5])
    robot, perception = sim.robots["ugv1"], sim.cosim.perception
    driver = sim.cosim.drivers["ugv1"]
    sim.cosim.execute(robot, Motion(np.array([robot.pose, (71.0, 83.0, 0.0)]), robot.speed,
                                    accel=robot.accel))
    sim.env.run(until=sim.env.now + 1.5)
    scans, readings = perception.clock.calls["lidar"], perception.clock.calls["imu"]
    assert scans >= 10 and readings >= 20  # 10 Hz and 20 Hz while it moved
    sim.cosim.halt(robot)
    sim.env.run(until=sim.env.now + 3.0)
    assert perception.clock.calls["lidar"] == scans
    assert perception.clock.calls["imu"] == readings
    assert driver.husky.limit == math.inf
    sim.finish()


def test_the_imu_of_a_flying_uav_reads_one_g_up() -> None:
    """Flying from the corridor into a room, the UAV's IMU reads its thrust: about
    +9.81 m/s^2 on its z axis while it cruises (more while it speeds up or slows down, as
    the thrust then also pushes sideways), little on x and y; at its 20 Hz."""
    mission = load_mission(MISSIONS / "fig7.yaml").with_changes(
        fidelity="physics", time_limit=30.0, scene={"clutter": False},
        team=[{"id": "uav1", "kind": "uav", "start": [73, 78.25, 0]}],
        timeline=[{"at": 0.0, "event": "command", "robot": "uav1", "action": "move",
                   "room": "A.1.1.3"}], assignment={"search": ["A.1.2"]})
    sim = Simulation(mission)
    result = sim.run()
    trace = sim.cosim.perception.imu_traces["uav1"]
    up = next(e["t"] for e in result.events if e["kind"] == "took_off")
    arrived = next(e["t"] for e in result.events if e["kind"] == "task_finished")
    cruise = [r for t, r in zip(trace.times, trace.readings, strict=True) if up < t < arrived]
    assert len(cruise) > 20  # (taking off and landing, it reads more and less than 1 g)
    force = np.array([r.specific_force for r in cruise])
    assert np.median(force[:, 2]) == pytest.approx(9.81, abs=0.3)
    assert force[:, 2].min() > 9.0 and np.median(np.abs(force[:, :2])) < 0.5
    gaps = np.diff(trace.times)
    assert np.median(gaps) == pytest.approx(1 / 20, abs=1e-6)


def test_each_kind_carries_its_sensor_set_unless_told() -> None:
    """No sensors key: UAV camera + IMU, UGV camera + lidar + IMU, human camera. Naming a
    lidar keeps the camera and adds no IMU; camera: null carries none."""
    mission = load_mission(MISSIONS / "fig7.yaml")
    sets = {m.id: m.sensor_set for m in mission.spec.team}
    carried = {rid: [n for n in ("camera", "lidar", "imu") if getattr(s, n) is not None]
               for rid, s in sets.items()}
    assert carried == {"uav1": ["camera", "imu"], "uav2": ["camera", "imu"],
                       "ugv1": ["camera", "lidar", "imu"], "op1": ["camera"]}
    named = mission.with_changes(team=[{**UGV, "sensors": {"lidar": {"beams": 90}}}])
    one = named.spec.team[0].sensor_set
    assert one.camera == CameraSpec() and one.lidar == LidarSpec(beams=90) and one.imu is None
    blind = mission.with_changes(team=[{**UGV, "sensors": {"camera": None}}])
    sim = Simulation(blind)
    assert sim.robots["ugv1"].view is None


def test_a_robot_without_a_camera_never_detects() -> None:
    """In either fidelity a camera-less UGV facing the target sees nothing."""
    for fidelity in ("kinematic", "physics"):
        sim = sim_with({**UGV, "sensors": {"camera": None}}, fidelity=fidelity)
        assert sim.cosim.look(sim.robots["ugv1"], sim.sensor) is None
        sim.finish()


def test_detections_carry_the_estimate_in_both_fidelities() -> None:
    """The detection event names the sensor, the estimate and its error, the avatar, and the
    target's pixels: counted in the rendered frame (physics) or predicted (kinematic), within
    15% of each other."""
    pixels = {}
    for fidelity in ("kinematic", "physics"):
        sim = sim_with(UGV, fidelity=fidelity)
        hit = sim.cosim.look(sim.robots["ugv1"], sim.sensor)
        assert hit is not None
        sim.report_detection(sim.robots["ugv1"], hit)
        event = next(e for e in sim.log.records if e["kind"] == "detection")
        assert event["sensor"] == "camera" and event["avatar"]["activity"] == "idle"
        assert np.linalg.norm(np.subtract(event["estimate"], TARGET)) == pytest.approx(
            event["error"], abs=1e-5)
        pixels[fidelity] = event["pixels"]
        sim.finish()
    assert pixels["kinematic"] == pytest.approx(pixels["physics"], rel=0.15)
