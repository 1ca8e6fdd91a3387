"""A motion's kept course: keyed on the path and every parameter, read-only, and the same
poses as interpolating the path with numpy."""

from __future__ import annotations

import numpy as np
import pytest

from astralis_des.kernel.course import course_of
from astralis_des.kernel.robot import Motion

PATH = np.array([[0.0, 0.0, 1.5], [4.0, 0.0, 1.5], [4.0, 3.0, 1.5], [4.0, 3.0, 2.5]])


def test_a_moved_start_is_not_the_kept_course() -> None:
    """The same path from another start has its own length and duration."""
    kept = Motion(PATH.copy(), 2.0, accel=1.0)
    moved = PATH.copy()
    moved[0, 0] = -1.0
    other = Motion(moved, 2.0, accel=1.0)
    assert kept.length == pytest.approx(8.0)
    assert other.length == pytest.approx(9.0)
    assert other.duration > kept.duration


def test_every_parameter_is_in_the_key() -> None:
    """Speed, acceleration, turn rate and the heading at the start each change the profile."""
    durations = {Motion(PATH.copy(), *args, **kw).duration for args, kw in (
        ((2.0,), {}), ((1.0,), {}), ((2.0,), {"accel": 1.0}),
        ((2.0,), {"turn_rate": 1.0}), ((2.0,), {"turn_rate": 1.0, "heading": 3.0}))}
    assert len(durations) == 5


def test_a_kept_course_cannot_be_changed() -> None:
    """Its arrays are read-only: a caller cannot spoil it for the next motion."""
    motion = Motion(PATH.copy(), 2.0)
    with pytest.raises(ValueError):
        motion.cum[0] = 1.0
    with pytest.raises(ValueError):
        motion.profile.t[0] = 1.0
    assert course_of(PATH, 2.0) is motion._course


def test_poses_are_numpy_interpolation_bit_for_bit() -> None:
    """``at`` gives what ``np.interp`` gives on each axis, at any time (also duplicated points)."""
    rng = np.random.default_rng(3)
    for _ in range(200):
        points = rng.normal(0.0, 4.0, (int(rng.integers(1, 8)), 3))
        if len(points) > 2:
            points[1] = points[0]
        motion = Motion(points, 1.5, accel=0.8)
        for t in [-1.0, 0.0, motion.duration, *(rng.random(6) * motion.duration)]:
            s = float(motion.profile.arc(t))
            expected = [np.interp(s, motion.cum, points[:, k]) for k in range(3)]
            assert motion.at(float(t)).tolist() == expected
            assert motion.travelled(float(t)) == s


def test_what_is_derived_from_a_course_is_kept_by_key() -> None:
    """A value derived from a course is made once per key and shared by motions on it; another
    key (the camera's heading before the start) is made anew."""
    made: list[float] = []

    def make(heading: float) -> float:
        made.append(heading)
        return heading * 2

    first, second = Motion(PATH.copy(), 2.0), Motion(PATH.copy(), 2.0)
    assert first.derived(("x", 0.5), lambda: make(0.5)) == 1.0
    assert second.derived(("x", 0.5), lambda: make(0.5)) == 1.0
    assert second.derived(("x", 0.7), lambda: make(0.7)) == 1.4
    assert made == [0.5, 0.7]


def test_the_vertices_passed_are_those_before_the_time_bit_for_bit() -> None:
    """``vertices_until``: the vertices reached before ``t`` (at their times) and the pose at
    ``t``, as masking every vertex's time gives them, at any time."""
    rng = np.random.default_rng(5)
    for _ in range(200):
        points = rng.normal(0.0, 4.0, (int(rng.integers(1, 8)), 3))
        if len(points) > 2:
            points[1] = points[0]
        motion = Motion(points, 1.5, t0=float(rng.random() * 50), accel=0.8,
                        turn_rate=1.0 if rng.random() < 0.5 else None)
        end = motion.t0 + motion.duration
        for t in [motion.t0 - 1.0, motion.t0, end, end + 1.0,
                  *(motion.t0 + rng.random(6) * motion.duration)]:
            times = motion.t0 + motion._course.vertex_times()
            keep = times < t
            got_t, got_p = motion.vertices_until(float(t))
            assert got_t.tolist() == [*times[keep].tolist(), float(t)]
            assert got_p.tolist() == [*points[keep].tolist(), motion.at(float(t)).tolist()]
