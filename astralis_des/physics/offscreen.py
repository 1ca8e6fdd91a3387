"""Bodies a camera cannot see are left out of its render.

TinyRenderer transforms every triangle of every visual shape for each frame, seen or not: a
Husky's meshes cost about 10 ms a frame wherever it stands. A robot whose bounding sphere
lies wholly outside a frame's view frustum adds no pixel to it, so it is painted fully
transparent (which TinyRenderer skips) for that frame and painted back after: the frame is
the same, pixel for pixel, and costs what the bodies in view cost.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from astralis_des.kernel.perceived import Intrinsics
from astralis_des.physics.client import PhysicsClient
from astralis_des.world.geometry import FloatArray

MARGIN = 0.05  # m added to each sphere: a body this near the frustum's edge is rendered
CLEAR = (0.0, 0.0, 0.0, 0.0)


@dataclass
class Shape:
    """A body's visual shapes and colours, and the sphere about its base that holds them."""

    body: int
    visuals: list[tuple[int, int, list[float]]]  # (link, shape index, colour)
    radius: float


class Offscreen:
    """The robots' bodies, each hidden from the frames it cannot show in."""

    def __init__(self, client: PhysicsClient, bodies: list[int]) -> None:
        """``bodies``: read now, at rest and in their own colours (a camera hiding its own
        body reads its colours the same way)."""
        self.client = client
        self.shapes = [self._shape(body) for body in bodies]

    def _shape(self, body: int) -> Shape:
        per_link: dict[int, int] = {}
        visuals = []
        for shape in self.client.call("getVisualShapeData", body):
            index = per_link[shape[1]] = per_link.get(shape[1], -1) + 1
            visuals.append((shape[1], index, list(shape[7])))
        base = np.asarray(self.client.call("getBasePositionAndOrientation", body)[0])
        links = range(-1, self.client.call("getNumJoints", body))
        corners = np.array([self.client.call("getAABB", body, link) for link in links])
        reach = np.abs(corners - base).max(axis=1)  # (links, 3): the far corner of each box
        return Shape(body, visuals, float(np.linalg.norm(reach, axis=1).max()) + MARGIN)

    @contextmanager
    def hidden(self, eye: FloatArray, rotation: FloatArray, intrinsics: Intrinsics,
               skip: int) -> Iterator[None]:
        """While rendering from ``eye`` (``rotation``: world from camera, z forward), the
        bodies (but ``skip``, the camera's own) wholly outside the view, painted out."""
        out = [shape for shape in self.shapes
               if shape.body != skip and not self._may_show(shape, eye, rotation, intrinsics)]
        self._paint(out, hide=True)
        try:
            yield
        finally:
            self._paint(out, hide=False)

    def _may_show(self, shape: Shape, eye: FloatArray, rotation: FloatArray,
                  k: Intrinsics) -> bool:
        """Does the body's sphere reach into the frustum (near to far, the image's angles)?"""
        centre = np.asarray(self.client.base_pose(shape.body)[0])
        x, y, z = (float(v) for v in rotation.T @ (centre - eye))
        r = shape.radius
        if z < k.near - r or z > k.far + r:
            return False
        tan_y = math.tan(math.radians(k.fov_deg) / 2)
        tan_x = tan_y * k.width / k.height
        # the distance from the centre to each side plane through the eye, outward positive
        for tan, across in ((tan_x, x), (tan_y, y)):
            if (abs(across) - tan * z) / math.hypot(1.0, tan) > r:
                return False
        return True

    def _paint(self, shapes: list[Shape], hide: bool) -> None:
        for shape in shapes:
            for link, index, rgba in shape.visuals:
                self.client.call("changeVisualShape", shape.body, link, shapeIndex=index,
                                 rgbaColor=CLEAR if hide else rgba)
