"""A run as ROS 2 messages, for the MCAP output: what each topic carries, built with the
message types of ``rosbags`` (ROS 2 Humble's definitions) and stamped with simulated time.

Frames: ``map`` (the world's frame, z up), ``ROBOT/base_link`` (where the robot is, its yaw
the direction it last moved in), ``ROBOT/camera`` (the optical frame of a kept camera frame:
x right, y down, z forward) and ``ROBOT/lidar`` (at the scanner, axes of ``map``: the scan's
angles are bearings in the map).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from functools import cache
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from astralis_des.kernel.perceived import KeptCloud, KeptFrame, KeptScan
    from astralis_des.simulation import Simulation

Stamped = tuple[float, str, str, Any]  # (time s, topic, type name, message)


class Types:
    """The typestore and its message classes, as attributes: ``ty.geometry_msgs__Pose``."""

    def __init__(self, store: Any) -> None:
        self.store = store

    def __getattr__(self, name: str) -> Any:  # once per class: then an attribute
        package, _, short = name.rpartition("__")
        cls = self.store.types[f"{package}/msg/{short}"]
        setattr(self, name, cls)
        return cls


@cache
def typestore() -> Types:
    """ROS 2 Humble's message types (one store a process: its serialisers are generated on
    first use)."""
    from rosbags.typesys import Stores, get_typestore

    return Types(get_typestore(Stores.ROS2_HUMBLE))


def stamp(ty: Types, t: float) -> Any:
    sec, nanosec = divmod(round(t * 1e9), 10**9)
    return ty.builtin_interfaces__Time(sec=sec, nanosec=nanosec)


def header(ty: Types, t: float, frame: str) -> Any:
    return ty.std_msgs__Header(stamp=stamp(ty, t), frame_id=frame)


def quaternion(ty: Types, yaw: float = 0.0, matrix: np.ndarray | None = None) -> Any:
    if matrix is not None:
        from scipy.spatial.transform import Rotation

        x, y, z, w = Rotation.from_matrix(np.asarray(matrix, dtype=float)).as_quat()
        return ty.geometry_msgs__Quaternion(x=float(x), y=float(y), z=float(z), w=float(w))
    return ty.geometry_msgs__Quaternion(x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))


def point(ty: Types, p: Any) -> Any:
    x, y, z = (float(v) for v in p)
    return ty.geometry_msgs__Point(x=x, y=y, z=z)


def vector(ty: Types, p: Any) -> Any:
    x, y, z = (float(v) for v in p)
    return ty.geometry_msgs__Vector3(x=x, y=y, z=z)


def yaws(points: np.ndarray) -> np.ndarray:
    """The direction each point was reached from (the first: that of the first move)."""
    out = np.zeros(len(points))
    last = 0.0
    for k in range(1, len(points)):
        d = points[k, :2] - points[k - 1, :2]
        if np.hypot(*d) > 1e-6:
            last = math.atan2(d[1], d[0])
        out[k] = last
    if len(points) > 1:
        moved = np.flatnonzero(np.hypot(*(np.diff(points[:, :2], axis=0).T)) > 1e-6)
        out[0] = out[moved[0] + 1] if len(moved) else 0.0
    return out


def robot_poses(ty: Types, sim: Simulation) -> Iterator[Stamped]:
    """Per robot and trail point: its TF, PoseStamped and Odometry (the twist from the next
    point). The three share their header, pose and quaternion (read-only messages)."""
    zero36, still = np.zeros(36), vector(ty, (0.0, 0.0, 0.0))
    for rid, robot in sim.robots.items():
        times = np.asarray(robot.trail_t, dtype=float)
        pts = np.asarray(robot.trail_p, dtype=float).reshape(-1, 3)
        yaw = yaws(pts)
        vel = np.zeros_like(pts)
        if len(pts) > 1:
            dt = np.maximum(np.diff(times), 1e-9)[:, None]
            vel[:-1] = np.diff(pts, axis=0) / dt
        frame = f"{rid}/base_link"
        for k, t in enumerate(times.tolist()):
            h = header(ty, t, "map")
            q = quaternion(ty, float(yaw[k]))
            pose = ty.geometry_msgs__Pose(position=point(ty, pts[k]), orientation=q)
            tf = ty.geometry_msgs__TransformStamped(
                header=h, child_frame_id=frame,
                transform=ty.geometry_msgs__Transform(translation=vector(ty, pts[k]), rotation=q))
            yield t, "/tf", "tf2_msgs/msg/TFMessage", ty.tf2_msgs__TFMessage(transforms=[tf])
            yield (t, f"/{rid}/pose", "geometry_msgs/msg/PoseStamped",
                   ty.geometry_msgs__PoseStamped(header=h, pose=pose))
            twist = ty.geometry_msgs__Twist(linear=vector(ty, vel[k]), angular=still)
            yield (t, f"/{rid}/odom", "nav_msgs/msg/Odometry", ty.nav_msgs__Odometry(
                header=h, child_frame_id=frame,
                pose=ty.geometry_msgs__PoseWithCovariance(pose=pose, covariance=zero36),
                twist=ty.geometry_msgs__TwistWithCovariance(twist=twist, covariance=zero36)))


def planned_paths(ty: Types, sim: Simulation) -> Iterator[Stamped]:
    """Each leg's planned path, when the robot set out on it."""
    for rid, robot in sim.robots.items():
        for t, path in robot.plans:
            poses = [ty.geometry_msgs__PoseStamped(
                header=header(ty, t, "map"),
                pose=ty.geometry_msgs__Pose(position=point(ty, p), orientation=quaternion(ty)))
                for p in np.asarray(path, dtype=float)]
            yield (t, f"/{rid}/plan", "nav_msgs/msg/Path",
                   ty.nav_msgs__Path(header=header(ty, t, "map"), poses=poses))


def sensors(ty: Types, sim: Simulation) -> Iterator[Stamped]:
    """The pose sensors' readings (NavSatFix, FluidPressure, MagneticField; both fidelities)
    and what the physics fidelity's sensors kept: camera frames (Image and CameraInfo, with
    the camera's TF), lidar scans (LaserScan) and IMU readings (Imu)."""
    yield from pose_sensors(ty, sim)
    perception = sim.cosim.perception
    if perception is None:
        return
    for frame in perception.frames:
        yield from _camera(ty, frame)
    beams = {m.id: m.sensor_set.lidar.beams for m in sim.mission.spec.team
             if m.sensor_set.lidar is not None}
    ranges = {m.id: m.sensor_set.lidar.range for m in sim.mission.spec.team
              if m.sensor_set.lidar is not None}
    for scan in perception.scans:
        yield from _scan(ty, sim, scan, beams.get(scan.robot, 360),
                         ranges.get(scan.robot, 30.0))
    for cloud in perception.clouds:
        yield _cloud(ty, cloud)
    for rid, trace in perception.imu_traces.items():
        for t, reading in zip(trace.times, trace.readings, strict=True):
            yield (t, f"/{rid}/imu", "sensor_msgs/msg/Imu", ty.sensor_msgs__Imu(
                header=header(ty, t, f"{rid}/base_link"), orientation=quaternion(ty),
                orientation_covariance=np.array([-1.0] + [0.0] * 8),
                angular_velocity=vector(ty, reading.angular_rate),
                angular_velocity_covariance=np.zeros(9),
                linear_acceleration=vector(ty, reading.specific_force),
                linear_acceleration_covariance=np.zeros(9)))


def _camera(ty: Types, frame: KeptFrame) -> Iterator[Stamped]:
    rid, t, k = frame.robot, frame.time, frame.intrinsics
    optical = f"{rid}/camera"
    tf = ty.geometry_msgs__TransformStamped(
        header=header(ty, t, "map"), child_frame_id=optical,
        transform=ty.geometry_msgs__Transform(translation=vector(ty, frame.eye),
                                              rotation=quaternion(ty, matrix=frame.rotation)))
    yield t, "/tf", "tf2_msgs/msg/TFMessage", ty.tf2_msgs__TFMessage(transforms=[tf])
    rgb = np.ascontiguousarray(frame.rgb[..., :3], dtype=np.uint8)
    height, width = rgb.shape[:2]
    yield (t, f"/{rid}/camera/image", "sensor_msgs/msg/Image", ty.sensor_msgs__Image(
        header=header(ty, t, optical), height=height, width=width, encoding="rgb8",
        is_bigendian=0, step=width * 3, data=rgb.ravel()))
    fx, fy = k.fx * width / k.width, k.fy * height / k.height  # kept at half resolution
    K = np.array([fx, 0.0, width / 2, 0.0, fy, height / 2, 0.0, 0.0, 1.0])
    P = np.array([fx, 0.0, width / 2, 0.0, 0.0, fy, height / 2, 0.0, 0.0, 0.0, 1.0, 0.0])
    yield (t, f"/{rid}/camera/camera_info", "sensor_msgs/msg/CameraInfo",
           ty.sensor_msgs__CameraInfo(
               header=header(ty, t, optical), height=height, width=width,
               distortion_model="plumb_bob", d=np.zeros(5), k=K,
               r=np.eye(3).ravel(), p=P, binning_x=0, binning_y=0,
               roi=ty.sensor_msgs__RegionOfInterest(x_offset=0, y_offset=0, height=0, width=0,
                                                    do_rectify=False)))


def _scan(ty: Types, sim: Simulation, scan: KeptScan, beams: int,
          reach: float) -> Iterator[Stamped]:
    """A scan's returns as ranges by bearing (``inf``: no return), from where the robot was."""
    robot = sim.robots[scan.robot]
    times = np.asarray(robot.trail_t, dtype=float)
    k = max(0, int(np.searchsorted(times, scan.time, side="right")) - 1)
    origin = np.asarray(robot.trail_p[k], dtype=float)
    pts = np.asarray(scan.points, dtype=float).reshape(-1, 3)
    if len(pts):
        origin = np.array([origin[0], origin[1], float(np.median(pts[:, 2]))])
    d = pts[:, :2] - origin[:2]
    step = 2 * math.pi / beams
    ranges = np.full(beams, np.inf, dtype=np.float32)
    if len(pts):
        bins = np.round((np.arctan2(d[:, 1], d[:, 0]) + math.pi) / step).astype(int) % beams
        np.minimum.at(ranges, bins, np.hypot(d[:, 0], d[:, 1]).astype(np.float32))
    frame = f"{scan.robot}/lidar"
    tf = ty.geometry_msgs__TransformStamped(
        header=header(ty, scan.time, "map"), child_frame_id=frame,
        transform=ty.geometry_msgs__Transform(translation=vector(ty, origin),
                                              rotation=quaternion(ty)))
    yield scan.time, "/tf", "tf2_msgs/msg/TFMessage", ty.tf2_msgs__TFMessage(transforms=[tf])
    yield (scan.time, f"/{scan.robot}/scan", "sensor_msgs/msg/LaserScan",
           ty.sensor_msgs__LaserScan(
               header=header(ty, scan.time, frame), angle_min=-math.pi,
               angle_max=math.pi - step, angle_increment=step, time_increment=0.0,
               scan_time=0.0, range_min=0.05, range_max=float(reach), ranges=ranges,
               intensities=np.zeros(0, dtype=np.float32)))


NO_FIX, FIX = -1, 0  # sensor_msgs/NavSatStatus: STATUS_NO_FIX, STATUS_FIX
SERVICE_GPS, COVARIANCE_DIAGONAL_KNOWN = 1, 2


def pose_sensors(ty: Types, sim: Simulation) -> Iterator[Stamped]:
    """Each GNSS fix as a NavSatFix (no fix: NaN with STATUS_NO_FIX; the covariance its noise
    was drawn with), each barometer reading as a FluidPressure (Pa) and each magnetometer
    reading as a MagneticField (tesla, in ``ROBOT/base_link``: x forward, y left, z up)."""
    specs = {m.id: m.sensor_set for m in sim.mission.spec.team}
    for rid, name in sim.pose_sensors.sensors:
        got = sim.pose_sensors.readings(rid, name)
        c, frame = got.columns, f"{rid}/base_link"
        for i, t in enumerate(got.t.tolist()):
            if name == "gnss":
                h, v = float(c["horizontal_std"][i]), float(c["vertical_std"][i])
                fixed = math.isfinite(h)
                yield (t, f"/{rid}/gnss/fix", "sensor_msgs/msg/NavSatFix",
                       ty.sensor_msgs__NavSatFix(
                           header=header(ty, t, frame), status=ty.sensor_msgs__NavSatStatus(
                               status=FIX if fixed else NO_FIX, service=SERVICE_GPS),
                           latitude=float(c["latitude"][i]),
                           longitude=float(c["longitude"][i]),
                           altitude=float(c["altitude"][i]),
                           position_covariance=np.diag([h * h, h * h, v * v]).ravel()
                           if fixed else np.full(9, -1.0),
                           position_covariance_type=COVARIANCE_DIAGONAL_KNOWN if fixed else 0))
            elif name == "barometer":
                noise = specs[rid].barometer.noise  # type: ignore[union-attr]
                yield (t, f"/{rid}/barometer", "sensor_msgs/msg/FluidPressure",
                       ty.sensor_msgs__FluidPressure(
                           header=header(ty, t, frame), fluid_pressure=float(c["pressure"][i]),
                           variance=float(noise * noise)))
            else:
                sigma = specs[rid].magnetometer.noise * 1e-6  # type: ignore[union-attr]
                yield (t, f"/{rid}/magnetometer", "sensor_msgs/msg/MagneticField",
                       ty.sensor_msgs__MagneticField(
                           header=header(ty, t, frame),
                           magnetic_field=vector(ty, np.asarray(c["field"][i]) * 1e-6),
                           magnetic_field_covariance=np.diag([sigma * sigma] * 3).ravel()))


INT32, FLOAT32 = 5, 7  # sensor_msgs/PointField datatypes


def _cloud(ty: Types, cloud: KeptCloud) -> Stamped:
    """A kept 3-D lidar sweep as a PointCloud2 in ``map``: x, y, z (float32) and the id of
    the body each return hit (int32, its segmentation id)."""
    n = len(cloud.points)
    rows = np.zeros(n, dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("id", "<i4")])
    rows["x"], rows["y"], rows["z"] = (cloud.points[:, k] for k in range(3))
    rows["id"] = cloud.ids
    fields = [ty.sensor_msgs__PointField(name=name, offset=4 * k, datatype=kind, count=1)
              for k, (name, kind) in enumerate((("x", FLOAT32), ("y", FLOAT32),
                                                ("z", FLOAT32), ("id", INT32)))]
    return (cloud.time, f"/{cloud.robot}/lidar3d/points", "sensor_msgs/msg/PointCloud2",
            ty.sensor_msgs__PointCloud2(
                header=header(ty, cloud.time, "map"), height=1, width=n, fields=fields,
                is_bigendian=False, point_step=16, row_step=16 * n,
                data=rows.view(np.uint8).ravel(), is_dense=True))
