"""A camera's field of view as the geometric sensing model sees it, and where it looks.

The camera frame is the computer-vision one: x right, y down, z forward along the optical
axis. A heading is the yaw of the camera's forward axis, counter-clockwise from +x.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from astralis_des.world.geometry import FloatArray

LOOK_AROUND = 8  # headings a camera that pans a full turn looks along
Axes = tuple[FloatArray, FloatArray, FloatArray]  # right, down, forward: one row per heading


def pick(axes: Axes, rows: np.ndarray) -> Axes:
    """The rows ``rows`` of ``axes`` (the same numbers as the axes of those headings)."""
    return axes[0][rows], axes[1][rows], axes[2][rows]


@dataclass(frozen=True)
class View:
    """A pinhole camera's field of view on a robot: what the geometric model checks."""

    range: float | None  # m: a cap on the depth of what is detected; None: no cap
    fov_deg: float  # vertical
    aspect: float  # width / height: square pixels give the horizontal field of view
    pitch_deg: float  # 0 forward, 90 straight down
    gimbal: bool = True  # levelled, turned to the direction of travel
    look_around: bool = False  # pans a full turn while waiting in place
    position_noise: float = 0.0  # the estimate's error per axis, a share of the distance
    pixels: tuple[int, int] = (320, 240)  # the frame's width and height
    min_pixels: int = 40  # target pixels a detection needs (astralis_des.detection)

    @classmethod
    def of_kind(cls, kind: str, pixels: tuple[int, int] = (320, 240), min_pixels: int = 40,
                **changes: float) -> View:
        """A kind's default camera (``astralis_des.kinds``), with ``changes``."""
        from astralis_des.kinds import KIND_DEFAULTS

        d = KIND_DEFAULTS[kind].camera
        values: dict[str, float | None] = {"range": d.range, "fov_deg": d.fov_deg,
                                           "pitch_deg": d.pitch_deg, **changes}
        fov, pitch = values["fov_deg"], values["pitch_deg"]
        assert fov is not None and pitch is not None
        return cls(values["range"], fov, pixels[0] / pixels[1], pitch,
                   gimbal=d.gimbal, look_around=d.look_around,
                   position_noise=float(values.get("position_noise") or 0.0),
                   pixels=pixels, min_pixels=min_pixels)

    @cached_property
    def focal(self) -> float:
        """The focal length in pixels (square pixels)."""
        return (self.pixels[1] / 2) / self.tan_v

    @cached_property
    def tan_v(self) -> float:
        return math.tan(math.radians(self.fov_deg) / 2)

    @cached_property
    def tan_h(self) -> float:
        return self.tan_v * self.aspect

    def axes(self, headings: FloatArray) -> Axes:
        """Camera right, down and forward unit vectors in the world, one row per heading."""
        h = np.asarray(headings, dtype=float)
        p = math.radians(self.pitch_deg)
        forward = np.column_stack([math.cos(p) * np.cos(h), math.cos(p) * np.sin(h),
                                   np.full(h.shape, -math.sin(p))])
        right = np.column_stack([np.sin(h), -np.cos(h), np.zeros(h.shape)])
        (f0, f1, f2), (r0, r1, r2) = forward.T, right.T  # np.cross's products, without its
        down = np.column_stack([f1 * r2 - f2 * r1, f2 * r0 - f0 * r2,  # set-up (bit for bit)
                                f0 * r1 - f1 * r0])
        return right, down, forward

    def sees(self, eyes: FloatArray, headings: FloatArray, points: FloatArray,
             axes: Axes | None = None) -> FloatArray:
        """Which ``points`` are in range and in the frustum of the camera at ``eyes`` facing
        ``headings`` (row by row; sight lines are not checked). ``axes``: those of
        ``headings``, when the caller has them already."""
        d = np.asarray(points, dtype=float) - np.asarray(eyes, dtype=float)
        right, down, forward = self.axes(headings) if axes is None else axes
        z = np.einsum("ij,ij->i", d, forward)
        x = np.abs(np.einsum("ij,ij->i", d, right))
        y = np.abs(np.einsum("ij,ij->i", d, down))
        near = np.einsum("ij,ij->i", d, d) <= self.reach**2
        result: FloatArray = near & (z > 1e-6) & (x <= z * self.tan_h) & (y <= z * self.tan_v)
        return result

    @property
    def reach(self) -> float:
        """How far the camera can detect the target at all: its range cap, else the distance
        at which a target seen square on shrinks to ``min_pixels``."""
        if self.range is not None:
            return self.range
        from astralis_des.kinds import TARGET_FACE

        return float(self.focal * math.sqrt(TARGET_FACE / self.min_pixels))


def travel_headings(points: FloatArray, initial: float) -> FloatArray:
    """The heading of travel at each point (that of the leg leaving it; the last leg's at the
    end); where the path does not move horizontally, the heading before."""
    pts = np.asarray(points, dtype=float)
    legs = np.diff(pts[:, :2], axis=0)
    moving = np.hypot(legs[:, 0], legs[:, 1]) > 1e-6
    out = np.full(len(pts), initial, dtype=float)
    if not moving.any():
        return out
    angle = np.arctan2(legs[:, 1], legs[:, 0])
    last = np.maximum.accumulate(np.where(moving, np.arange(len(legs)), -1))
    ahead = np.where(last >= 0, angle[np.maximum(last, 0)], initial)
    out[:-1] = ahead
    out[-1] = ahead[-1]
    return out


def look_headings(view: View, heading: float) -> FloatArray:
    """Where a waiting camera looks: a full turn for one that pans, else straight ahead."""
    if not view.look_around:
        return np.array([heading])
    out: FloatArray = heading + np.arange(LOOK_AROUND, dtype=float) * (2 * math.pi / LOOK_AROUND)
    return out


