"""How high a UAV flies indoors: over the heads of standing people and the free-standing
furniture, under the door lintels it passes through.

The height is halfway between the two limits, each less the craft's half-height; in the
default world (doors 2.1 m, the tallest standing bystander 1.85 m) that is 1.975 m, with 6.5 cm
to spare over a head and under a lintel. A world whose doors leave no room over a standing
person gets the highest height that passes its doors, and a warning. A mission's ``height:``
of a team member overrides it.
"""

from __future__ import annotations

import logging

from astralis_des.kinds import KIND_DEFAULTS, UAV_BODY_HALF_HEIGHT
from astralis_des.world.catalogue import AVATAR_HEIGHTS, SITTING_HEIGHT, Catalogue
from astralis_des.world.model import World

log = logging.getLogger(__name__)
OPEN_CLEARANCE = 0.3  # m over the tallest thing below, where no door limits the height
STANDING = ("patrolling", "idle")


def tallest_below(catalogue: Catalogue) -> float:
    """The highest top a UAV may pass over in a room: a standing bystander's head (sitting,
    if the catalogue has no standing ones) or a free-standing item; items against a wall
    (cabinets) are not under a pattern, which keeps away from the walls."""
    people = catalogue.avatars.attributes
    heads = [AVATAR_HEIGHTS[h] for h in people.height] \
        if set(people.activity) & set(STANDING) else [SITTING_HEIGHT]
    items = [spec.size_max[2] for spec in catalogue.items.present().values()
             if not spec.against_wall]
    return max([*heads, *items])


def flight_height(world: World, catalogue: Catalogue) -> float:
    """The flight height, in metres above the floor, of a UAV in ``world`` furnished from
    ``catalogue`` (see the module's docstring)."""
    half = UAV_BODY_HALF_HEIGHT
    low = tallest_below(catalogue) + half
    lintels = [r.door.height for r in world.rooms.values() if r.building in world.indoors]
    if not lintels:
        return round(max(low + OPEN_CLEARANCE, KIND_DEFAULTS["uav"].height), 3)
    high = min(lintels) - half
    if high < low:
        log.warning("%s: doors of %.2f m leave no room over a standing person (%.2f m): "
                    "UAVs fly at %.2f m", world.name, min(lintels), low - half, high)
        return round(high, 3)
    return round((low + high) / 2, 3)
