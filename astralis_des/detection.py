"""The detection model both fidelities share: how many pixels of the target a camera shows.

A detector (a person detector on the camera's frames) needs the target to cover at least
``min_pixels`` of the frame, within the camera's ``range`` when one is set. The physics
fidelity counts those pixels in the rendered segmentation; the kinematic fidelity predicts
them here, from the same camera (intrinsics, pose) and the same target box:

- the box's **image area**, unoccluded: each face that turns to the camera is sampled on a
  ``SAMPLES`` x ``SAMPLES`` grid, and each sample stands for its share of the face's area seen
  along the ray, which covers ``f^2 r / z^3`` pixels per square metre (``f`` the focal length
  in pixels, ``r`` the distance and ``z`` the depth along the optical axis);
- its **visible share**: only samples inside the image, within range and with a clear line of
  sight (walls, slabs, furniture, other avatars) count.

The prediction is the sum over the samples that count, so a target half behind a table
shows about half its pixels, one at the frame's edge the part inside it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from astralis_des.kinds import TARGET_SIZE
from astralis_des.view import Axes, View
from astralis_des.world.geometry import FloatArray

SAMPLES = 5  # per side of each face, where something may hide part of the target (a strip
# showing over a cabinet must meet a sample: 3 a side left a top sixth unsampled)
COARSE = 3  # per side, for the unhidden bound (an area sum: accurate at 3 already)
NEAR = 0.05  # m: the renderer's near plane
SWATH_ROWS = 8  # offsets across the track judged at a time by swath
Sight = Callable[[FloatArray, FloatArray], np.ndarray]  # (eyes, points) -> clear


@dataclass(frozen=True)
class Sighting:
    """A detection: when (seconds after the motion's start), from where, of what, how well."""

    t: float  # seconds after the motion's start
    robot_position: tuple[float, float, float]
    target_position: tuple[float, float, float]
    distance: float
    estimate: tuple[float, float, float]  # where the sensor put the target
    error: float  # m between the estimate and the target
    pixels: int | None = None  # target pixels in the frame (physics)


def _face_grid(n: int) -> FloatArray:
    """Sample offsets on a box's faces in units of its half size, ``(3, n*n, 3)``: the faces
    normal to x, y and z (the side of each is set per look)."""
    ticks = (np.arange(n) + 0.5) / n * 2 - 1
    a, b = np.meshgrid(ticks, ticks, indexing="ij")
    grids = np.zeros((3, n * n, 3))
    for axis in range(3):
        others = [k for k in range(3) if k != axis]
        grids[axis, :, others[0]], grids[axis, :, others[1]] = a.ravel(), b.ravel()
        grids[axis, :, axis] = 1.0
    return grids


GRIDS = {n: _face_grid(n) for n in (SAMPLES, COARSE)}


def face_areas(half: FloatArray) -> FloatArray:
    """The areas of a box's faces normal to x, y and z, from its half sizes."""
    return 4 * np.array([half[1] * half[2], half[0] * half[2], half[0] * half[1]])


def target_samples(eyes: FloatArray, centres: FloatArray, size: FloatArray,
                   samples: int = SAMPLES) -> tuple[FloatArray, FloatArray]:
    """Sample points on the faces of each target box that turn to its eye, ``(M, K, 3)``, and
    each sample's area seen along the ray from the eye, ``(M, K)`` square metres;
    ``samples`` a side of each face."""
    half = np.asarray(size, dtype=float) / 2
    d = centres - eyes
    toward = -np.sign(d)  # the face of each axis that looks back at the eye
    toward[toward == 0] = 1.0
    k = samples * samples
    offsets = GRIDS[samples][None, :, :, :] * half  # (1, 3, k, 3)
    offsets = np.where(np.eye(3, dtype=bool)[None, :, None, :],
                       offsets * toward[:, None, None, :], offsets)
    points = centres[:, None, None, :] + offsets  # (M, 3, k, 3)
    face_area = face_areas(half) / k
    rays = points - eyes[:, None, None, :]
    r = np.linalg.norm(rays, axis=3)
    along_normal = np.stack([rays[:, a, :, a] for a in range(3)], axis=1)
    cos = np.abs(along_normal) / np.maximum(r, 1e-9)
    # a face seen edge-on, or from behind its own box (the eye inside the slab), shows nothing
    facing = (np.abs(d) > half)[:, :, None]
    area = np.where(facing, face_area[None, :, None] * cos, 0.0)
    return points.reshape(len(eyes), 3 * k, 3), area.reshape(len(eyes), 3 * k)


def predict_pixels(view: View, eyes: FloatArray, headings: FloatArray, centres: FloatArray,
                   size: FloatArray, sight: Sight | None, axes: Axes | None = None) -> FloatArray:
    """The target's pixels in the frame of each camera (``eyes[m]`` facing ``headings[m]``,
    the target's box at ``centres[m]``): unoccluded when ``sight`` is None (sampled
    ``COARSE``), else counting only the samples it calls clear (sampled ``SAMPLES``)."""
    eyes = np.atleast_2d(np.asarray(eyes, dtype=float))
    centres = np.atleast_2d(np.asarray(centres, dtype=float))
    if len(eyes) == 0:
        return np.zeros(0)
    points, area = target_samples(eyes, centres, size, COARSE if sight is None else SAMPLES)
    right, down, forward = (view.axes(np.asarray(headings, dtype=float)) if axes is None
                            else axes)
    rays = points - eyes[:, None, :]
    x = np.einsum("mkj,mj->mk", rays, right)
    y = np.einsum("mkj,mj->mk", rays, down)
    z = np.einsum("mkj,mj->mk", rays, forward)
    inside = (z > NEAR) & (np.abs(x) <= z * view.tan_h) & (np.abs(y) <= z * view.tan_v)
    if view.range is not None:
        inside &= z <= view.range
    inside &= area > 0
    zc = np.maximum(z, NEAR)
    r = np.linalg.norm(rays, axis=2)
    pixels_each = area * view.focal**2 * r / zc**3
    if sight is not None and inside.any():
        m, kk = np.nonzero(inside)
        clear = sight(eyes[m], points[m, kk])
        inside[m[~clear], kk[~clear]] = False
    out: FloatArray = np.minimum((pixels_each * inside).sum(axis=1),
                                 float(view.pixels[0] * view.pixels[1]))
    return out


def swath(view: View, drop: float) -> float:
    """Width across the direction of travel within which a target whose centre is ``drop``
    metres below the camera shows enough pixels to be detected at some point of a straight
    pass (to 1 cm): moving ahead, the camera searches a strip this wide."""
    return _swath(view, round(drop, 3))


@lru_cache(maxsize=64)
def _swath(view: View, drop: float) -> float:
    reach = min(view.reach, 4.0 * max(drop, 0.5))
    xs = np.arange(-reach, reach + 1e-9, 0.05)  # along the track

    def widest(ys: FloatArray) -> float | None:
        """The largest offset across the track in ``ys`` at which the target is detected:
        rows of ``ys`` judged a block at a time from the widest (each on its own, so the
        first block with a detection holds the answer)."""
        for stop in range(len(ys), 0, -SWATH_ROWS):
            found = widest_of(ys[max(stop - SWATH_ROWS, 0):stop])
            if found is not None:
                return found
        return None

    def widest_of(ys: FloatArray) -> float | None:
        gx, gy = np.meshgrid(xs, ys, indexing="ij")
        centres = np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, -drop)])
        eye, size = np.zeros((1, 3)), np.asarray(TARGET_SIZE, dtype=float)
        (_, sure), (_, maybe) = cull(view, eye, view.axes(np.zeros(1)), centres, size,
                                     reach=False)  # most of the grid is surely in or out
        shown = np.zeros(len(centres), dtype=bool)
        shown[sure] = True
        shown[maybe] = predict_pixels(view, np.zeros((len(maybe), 3)), np.zeros(len(maybe)),
                                      centres[maybe], size, None) >= view.min_pixels
        seen = shown.reshape(gx.shape).any(axis=0)
        return float(ys[seen].max()) if seen.any() else None

    coarse = widest(np.arange(0.0, reach + 1e-9, 0.1))
    if coarse is None:
        return 0.0
    fine = widest(np.arange(coarse, coarse + 0.1, 0.01))
    return round(2 * (fine if fine is not None else coarse), 2)


PROBES = np.vstack([np.zeros(3), np.array(np.meshgrid([-0.5, 0.5], [-0.5, 0.5], [-0.5, 0.5]))
                    .reshape(3, -1).T])  # the centre and corners of a unit box


def shows_unhidden(view: View, eyes: FloatArray, axes: Axes, centres: FloatArray,
                   size: FloatArray, m: np.ndarray, n: np.ndarray) -> np.ndarray:
    """For each pair (camera ``eyes[m[p]]`` with ``axes`` rows ``m[p]``, target box at
    ``centres[n[p]]``): whether the centre or a corner of the box is in the frame and reach
    (``sensing.in_frame``) and the box would show ``min_pixels`` if nothing hid it
    (:func:`predict_pixels` with ``sight=None``). The same model, computed in the camera
    frame: each eye's axes turn the box's probe and sample offsets once, and a pair adds them
    to its centre's camera coordinates, instead of building every sample in the world."""
    right, down, forward = (np.asarray(a, dtype=float) for a in axes)
    d = centres[n] - eyes[m]  # (P, 3)
    frame = np.stack([right, down, forward])  # (3, M, 3): camera axis, eye, world axis
    centre = np.einsum("pj,cpj->cp", d, frame[:, m])  # (3, P): x, y, z of the centre
    size = np.asarray(size, dtype=float)
    probes = centre[:, :, None] + (frame @ (PROBES * size).T)[:, m]  # (3, P, 9)
    x, y, z = probes
    near = x * x + y * y + z * z <= view.reach**2
    shown = (near & (z > 1e-6) & (np.abs(x) <= z * view.tan_h)
             & (np.abs(y) <= z * view.tan_v)).any(axis=1)
    half = size / 2
    grid = GRIDS[COARSE]  # (3 faces, k, 3): the sample offsets in half sizes, side +1
    k = grid.shape[1]
    toward = np.where(d[shown] > 0, -1.0, 1.0)  # (S, 3): the face of each axis facing the eye
    facing = np.abs(d[shown]) > half  # (S, 3)
    on_face = (frame @ (np.where(np.eye(3, dtype=bool)[:, None, :], 0.0, grid) * half)
               .reshape(-1, 3).T).reshape(3, -1, 3, k)  # (3, M, 3 faces, k): in-face offsets
    out_face = frame * half  # (3, M, 3): half a size along each world axis
    rows = m[shown]
    # (3, S, 3, k): gathered with take and summed in place (the same sums: fancy indexing of
    # a middle axis and the temporaries cost more than the arithmetic)
    s = np.take(on_face, rows, axis=1)
    s += np.compress(shown, centre, axis=1)[:, :, None, None]
    turned = np.take(out_face, rows, axis=1)
    turned *= toward[None, :, :]
    s += turned[:, :, :, None]
    x, y, z = s
    inside = (z > NEAR) & (np.abs(x) <= z * view.tan_h) & (np.abs(y) <= z * view.tan_v)
    if view.range is not None:
        inside &= z <= view.range
    height = np.where(facing, np.abs(d[shown]) - half, 0.0)  # the eye over each face's plane
    face_area = face_areas(half) / k
    each = (face_area * height)[:, :, None] * view.focal**2 / np.maximum(z, NEAR) ** 3
    pixels = np.minimum((each * inside * facing[:, :, None]).sum(axis=(1, 2)),
                        float(view.pixels[0] * view.pixels[1]))
    out = np.zeros(len(m), dtype=bool)
    out[np.flatnonzero(shown)] = pixels >= view.min_pixels
    return out


def cull(view: View, eyes: FloatArray, axes: Axes, centres: FloatArray, size: FloatArray,
         reach: bool = True) -> tuple[tuple[np.ndarray, ...], tuple[np.ndarray, ...]]:
    """The pairs (eye ``m``, target box at ``centres[n]``) sure to pass :func:`in_frame` and
    show ``min_pixels`` unhidden, and those that need the exact tests (as ``nonzero`` index
    pairs); the rest cannot pass them (nor show a pixel: unless ``reach``, the camera's
    reach is not tested). Box-frustum culling in the camera frame: a box whose
    eight corners are in the frame is wholly in it, one whose corners are all beyond one side
    of it has no probe in it; for a box wholly in the frame, each face turned to the eye shows
    at least its area times ``f^2 h / z^3`` pixels, ``h`` the eye's height over the face's
    plane and ``z`` the box's farthest depth. The margins keep rounding on the safe side: a
    pair the exact tests would judge differently is never decided here."""
    right, down, forward = axes
    half = np.asarray(size, dtype=float) / 2
    corners = PROBES[1:] * np.asarray(size, dtype=float)  # (8, 3) offsets from the centre

    def frame(axis: FloatArray) -> FloatArray:  # (M, N, 8): the corners' coordinate
        centre = axis @ centres.T - np.einsum("ij,ij->i", axis, eyes)[:, None]
        return centre[:, :, None] + (axis @ corners.T)[:, None, :]

    x, y, z = frame(right), frame(down), frame(forward)
    tol = 1e-6
    side_h, side_v = z * view.tan_h, z * view.tan_v
    culled = (_all_corners(z < -tol) | _all_corners(x > side_h + tol)
              | _all_corners(-x > side_h + tol) | _all_corners(y > side_v + tol)
              | _all_corners(-y > side_v + tol))
    d = centres[None, :, :] - eyes[:, None, :]
    inside = _all_corners((z > NEAR + tol) & (np.abs(x) < side_h - tol)
                          & (np.abs(y) < side_v - tol))
    if reach:
        far = np.einsum("mnj,mnj->mn", d, d)
        culled |= far > (view.reach + float(np.linalg.norm(half)) + tol) ** 2
        inside &= far < (view.reach - float(np.linalg.norm(half)) - tol) ** 2
    if view.range is not None:
        inside &= _all_corners(z < view.range - tol)
    sure = np.zeros_like(inside)
    if inside.any() and view.min_pixels <= view.pixels[0] * view.pixels[1]:
        m, n = np.nonzero(inside)
        over = np.maximum(np.abs(d[m, n]) - half, 0.0)  # the eye over each face's plane
        bound = view.focal**2 * (over @ face_areas(half)) / z[m, n].max(axis=1) ** 3
        ok = bound >= view.min_pixels * 1.001
        sure[m[ok], n[ok]] = True
    return np.nonzero(sure), np.nonzero(~culled & ~sure)


_EIGHT_TRUE = np.frombuffer(b"\x01" * 8, dtype=np.uint64)[0]


def _all_corners(held: np.ndarray) -> np.ndarray:
    """``held.all(axis=2)`` for ``(M, N, 8)`` booleans (a box's corners, fresh from a
    comparison, so contiguous): each row of 8 read as one 8-byte word, all true when every
    byte is 1 (numpy's reductions over a short last axis cost more than the comparisons)."""
    out: np.ndarray = held.view(np.uint64)[..., 0] == _EIGHT_TRUE
    return out
