"""Entity paths of a recording, in one place: ``world/...``, ``robots/<id>/...``,
``mission/...``."""

from __future__ import annotations

TIMELINE = "sim_time"
WORLD_SOLIDS = "world/site/solids"  # outdoors; a building's are under world/<b>/<storey>/
WORLD_ROOMS = "world/rooms"
WORLD_TARGET = "world/target"
WORLD_FURNITURE = "world/furniture"
WORLD_ROADS = "world/roads"
WORLD_OCCUPANCY = "world/occupancy"  # the planner's voxel map
WORLD_BLOCKS = "world/blocks"  # an imported world's voxel boxes
WORLD_MESH = "world/mesh"  # an imported mesh
WORLD_CLOUD = "world/cloud"  # an imported cloud, downsampled
MISSION_EVENTS = "mission/events"
MISSION_ROUNDS = "mission/assignment"
MISSION_MATRIX = f"{MISSION_ROUNDS}/matrix"  # each round's Eq. 1 costs, the chosen pairs marked
MISSION_GRAPH = f"{MISSION_ROUNDS}/graph"  # each round's bipartite graph (a small team's)


def world_part(place: str, what: str) -> str:
    """``world/A/2/solids``: what belongs to storey 2 of building A (``roof``: above the top
    storey; ``site``: outdoors), so that the storeys above the robots can be hidden."""
    return f"world/{place}/{what}"


def robot_body(robot_id: str) -> str:
    """The robot's shape, turned to its heading, moved along its trail."""
    return f"robots/{robot_id}/body"


def robot(robot_id: str) -> str:
    return f"robots/{robot_id}"


def robot_pose(robot_id: str) -> str:
    return f"robots/{robot_id}/pose"


def robot_trail(robot_id: str) -> str:
    return f"robots/{robot_id}/trail"


def robot_plan(robot_id: str) -> str:
    """The path the robot's current leg follows (as planned)."""
    return f"robots/{robot_id}/plan"


def robot_task(robot_id: str) -> str:
    return f"robots/{robot_id}/task"


def mover(mover_id: str) -> str:
    return "world/movers/" + mover_id.replace(":", "_")


def robot_camera(robot_id: str) -> str:
    return f"robots/{robot_id}/camera"


def robot_camera_preview(robot_id: str) -> str:
    """The camera's first kept frame, dimmed, shown from the start until it is taken."""
    return f"robots/{robot_id}/camera/preview"


def robot_lidar(robot_id: str) -> str:
    return f"robots/{robot_id}/lidar"


def robot_imu(robot_id: str, what: str) -> str:
    return f"robots/{robot_id}/imu/{what}"


def robot_sensor(robot_id: str, sensor: str, what: str = "") -> str:
    """A pose sensor's entity (``gnss``, ``barometer``, ``magnetometer``), or a series of it."""
    return f"robots/{robot_id}/{sensor}" + (f"/{what}" if what else "")


MISSION_DETECTIONS = "mission/detections"


def robot_state(robot_id: str) -> str:
    """The robot's task lane (a state timeline)."""
    return f"robots/{robot_id}/state"


MISSION_METRICS = "mission/metrics"


def mission_metric(name: str) -> str:
    return f"{MISSION_METRICS}/{name}"
