"""``run.mcap``: the run as ROS 2 messages, each topic's definition embedded (``ros2msg``
schemas, CDR messages), stamped with simulated time, for ``ros2 bag play``, rosbags, Foxglove,
RViz and the Rerun viewer. Written when the run closes (also when it is interrupted), in time
order; every frame a message names is ``map`` or a child ``/tf`` gives.

Topics:

- ``/tf`` (``tf2_msgs/TFMessage``): ``map`` to ``ROBOT/base_link`` at each pose, and in physics
  fidelity to ``ROBOT/camera`` and ``ROBOT/lidar`` with each kept frame and scan
  (:mod:`astralis_des.sinks.ros_messages` says what the frames are).
- ``/world/cloud`` (``sensor_msgs/PointCloud2``) and ``/world/markers``
  (``visualization_msgs/MarkerArray``): the world, once at t = 0
  (:mod:`astralis_des.sinks.ros_world`).
- per robot: ``/ROBOT/pose`` (``geometry_msgs/PoseStamped``, in ``map``), ``/ROBOT/odom``
  (``nav_msgs/Odometry``), ``/ROBOT/body`` (``sensor_msgs/PointCloud2``, its shape in
  ``ROBOT/base_link``), ``/ROBOT/plan`` (``nav_msgs/Path``, each leg as it set out); the pose
  sensors it carries (``/ROBOT/gnss/fix``, ``/ROBOT/barometer``, ``/ROBOT/magnetometer``); in
  physics fidelity ``/ROBOT/camera/image`` and ``camera_info``, ``/ROBOT/scan``,
  ``/ROBOT/lidar3d/points`` and ``/ROBOT/imu``.
- the mission's decisions, as ``std_msgs/String``: each message's ``data`` is one event as a
  JSON object, the record of its line in events.jsonl (compact, non-ASCII escaped; the same
  text these topics carried before as JSON messages): ``t`` in simulated seconds, ``kind``,
  ``robot`` when there is one and the kind's fields (docs/events.md), so any ROS 2 tool opens
  them and ``json.loads(msg.data)`` reads them. ``/mission/events`` carries every event, the
  others a part of them (``DECISIONS``): ``/mission/tasks`` a task queued, started or
  finished (``task``, ``action``, ``room``; ``origin``; ``status``, ``message``,
  ``distance``, a search's ``coverage``); ``/mission/assignment`` each assignment round
  (``segment``, ``agents``, ``rooms`` with their ``risk`` and ``messiness``, Eq. 1's
  ``costs``, the ``matching`` and who is ``unassigned``); ``/mission/detections`` the target
  seen (``sensor``, ``target_room``, ``estimate``, ``error``, ``robot_position``,
  ``target_position``, ``distance``, ``avatar``); ``/mission/faults`` a robot down
  (``fault``, its ``reason``), back (``recover``) or a segment left with no one
  (``team_lost``); ``/mission/commands`` a command (``command``: a timeline's ``action``,
  ``room``, ``params`` and ``preempt``, or the API's ``op`` and what it was given) and a
  timeline's ``cancel`` (its ``tasks``). The six topics are in every file, without messages
  when nothing of theirs happened.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

from astralis_des.errors import InputError
from astralis_des.kernel.events import Record
from astralis_des.outdir import dumps
from astralis_des.sinks import ros_messages as ros
from astralis_des.sinks import ros_world

if TYPE_CHECKING:
    from astralis_des.simulation import Simulation
    from astralis_des.simulation.result import RunResult

STRING = "std_msgs/msg/String"
# topic -> the event kinds it carries (None: every one)
DECISIONS: dict[str, tuple[str, ...] | None] = {
    "/mission/events": None,
    "/mission/tasks": ("task_queued", "task_started", "task_finished"),
    "/mission/assignment": ("assignment",),
    "/mission/detections": ("detection",),
    "/mission/faults": ("fault", "recover", "team_lost"),
    "/mission/commands": ("command", "cancel"),
}
WORLD = {"/world/markers": "visualization_msgs/msg/MarkerArray",
         "/world/cloud": "sensor_msgs/msg/PointCloud2"}


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
            schemas: dict[str, int] = {}
            channels: dict[str, int] = {}

            def channel(topic: str, typename: str) -> int:
                if typename not in schemas:
                    text, _ = ty.store.generate_msgdef(typename, ros_version=2)
                    schemas[typename] = writer.register_schema(
                        name=typename, encoding="ros2msg", data=text.encode())
                if topic not in channels:
                    channels[topic] = writer.register_channel(
                        topic, message_encoding="cdr", schema_id=schemas[typename])
                return channels[topic]

            for topic, typename in (*WORLD.items(), *((d, STRING) for d in DECISIONS)):
                channel(topic, typename)  # there even without a message
            for seq, (t, topic, typename, msg) in enumerate(messages):
                ns = round(t * 1e9)
                writer.add_message(channel(topic, typename), log_time=ns, publish_time=ns,
                                   data=bytes(ty.store.serialize_cdr(msg, typename)),
                                   sequence=seq)
            writer.finish()
            f.flush()
            os.fsync(f.fileno())  # a full disk fails here, not as a short file later

    def finish(self) -> None:
        pass

    def discard(self) -> None:
        pass

    def _messages(self, ty: ros.Types) -> Iterator[ros.Stamped]:
        sim = self.sim
        yield 0.0, "/world/markers", WORLD["/world/markers"], ros_world.markers(ty, sim)
        yield 0.0, "/world/cloud", WORLD["/world/cloud"], ros_world.world_cloud(ty, sim)
        yield from decisions(ty, self.records)
        yield from ros.robot_poses(ty, sim)
        yield from ros_world.bodies(ty, sim)
        yield from ros.planned_paths(ty, sim)
        yield from ros.sensors(ty, sim)


def decisions(ty: ros.Types, records: list[Record]) -> Iterator[ros.Stamped]:
    """Each event as a String holding its JSON, on ``/mission/events`` and on the topic of
    its kind (``DECISIONS``)."""
    for record in records:
        msg = ty.std_msgs__String(data=dumps(record, separators=(",", ":")))
        for topic, kinds in DECISIONS.items():
            if kinds is None or record["kind"] in kinds:
                yield record["t"], topic, STRING, msg
