"""``astralis run --mcap``: run.mcap read back with mcap's reader and rosbags' deserialiser."""

from __future__ import annotations

import contextlib
import io
import json
from collections import Counter, defaultdict
from pathlib import Path
from typing import Any

import numpy as np
import pytest

pytest.importorskip("mcap")
pytest.importorskip("rosbags")

from mcap.reader import make_reader
from rosbags.typesys import Stores, get_typestore

from astralis_des.cli import main

ROOT = Path(__file__).resolve().parents[1]
DEFAULT = ROOT / "missions" / "urban_search.yaml"
STORE = get_typestore(Stores.ROS2_HUMBLE)


def _run(out: Path, *extra: str) -> None:
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(["run", str(DEFAULT), "--out", str(out), "--mcap", *extra]) == 0


def _read(path: Path) -> tuple[dict[str, str], dict[str, list[tuple[float, Any]]]]:
    """Each topic's schema name, and its messages (decoded) in log-time order."""
    types: dict[str, str] = {}
    messages: dict[str, list[tuple[float, Any]]] = defaultdict(list)
    with path.open("rb") as f:
        for schema, channel, message in make_reader(f).iter_messages(log_time_order=True):
            types[channel.topic] = schema.name
            if channel.message_encoding == "json":
                value: Any = json.loads(message.data)
            else:
                value = STORE.deserialize_cdr(message.data, schema.name)
            messages[channel.topic].append((message.log_time / 1e9, value))
    return types, messages


@pytest.fixture(scope="module")
def kinematic(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict, dict]:
    out = tmp_path_factory.mktemp("mcap") / "run"
    _run(out)
    return (out, *_read(out / "run.mcap"))


@pytest.fixture(scope="module")
def physics(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict, dict]:
    out = tmp_path_factory.mktemp("mcap") / "physics"
    _run(out, "--fidelity", "physics")
    return (out, *_read(out / "run.mcap"))


def _events(out: Path) -> list[dict[str, Any]]:
    return [json.loads(line) for line in (out / "events.jsonl").read_text().splitlines()]


def test_topics_and_their_message_types(kinematic: tuple[Path, dict, dict]) -> None:
    _, types, _ = kinematic
    for robot in ("uav1", "uav2", "ugv1", "op1"):
        assert types[f"/{robot}/pose"] == "geometry_msgs/msg/PoseStamped"
        assert types[f"/{robot}/odom"] == "nav_msgs/msg/Odometry"
    assert types["/uav1/plan"] == "nav_msgs/msg/Path"
    assert types["/tf"] == "tf2_msgs/msg/TFMessage"
    assert types["/world/markers"] == "visualization_msgs/msg/MarkerArray"
    for topic in ("/mission/events", "/mission/tasks", "/mission/assignment",
                  "/mission/detections"):
        assert types[topic] == "astralis_des/Event"


def test_the_decisions_are_the_event_log(kinematic: tuple[Path, dict, dict]) -> None:
    out, _, messages = kinematic
    events = _events(out)
    assert [m for _, m in messages["/mission/events"]] == events
    kinds = Counter(e["kind"] for e in events)
    assert len(messages["/mission/assignment"]) == kinds["assignment"]
    assert len(messages["/mission/tasks"]) == (kinds["task_queued"] + kinds["task_started"]
                                               + kinds["task_finished"])
    assert all(t == m["t"] for t, m in messages["/mission/events"])  # stamped in sim time


def test_poses_follow_the_robots_and_end_where_the_finder_saw_the_target(
        kinematic: tuple[Path, dict, dict]) -> None:
    out, _, messages = kinematic
    detection = next(e for e in _events(out) if e["kind"] == "detection")
    poses = messages[f"/{detection['robot']}/pose"]
    t, seen = next((t, m) for t, m in poses if t >= detection["t"] - 1e-6)
    assert t == pytest.approx(detection["t"], abs=1e-6)
    where = seen.pose.position
    assert [where.x, where.y, where.z] == pytest.approx(detection["robot_position"], abs=1e-3)
    stamp = seen.header.stamp
    assert stamp.sec + stamp.nanosec / 1e9 == pytest.approx(t, abs=1e-6)
    t, last = poses[-1]  # then it landed
    landed = next(e for e in _events(out) if e["kind"] == "landed"
                  and e["robot"] == detection["robot"])
    assert t == pytest.approx(landed["t"], abs=1e-6) and t > detection["t"]
    where = last.pose.position
    assert [where.x, where.y, where.z] == pytest.approx(landed["position"], abs=1e-3)
    assert last.header.frame_id == "map"
    tfs = [m.transforms[0] for _, m in messages["/tf"]
           if m.transforms[0].child_frame_id == f"{detection['robot']}/base_link"]
    assert len(tfs) == len(poses)


def test_the_world_markers_hold_walls_rooms_and_furniture(
        kinematic: tuple[Path, dict, dict]) -> None:
    _, _, messages = kinematic
    (t, array), = messages["/world/markers"]
    namespaces = Counter(m.ns for m in array.markers)
    assert t == 0.0 and namespaces["rooms"] > 0 and namespaces["solids"] > 0
    assert namespaces["furniture"] > 0
    assert all(m.type == 1 and min(m.scale.x, m.scale.y, m.scale.z) > 0 for m in array.markers)


def test_physics_sensors_come_as_ros_messages(physics: tuple[Path, dict, dict]) -> None:
    _, types, messages = physics
    assert types["/uav1/imu"] == "sensor_msgs/msg/Imu"
    assert types["/uav1/camera/image"] == "sensor_msgs/msg/Image"
    assert types["/uav1/camera/camera_info"] == "sensor_msgs/msg/CameraInfo"
    assert types["/ugv1/scan"] == "sensor_msgs/msg/LaserScan"
    _, image = messages["/uav1/camera/image"][0]
    assert image.encoding == "rgb8" and len(image.data) == image.height * image.step
    _, info = messages["/uav1/camera/camera_info"][0]
    assert info.width == image.width and info.k[2] == pytest.approx(image.width / 2)
    _, scan = messages["/ugv1/scan"][0]
    ranges = np.asarray(scan.ranges)
    assert len(ranges) == 360 and np.isfinite(ranges).any()
    assert np.nanmin(ranges[np.isfinite(ranges)]) >= 0.0
    hovering = [m.linear_acceleration.z for _, m in messages["/uav1/imu"][:20]]
    assert np.median(hovering) == pytest.approx(9.81, abs=1.0)  # gravity, held off


def test_without_the_flag_there_is_no_mcap(tmp_path: Path) -> None:
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(["run", str(DEFAULT), "--out", str(tmp_path), "--no-recording"]) == 0
    assert not (tmp_path / "run.mcap").exists()


def test_export_writes_the_same_mcap_for_a_run_already_made(
        kinematic: tuple[Path, dict, dict], tmp_path: Path) -> None:
    made, _, _ = kinematic
    out = tmp_path / "plain"
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(["run", str(DEFAULT), "--out", str(out), "--no-recording"]) == 0
        assert main(["export", str(out), "--mcap", "--mission", str(DEFAULT)]) == 0
    assert (out / "run.mcap").read_bytes() == (made / "run.mcap").read_bytes()


def test_export_refuses_a_run_its_mission_does_not_reproduce(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "run"
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(["run", str(DEFAULT), "--out", str(out), "--no-recording"]) == 0
    lines = (out / "events.jsonl").read_text().splitlines(keepends=True)
    lines[5] = lines[5].replace('"task":', '"task": ', 1)
    (out / "events.jsonl").write_text("".join(lines))
    capsys.readouterr()  # the run's progress bar
    assert main(["export", str(out), "--mcap", "--mission", str(DEFAULT)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: ") and "\n" not in err
    assert "events.jsonl:6:" in err and "does not reproduce this run" in err
    assert not (out / "run.mcap").exists()


def test_pose_sensors_come_as_navsatfix_fluidpressure_and_magneticfield(
        tmp_path: Path) -> None:
    """missions/sensor_suite.yaml with --mcap: its kept 3-D lidar sweeps as PointCloud2
    (x, y, z and the id of the body hit); the UAV's GNSS fixes as NavSatFix (a fix in
    the street near the site's origin, STATUS_NO_FIX with NaN once under the slab), its
    barometer as FluidPressure (Pa, about the ISA pressure 130-132 m up) and its
    magnetometer as MagneticField (tesla, the site's 51.5 microtesla)."""
    out = tmp_path / "suite"
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(["run", str(ROOT / "missions" / "sensor_suite.yaml"), "--out", str(out),
                     "--mcap", "--no-recording"]) == 0
    types, messages = _read(out / "run.mcap")
    assert types["/uav1/gnss/fix"] == "sensor_msgs/msg/NavSatFix"
    assert types["/uav1/barometer"] == "sensor_msgs/msg/FluidPressure"
    assert types["/uav1/magnetometer"] == "sensor_msgs/msg/MagneticField"
    fixes = [m for _, m in messages["/uav1/gnss/fix"]]
    assert fixes[0].status.status == 0 and fixes[0].latitude == pytest.approx(44.0582, abs=1e-3)
    assert fixes[0].position_covariance[0] == pytest.approx(1.5**2)
    lost = [f for f in fixes if f.status.status == -1]
    assert lost and all(np.isnan(f.latitude) for f in lost)
    pressures = np.array([m.fluid_pressure for _, m in messages["/uav1/barometer"]])
    assert pressures.min() > 99_500 and pressures.max() < 99_800  # 130-132 m up
    field = np.array([[m.magnetic_field.x, m.magnetic_field.y, m.magnetic_field.z]
                      for _, m in messages["/uav1/magnetometer"]])
    assert np.linalg.norm(field, axis=1).mean() == pytest.approx(51.5e-6, rel=0.02)
    assert types["/uav1/lidar3d/points"] == "sensor_msgs/msg/PointCloud2"
    cloud = messages["/uav1/lidar3d/points"][-1][1]
    assert [f.name for f in cloud.fields] == ["x", "y", "z", "id"] and cloud.point_step == 16
    rows = np.frombuffer(bytes(cloud.data), dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"),
                                                   ("id", "<i4")])
    assert len(rows) == cloud.width > 5000 and (rows["id"] >= 0).all()
