"""What each agent kind is: one record (:class:`KindDefaults`) carrying its speed, camera,
sensor height and sensor set, its body (for the planners, the local layer and the lidar), how it
moves between floors, which planner plans its legs, which rooms are its hazard, the Eq. 1
weights it reads and how a recording draws it. Code elsewhere asks the record
(``KIND_DEFAULTS[kind].flies``), never compares the kind's name.

A new kind is registered from a plug-in (:func:`register_kind`), with its actions
(:func:`astralis_des.plugins.action`), its physics driver (``astralis_des.physics.drivers``'s
``DRIVERS``) and, if it needs them, its planner and look; ``examples/plugins/`` adds a legged
robot that way. ``KINDS`` is a live view: it lists the kinds registered so far.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import Literal, overload


@dataclass(frozen=True)
class CameraDefaults:
    """A kind's camera when the mission does not say: its reach and where it looks."""

    range: float | None  # m: a cap on the detector's reach; None: the pixels decide
    fov_deg: float  # vertical field of view
    pitch_deg: float  # 0 forward, 90 straight down
    gimbal: bool  # levelled and turned to the direction of travel (else fixed to the body)
    look_around: bool  # while waiting in place it pans a full turn (a hovering UAV, a person)


@dataclass(frozen=True)
class KindDefaults:
    planner: str  # the entry of astralis_des.planning.planners.PLANNERS that plans its legs
    speed: float  # m/s, cruise
    camera: CameraDefaults
    height: float  # m above the floor of its sensor (a UAV's flight altitude indoors)
    distance: str  # Eq. 1's distance for this kind: "l2" or "manhattan"
    sensors: tuple[str, ...]  # what it carries when the mission names no sensors
    radius: float  # m: the disc round its centre that planners keep clear of walls
    accel: float | None = None  # m/s^2 speeding up and slowing down; None for a walker
    turn_rate: float | None = None  # rad/s turning on the spot (a non-holonomic robot)
    footprint: tuple[float, float] | None = None  # m, length and width of a long body
    rest: float | None = None  # m above the floor of its sensor when landed; None: it walks
    # or drives (its sensor is always at ``height``)
    keep_out: float = 0.0  # m more kept from furniture and people than from walls
    band: tuple[float, float] = (-0.1, 0.1)  # m below and above its pose its body takes
    passing_radius: float | None = None  # m: the disc others pass it by (None: ``radius``)
    half_width: float = 0.0  # m beside it others keep clear of (0: its passing radius)
    lidar_offset: float = 0.5  # m from its centre where a lidar's rays start, outside the body
    # between floors: the stairs, the lift (where there is one, else the stairs), or flown up
    # the stairwell
    floors: Literal["stairs", "lift", "well"] = "stairs"
    hazard: Literal["risk", "messiness"] | None = None  # rooms high in it are unsafe for it
    person: bool = False  # a person (not a robot): who teleop drives, whom robots keep from
    label: str = ""  # its name in a table's heading (else the kind's)
    carries: tuple[str, ...] | None = None  # the sensors it can carry (None: every one)
    look: str = "rover"  # how a recording draws it (astralis_des.sinks.looks.LOOKS)
    color: tuple[int, int, int] = (200, 200, 200)  # its node in a recording's round graph
    weights: str | None = None  # the kind whose Eq. 1 weights it reads where the mission sets
    # none for it (None: its own, 0 where unset)

    @property
    def flies(self) -> bool:
        """Whether it takes off and lands (a UAV): it has a resting height."""
        return self.rest is not None

    @property
    def passes_by(self) -> float:
        """The disc others pass it by (a long body's half-diagonal)."""
        return self.passing_radius if self.passing_radius is not None else self.radius

    @property
    def length(self) -> float:
        """The longest side of its body seen from above (its footprint, else its disc)."""
        return max(self.footprint) if self.footprint is not None else 2 * self.radius

    @property
    def swept_radius(self) -> float | None:
        """The circle a body with a footprint sweeps turning on the spot (its half-diagonal)."""
        if self.footprint is None:
            return None
        return math.hypot(self.footprint[0] / 2, self.footprint[1] / 2)


UAV_BODY_HALF_HEIGHT = 0.06  # m: half the hexacopter's body (its collision cylinder)
UAV_FLIGHT_HEIGHT = 1.975  # m: the default world's flight height (see world.flight)
UAV_REST = 0.07  # m: its centre standing on the floor (half its body and a centimetre)
CLIMB_SPEED = 1.0  # m/s: a UAV taking off or landing

KIND_DEFAULTS: dict[str, KindDefaults] = {
    # A gimballed camera 75 degrees down: at 2 m over the floor it sees a strip about 4 m
    # wide below the craft, mostly ahead of it. Indoors it flies over the heads of standing
    # people and under the door lintels (:func:`astralis_des.world.flight.flight_height`):
    # ``height`` is the flight height where the world sets none. It starts and ends landed.
    # It keeps 0.2 m more from furniture and people: it cuts a corner of its path by up to a
    # quarter metre (measured), and it should not brush a person's head.
    "uav": KindDefaults(planner="fly", speed=1.5,
                        camera=CameraDefaults(None, 90.0, 75.0, True, True),
                        height=UAV_FLIGHT_HEIGHT, distance="l2", sensors=("camera", "imu"),
                        radius=0.3, accel=2.0, rest=UAV_REST, keep_out=0.2,
                        band=(-0.1, 0.1), floors="well", label="UAV", look="rotorcraft",
                        color=(30, 144, 255)),
    # A forward camera on the body, and a lidar the local planner slows down for.
    # Others pass it by its half-diagonal, and keep 0.4 m beside it (the Husky's half-width and
    # a margin for its turning); it takes the lift; rooms high in messiness are unsafe for it.
    "ugv": KindDefaults(planner="drive", speed=1.0,
                        camera=CameraDefaults(None, 60.0, 0.0, False, False),
                        height=0.5, distance="manhattan", sensors=("camera", "lidar", "imu"),
                        radius=0.35, accel=1.0, turn_rate=1.0,
                        footprint=(1.01, 0.69),  # the Husky
                        band=(-0.5, 0.15), passing_radius=0.62, half_width=0.4,
                        lidar_offset=0.6, floors="lift", hazard="messiness", label="UGV",
                        color=(255, 165, 0)),
    # A person's eyes: a wide view a little down, ahead of where they walk.
    # Rooms high in risk are unsafe for a person. The operator has eyes (a camera model) and
    # nothing else.
    "human": KindDefaults(planner="walk", speed=1.2,
                          camera=CameraDefaults(None, 90.0, 15.0, True, True),
                          height=1.6, distance="manhattan", sensors=("camera",), radius=0.25,
                          band=(-1.6, 0.15), hazard="risk", person=True,
                          carries=("camera",), look="person", color=(220, 20, 60)),
}
NAME = re.compile(r"^[a-z][a-z0-9_]*$")  # a kind's name, as a mission writes it


class _Kinds(Sequence[str]):
    """The names of the kinds registered so far, in the order they were (the paper's three
    first): a view, so what a plug-in adds later is in it."""

    @overload
    def __getitem__(self, i: int) -> str: ...
    @overload
    def __getitem__(self, i: slice) -> Sequence[str]: ...

    def __getitem__(self, i: int | slice) -> str | Sequence[str]:
        return tuple(KIND_DEFAULTS)[i]

    def __len__(self) -> int:
        return len(KIND_DEFAULTS)

    def __iter__(self) -> Iterator[str]:
        return iter(tuple(KIND_DEFAULTS))

    def __contains__(self, kind: object) -> bool:
        return kind in KIND_DEFAULTS

    def __repr__(self) -> str:
        return repr(tuple(KIND_DEFAULTS))


KINDS: Sequence[str] = _Kinds()


def register_kind(name: str, record: KindDefaults) -> KindDefaults:
    """Add the kind ``name`` (lower-case letters, digits and ``_``); registering a name twice
    is a bug and is refused, unless with the same record (a plug-in imported again)."""
    if not NAME.match(name):
        raise ValueError(f"a kind's name is lower-case letters, digits and _, not {name!r}")
    if name in KIND_DEFAULTS and KIND_DEFAULTS[name] != record:
        raise ValueError(f"robot kind {name!r} is registered twice")
    KIND_DEFAULTS[name] = record
    return record


def largest() -> str:
    """The kind of the longest body registered (the UGV's, of the paper's three)."""
    return max(KINDS, key=lambda k: KIND_DEFAULTS[k].length)


def known_kind(kind: str) -> str:
    """``kind`` if registered, else a ``ValueError`` naming those that are."""
    if kind not in KIND_DEFAULTS:
        known = ", ".join(repr(k) for k in KINDS)
        raise ValueError(f"unknown robot kind {kind!r}; known: {known} (a plug-in adds "
                         "others: plugins: [file.py])")
    return kind


TARGET_HEIGHT = 0.5  # m above the floor: the centre of a sitting or laying avatar
TARGET_SIZE = (0.5, 0.5, 2 * TARGET_HEIGHT)  # m: the box of a sitting avatar
TARGET_FACE = TARGET_SIZE[1] * TARGET_SIZE[2]  # m^2: its side, seen square on
