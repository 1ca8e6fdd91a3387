"""An indoor import's ``interior:`` section: :func:`find_interior` on the cloud in world
coordinates, then :func:`twin_section`; a cloud where no closed storey or no room is found is
refused in one line."""

from __future__ import annotations

import logging
import math
from pathlib import Path
from typing import Any

import numpy as np

from astralis_des.errors import InputError
from astralis_des.importers.indoor import find_interior
from astralis_des.importers.indoor.rooms import DOOR_MAX
from astralis_des.importers.indoor.twin import twin_section
from astralis_des.world.interior_walls import interior_bounds
from astralis_des.world.spec import InteriorSpec

log = logging.getLogger(__name__)
TURN = 1.0  # degrees: walls further off the axes are refused (the world's rooms are boxes)


def indoor_section(points: np.ndarray, group: str, path: Path, notes: list[str],
                   door_max: float = DOOR_MAX) -> tuple[dict[str, Any], float]:
    """The ``interior:`` section of ``points`` (``(N, 3)``, world frame), its lowest floor at
    ``z = 0``, and the height that floor was found at (the world is lowered by it); passages up
    to ``door_max`` wide part rooms."""
    try:
        found = find_interior(np.asarray(points, dtype=float), door_max=door_max)
        turn = math.degrees(found.heading)
        if abs(turn) > TURN:
            raise InputError(f"--indoor: the walls run at {turn:.1f} degrees to the scan's x "
                             "axis; turn the scan so they run along x and y", file=path)
        if found.heading != 0.0:  # nearly along the axes: planned along them
            found = find_interior(np.asarray(points, dtype=float), heading=0.0,
                                  door_max=door_max)
    except ValueError as exc:
        raise InputError(f"--indoor: {exc}", file=path) from None
    if not found.storeys:
        raise InputError("--indoor: no storey found (no floor under a ceiling with walls "
                         "between): is this an indoor scan?", file=path)
    lowest = found.storeys[0].z
    twin = twin_section(found, group, [round(s.z - lowest, 2) for s in found.storeys])
    notes.extend(twin.notes)
    places: list[dict[str, Any]] = twin.section["places"]  # type: ignore[assignment]
    rooms = [p for p in places if p["kind"] in ("room", "hall")]
    if not rooms:
        raise InputError(f"--indoor: {len(found.storeys)} storeys but no room a robot fits "
                         "in (walls not closed? the scan too sparse?)", file=path)
    notes.append(f"indoor: {len(found.storeys)} storeys, {len(rooms)} rooms, "
                 f"{len(places) - len(rooms)} corridors and stairwells, "
                 f"{len(twin.section['doors'])} doors (walls at "  # type: ignore[arg-type]
                 f"{math.degrees(found.heading):.1f} degrees)")
    return twin.section, lowest


def outside_interior(boxes: np.ndarray, voxel: float, section: dict[str, Any]) -> np.ndarray:
    """The blocks (``(K, 6)`` voxel index ranges) not within the interior's bounds: its walls,
    floors and roof are made from its places and doors (:mod:`astralis_des.world.
    interior_walls`), and what stood in its rooms is furnished anew by the mission."""
    (x0, y0), (x1, y1) = interior_bounds(InteriorSpec.model_validate(section))
    lo = np.floor(np.array([x0, y0]) / voxel) - 1
    hi = np.ceil(np.array([x1, y1]) / voxel) + 1
    within = np.all(boxes[:, :2] >= lo, axis=1) & np.all(boxes[:, 3:5] <= hi, axis=1)
    return boxes[~within]
