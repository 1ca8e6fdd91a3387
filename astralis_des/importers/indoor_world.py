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
from astralis_des.importers.indoor import find_interior, find_storeys
from astralis_des.importers.indoor.interior import walls_heading
from astralis_des.importers.indoor.rooms import DOOR_MAX
from astralis_des.importers.indoor.twin import twin_section
from astralis_des.world.interior_walls import interior_bounds
from astralis_des.world.spec import InteriorSpec

log = logging.getLogger(__name__)
TURN = 0.2  # degrees: a scan whose walls run further off its axes is turned along them
NO_STOREY = ("--indoor: no storey found (no floor under a ceiling with walls between): is this "
             "an indoor scan?")
HEADING_SAMPLE = 1_000_000  # points the walls' heading is found from


def indoor_heading(points: np.ndarray, path: Path) -> float:
    """How far (radians) the walls of ``points`` (``(N, 3)``, metres) run off the axes, 0 when
    within ``TURN``: the import turns the scan by minus that, so that the world's rooms lie
    along x and y. A cloud with no storey is refused here, before anything is built."""
    pts = np.asarray(points[:: max(1, len(points) // HEADING_SAMPLE)], dtype=float)
    try:
        storeys = find_storeys(pts)
    except ValueError as exc:
        raise InputError(f"--indoor: {exc}", file=path) from None
    if not storeys:
        raise InputError(NO_STOREY, file=path)
    heading = walls_heading(pts, storeys)
    return heading if abs(math.degrees(heading)) > TURN else 0.0


def indoor_section(points: np.ndarray, group: str, path: Path, notes: list[str],
                   door_max: float = DOOR_MAX, heading: float = 0.0
                   ) -> tuple[dict[str, Any], float]:
    """The ``interior:`` section of ``points`` (``(N, 3)``, world frame, its walls along the
    axes: the scan turned by ``-heading`` radians, :func:`indoor_heading`), its lowest floor
    at ``z = 0``, and the height that floor was found at (the world is lowered by it);
    passages up to ``door_max`` wide part rooms."""
    try:
        found = find_interior(np.asarray(points, dtype=float), heading=0.0, door_max=door_max)
    except ValueError as exc:
        raise InputError(f"--indoor: {exc}", file=path) from None
    if not found.storeys:
        raise InputError(NO_STOREY, file=path)
    lowest = found.storeys[0].z
    twin = twin_section(found, group, [round(s.z - lowest, 2) for s in found.storeys],
                        round(math.degrees(heading), 2))
    notes.extend(twin.notes)
    places: list[dict[str, Any]] = twin.section["places"]  # type: ignore[assignment]
    rooms = [p for p in places if p["kind"] in ("room", "hall")]
    if not rooms:
        raise InputError(f"--indoor: {len(found.storeys)} storeys but no room a robot fits "
                         "in (walls not closed? the scan too sparse?)", file=path)
    turn = (f"; the scan turned by {-math.degrees(heading):.1f} degrees so that its walls "
            "run along x and y" if heading else "")
    notes.append(f"indoor: {len(found.storeys)} storeys, {len(rooms)} rooms, "
                 f"{len(places) - len(rooms)} corridors and stairwells, "
                 f"{len(twin.section['doors'])} doors{turn}")  # type: ignore[arg-type]
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
