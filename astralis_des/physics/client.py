"""One PyBullet client per simulation, holding the world's static geometry."""

from __future__ import annotations

import contextlib
import time
from typing import Any

import numpy as np
import pybullet as pb
import pybullet_data
from numpy.typing import NDArray

from astralis_des.physics.planar import BoxIndex, crossings, cut
from astralis_des.physics.quiet import quiet_c_output
from astralis_des.world.geometry import FloatArray
from astralis_des.world.model import BLOCK, World

__all__ = ["GRAVITY", "PhysicsClient", "quiet_c_output"]

GRAVITY = 9.81
READS = ("get", "compute", "ray")  # what ``call`` may ask without moving any body
COMPOUND = 16  # shapes PyBullet keeps in one compound (MAX_COMPOUND_COLLISION_SHAPES)
MESH_BOXES = 1000  # boxes in one mesh body: 8,000 vertices, under what one call may pass


class PhysicsClient:
    """A DIRECT-mode PyBullet client with the world's walls, slabs and obstacles in it.

    The static geometry is compound bodies of boxes (simple shapes, few broadphase entries);
    the ground is a plane. ``step`` counts the wall time spent inside ``stepSimulation``.

    A body's base pose and velocity (``base_pose``, ``base_velocity``) are read from PyBullet
    once between two changes of the state (a step, or a ``call`` that is not a read): the
    controllers, the checks and the sensors of one tick ask for the same numbers, and each
    read costs PyBullet a request of the body's whole state. Whatever sets a body's pose or
    velocity does it through ``call`` (or ``place``), not through ``pybullet`` itself, so
    that the next read sees it.
    """

    def __init__(self, world: World, dt: float, substeps: int, solver_iterations: int) -> None:
        with quiet_c_output():  # PyBullet prints its build time on connecting
            self.id = pb.connect(pb.DIRECT)
        self.dt = dt
        self.substeps = substeps
        self.step_time = 0.0  # seconds of wall time inside stepSimulation
        self.steps = 0  # physics steps of dt taken
        self.changes = 0  # the state's changes so far (steps, calls that set something)
        self._read_at = 0  # the change the reads kept were made after
        self._poses: dict[int, tuple[Any, Any]] = {}
        self._velocities: dict[int, tuple[Any, Any]] = {}
        self.call("setAdditionalSearchPath", pybullet_data.getDataPath())
        self.call("setGravity", 0.0, 0.0, -GRAVITY)
        self.call("setPhysicsEngineParameter", fixedTimeStep=dt * substeps,
                  numSubSteps=substeps, numSolverIterations=solver_iterations,
                  deterministicOverlappingPairs=1)
        plane = self.call("createCollisionShape", pb.GEOM_PLANE)
        self.ground = self.call("createMultiBody", 0, plane)
        self.boxes = BoxIndex()  # every box of ``add_boxes``, for the lidar's planar rays
        self.static = self._add_static(world)

    def call(self, name: str, *args: Any, **kwargs: Any) -> Any:
        """``pybullet.<name>(*args, **kwargs)`` on this client."""
        if not name.startswith(READS):
            self.changes += 1
        return getattr(pb, name)(*args, physicsClientId=self.id, **kwargs)

    def base_pose(self, body: int) -> tuple[Any, Any]:
        """``getBasePositionAndOrientation``: position (x, y, z) and quaternion, as PyBullet
        gives them, read once since the state last changed."""
        if self._read_at != self.changes:
            self._forget()
        pose = self._poses.get(body)
        if pose is None:
            pose = self._poses[body] = pb.getBasePositionAndOrientation(
                body, physicsClientId=self.id)
        return pose

    def base_velocity(self, body: int) -> tuple[Any, Any]:
        """``getBaseVelocity``: linear and angular velocity in the world frame, read once
        since the state last changed."""
        if self._read_at != self.changes:
            self._forget()
        velocity = self._velocities.get(body)
        if velocity is None:
            velocity = self._velocities[body] = pb.getBaseVelocity(body, physicsClientId=self.id)
        return velocity

    def _forget(self) -> None:
        self._poses.clear()
        self._velocities.clear()
        self._read_at = self.changes

    def place(self, body: int, position: Any, orientation: Any) -> None:
        """``resetBasePositionAndOrientation`` without ``call``'s look-up (a walker is placed
        every control period)."""
        self.changes += 1
        pb.resetBasePositionAndOrientation(body, position, orientation, physicsClientId=self.id)

    def _add_static(self, world: World) -> list[int]:
        """Walls, slabs and obstacles; not what lies wholly below the ground plane (the ground
        floors' slabs): the plane is that floor already, and a wheel on a plane costs half what
        it costs on a box. An imported world's geometry as its ``collision`` says: its blocks
        as static triangle meshes (thousands of box bodies would cost every step), or its
        mesh, concave or in convex parts."""
        above = [s for s in world.solids if s.box.hi[2] > 1e-6 and s.kind != BLOCK]
        bodies = self.add_boxes([s.box.lo for s in above], [s.box.hi for s in above])
        imported = world.imported
        if imported is None:
            return bodies
        if imported.collision == "boxes":
            blocks = world.block_array
            return bodies + self.add_box_meshes(blocks[:, 0], blocks[:, 1])
        mesh_file = imported.parts_file if imported.collision == "convex" else imported.mesh_file
        flags = pb.GEOM_FORCE_CONCAVE_TRIMESH if imported.collision == "concave" else 0
        shape = self.call("createCollisionShape", pb.GEOM_MESH, fileName=str(mesh_file),
                          flags=flags)
        return [*bodies, int(self.call("createMultiBody", 0, shape))]

    def add_box_meshes(self, los: Any, his: Any) -> list[int]:
        """Static triangle-mesh bodies of axis-aligned boxes, ``MESH_BOXES`` a body (what
        PyBullet takes in one call from memory)."""
        from astralis_des.world.freespace import boxes_to_mesh
        from astralis_des.world.geometry import Box

        lo, hi = np.asarray(los, dtype=float), np.asarray(his, dtype=float)
        bodies = []
        for start in range(0, len(lo), MESH_BOXES):
            boxes = [Box(tuple(a), tuple(b)) for a, b in zip(lo[start:start + MESH_BOXES].tolist(),
                                                             hi[start:start + MESH_BOXES].tolist(),
                                                             strict=True)]
            vertices, faces = boxes_to_mesh(boxes)
            shape = self.call("createCollisionShape", pb.GEOM_MESH, vertices=vertices.tolist(),
                              indices=faces.ravel().tolist(),
                              flags=pb.GEOM_FORCE_CONCAVE_TRIMESH)
            bodies.append(int(self.call("createMultiBody", 0, shape)))
        return bodies

    def add_boxes(self, los: Any, his: Any) -> list[int]:
        """Static compound bodies of axis-aligned boxes given by their corners.

        PyBullet keeps at most 16 shapes of one ``createCollisionShapeArray`` call and drops
        the rest without a word, so the boxes go in compounds of ``COMPOUND`` at most. They
        are in ``boxes`` too, for the lidar.
        """
        lo, hi = np.asarray(los, dtype=float), np.asarray(his, dtype=float)
        bodies = []
        for start in range(0, len(lo), COMPOUND):
            a, b = lo[start:start + COMPOUND], hi[start:start + COMPOUND]
            shape = self.call("createCollisionShapeArray", [pb.GEOM_BOX] * len(a),
                              halfExtents=((b - a) / 2).tolist(),
                              collisionFramePositions=((b + a) / 2).tolist())
            body = int(self.call("createMultiBody", 0, shape))
            self.boxes.add(a, b, body)
            bodies.append(body)
        return bodies

    def add_box(self, centre: Any, size: Any) -> int:
        """A box body without mass: static, or moved kinematically by resetting its pose."""
        shape = self.call("createCollisionShape", pb.GEOM_BOX,
                          halfExtents=[float(v) / 2 for v in size])
        return int(self.call("createMultiBody", 0, shape,
                             basePosition=[float(v) for v in centre]))

    def step(self, calls: int = 1) -> None:
        """Advance ``calls`` x ``substeps`` physics steps of ``dt``."""
        self.changes += 1
        t0 = time.perf_counter()
        for _ in range(calls):
            pb.stepSimulation(physicsClientId=self.id)
        self.step_time += time.perf_counter() - t0
        self.steps += calls * self.substeps

    def set_substeps(self, substeps: int) -> None:
        if substeps != self.substeps:
            self.substeps = substeps
            self.call("setPhysicsEngineParameter", fixedTimeStep=self.dt * substeps,
                      numSubSteps=substeps)

    def close(self) -> None:
        with contextlib.suppress(pb.error):
            pb.disconnect(physicsClientId=self.id)


def beams_near_bodies(client: PhysicsClient, centre: FloatArray, directions: FloatArray,
                      start: float, stop: FloatArray) -> NDArray[np.intp]:
    """The rays (from ``start`` to each one's ``stop``) that cross the bounding box of a body
    part that is not a static box: the only ones Bullet need follow. The broadphase names the
    parts near the centre; the ground plane counts only for rays at or below it."""
    reach = float(stop.max(initial=0.0))
    x, y, z = (float(v) for v in centre)
    near = client.call("getOverlappingObjects", [x - reach, y - reach, z - 1e-3],
                       [x + reach, y + reach, z + 1e-3]) or ()
    parts = [(b, link) for b, link in near
             if b not in client.boxes.bodies and (b != client.ground or z <= 0.0)]
    if not parts:
        return np.empty(0, dtype=np.intp)
    boxes = np.array([client.call("getAABB", b, link) for b, link in parts])
    near_boxes = cut(boxes[:, 0], boxes[:, 1], centre, reach)
    if len(near_boxes) == 0:
        return np.empty(0, dtype=np.intp)
    enter = crossings(boxes[near_boxes, 0], boxes[near_boxes, 1], centre, directions, start,
                      stop, inside=True)
    return np.flatnonzero(np.isfinite(enter).any(axis=0))
