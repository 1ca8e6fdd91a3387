"""The world and the robots' bodies as ROS 2 messages, for the MCAP output.

``/world/cloud`` is the world as one ``sensor_msgs/PointCloud2`` in ``map`` at t = 0: points
on the faces of the walls, slabs, outdoor obstacles, roads and furniture that one could see
(those above the ground), ``SPACING`` apart with each box's edges and corners (wider on a site
whose faces would take more than ``POINTS``), and an imported world's own scan (its blocks'
faces where it has no scan). Each point has x, y, z and a packed ``rgb`` (PCL's convention:
the bytes of ``0x00RRGGBB`` in a field declared FLOAT32) by kind, in the colours of the Rerun
recording (walls light grey, slabs darker, obstacles green, roads dark grey, furniture by
kind, an avatar in its Table II colour). Every viewer draws a point cloud (Foxglove and RViz
in these colours; Rerun, which does not read ``rgb``, in one colour a topic);
``/world/markers`` (``visualization_msgs/MarkerArray``: the same boxes and the rooms by risk)
comes beside it for the viewers that draw markers.

``/ROBOT/body`` is a robot's shape as a ``PointCloud2`` in ``ROBOT/base_link``: the box of its
kind's footprint (its disc's square where it has none) and of the band below and above its
pose that its body takes, in the robot's colour; sent with each of its poses, so a viewer that
places a message by the transform at its stamp draws the body where the robot was.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np

from astralis_des.kinds import KIND_DEFAULTS
from astralis_des.sinks import ros_messages as ros
from astralis_des.sinks.looks import ROAD_COLOR, placed_color, robot_colors, solid_color
from astralis_des.world.geometry import Box
from astralis_des.world.model import BLOCK, World

if TYPE_CHECKING:
    from astralis_des.simulation import Simulation
    from astralis_des.world.clutter import Placed

SPACING = 0.2  # m between the world cloud's points on a face (the planner's voxel)
POINTS = 500_000  # about the most points the world's faces take (8 MB)
BODY_SPACING = 0.1  # m between a body's points
BLOCK_COLOR = (150, 160, 170, 255)  # an imported world's blocks (others: looks.solid_color)
SCAN_COLOR = (200, 200, 200)  # an imported scan's points that come without colours
FIELDS = ("x", "y", "z", "rgb")  # each declared FLOAT32 (rgb: the packed colour's bytes)
ROWS = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("rgb", "<u4")])
Colour = tuple[int, ...]  # r, g, b (and a, not used)


def face_points(lo: np.ndarray, hi: np.ndarray, spacing: float,
                bottom: bool = True) -> np.ndarray:
    """``(N, 3)`` points on the faces of the box ``lo``-``hi`` (all six, or all but the
    bottom): on each face a grid at most ``spacing`` apart, its edges and corners included,
    each point once (a flat box's two faces are one)."""
    axes = [np.linspace(lo[k], hi[k], math.ceil((hi[k] - lo[k]) / spacing) + 1)
            for k in range(3)]  # one value along a flat side
    faces = [np.zeros((0, 3))]
    for k, (a, b) in enumerate(((1, 2), (0, 2), (0, 1))):  # the face normal to k spans a, b
        # an edge belongs to the first face it is on: axes before k without their ends
        u = axes[a][1:-1] if a < k else axes[a]
        v = axes[b][1:-1] if b < k else axes[b]
        ends = axes[k][[0, -1]] if len(axes[k]) > 1 else axes[k]
        for side in ends if bottom or k != 2 else ends[-1:]:
            face = np.empty((len(u) * len(v), 3))
            face[:, k] = side
            face[:, a] = np.repeat(u, len(v))
            face[:, b] = np.tile(v, len(u))
            faces.append(face)
    return np.concatenate(faces)


def boxes_points(boxes: Sequence[Box],
                 colours: Sequence[Colour]) -> tuple[np.ndarray, np.ndarray]:
    """The points of the faces one could see (above the ground, z = 0) of each box, and each
    point's colour (``0x00RRGGBB``): ``SPACING`` apart, or as much wider as keeps them to about
    ``POINTS`` (a big site's ground)."""
    lo = np.array([b.lo for b in boxes], dtype=float).reshape(-1, 3)
    hi = np.array([b.hi for b in boxes], dtype=float).reshape(-1, 3)
    lo[:, 2] = np.clip(lo[:, 2], 0.0, hi[:, 2])  # nothing sees below the ground
    bottom = lo[:, 2] > 0.0  # nor a face lying on it
    dx, dy, dz = (hi - lo).T
    area = float((dx * dy * (1 + bottom) + 2 * dz * (dx + dy)).sum())
    spacing = max(SPACING, math.sqrt(area / POINTS))
    points, rgb = [np.zeros((0, 3))], [np.zeros(0, dtype=np.uint32)]
    for k, colour in enumerate(colours):
        pts = face_points(lo[k], hi[k], spacing, bottom=bool(bottom[k]))
        points.append(pts)
        rgb.append(np.full(len(pts), packed(colour), dtype=np.uint32))
    return np.concatenate(points), np.concatenate(rgb)


def packed(colour: Sequence[int]) -> int:
    r, g, b = (int(c) for c in colour[:3])
    return (r << 16) | (g << 8) | b


def world_parts(world: World, furniture: Sequence[Placed]) -> tuple[list[Box], list[Colour]]:
    """The boxes the world cloud samples, with their colours: walls and slabs, outdoor
    obstacles, roads, furniture (an avatar in its Table II colour) and an imported world's
    blocks unless its scan shows them."""
    boxes: list[Box] = []
    colours: list[Colour] = []
    scanned = len(scan_points(world)[0]) > 0
    for solid in world.solids:
        if solid.kind != BLOCK or not scanned:
            boxes.append(solid.box)
            colours.append(BLOCK_COLOR if solid.kind == BLOCK else solid_color(solid.kind))
    for surface in world.surfaces:
        boxes.append(surface.box)
        colours.append(ROAD_COLOR)
    for placed in furniture:
        boxes.append(placed.box)
        colours.append(placed_color(placed))
    return boxes, colours


def scan_points(world: World) -> tuple[np.ndarray, np.ndarray]:
    """An imported world's scan and its colours (grey where it has none); nothing for a
    world of boxes."""
    imported = world.imported
    if imported is None or imported.cloud is None:
        return np.zeros((0, 3)), np.zeros(0, dtype=np.uint32)
    scan = np.asarray(imported.cloud, dtype=float).reshape(-1, 3)
    if imported.cloud_colors is None:
        return scan, np.full(len(scan), packed(SCAN_COLOR), dtype=np.uint32)
    c = np.asarray(imported.cloud_colors, dtype=np.uint32).reshape(-1, 3)
    return scan, (c[:, 0] << 16) | (c[:, 1] << 8) | c[:, 2]


def world_cloud(ty: ros.Types, sim: Simulation) -> Any:
    """The world's surfaces (and an imported world's scan) as one PointCloud2 in ``map``."""
    points, rgb = boxes_points(*world_parts(sim.world, sim.scene.furnished()))
    scan, scan_rgb = scan_points(sim.world)
    return cloud(ty, 0.0, "map", np.concatenate([points, scan]), np.concatenate([rgb, scan_rgb]))


def cloud(ty: ros.Types, t: float, frame: str, points: np.ndarray, rgb: np.ndarray) -> Any:
    """A PointCloud2 of ``points`` (float32 x, y, z) and their packed colours (``rgb``)."""
    n = len(points)
    rows = np.zeros(n, dtype=ROWS)
    for k, axis in enumerate("xyz"):
        rows[axis] = points[:, k]
    rows["rgb"] = rgb
    fields = [ty.sensor_msgs__PointField(name=name, offset=4 * k, datatype=ros.FLOAT32, count=1)
              for k, name in enumerate(FIELDS)]
    return ty.sensor_msgs__PointCloud2(
        header=ros.header(ty, t, frame), height=1, width=n, fields=fields, is_bigendian=False,
        point_step=ROWS.itemsize, row_step=ROWS.itemsize * n,
        data=rows.view(np.uint8).ravel(), is_dense=True)


def body_points(kind: str) -> np.ndarray:
    """A robot's shape in its own frame: the box of its footprint and its body's band."""
    record = KIND_DEFAULTS[kind]
    length, width = record.footprint or (2 * record.radius, 2 * record.radius)
    below, above = record.band
    return face_points(np.array([-length / 2, -width / 2, below]),
                       np.array([length / 2, width / 2, above]), BODY_SPACING)


def bodies(ty: ros.Types, sim: Simulation) -> Iterator[ros.Stamped]:
    """Each robot's body at each of its poses, in its ``ROBOT/base_link`` (one cloud a robot,
    restamped: the messages share their points)."""
    colours = robot_colors(list(sim.robots))
    for rid, robot in sim.robots.items():
        points = body_points(robot.kind)
        frame = f"{rid}/base_link"
        body = cloud(ty, 0.0, frame, points,
                     np.full(len(points), packed(colours[rid]), dtype=np.uint32))
        for t in robot.trail_t:
            yield (float(t), f"/{rid}/body", "sensor_msgs/msg/PointCloud2",
                   replace(body, header=ros.header(ty, float(t), frame)))


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
