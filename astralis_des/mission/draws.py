"""What a mission draws from its seed: room properties, the target and its attributes."""

from __future__ import annotations

from dataclasses import dataclass

from astralis_des.mission.loader import Mission
from astralis_des.streams import stream
from astralis_des.world.catalogue import agree
from astralis_des.world.scene import Scene, Target

SOUNDS = ("minimal", "moderate", "loud")
AVATAR_VALUES: dict[str, tuple[object, ...]] = {
    "activity": ("sitting", "laying", "patrolling", "idle"),
    "color": ("yellow", "red", "purple", "blue"),
    "gender": ("male", "female"),
    "height": ("tall", "medium", "short"),
    "tied_to_chair": (True, False),
}
@dataclass
class RoomState:
    risk: float
    messiness: float
    sound: str


def draw_rooms(mission: Mission) -> dict[str, RoomState]:
    """Uniform risk and messiness in [0, 1] and a sound per room, then the file's overrides."""
    gen = stream(mission.spec.seed, "rooms")
    states = {}
    for room_id in sorted(mission.world.rooms):
        risk, mess = gen.uniform(0.0, 1.0, size=2)
        states[room_id] = RoomState(float(risk), float(mess), SOUNDS[int(gen.integers(3))])
    for room_id, props in mission.spec.rooms.set.items():
        state = states[room_id]
        for key, value in props.model_dump(exclude_none=True).items():
            setattr(state, key, value)
    return states


def draw_target(mission: Mission, scene: Scene) -> Target:
    """The target avatar: its room (given or drawn from the searched rooms), attributes (given
    or drawn from Table II), and place (given, or a free spot among the furniture)."""
    spec = mission.spec.target
    gen = stream(mission.spec.seed, "target")
    candidates = mission.searched_rooms() or sorted(mission.world.rooms)
    room_id = spec.room or candidates[int(gen.integers(len(candidates)))]
    given = spec.avatar.model_dump(exclude_none=True)
    avatar_gen = stream(mission.spec.seed, "avatar")
    avatar = {}
    for key, values in AVATAR_VALUES.items():
        drawn = values[int(avatar_gen.integers(len(values)))]
        avatar[key] = given.get(key, drawn)
    agree(avatar, frozenset(given))
    position = tuple(float(v) for v in spec.position) if spec.position is not None else None
    return scene.place_target(room_id, avatar, position)  # type: ignore[arg-type]
