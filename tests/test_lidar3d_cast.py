"""The 3-D lidar's slab test against static boxes (``cast_boxes``) takes every box's window
of beams at once. It answers as the test box by box did (kept here as the reference): the
same distance to the bit and the same box on every beam, ties to the lower index, from inside
boxes, over and under them, across the azimuths' wrap and with ``inside``."""

from __future__ import annotations

import math

import numpy as np
import pytest

from astralis_des.physics import lidar3d
from astralis_des.physics.lidar3d import SLACK, Lidar3D, cast_boxes
from astralis_des.physics.planar import TINY


def box_by_box(centre: np.ndarray, dirs: np.ndarray, heading: float, elevations: np.ndarray,
               step: float, lo: np.ndarray, hi: np.ndarray, start: float, stop: float,
               inside: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """The reference: each box along the beams of its window, one box after another."""
    n_ch, n_az = dirs.shape[:2]
    best = np.full((n_ch, n_az), np.inf)
    which = np.full((n_ch, n_az), -1, dtype=np.intp)
    rel_lo, rel_hi = lo - centre, hi - centre
    gap = np.maximum(np.maximum(rel_lo, -rel_hi), 0.0)
    near = np.flatnonzero(np.einsum("ij,ij->i", gap, gap) <= stop * stop)
    inv = 1.0 / np.where(np.abs(dirs) < TINY, np.copysign(TINY, dirs), dirs)
    for k in near.tolist():
        a0, a1, b0, b1 = rel_lo[k, 0], rel_hi[k, 0], rel_lo[k, 1], rel_hi[k, 1]
        r_min = math.hypot(gap[k, 0], gap[k, 1])
        r_max = max(math.hypot(x, y) for x in (a0, a1) for y in (b0, b1))
        z0, z1 = rel_lo[k, 2], rel_hi[k, 2]
        e_lo = math.atan2(z0, max(r_min, 1e-12) if z0 < 0 else r_max) - SLACK
        e_hi = math.atan2(z1, max(r_min, 1e-12) if z1 > 0 else r_max) + SLACK
        channels = np.flatnonzero((elevations >= e_lo) & (elevations <= e_hi))
        if not len(channels):
            continue
        if r_min == 0.0:
            cols = np.arange(n_az)
        else:
            mid = math.atan2(0.5 * (b0 + b1), 0.5 * (a0 + a1))
            offs = [math.remainder(math.atan2(y, x) - mid, math.tau)
                    for x in (a0, a1) for y in (b0, b1)]
            first = math.floor((mid + min(offs) - SLACK - heading) / step)
            last = math.ceil((mid + max(offs) + SLACK - heading) / step)
            cols = np.arange(first, last + 1) % n_az
        d = inv[channels[:, None], cols[None, :]]
        t1, t2 = rel_lo[k] * d, rel_hi[k] * d
        enter = np.minimum(t1, t2).max(axis=-1)
        leave = np.maximum(t1, t2).min(axis=-1)
        if inside:
            enter = np.maximum(enter, start)
        ok = (enter <= leave) & (enter >= start) & (enter <= stop)
        sub = best[channels[:, None], cols[None, :]]
        better = ok & (enter < sub)
        if better.any():
            ci, ai = np.nonzero(better)
            best[channels[ci], cols[ai]] = enter[ci, ai]
            which[channels[ci], cols[ai]] = k
    return best, which


def scene(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Boxes round the origin: walls, slabs over and under it, one holding it, and two
    the same (a tie)."""
    centres = rng.uniform(-12, 12, size=(60, 3)) * (1, 1, 0.3)
    sizes = rng.uniform(0.05, 4.0, size=(60, 3))
    lo, hi = centres - sizes / 2, centres + sizes / 2
    extra_lo = np.array([[-20, -20, 3.0], [-20, -20, -2.0], [-0.5, -0.5, -0.5], [4, -1, -1],
                         [4, -1, -1], [-6, -0.2, -1]])
    extra_hi = np.array([[20, 20, 3.2], [20, 20, -1.8], [0.5, 0.5, 0.5], [5, 1, 1],
                         [5, 1, 1], [-5, 0.2, 1]])  # the last straddles the azimuths' wrap
    return np.concatenate([lo, extra_lo]), np.concatenate([hi, extra_hi])


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("inside", [False, True])
@pytest.mark.parametrize("pairs", [lidar3d.PAIRS, 500])
def test_every_box_at_once_answers_as_box_by_box(seed: int, inside: bool, pairs: int,
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    """Also a few hundred beam-box pairs at a time (a box's windows split between them)."""
    monkeypatch.setattr(lidar3d, "PAIRS", pairs)
    rng = np.random.default_rng(seed)
    lidar = Lidar3D.__new__(Lidar3D)  # its beams alone: no client needed
    lidar.elevations = np.radians(np.linspace(-15.0, 15.0, 16))
    lidar.step = math.radians(0.4)
    lidar.azimuths = np.arange(900) * lidar.step
    lo, hi = scene(rng)
    for _ in range(5):
        centre = rng.uniform(-3, 3, size=3) * (1, 1, 0.2)
        heading = float(rng.uniform(-math.pi, math.pi))
        dirs = lidar.directions(heading)
        for start, stop in ((0.5, 100.0), (0.0, 6.0)):
            args = (centre, dirs, heading, lidar.elevations, lidar.step, lo, hi, start, stop)
            expected_t, expected_box = box_by_box(*args, inside=inside)
            t, box = cast_boxes(*args, inside=inside)
            np.testing.assert_array_equal(t, expected_t)
            np.testing.assert_array_equal(box, expected_box)
            assert np.isfinite(t).mean() > 0.1 and (box >= 0).any()


def test_ties_go_to_the_lower_index_and_no_boxes_is_no_return() -> None:
    lidar = Lidar3D.__new__(Lidar3D)
    lidar.elevations, lidar.step = np.radians([0.0]), math.radians(1.0)
    lidar.azimuths = np.arange(360) * lidar.step
    dirs = lidar.directions(0.0)
    lo = np.array([[5.0, -1, -1], [5.0, -1, -1], [3.0, -1, -1]])
    hi = np.array([[6.0, 1, 1], [6.0, 1, 1], [3.5, 1, 1]])
    args = (np.zeros(3), dirs, 0.0, lidar.elevations, lidar.step)
    t, box = cast_boxes(*args, lo[:2], hi[:2], 0.1, 100.0)
    assert t[0, 0] == 5.0 and box[0, 0] == 0 and box[0, 180] == -1
    t, box = cast_boxes(*args, lo, hi, 0.1, 100.0)
    assert t[0, 0] == 3.0 and box[0, 0] == 2
    t, box = cast_boxes(*args, lo[:0], hi[:0], 0.1, 100.0)
    assert np.isinf(t).all() and (box == -1).all()
