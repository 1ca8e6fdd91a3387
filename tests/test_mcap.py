"""``astralis run --mcap``: run.mcap read back as ROS 2 tools read it, with rosbags' AnyReader
(every message deserialised) and with mcap's reader and mcap-ros2-support's decoder."""

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
pytest.importorskip("mcap_ros2")
pytest.importorskip("rosbags")

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.highlevel import AnyReader

from astralis_des.cli import main
from astralis_des.world.model import World

ROOT = Path(__file__).resolve().parents[1]
DEFAULT = ROOT / "missions" / "urban_search.yaml"
TEAM = ("uav1", "uav2", "ugv1", "op1")
DECISIONS = {"/mission/tasks": {"task_queued", "task_started", "task_finished"},
             "/mission/assignment": {"assignment"}, "/mission/detections": {"detection"},
             "/mission/faults": {"fault", "recover", "team_lost"},
             "/mission/commands": {"command", "cancel"}}
CLOUD = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("rgb", "<u4")])
Read = tuple[Path, dict[str, str], dict[str, list[tuple[float, Any]]]]


def _run(out: Path, *extra: str, mission: Path = DEFAULT) -> None:
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(["run", str(mission), "--out", str(out), "--mcap", *extra]) == 0


def _read(path: Path) -> tuple[dict[str, str], dict[str, list[tuple[float, Any]]]]:
    """Each topic's message type, and every message of it deserialised by rosbags' AnyReader
    (a ROS 2 bag reader), in log-time order."""
    messages: dict[str, list[tuple[float, Any]]] = defaultdict(list)
    with AnyReader([path]) as reader:
        types = {c.topic: c.msgtype for c in reader.connections}
        for connection, ns, raw in reader.messages():
            messages[connection.topic].append((ns / 1e9,
                                               reader.deserialize(raw, connection.msgtype)))
    return types, messages


def _decoded(path: Path) -> dict[str, list[Any]]:
    """Every message decoded by mcap-ros2-support (from the definitions the file embeds)."""
    out: dict[str, list[Any]] = defaultdict(list)
    with path.open("rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for schema, channel, _, msg in reader.iter_decoded_messages(log_time_order=True):
            assert (schema.encoding, channel.message_encoding) == ("ros2msg", "cdr")
            out[channel.topic].append(msg)
    return out


@pytest.fixture(scope="module")
def kinematic(tmp_path_factory: pytest.TempPathFactory) -> Read:
    out = tmp_path_factory.mktemp("mcap") / "run"
    _run(out)
    return (out, *_read(out / "run.mcap"))


@pytest.fixture(scope="module")
def physics(tmp_path_factory: pytest.TempPathFactory) -> Read:
    out = tmp_path_factory.mktemp("mcap") / "physics"
    _run(out, "--fidelity", "physics")
    return (out, *_read(out / "run.mcap"))


def _events(out: Path) -> list[dict[str, Any]]:
    return [json.loads(line) for line in (out / "events.jsonl").read_text().splitlines()]


def _seconds(stamp: Any) -> float:
    return float(stamp.sec + stamp.nanosec / 1e9)


def _headers(msgtype: str, msg: Any) -> list[Any]:
    """The headers a message carries: its own, a path's poses', a marker array's markers'."""
    if msgtype == "visualization_msgs/msg/MarkerArray":
        return [m.header for m in msg.markers]
    if msgtype == "nav_msgs/msg/Path":
        return [msg.header, *(p.header for p in msg.poses)]
    if msgtype in ("std_msgs/msg/String", "tf2_msgs/msg/TFMessage"):
        return []
    return [msg.header]


def test_topics_and_their_message_types(kinematic: Read) -> None:
    """The topic list as ``ros2 bag info`` shows it: the decisions as std_msgs/String."""
    _, types, messages = kinematic
    expected = {"/tf": "tf2_msgs/msg/TFMessage",
                "/world/cloud": "sensor_msgs/msg/PointCloud2",
                "/world/markers": "visualization_msgs/msg/MarkerArray",
                "/mission/events": "std_msgs/msg/String",
                **dict.fromkeys(DECISIONS, "std_msgs/msg/String")}
    for robot in TEAM:
        expected |= {f"/{robot}/pose": "geometry_msgs/msg/PoseStamped",
                     f"/{robot}/odom": "nav_msgs/msg/Odometry",
                     f"/{robot}/body": "sensor_msgs/msg/PointCloud2",
                     f"/{robot}/plan": "nav_msgs/msg/Path"}
    assert types == expected
    assert len(messages["/world/cloud"]) == len(messages["/world/markers"]) == 1
    assert "/mission/faults" not in messages  # declared, but no robot failed in this run


@pytest.mark.parametrize("run", ["kinematic", "physics"])
def test_mcap_ros2_decodes_every_message_as_rosbags_does(
        run: str, request: pytest.FixtureRequest) -> None:
    """Both readers get the same messages, topic by topic, from the definitions in the file."""
    out, types, messages = request.getfixturevalue(run)
    decoded = _decoded(out / "run.mcap")
    assert {t: len(m) for t, m in decoded.items()} == {t: len(m) for t, m in messages.items()}
    for topic, got in decoded.items():
        def stamps(msgs: list[Any], msgtype: str = types[topic]) -> list[tuple[str, float]]:
            return [(h.frame_id, _seconds(h.stamp)) for m in msgs for h in _headers(msgtype, m)]
        assert stamps(got) == stamps([m for _, m in messages[topic]])
    assert [m.data for m in decoded["/mission/events"]] == [
        m.data for _, m in messages["/mission/events"]]
    cloud = decoded["/world/cloud"][0]
    assert bytes(cloud.data) == bytes(messages["/world/cloud"][0][1].data)


def test_the_decisions_are_the_event_log(tmp_path: Path) -> None:
    """missions/faults.yaml (a fault, a recovery, a command): each decision topic carries the
    events of its kinds, each a String whose JSON is the events.jsonl line's record."""
    out = tmp_path / "faults"
    _run(out, "--no-recording", mission=ROOT / "missions" / "faults.yaml")
    _, messages = _read(out / "run.mcap")
    events = _events(out)
    records = [(t, json.loads(m.data)) for t, m in messages["/mission/events"]]
    assert [r for _, r in records] == events
    assert all(t == r["t"] for t, r in records)  # stamped in simulated time
    for topic, kinds in DECISIONS.items():
        assert [json.loads(m.data) for _, m in messages.get(topic, [])] == [
            e for e in events if e["kind"] in kinds]
    kinds = Counter(e["kind"] for e in events)
    assert kinds["fault"] == kinds["recover"] == kinds["command"] == 1
    assert len(messages["/mission/faults"]) == 2 and len(messages["/mission/commands"]) == 1
    assert len(messages["/mission/assignment"]) == kinds["assignment"] > 1


def test_the_world_cloud_samples_walls_slabs_and_furniture(
        kinematic: Read, world: World) -> None:
    """One PointCloud2 in ``map`` at t = 0: x, y, z and a packed rgb, inside the site and on
    the walls and the furniture the markers draw, a few MB."""
    _, _, messages = kinematic
    (t, cloud), = messages["/world/cloud"]
    assert t == 0.0 and cloud.header.frame_id == "map" and _seconds(cloud.header.stamp) == 0.0
    assert [(f.name, f.offset, f.datatype) for f in cloud.fields] == [
        ("x", 0, 7), ("y", 4, 7), ("z", 8, 7), ("rgb", 12, 7)]  # rgb: PCL's packed float
    rows = np.frombuffer(bytes(cloud.data), dtype=CLOUD)
    assert len(rows) == cloud.width == cloud.row_step // cloud.point_step
    assert len(rows) > 100_000 and len(cloud.data) < 20e6
    xyz = np.column_stack([rows["x"], rows["y"], rows["z"]]).astype(float)
    tops = max(s.box.hi[2] for s in world.solids)
    bottom = min(s.box.lo[2] for s in world.solids)
    assert (xyz.min(axis=0) >= [0.0, 0.0, bottom - 1e-3]).all()
    assert (xyz.max(axis=0) <= [*world.site, tops + 1e-3]).all()
    colours = Counter(rows["rgb"].tolist())
    wall, slab = (170 << 16) | (170 << 8) | 180, (120 << 16) | (120 << 8) | 130
    assert colours[wall] > 50_000 and colours[slab] > 50_000
    (_, markers), = messages["/world/markers"]
    for marker in markers.markers:
        if marker.ns in ("solids", "furniture"):
            centre = np.array([marker.pose.position.x, marker.pose.position.y,
                               marker.pose.position.z])
            half = np.array([marker.scale.x, marker.scale.y, marker.scale.z]) / 2 + 1e-3
            assert (np.abs(xyz - centre) <= half).all(axis=1).sum() >= 8, marker.ns


def test_each_robot_has_a_body_at_each_of_its_poses(kinematic: Read) -> None:
    """Its kind's box (footprint, and the band its body takes) in its base_link."""
    _, _, messages = kinematic
    for robot, (half, below, above) in {"uav1": (0.3, -0.1, 0.1),
                                        "ugv1": (0.505, -0.5, 0.15),
                                        "op1": (0.25, -1.6, 0.15)}.items():
        bodies = messages[f"/{robot}/body"]
        assert [t for t, _ in bodies] == [t for t, _ in messages[f"/{robot}/pose"]]
        _, body = bodies[0]
        assert body.header.frame_id == f"{robot}/base_link"
        rows = np.frombuffer(bytes(body.data), dtype=CLOUD)
        assert np.abs(rows["x"]).max() == pytest.approx(half, abs=1e-6)
        assert (rows["z"].min(), rows["z"].max()) == pytest.approx((below, above), abs=1e-6)


@pytest.mark.parametrize("run", ["kinematic", "physics"])
def test_every_frame_is_map_or_one_tf_gives_before_it_is_used(
        run: str, request: pytest.FixtureRequest) -> None:
    """A viewer can place every message: its frame is ``map`` or a child of it on ``/tf``,
    given no later than the first message in it."""
    _, types, messages = request.getfixturevalue(run)
    given: dict[str, float] = {}
    for t, tfs in messages["/tf"]:
        for tf in tfs.transforms:
            assert tf.header.frame_id == "map"
            assert _seconds(tf.header.stamp) == pytest.approx(t, abs=1e-9)
            given.setdefault(tf.child_frame_id, _seconds(tf.header.stamp))
    used: dict[str, float] = {}
    for topic, stamped in messages.items():
        for _, msg in stamped:
            for h in _headers(types[topic], msg):
                used[h.frame_id] = min(used.get(h.frame_id, np.inf), _seconds(h.stamp))
                assert h.frame_id == "map" or h.frame_id in given, (topic, h.frame_id)
    assert "map" in used and {f for f in used if f != "map"} == set(given)
    assert all(given[f] <= t + 1e-9 for f, t in used.items() if f != "map")
    if run == "physics":
        assert {"uav1/camera", "ugv1/lidar", "uav1/base_link"} <= set(given)


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


def test_a_box_is_sampled_on_its_faces_each_point_once() -> None:
    """A 1 m cube at 0.5 m: the 3 x 3 x 3 grid but its centre; a flat box's two faces once."""
    from astralis_des.sinks.ros_world import face_points

    cube = face_points(np.zeros(3), np.ones(3), 0.5)
    assert len(cube) == 26 == len(np.unique(cube, axis=0))
    assert not ((cube == 0.5).all(axis=1)).any()
    no_bottom = face_points(np.zeros(3), np.ones(3), 0.5, bottom=False)
    assert len(no_bottom) == 25  # the bottom's middle goes; its edges are the sides'
    assert [0.5, 0.5, 0.0] not in no_bottom.tolist()
    flat = face_points(np.zeros(3), np.array([1.0, 1.0, 0.0]), 0.5)  # a road's top, once
    assert len(flat) == 9 and (flat[:, 2] == 0).all()


def test_a_big_site_is_sampled_wider_and_its_ground_from_above() -> None:
    """Autzen's 363 m x 176 m ground: its top alone, spaced to keep the cloud near 500,000."""
    from astralis_des.sinks.ros_world import POINTS, boxes_points
    from astralis_des.world.geometry import Box

    points, rgb = boxes_points([Box((0.0, 0.0, -0.2), (363.0, 176.0, 0.0))], [(1, 2, 3)])
    assert 0.8 * POINTS < len(points) <= 1.01 * POINTS
    assert (points[:, 2] == 0.0).all() and (rgb == 0x010203).all()
    step = np.diff(np.unique(points[:, 0]))
    assert step.max() == pytest.approx(step.min())
    assert step[0] == pytest.approx((363 * 176 / POINTS) ** 0.5, rel=0.01)  # 0.36 m, not 0.2
