"""``run.mcap``: the run as ROS 2 messages (CDR, with their ``ros2msg`` schemas) and the
mission's decisions as JSON (with JSON Schemas), on simulated time, for ``ros2 bag play``,
Foxglove and the Rerun viewer.

Topics: ``/tf`` (``tf2_msgs/TFMessage``), per robot ``/ROBOT/pose``
(``geometry_msgs/PoseStamped``), ``/ROBOT/odom`` (``nav_msgs/Odometry``), ``/ROBOT/plan``
(``nav_msgs/Path``), and in physics fidelity ``/ROBOT/camera/image`` and ``camera_info``,
``/ROBOT/scan``, ``/ROBOT/imu``; ``/world/markers`` (``visualization_msgs/MarkerArray``: walls
and slabs, rooms coloured by risk, furniture) once at the start; ``/mission/events`` (every
event), ``/mission/tasks``, ``/mission/assignment``, ``/mission/detections``,
``/mission/faults`` and ``/mission/commands`` (JSON). Written when the run closes (also when
it is interrupted), in time order.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from astralis_des.errors import InputError
from astralis_des.kernel.catalogue import EVENTS
from astralis_des.kernel.events import Record
from astralis_des.outdir import dumps
from astralis_des.sinks import ros_messages as ros
from astralis_des.world.geometry import Box
from astralis_des.world.model import BLOCK

if TYPE_CHECKING:
    from astralis_des.simulation import Simulation
    from astralis_des.simulation.result import RunResult

JSON_TOPICS: dict[str, tuple[str, ...]] = {
    "/mission/tasks": ("task_queued", "task_started", "task_finished"),
    "/mission/assignment": ("assignment",),
    "/mission/detections": ("detection",),
    "/mission/faults": ("fault", "recover", "team_lost"),
    "/mission/commands": ("command", "cancel"),
}
def event_schema() -> dict[str, Any]:
    """The JSON Schema of ``/mission/events``: a line of events.jsonl, its kind one of the
    catalogue's (a plug-in's too)."""
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "astralis_des event",
        "description": "One line of events.jsonl: simulated time, kind, the robot if any, and "
                       "the kind's fields (docs/events.md).",
        "type": "object",
        "properties": {"t": {"type": "number", "description": "simulated seconds"},
                       "kind": {"enum": list(EVENTS)}, "robot": {"type": "string"}},
        "required": ["t", "kind"],
        "additionalProperties": True,
    }


def require() -> None:
    """A clear error, before anything is written, when the mcap extra is not installed."""
    try:
        import mcap  # noqa: F401
        import rosbags  # noqa: F401
    except ImportError as exc:
        raise InputError("run.mcap needs the mcap extra: pip install 'astralis-des[mcap]'",
                         key="--mcap") from exc


class McapWriter:
    """Collects the run's events; writes ``run.mcap`` when the run closes."""

    def __init__(self, sim: Simulation, path: Path) -> None:
        require()
        self.sim = sim
        self.path = path
        self.records: list[Record] = []

    def on_event(self, record: Record) -> None:
        self.records.append(record)

    def close(self, result: RunResult) -> None:
        from mcap.writer import CompressionType, Writer

        ty = ros.typestore()
        messages = sorted(self._messages(ty), key=lambda m: m[0])  # stable: ties keep order
        with self.path.open("wb") as f:
            writer = Writer(f, compression=CompressionType.LZ4)  # ZSTD: 25% smaller, slower
            writer.start(profile="ros2", library="astralis-des")
            channels: dict[str, int] = {}
            json_schema = writer.register_schema(
                name="astralis_des/Event", encoding="jsonschema",
                data=dumps(event_schema()).encode())
            for seq, (t, topic, typename, msg) in enumerate(messages):
                if topic not in channels:
                    if typename == "json":
                        channels[topic] = writer.register_channel(
                            topic, message_encoding="json", schema_id=json_schema)
                    else:
                        text, _ = ty.store.generate_msgdef(typename, ros_version=2)
                        schema = writer.register_schema(name=typename, encoding="ros2msg",
                                                        data=text.encode())
                        channels[topic] = writer.register_channel(
                            topic, message_encoding="cdr", schema_id=schema)
                data = (dumps(msg, separators=(",", ":")).encode() if typename == "json"
                        else bytes(ty.store.serialize_cdr(msg, typename)))
                ns = round(t * 1e9)
                writer.add_message(channels[topic], log_time=ns, publish_time=ns, data=data,
                                   sequence=seq)
            writer.finish()
            f.flush()
            os.fsync(f.fileno())  # a full disk fails here, not as a short file later

    def discard(self) -> None:
        pass

    def _messages(self, ty: ros.Types) -> Iterator[ros.Stamped]:
        sim = self.sim
        yield 0.0, "/world/markers", "visualization_msgs/msg/MarkerArray", markers(ty, sim)
        for record in self.records:
            yield record["t"], "/mission/events", "json", record
            for topic, kinds in JSON_TOPICS.items():
                if record["kind"] in kinds:
                    yield record["t"], topic, "json", record
        yield from ros.robot_poses(ty, sim)
        yield from ros.planned_paths(ty, sim)
        yield from ros.sensors(ty, sim)


def markers(ty: ros.Types, sim: Simulation) -> Any:
    """The world as boxes: walls and slabs (grey), obstacles (green), rooms (translucent, red
    as their risk rises), furniture (brown)."""
    boxes: list[tuple[str, Any, tuple[float, float, float, float]]] = []
    for solid in sim.world.solids:
        if solid.kind != BLOCK:
            colour = (0.67, 0.67, 0.7, 1.0) if solid.kind == "wall" else (
                (0.47, 0.47, 0.5, 0.25) if solid.kind == "slab" else (0.24, 0.55, 0.24, 1.0))
            boxes.append(("solids", solid.box, colour))
    for rid in sorted(sim.world.rooms):
        risk = sim.rooms[rid].risk if rid in sim.rooms else 0.0
        boxes.append(("rooms", sim.world.rooms[rid].box, (float(risk), 0.3, 0.3, 0.15)))
    for placed in sim.scene.furnished():
        centre, size = np.asarray(placed.center, dtype=float), np.asarray(placed.size)
        boxes.append(("furniture", Box(tuple(centre - size / 2), tuple(centre + size / 2)),
                      (0.55, 0.35, 0.17, 1.0)))
    stamp = ros.header(ty, 0.0, "map")
    out = []
    for k, (ns, box, rgba) in enumerate(boxes):
        lo, hi = np.asarray(box.lo, dtype=float), np.asarray(box.hi, dtype=float)
        out.append(ty.visualization_msgs__Marker(
            header=stamp, ns=ns, id=k, type=1, action=0,  # CUBE, ADD
            pose=ty.geometry_msgs__Pose(position=ros.point(ty, (lo + hi) / 2),
                                        orientation=ros.quaternion(ty)),
            scale=ros.vector(ty, np.maximum(hi - lo, 0.01)),
            color=ty.std_msgs__ColorRGBA(r=rgba[0], g=rgba[1], b=rgba[2], a=rgba[3]),
            lifetime=ty.builtin_interfaces__Duration(sec=0, nanosec=0), frame_locked=False,
            points=[], colors=[], texture_resource="",
            texture=ty.sensor_msgs__CompressedImage(header=stamp, format="", data=np.zeros(
                0, dtype=np.uint8)),
            uv_coordinates=[], text="", mesh_resource="",
            mesh_file=ty.visualization_msgs__MeshFile(filename="", data=np.zeros(
                0, dtype=np.uint8)),
            mesh_use_embedded_materials=False))
    return ty.visualization_msgs__MarkerArray(markers=out)
