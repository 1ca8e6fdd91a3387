"""The scene's bodies in the physics co-simulation: what each body is (a robot, a wall, the
ground, a lift, furniture, a mover, the target), the target's and the movers' bodies kept
where their scripts have them, each room's furniture added when the room is furnished, and
the contacts of the moving robots with them."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np

from astralis_des.kinds import KIND_DEFAULTS
from astralis_des.physics import pb  # imported quietly there (its build time on stderr)

if TYPE_CHECKING:
    import simpy

    from astralis_des.kernel.events import EventLog
    from astralis_des.kernel.robot import Robot
    from astralis_des.physics.client import PhysicsClient
    from astralis_des.physics.drivers import Driver
    from astralis_des.physics.lift import Lift
    from astralis_des.physics.track import Track
    from astralis_des.world.clutter import Clutter
    from astralis_des.world.geometry import FloatArray
    from astralis_des.world.scene import Mover, Scene, Target

SUPPORT = 0.7  # a contact normal steeper than this holds a ground robot up: not a collision
FLOORS = ("wall", "ground", "lift")  # what holds a ground robot up (slabs are static boxes)
WAKE_RANGE = 2.0  # m between a mover's centre and a sleeping robot's that wakes it
PLACES_AGE = 1.0  # s: the sleepers' places are read again this often (sleep takes 2 s still)


class SceneBodies:
    """The bodies of the scene besides the robots' (the target, the movers, the furniture),
    the name of every body, and which robot touches what."""

    def __init__(self, client: PhysicsClient, drivers: dict[str, Driver], lifts: list[Lift],
                 scene: Scene, log: EventLog, clock: Callable[[], float],
                 sleepers: Sequence[str] = ()) -> None:
        """``clock`` gives the physics time now (a mover added is put where it is then);
        ``sleepers`` are the robots whose bodies sleep while idle (woken as a mover nears)."""
        self.client, self.drivers, self.log = client, drivers, log
        self.sleepers = list(sleepers)
        self._places = np.zeros((len(self.sleepers), 2))  # where the sleepers stand, as of
        self._places_at = -np.inf
        self._scene = scene
        self._clock = clock
        self.names = {d.body: rid for rid, d in drivers.items()}
        self.names.update(dict.fromkeys(client.static, "wall"))
        self.names[client.ground] = "ground"
        self.names.update({lift.body: "lift" for lift in lifts})
        self.movers: list[tuple[Mover, int]] = []
        self.movers_time = 0.0  # the time the movers were last put at
        self.touching: set[tuple[str, str]] = set()

    def add_scene(self, target: Target) -> None:
        """The target and the movers now; each room's furniture (one static body) and its
        patrolling avatars when the room is furnished, before any robot goes in."""
        scene = self._scene
        self.add_movers([*scene.movers, *scene.avatar_movers()])
        for room_id in scene.furnished_rooms():
            self.furnish(room_id, scene.clutter(room_id), movers=False)
        scene.listeners.append(self.furnish)
        self.target = target
        self.target_size = np.asarray(target.size, dtype=float)
        if target.mover is None:
            self.target_body = self.client.add_box(target.start, self.target_size)
            self.names[self.target_body] = "target"
        else:
            self.target_body = next(b for m, b in self.movers if m is target.mover)

    def target_now(self, now: float) -> tuple[int, FloatArray, FloatArray]:
        """The target's body, centre and size now (a patrolling one is put there first)."""
        if self.target.mover is None:
            return self.target_body, np.asarray(self.target.start, dtype=float), self.target_size
        centre = self.target.mover.position_at(now)
        self.client.call("resetBasePositionAndOrientation", self.target_body, centre.tolist(),
                         [0.0, 0.0, 0.0, 1.0])
        return self.target_body, centre, self.target_size

    def furnish(self, room_id: str, clutter: Clutter, movers: bool = True) -> None:
        """A room's furniture as one set of static bodies, and (unless ``movers`` is False)
        its patrolling avatars."""
        still = self._scene.still_boxes([room_id])
        if len(still):
            bodies = self.client.add_boxes(still[:, 0], still[:, 1])
            self.names.update(dict.fromkeys(bodies, "furniture"))
        if movers:
            self.add_movers(self._scene.avatar_movers([room_id]))

    def add_movers(self, movers: list[Mover]) -> None:
        """A body for each mover, where its script has it at the physics time now."""
        for mover in movers:
            body = self.client.add_box(mover.position_at(self._clock()), mover.size)
            self.movers.append((mover, body))
            self.names[body] = mover.kind

    def move_movers(self, near: list[int], then: float) -> None:
        """Put the movers near a moving robot (their indices, ``near``) where they are at
        ``then``, the end of the coming tick. Done at the contact checks' rate (30 Hz): a
        walker then jumps about 3 cm at a time; one far from every moving robot touches
        nothing and jumps when it comes near."""
        self.movers_time = then
        moved = [self.movers[index] for index in near]
        self._put_movers(moved, then)
        if self.sleepers and moved:
            self._wake_near(np.array([m.position_at(then)[:2] for m, _ in moved]), then)

    def _wake_near(self, movers: FloatArray, t: float) -> None:
        """Wake the sleeping robots a mover is about to walk into (a placed body pushes a
        body that is awake, not one asleep). Their places are read again every
        ``PLACES_AGE`` s: a robot falls asleep only after standing still longer than that."""
        if t >= self._places_at + PLACES_AGE:
            self._places = np.array([self.drivers[rid].position()[:2] for rid in self.sleepers])
            self._places_at = t
        gaps = np.linalg.norm(self._places[:, None, :] - movers[None, :, :], axis=2)
        for index in np.flatnonzero((gaps < WAKE_RANGE).any(axis=1)):
            self.drivers[self.sleepers[index]].wake()

    def place_movers(self, now: float) -> None:
        """Every mover where it is now, as a robot sets off: a body not moved while no robot
        was near it stays where it was last simulated, and a robot setting off there would
        meet it (a UAV waiting where a patrolling avatar had stopped being moved was tipped
        over by it)."""
        self._put_movers(self.movers, now)

    def _put_movers(self, movers: list[tuple[Mover, int]], t: float) -> None:
        """Each mover's body where its script has it at ``t``."""
        for mover, body in movers:
            self.client.call("resetBasePositionAndOrientation", body,
                             mover.position_at(t).tolist(), [0.0, 0.0, 0.0, 1.0])

    def contacts(self, active: dict[str, tuple[Robot, Track, simpy.Event]], t: float) -> None:
        """A moving robot touching a wall, the ground (a UAV) or another robot: one event a
        touch, at physics time ``t``."""
        now: set[tuple[str, str]] = set()
        impulses: dict[tuple[str, str], float] = {}
        names, cid = self.names, self.client.id
        for rid, (robot, _, _) in active.items():
            grounded = not KIND_DEFAULTS[robot.kind].flies or not robot.airborne
            # pybullet at first hand: a Husky on the ground has a few points at 30 Hz
            for c in pb.getContactPoints(bodyA=self.drivers[rid].body, physicsClientId=cid):
                other = names.get(c[2], "object")
                if grounded and other in FLOORS and c[7][2] > SUPPORT:
                    continue  # wheels or feet on a floor, a UAV taking off or landing
                key = (rid, other)
                now.add(key)
                impulses[key] = impulses.get(key, 0.0) + c[9] * self.client.dt
        for key in sorted(now - self.touching):
            self.log.emit("contact", key[0], at=t, other=key[1],
                          impulse=round(impulses[key], 4))
        self.touching = now
