"""A spinning multi-channel lidar (a 16-channel unit by default), with the 2-D lidar's hit
model in three dimensions.

Its beams fan out over ``channels`` elevations and a full turn of azimuths, levelled and
turned with the body's heading. The static boxes (walls, slabs, obstacles, furniture: the
client's ``boxes``) are met by an exact slab test in numpy, each box only along the beams of
its angular window (the azimuths and elevations its corners span from the sensor); the
ground plane analytically; Bullet's ``rayTestBatch`` follows only the beams that cross the
bounding box of another body (robots, avatars, the target, imported meshes), as far as
their first static hit. Each return carries the unique id of the body hit (its
segmentation id); a beam without one is ``inf`` and -1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from astralis_des.physics.client import PhysicsClient
from astralis_des.physics.planar import TINY, inverse
from astralis_des.physics.sensors import NO_BODY, _body_pose, _need_rng
from astralis_des.world.geometry import FloatArray

IntArray = NDArray[np.int32]
SLACK = 1e-9  # rad: the angular windows are widened by this


@dataclass
class Scan3D:
    """One sweep: ``(channels, azimuths)`` ranges (``inf``: no return), points and ids."""

    ranges: FloatArray
    points: FloatArray  # (channels, azimuths, 3) world points; nan without a return
    hit_ids: IntArray
    time: float = 0.0


class Lidar3D:
    def __init__(self, client: PhysicsClient, body: int, *, channels: int = 16,
                 vertical_fov: tuple[float, float] = (-15.0, 15.0), resolution: float = 0.2,
                 range_max: float = 100.0, range_min: float = 0.1, noise_std: float = 0.01,
                 rng: np.random.Generator | None = None, start_offset: float = 0.5,
                 mount: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> None:
        _need_rng(noise_std, rng, "Lidar3D")
        self.client, self.body, self.rng = client, body, rng
        self.range_max, self.range_min, self.noise_std = range_max, range_min, noise_std
        self.start = start_offset
        self.mount = np.asarray(mount, dtype=float)
        low, high = vertical_fov
        self.elevations = np.radians(np.linspace(low, high, channels)) if channels > 1 \
            else np.radians([0.5 * (low + high)])
        self.step = math.radians(resolution)
        self.azimuths = np.arange(round(360.0 / resolution)) * self.step  # from the heading

    def pose(self) -> tuple[FloatArray, float]:
        """The sensor's centre and the body's heading (the beams' zero azimuth)."""
        position, m = _body_pose(self.client, self.body)
        return position + m @ self.mount, math.atan2(m[1, 0], m[0, 0])

    def directions(self, heading: float) -> FloatArray:
        a = self.azimuths + heading
        e = self.elevations[:, None]
        return np.stack([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a),
                         np.broadcast_to(np.sin(e), (len(self.elevations), len(a)))], axis=-1)

    def scan(self, time: float = 0.0) -> Scan3D:
        centre, heading = self.pose()
        dirs = self.directions(heading)
        boxes = self.client.boxes
        t, which = cast_boxes(centre, dirs, heading, self.elevations, self.step, boxes.lo,
                              boxes.hi, self.start, self.range_max)
        ids = np.where(which >= 0, boxes.body[np.maximum(which, 0)], NO_BODY).astype(np.int32)
        down = dirs[..., 2] < -TINY
        ground = np.where(down, -centre[2] / np.where(down, dirs[..., 2], -1.0), np.inf)
        closer = (ground >= self.start) & (ground < t) & (centre[2] > 0.0)
        t, ids = np.where(closer, ground, t), np.where(closer, self.client.ground, ids)
        self._bodies(centre, dirs, heading, t, ids)
        ranges = t.copy()
        if self.noise_std > 0 and self.rng is not None:  # drawn for every beam
            ranges = ranges + self.rng.normal(0.0, self.noise_std, ranges.shape)
        missed = ~np.isfinite(t) | (ranges < self.range_min) | (t > self.range_max)
        ranges[missed], ids[missed] = np.inf, NO_BODY
        points = centre + np.where(missed, np.nan, ranges)[..., None] * dirs
        return Scan3D(ranges, points, ids.astype(np.int32), time)

    def _bodies(self, centre: FloatArray, dirs: FloatArray, heading: float, t: FloatArray,
                ids: NDArray[Any]) -> None:
        """Bullet along the beams that cross another body's bounding box, to their first
        static hit (or the range): a nearer body's hit replaces it."""
        client, reach = self.client, self.range_max
        near = client.call("getOverlappingObjects", (centre - reach).tolist(),
                           (centre + reach).tolist()) or ()
        parts = sorted({(b, link) for b, link in near
                        if b not in client.boxes.bodies and b != client.ground
                        and b != self.body})
        if not parts:
            return
        aabbs = np.array([client.call("getAABB", b, link) for b, link in parts])
        stop = np.minimum(t, reach)
        crossed, _ = cast_boxes(centre, dirs, heading, self.elevations, self.step,
                                aabbs[:, 0], aabbs[:, 1], 0.0, reach, inside=True)
        rows = np.flatnonzero((crossed < stop).ravel())
        if not len(rows):
            return
        flat = dirs.reshape(-1, 3)[rows]
        far = stop.ravel()[rows]
        hits = client.call("rayTestBatch", (centre + self.start * flat).tolist(),
                           (centre + far[:, None] * flat).tolist())
        found = np.array([h[0] for h in hits], dtype=np.int64)
        at = self.start + np.array([h[2] for h in hits]) * (far - self.start)
        hit = (found >= 0) & (at < far)
        t.ravel()[rows[hit]] = at[hit]
        ids.ravel()[rows[hit]] = found[hit]


def cast_boxes(centre: FloatArray, dirs: FloatArray, heading: float, elevations: FloatArray,
               step: float, lo: FloatArray, hi: FloatArray, start: float, stop: float,
               inside: bool = False) -> tuple[FloatArray, NDArray[np.intp]]:
    """The nearest box along each beam (``dirs``: ``(channels, azimuths, 3)``, azimuth ``j``
    at ``heading + j * step``) entered between ``start`` and ``stop``: its distance and
    index (``inf``, -1: none). A beam starting inside a box misses it, unless ``inside``
    (then it enters at ``start``). Each box is tested only along the beams of the window of
    azimuths and elevations its corners span from ``centre`` (all azimuths from inside its
    footprint), the boxes' windows together, :data:`PAIRS` beams at a time; ties go to the
    lower index."""
    n_ch, n_az = dirs.shape[:2]
    best = np.full(n_ch * n_az, np.inf)
    which = np.full(n_ch * n_az, -1, dtype=np.intp)
    if len(lo):
        rel_lo, rel_hi = lo - centre, hi - centre
        gap = np.maximum(np.maximum(rel_lo, -rel_hi), 0.0)
        near = np.flatnonzero(np.einsum("ij,ij->i", gap, gap) <= stop * stop)
        box, channel, first, count = _windows(rel_lo[near], rel_hi[near], gap[near], heading,
                                              elevations, step, n_az)
        inv = inverse(dirs.reshape(-1, 3).T)  # per axis
        ends = np.cumsum(count)
        cuts = np.searchsorted(ends, np.arange(PAIRS, ends[-1] if len(ends) else 0, PAIRS),
                               side="right")
        for a, b in zip([0, *cuts.tolist()], [*cuts.tolist(), len(box)], strict=True):
            if b > a:  # the (box, channel) pairs a to b, by box then channel
                window = _Window(near[box[a:b]], channel[a:b], first[a:b], count[a:b])
                _nearest(best, which, window, inv, rel_lo, rel_hi, n_az,
                         (start, stop, inside))
    return best.reshape(n_ch, n_az), which.reshape(n_ch, n_az)


PAIRS = 1 << 18  # beam-box pairs tested at once (a few MB of arrays), the rest after them


@dataclass
class _Window:
    """Boxes' windows of beams: for each ``(box, channel)`` pair, ``count`` azimuths from
    ``first`` on (modulo a turn)."""

    box: NDArray[np.intp]
    channel: NDArray[np.intp]
    first: NDArray[np.intp]
    count: NDArray[np.intp]


def _nearest(best: FloatArray, which: NDArray[np.intp], window: _Window, inv: FloatArray,
             rel_lo: FloatArray, rel_hi: FloatArray, n_az: int,
             span: tuple[float, float, bool]) -> None:
    """Each beam's nearest entry into a box of ``window`` and that box (the lowest of equals)
    into ``best`` and ``which`` (flat, a beam a row), where nearer than what they hold: the
    windows come in boxes' order, so an equal entry keeps the lower box."""
    start, stop, inside = span
    pair = np.repeat(np.arange(len(window.box)), window.count)
    local = np.arange(len(pair)) - np.repeat(np.cumsum(window.count) - window.count,
                                             window.count)
    beam = window.channel[pair] * n_az + (window.first[pair] + local) % n_az
    boxes = window.box[pair]
    enter = np.full(len(beam), -np.inf)
    leave = np.full(len(beam), np.inf)
    for axis in range(3):  # the slab test, an axis at a time
        d = inv[axis][beam]
        t1, t2 = rel_lo[boxes, axis] * d, rel_hi[boxes, axis] * d
        np.maximum(enter, np.minimum(t1, t2), out=enter)
        np.minimum(leave, np.maximum(t1, t2), out=leave)
    if inside:
        enter = np.maximum(enter, start)
    ok = np.flatnonzero((enter <= leave) & (enter >= start) & (enter <= stop))
    nearest = np.full(len(best), np.inf)
    np.minimum.at(nearest, beam[ok], enter[ok])
    won = ok[enter[ok] == nearest[beam[ok]]]  # the nearest entries; ties: the lowest index
    lowest = np.full(len(best), np.iinfo(np.intp).max, dtype=np.intp)
    np.minimum.at(lowest, beam[won], boxes[won])
    nearer = np.flatnonzero(nearest < best)
    best[nearer] = nearest[nearer]
    which[nearer] = lowest[nearer]


def _windows(rel_lo: FloatArray, rel_hi: FloatArray, gap: FloatArray, heading: float,
             elevations: FloatArray, step: float, n_az: int
             ) -> tuple[NDArray[np.intp], NDArray[np.intp], NDArray[np.intp], NDArray[np.intp]]:
    """The beams each box may meet, as ``(box, channel)`` pairs (by box, then channel) and
    each pair's azimuths: ``count`` of them from ``first`` on (modulo a turn). A box spans
    the elevations from its bottom (nearest if below the sensor, else farthest) to its top,
    and the azimuths its corners span (all from inside its footprint); both windows are
    widened by ``SLACK``, beyond any rounding of the angles, so no beam that meets the box is
    left out (and a beam let in that does not is missed by the slab test)."""
    a0, a1, b0, b1 = rel_lo[:, 0], rel_hi[:, 0], rel_lo[:, 1], rel_hi[:, 1]
    r_min = np.hypot(gap[:, 0], gap[:, 1])
    corners_x = np.stack([a0, a0, a1, a1], axis=1)
    corners_y = np.stack([b0, b1, b0, b1], axis=1)
    r_max = np.hypot(corners_x, corners_y).max(axis=1)
    z0, z1 = rel_lo[:, 2], rel_hi[:, 2]
    near_r = np.maximum(r_min, 1e-12)
    e_lo = np.arctan2(z0, np.where(z0 < 0, near_r, r_max)) - SLACK
    e_hi = np.arctan2(z1, np.where(z1 > 0, near_r, r_max)) + SLACK
    box, channel = np.nonzero((elevations >= e_lo[:, None]) & (elevations <= e_hi[:, None]))
    mid = np.arctan2(0.5 * (b0 + b1), 0.5 * (a0 + a1))
    offs = np.arctan2(corners_y, corners_x) - mid[:, None]
    offs -= math.tau * np.round(offs / math.tau)  # within half a turn of the middle
    first = np.floor((mid + offs.min(axis=1) - SLACK - heading) / step).astype(np.intp)
    last = np.ceil((mid + offs.max(axis=1) + SLACK - heading) / step).astype(np.intp)
    around = r_min == 0.0  # over or under its footprint: every azimuth
    first = np.where(around, 0, first)
    count = np.where(around, n_az, last - first + 1)
    return box, channel, first[box], count[box]
