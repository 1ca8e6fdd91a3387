"""What :func:`.interior.find_interior` found, as a world file's ``interior:`` section.

- **Stairwells.** A room (not a corridor or hall, which may hold a landing) most of whose
  floor lies under an opening in the storey above (free of walls inside the building, with no
  floor) is a stairwell. Each opening of at least
  ``MIN_SHAFT`` m² has stairs, from the place under it (or beside it, where the storey below
  has no floor there either) to the place beside it above.
- **Ids.** ``GROUP.STOREY.SEGMENT.ROOM``. Passages (corridors, stairwells) are segment 0. A
  segment is the rooms whose doors open onto one side of one corridor or hall, sides taken
  north, south, east, west, corridors and halls from the south-west; rooms are numbered
  along their side from the west (or the south). Rooms reached only through other rooms or
  from outside are a segment of their own, after those.
- **Sizes.** A room smaller than the longest robot is left out (a note says so): no robot can
  search it.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from astralis_des.importers.indoor.doors import FoundDoor
from astralis_des.importers.indoor.interior import Interior
from astralis_des.importers.indoor.plan import Plan
from astralis_des.importers.indoor.rooms import FoundRoom
from astralis_des.world.spec import OUTSIDE, robot

MIN_SHAFT = 2.0  # m², the smallest opening in a floor that holds stairs
REACH = 0.1  # m: what borders an opening (a wall between is thicker)
NOTCH = 0.3  # m: narrower bits of a room's floor (into a doorway) are no part of its outline
FILLED = 0.92  # of its bounds: a room that fills them is a rectangle
SIDES = {(1, 1): 0, (1, -1): 1, (0, 1): 2, (0, -1): 3}  # north, south, east, west


@dataclass(frozen=True)
class Twin:
    """The ``interior:`` section and what was left out, a line each."""

    section: dict[str, object]
    notes: tuple[str, ...]


def twin_section(found: Interior, group: str, storey_z: list[float],
                 heading: float = 0.0) -> Twin:
    """The section for ``found`` (in world coordinates), its storeys' floors at ``storey_z``
    (the world's heights of the floors found), the scan turned by minus ``heading`` degrees
    to get there."""
    notes: list[str] = []
    stairwells, stairs = _shafts(found)
    length = robot()[1]
    kept = []
    for room in found.rooms:
        kind = "stairwell" if room.id in stairwells else room.kind
        small = kind in ("room", "hall") and min(np.subtract(room.hi, room.lo)) < length
        if small:
            notes.append(f"room {room.id} ({room.area:g} m^2) left out: narrower than a robot")
            continue
        kept.append((room, kind))
    kinds = {r.id: k for r, k in kept}
    doors = [d for d in found.doors if all(p is None or p in kinds for p in d.rooms)]
    entered = {p for d in doors for p in d.rooms}
    for room, kind in list(kept):
        if kind in ("room", "hall") and room.id not in entered:
            notes.append(f"room {room.id} ({room.area:g} m^2) left out: no door found")
            kept.remove((room, kind))
    ids = _ids(kept, doors, group)
    places = [{"id": ids[r.id], "kind": k, "outline": _outline(r)}
              for r, k in sorted(kept, key=lambda rk: _order(ids[rk[0].id]))]
    section: dict[str, object] = {
        "group": group,
        "heading": heading,
        "storeys": [{"level": s.index, "z": round(z, 3), "height": round(s.height, 3)}
                    for s, z in zip(found.storeys, storey_z, strict=True)],
        "places": places,
        "doors": [{"at": [round(d.centre[0], 3), round(d.centre[1], 3)],
                   "across": "x" if d.normal_axis == 0 else "y",
                   "width": round(d.width, 2),
                   "between": [ids[p] if p is not None else OUTSIDE for p in d.rooms]}
                  for d in doors],
        "stairs": [{"between": [ids[a], ids[b]]} for a, b in stairs if a in ids and b in ids],
    }
    return Twin(section, tuple(notes))


def _outline(room: FoundRoom) -> list[list[float]]:
    """The room's floor as a polygon: its cells opened by ``NOTCH`` (a doorway's half, a
    wall's ragged edge are no part of it), a rectangle where they fill ``FILLED`` of their
    bounds, else their outline simplified to within a cell and a half."""
    from skimage.measure import approximate_polygon, find_contours

    k = max(1, round(NOTCH / room.cell))
    mask = ndimage.binary_opening(np.pad(room.mask, k), np.ones((k, k), dtype=bool))
    if not mask.any():
        mask = np.pad(room.mask, k)
    i, j = np.nonzero(mask)
    lo = np.array(room.lo) + (np.array([i.min(), j.min()]) - k) * room.cell
    hi = np.array(room.lo) + (np.array([i.max(), j.max()]) + 1 - k) * room.cell
    if mask.sum() >= FILLED * (np.ptp(i) + 1) * (np.ptp(j) + 1):
        return [[round(float(x), 3), round(float(y), 3)] for x, y in
                ((lo[0], lo[1]), (hi[0], lo[1]), (hi[0], hi[1]), (lo[0], hi[1]))]
    contour = max(find_contours(np.pad(mask, 1).astype(float), 0.5), key=len)
    contour = approximate_polygon(contour, tolerance=1.5)[:-1]
    return [[round(float(room.lo[0] + (r - 1 - k + 0.5) * room.cell), 3),
             round(float(room.lo[1] + (c - 1 - k + 0.5) * room.cell), 3)] for r, c in contour]


def _order(pid: str) -> tuple[int, ...]:
    return tuple(int(p) for p in pid.split(".")[1:])


def _ids(kept: list[tuple[FoundRoom, str]], doors: list[FoundDoor], group: str) -> dict[str, str]:
    """Each kept place's id: passages numbered per storey from the south-west, rooms by the
    side of the passage or hall their door opens onto."""
    rooms = {r.id: r for r, _ in kept}
    kinds = {r.id: k for r, k in kept}
    ids: dict[str, str] = {}
    hubs: dict[int, list[FoundRoom]] = {}
    for room, kind in kept:  # kept is in storey order, south-west first
        if kind in ("corridor", "stairwell"):
            count = sum(1 for v in ids.values() if v.startswith(f"{group}.{room.storey}.0."))
            ids[room.id] = f"{group}.{room.storey}.0.{count + 1}"
        if kind in ("corridor", "hall"):
            hubs.setdefault(room.storey, []).append(room)
    sides: dict[tuple[str, int], list[tuple[float, str]]] = {}
    alone: dict[int, list[FoundRoom]] = {}
    for room, kind in kept:
        if kind not in ("room", "hall"):
            continue
        best = None
        for d in doors:
            if room.id not in d.rooms:
                continue
            other = d.rooms[1] if d.rooms[0] == room.id else d.rooms[0]
            if other is None or kinds.get(other) not in ("corridor", "hall") or other == room.id:
                continue
            axis = d.normal_axis
            sign = 1 if room.centre[axis] > rooms[other].centre[axis] else -1
            along = room.centre[1 - axis]
            key = (0 if kinds[other] == "corridor" else 1, SIDES[(axis, sign)])
            if best is None or key < best[0]:
                best = (key, other, SIDES[(axis, sign)], along)
        if best is None:
            alone.setdefault(room.storey, []).append(room)
        else:
            sides.setdefault((best[1], best[2]), []).append((best[3], room.id))
    for storey in sorted({r.storey for r, _ in kept}):
        segment = 0
        for hub in hubs.get(storey, []):
            for side in range(4):
                members = sorted(sides.get((hub.id, side), []))
                if not members:
                    continue
                segment += 1
                for k, (_, rid) in enumerate(members, start=1):
                    ids[rid] = f"{group}.{storey}.{segment}.{k}"
        for k, room in enumerate(alone.get(storey, []), start=1):
            ids[room.id] = f"{group}.{storey}.{segment + 1}.{k}"
    return ids


def _shafts(found: Interior) -> tuple[set[str], list[tuple[str, str]]]:
    """The places that are stairwells, and the stairs: pairs of found rooms' ids."""
    stairwells: set[str] = set()
    stairs: list[tuple[str, str]] = []
    by_label = {(r.storey, r.label): r.id for r in found.rooms}
    for k in range(len(found.storeys) - 1):
        low, high = found.plans[k], found.plans[k + 1]
        low_labels, high_labels = found.labels[k], found.labels[k + 1]
        opening = high.inside & ~high.floor & ~high.walls
        parts, count = ndimage.label(opening)
        below = _resample(low_labels, low, high, opening.shape)
        for room in (r for r in found.rooms if r.storey == k + 1 and r.kind == "room"):
            cells = below == room.label
            if cells.sum() and opening[cells].mean() >= 0.5:
                stairwells.add(room.id)
        reach = max(1, round(REACH / high.cell))  # cells
        for part in range(1, count + 1):
            shaft = parts == part
            if shaft.sum() * high.cell**2 < MIN_SHAFT:
                continue
            ring = ndimage.binary_dilation(shaft, iterations=reach) & ~shaft
            upper = _most(high_labels[ring])
            lower = _most(below[shaft]) or _most(below[ring])
            if upper and lower:
                pair = (by_label[(k + 1, lower)], by_label[(k + 2, upper)])
                if pair not in stairs:
                    stairs.append(pair)
    return stairwells, stairs


def _most(labels: np.ndarray) -> int:
    counts = Counter(int(v) for v in labels.ravel() if v > 0)
    return counts.most_common(1)[0][0] if counts else 0


def _resample(labels: np.ndarray, source: Plan, target: Plan, shape: tuple[int, int]
              ) -> np.ndarray:
    """``labels`` of ``source``'s grid read at the cells of ``target``'s (0 off the grid)."""
    i, j = np.indices(shape)
    xy = np.column_stack([i.ravel(), j.ravel()])
    cells = source.cells(target.centres(xy))
    ok = (cells[:, 0] >= 0) & (cells[:, 1] >= 0) & (cells[:, 0] < labels.shape[0]) & \
        (cells[:, 1] < labels.shape[1])
    out = np.zeros(len(xy), dtype=labels.dtype)
    out[ok] = labels[cells[ok, 0], cells[ok, 1]]
    return out.reshape(shape)
