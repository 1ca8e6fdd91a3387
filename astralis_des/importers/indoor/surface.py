"""A mesh's surfaces as a point cloud, so that a modelled building (OBJ, glTF, ...) can be
read by :func:`astralis_des.importers.indoor.find_interior` like a scanned one.

Points are spread evenly over the triangles' area: each triangle gets its area over
``spacing``² points, the fraction rounded up or down at random (so a mesh of many small
triangles keeps its density), each point uniform on its triangle. Every face is sampled,
those a scan could not see too (inside walls, under furniture, a wall's outer side): a mesh
does not say which faces are hidden, and :mod:`.plan` reads walls, floors and ceilings as
they come.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from astralis_des.world.geometry import FloatArray

CHUNK = 1_000_000  # points drawn at a time: memory stays a few times the cloud's


def surface_points(vertices: FloatArray, faces: NDArray[np.integer], spacing: float,
                   seed: int = 0) -> FloatArray:
    """``(N, 3)`` points on the triangles ``faces`` (``(F, 3)`` indices into the ``(V, 3)``
    ``vertices``), about one per ``spacing``² of surface, drawn with ``seed``."""
    if spacing <= 0:
        raise ValueError(f"spacing must be positive, not {spacing}")
    v = np.asarray(vertices, dtype=float).reshape(-1, 3)
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    if not len(f):
        return np.zeros((0, 3))
    tri = v[f]  # (F, 3, 3)
    a, b = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    area = 0.5 * np.linalg.norm(np.cross(a, b), axis=1)
    rng = np.random.default_rng(seed)
    counts = np.floor(area / spacing**2 + rng.random(len(f))).astype(np.int64)
    which = np.repeat(np.arange(len(f)), counts)
    out = np.empty((len(which), 3))
    for start in range(0, len(which), CHUNK):
        k = which[start:start + CHUNK]
        u, w = rng.random(len(k)), rng.random(len(k))
        flip = u + w > 1.0  # folded back into the triangle: uniform over its area
        u, w = np.where(flip, 1.0 - u, u), np.where(flip, 1.0 - w, w)
        out[start:start + len(k)] = tri[k, 0] + u[:, None] * a[k] + w[:, None] * b[k]
    return out
