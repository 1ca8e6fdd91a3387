"""What the sensors saw, in the recording: kept camera frames (RGB as JPEG, depth in
millimetres, segmentation) under a pinhole that moves with the camera, lidar returns, IMU
readings, and the detections (the estimate, and an arrow from the robot to it). Poses, points
and readings go in columns."""

from __future__ import annotations

import io
from collections import defaultdict
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np
import pyarrow as pa

from astralis_des.kernel.events import Record
from astralis_des.sinks import paths
from astralis_des.sinks.columns import colors, descriptor, floats, rows, send, texts, times, vectors
from astralis_des.sinks.looks import by_height

if TYPE_CHECKING:
    from astralis_des.kernel.contracts import Perceived
    from astralis_des.kernel.perceived import KeptCloud, KeptFrame, KeptScan
    from astralis_des.navsensors import PoseSensors

Kept = TypeVar("Kept", "KeptFrame", "KeptScan", "KeptCloud")
PREVIEW_DIM = 0.45  # a camera's first frame, shown before it is taken, at this brightness


def _by_robot(items: Sequence[Kept]) -> dict[str, list[Kept]]:
    """Kept frames or scans grouped by robot, each group in time order."""
    groups: dict[str, list[Kept]] = defaultdict(list)
    for item in items:
        groups[item.robot].append(item)
    return groups


def log_sensors(rr: Any, rec: Any, perception: Perceived) -> None:
    for rid, frames in _by_robot(perception.frames).items():
        _log_frames(rr, rec, paths.robot_camera(rid), frames)
        _log_preview(rr, rec, paths.robot_camera_preview(rid), frames[0])
    for rid, kept in _by_robot(perception.scans).items():
        points = np.vstack([s.points for s in kept])
        rec.send_columns(paths.robot_lidar(rid),
                         indexes=[rr.TimeColumn(paths.TIMELINE, duration=[s.time for s in kept])],
                         columns=rr.Points3D.columns(positions=points).partition(
                             [len(s.points) for s in kept]))
        rec.log(paths.robot_lidar(rid), rr.Points3D.from_fields(radii=0.03,
                                                                colors=[(255, 90, 90)]),
                static=True)
    for rid, clouds in _by_robot(perception.clouds).items():
        points = np.vstack([c.points for c in clouds])
        rec.send_columns(paths.robot_sensor(rid, "lidar3d"),
                         indexes=[rr.TimeColumn(paths.TIMELINE, duration=[c.time for c in clouds])],
                         columns=rr.Points3D.columns(positions=points,
                                                     colors=by_height(points[:, 2])).partition(
                             [len(c.points) for c in clouds]))
        rec.log(paths.robot_sensor(rid, "lidar3d"), rr.Points3D.from_fields(radii=0.02),
                static=True)
    for rid, trace in perception.imu_traces.items():
        if not trace.times:
            continue
        index = [rr.TimeColumn(paths.TIMELINE, duration=trace.times)]
        for what, values in (("specific_force", [r.specific_force for r in trace.readings]),
                             ("angular_rate", [r.angular_rate for r in trace.readings])):
            rows = np.asarray(values, dtype=float)
            rec.send_columns(paths.robot_imu(rid, what), indexes=index,
                             columns=rr.Scalars.columns(scalars=rows.ravel()).partition(
                                 [3] * len(rows)))
            rec.log(paths.robot_imu(rid, what), rr.SeriesLines(names=["x", "y", "z"]),
                    static=True)


def _log_frames(rr: Any, rec: Any, entity: str, frames: list[KeptFrame]) -> None:
    k = frames[0].intrinsics
    rec.log(entity, rr.Pinhole(focal_length=k.fx, width=k.width, height=k.height,
                               camera_xyz=rr.ViewCoordinates.RDF, image_plane_distance=0.5),
            static=True)
    index = [rr.TimeColumn(paths.TIMELINE, duration=[f.time for f in frames])]
    rec.send_columns(entity, indexes=index,
                     columns=rr.Transform3D.columns(translation=[f.eye for f in frames],
                                                    mat3x3=[f.rotation for f in frames]))
    rec.send_columns(f"{entity}/rgb", indexes=index, columns=rr.EncodedImage.columns(
        blob=jpegs([f.rgb for f in frames]), media_type=["image/jpeg"] * len(frames)))
    _send_images(rec, f"{entity}/depth", index, rr.DepthImage, [f.depth for f in frames],
                 meter=1000.0)
    _send_images(rec, f"{entity}/segmentation", index, rr.SegmentationImage,
                 [f.segmentation for f in frames])


def _send_images(rec: Any, entity: str, index: list[Any], archetype: Any,
                 images: list[np.ndarray], **each: float) -> None:
    """Images of one camera (one size and type) as a column of ``archetype`` at ``index``:
    each one's buffer, the format of the first, the ``each`` values on every row."""
    first, n = archetype(images[0], **each), len(images)
    rec.send_columns(entity, indexes=index, columns=archetype.columns(
        buffer=[np.ascontiguousarray(image).view(np.uint8).reshape(-1) for image in images],
        format=pa.concat_arrays([first.format.as_arrow_array()] * n),
        **{name: [value] * n for name, value in each.items()}))


def jpegs(images: Sequence[np.ndarray], quality: int = 85) -> list[bytes]:
    """RGB frames as JPEG, as ``rr.Image(rgb).compress(jpeg_quality)`` makes them, encoded on
    two threads (Pillow lets go of the GIL while it encodes)."""
    from concurrent.futures import ThreadPoolExecutor

    def encoded(rgb: np.ndarray) -> bytes:
        from PIL import Image

        output = io.BytesIO()
        Image.fromarray(rgb).save(output, format="JPEG", quality=quality)
        return output.getvalue()

    if len(images) < 4:
        return [encoded(rgb) for rgb in images]
    with ThreadPoolExecutor(2, thread_name_prefix="jpeg") as pool:
        return list(pool.map(encoded, images))


def _log_preview(rr: Any, rec: Any, entity: str, first: KeptFrame) -> None:
    """A camera keeps frames only once its robot searches, so from the start of the timeline
    (where the viewer opens) to its first frame its panel would be black: its first frame,
    dimmed and captioned with when it is taken, stands in until then."""
    if first.time <= 0.0:
        return
    height, width = first.rgb.shape[:2]
    rec.set_time(paths.TIMELINE, duration=0.0)
    rec.log(entity, rr.Image((first.rgb * PREVIEW_DIM).astype(np.uint8)).compress(
        jpeg_quality=85), rr.Points2D([(width / 2, height / 2)], radii=0.0,
                                       colors=[(255, 255, 255)], show_labels=True,
                                       labels=[f"first frame at {first.time:.1f} s"]))
    rec.set_time(paths.TIMELINE, duration=first.time)
    rec.log(entity, rr.Clear(recursive=False))


def log_detections(rec: Any, records: list[Record]) -> None:
    """Each detection at its time: the estimate (labelled with its error) and an arrow from
    the robot's camera to it."""
    hits = [r for r in records if r["kind"] == "detection"]
    if not hits:
        return
    origins = np.array([hit["robot_position"] for hit in hits], dtype=float).reshape(-1, 3)
    estimates = np.array([hit["estimate"] for hit in hits], dtype=float).reshape(-1, 3)
    red = colors([(255, 40, 40)] * len(hits))
    send(rec, paths.MISSION_DETECTIONS, times([hit["t"] for hit in hits]), {
        descriptor("Points3D", "positions"): rows(vectors(estimates, 3)),
        descriptor("Points3D", "radii"): rows(floats([0.25] * len(hits))),
        descriptor("Points3D", "colors"): rows(red),
        descriptor("Points3D", "labels"): rows(texts([
            f"{hit['robot']} saw the target (error {hit['error']:.2f} m)" for hit in hits])),
        descriptor("Arrows3D", "origins"): rows(vectors(origins, 3)),
        descriptor("Arrows3D", "vectors"): rows(vectors(estimates - origins, 3)),
        descriptor("Arrows3D", "colors"): rows(red)})


def log_pose_sensors(rr: Any, rec: Any, sensors: PoseSensors) -> None:
    """The GNSS fixes (positions in the site's frame at ``/robots/<id>/gnss``, latitude and
    longitude at ``.../gnss/geo`` for a map, the satellites seen and the open sky), the
    barometers' pressure and altitude, the magnetometers' field and heading, on the time
    line."""
    for rid, name in sensors.sensors:
        got = sensors.readings(rid, name)
        if not len(got):
            continue
        index = [rr.TimeColumn(paths.TIMELINE, duration=got.t)]
        c = got.columns
        if name == "gnss":
            entity = paths.robot_sensor(rid, name)
            rec.send_columns(entity, indexes=index,
                             columns=rr.Points3D.columns(positions=c["position"]))
            rec.log(entity, rr.Points3D.from_fields(radii=0.25, colors=[(40, 200, 120)]),
                    static=True)
            rec.send_columns(f"{entity}/geo", indexes=index, columns=rr.GeoPoints.columns(
                positions=np.column_stack([c["latitude"], c["longitude"]])))
        scalars = {"gnss": ("satellites", "open_sky"), "barometer": ("pressure", "altitude"),
                   "magnetometer": ("heading",)}[name]
        for what in scalars:
            rec.send_columns(paths.robot_sensor(rid, name, what), indexes=index,
                             columns=rr.Scalars.columns(
                                 scalars=np.asarray(c[what], dtype=float)))
        if name == "magnetometer":
            field = np.asarray(c["field"], dtype=float)
            rec.send_columns(paths.robot_sensor(rid, name, "field"), indexes=index,
                             columns=rr.Scalars.columns(scalars=field.ravel()).partition(
                                 [3] * len(field)))
            rec.log(paths.robot_sensor(rid, name, "field"),
                    rr.SeriesLines(names=["forward", "left", "up"]), static=True)
