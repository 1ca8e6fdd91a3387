"""The compiled kernels (imported by :func:`astralis_des.compiled.enable` alone: numba).

Each is the numpy path's answer worked out cell by cell or pair by pair, where numpy spends
more on a call's overhead than on the arithmetic (a room's grid is 44 x 74 cells):

- :func:`fits`: ``world.clutter._candidates``, the lower corners where a footprint's window
  holds only allowed cells (along a wall: with its back on the wall);
- :func:`place`: ``world.clutter.place_in``'s tries, each spot's cells worked out with the
  same floating-point steps as ``_Layout.spot`` and ``FreeSpace.cells``, and stamped by
  :func:`try_stamp` (``world.placing.Occupancy.try_stamp``: a footprint is kept when every
  cell reached from the door before is still reached, here by a flood fill from the door);
- :func:`segments_hit_boxes`: ``world.geometry.segments_hit_boxes``, the slab test with
  numpy's products and comparisons one by one (and its NaN and zero-direction rules);
- :func:`within`: which points lie in which boxes (rooms, furniture), the comparisons numpy
  broadcasts.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

compiled = njit(cache=True, nogil=True, error_model="numpy")  # machine code kept on disk


@compiled
def _allowed_table(free, keepout, halo, taken, grow):  # type: ignore[no-untyped-def]
    """The summed-area table (a row and column of zeros in front) of the free cells neither
    kept out, in a halo, nor within ``grow`` cells (a square) of a taken one."""
    nx, ny = free.shape
    near = np.zeros((nx + 1, ny + 1), dtype=np.int32)  # the taken cells' table first
    for i in range(nx):
        run = 0
        for j in range(ny):
            run += taken[i, j]
            near[i + 1, j + 1] = near[i, j + 1] + run
    table = np.zeros((nx + 1, ny + 1), dtype=np.int32)
    for i in range(nx):
        r0, r1 = max(i - grow, 0), min(i + grow + 1, nx)
        run = 0
        for j in range(ny):
            if free[i, j] and not keepout[i, j] and not halo[i, j]:
                c0, c1 = max(j - grow, 0), min(j + grow + 1, ny)
                if near[r1, c1] - near[r0, c1] - near[r1, c0] + near[r0, c0] == 0:
                    run += 1
            table[i + 1, j + 1] = table[i, j + 1] + run
    return table


@compiled
def fits(free, keepout, halo, taken, sides, grow, layouts):  # type: ignore[no-untyped-def]
    """For each layout ``(kx, ky, wall)``: the lower corners (flat indices into a grid
    ``ny - ky + 1`` wide, in row-major order) whose ``kx`` by ``ky`` window holds only
    allowed cells, along ``wall`` (``sides[wall]``: free cells whose neighbour that way is
    blocked) when it is 0..3. Returns the corners of all layouts end to end, and how many
    each has."""
    table = _allowed_table(free, keepout, halo, taken, grow)
    nx, ny = free.shape
    counts = np.zeros(len(layouts), dtype=np.int64)
    room = 0
    for n in range(len(layouts)):
        if layouts[n, 0] <= nx and layouts[n, 1] <= ny:
            room += (nx - layouts[n, 0] + 1) * (ny - layouts[n, 1] + 1)
    out = np.empty(room, dtype=np.int64)
    k = 0
    for n in range(len(layouts)):
        kx, ky, wall = layouts[n, 0], layouts[n, 1], layouts[n, 2]
        if kx > nx or ky > ny:
            continue
        width = ny - ky + 1
        start = k
        for i in range(nx - kx + 1):
            for j in range(width):
                # along a wall, its back first: few cells lie along one
                if wall >= 0 and not _backs_onto(sides[wall], wall, i, j, kx, ky):
                    continue
                if table[i + kx, j + ky] - table[i, j + ky] - table[i + kx, j] + table[i, j] \
                        == kx * ky:
                    out[k] = i * width + j
                    k += 1
        counts[n] = k - start
    return out[:k], counts


@compiled
def _backs_onto(side, wall, i, j, kx, ky):  # type: ignore[no-untyped-def]
    """Whether the window at ``(i, j)`` has its back row or column wholly on ``side``."""
    if wall == 0 or wall == 1:
        r = i if wall == 0 else i + kx - 1
        for c in range(j, j + ky):  # noqa: SIM110  (numba compiles a loop, not all(...))
            if not side[r, c]:
                return False
        return True
    c = j if wall == 2 else j + ky - 1
    for r in range(i, i + kx):  # noqa: SIM110
        if not side[r, c]:
            return False
    return True


@compiled
def _cells(lo, hi, origin, cell, size):  # type: ignore[no-untyped-def]
    """``FreeSpace.cells`` along one axis: the cells ``lo..hi`` overlaps, clipped."""
    first = math.floor((lo - origin) / cell + 1e-6)
    last = math.ceil((hi - origin) / cell - 1e-6)
    return min(max(first, 0), size), min(max(last, 0), size)


@compiled
def place(free, open_floor, inside, door, taken, halo, reach, walk_eroded,  # type: ignore[no-untyped-def]
          corners, counts, layouts, extents, tries, origin, cell, clearance, disk):
    """``world.clutter.place_in``'s tries: each pick of ``tries`` (an index into the
    ``corners`` of the layouts end to end, ``counts`` of each) is the footprint of its layout
    (``layouts``: cells and wall, ``extents``: metres) at that corner, stamped by
    :func:`try_stamp` (with its halo grown by ``clearance``) until one is kept. Returns the
    try kept (-1: none), and the cells reached and the eroded walk with it."""
    nx, ny = free.shape
    for t in range(len(tries)):
        pick, n = tries[t], 0
        while pick >= counts[n]:
            pick -= counts[n]
            n += 1
        kx, ky, wall = layouts[n, 0], layouts[n, 1], layouts[n, 2]
        ex, ey = extents[n, 0], extents[n, 1]
        flat = corners[tries[t]]
        i, j = flat // (ny - ky + 1), flat % (ny - ky + 1)
        # the spot's centre as ``_Layout.spot`` works it out, and its box's cells
        x0, y0 = origin[0] + i * cell, origin[1] + j * cell
        x1, y1 = x0 + kx * cell, y0 + ky * cell
        cx = x0 + ex / 2 if wall == 0 else x1 - ex / 2 if wall == 1 else (x0 + x1) / 2
        cy = y0 + ey / 2 if wall == 2 else y1 - ey / 2 if wall == 3 else (y0 + y1) / 2
        lo_x, hi_x, lo_y, hi_y = cx - ex / 2, cx + ex / 2, cy - ey / 2, cy + ey / 2
        i0, i1 = _cells(lo_x, hi_x, origin[0], cell, nx)
        j0, j1 = _cells(lo_y, hi_y, origin[1], cell, ny)
        h0, h1 = _cells(lo_x - clearance, hi_x + clearance, origin[0], cell, nx)
        g0, g1 = _cells(lo_y - clearance, hi_y + clearance, origin[1], cell, ny)
        kept, reached, walk = try_stamp(free, open_floor, inside, door, taken, halo, reach,
                                        walk_eroded, (i0, i1, j0, j1), (h0, h1, g0, g1), disk)
        if kept:
            return t, reached, walk
    return -1, np.zeros((nx, ny), dtype=np.bool_), np.zeros((nx, ny), dtype=np.bool_)


@compiled
def try_stamp(free, open_floor, inside, door, taken, halo, reach, walk_eroded,  # type: ignore[no-untyped-def]
              rect, halo_rect, disk):
    """Stamp the cells ``rect`` (rows ``rect[0]:rect[1]``, columns ``rect[2]:rect[3]``) into
    ``taken`` and ``halo_rect`` into ``halo``, in place; keep them when every cell reached
    from the door before is still reached, else put them back. Returns whether they were
    kept, and the cells reached and the walkable floor eroded by the ``disk`` (rows off its
    centre and their half widths) with them (new arrays; ``reach`` and ``walk_eroded`` are
    only read, the caller's to keep when the footprint is given up)."""
    nx, ny = taken.shape
    i0, i1, j0, j1 = rect
    h0, h1, g0, g1 = halo_rect
    lost_whole = True  # all of it free floor, none of it taken: the walk lost it whole
    for i in range(i0, i1):
        for j in range(j0, j1):
            if not free[i, j] or taken[i, j]:
                lost_whole = False
    taken_before = taken[i0:i1, j0:j1].copy()
    halo_before = halo[h0:h1, g0:g1].copy()
    taken[i0:i1, j0:j1] = True
    halo[h0:h1, g0:g1] = True
    walk = walk_eroded.copy()
    if lost_whole:
        if i0 < i1 and j0 < j1:  # the rectangle grown by the disk (``erode_without``)
            for n in range(len(disk)):
                di, h = disk[n, 0], disk[n, 1]
                walk[max(i0 - di, 0):min(i1 + di, nx), max(j0 - h, 0):min(j1 + h, ny)] = False
    else:  # the cells whose disk meets the rectangle, eroded again (``erode_near``)
        grow = disk[len(disk) - 1, 0]
        lo0, hi0 = max(i0 - grow, 0), min(i1 + grow, nx)
        lo1, hi1 = max(j0 - grow, 0), min(j1 + grow, ny)
        if lo0 < hi0 and lo1 < hi1:
            for i in range(lo0, hi0):
                for j in range(lo1, hi1):
                    walk[i, j] = _disk_walkable(free, open_floor, inside, taken, disk, i, j)
    reached = _from_door(walk, free, taken, door)
    for i in range(nx):
        for j in range(ny):
            if reach[i, j] and not reached[i, j] and walk[i, j] and free[i, j] \
                    and not taken[i, j]:  # a cell reached before, cut off from the door
                taken[i0:i1, j0:j1] = taken_before
                halo[h0:h1, g0:g1] = halo_before
                return False, reached, walk
    return True, reached, walk


@compiled
def _disk_walkable(free, open_floor, inside, taken, disk, i, j):  # type: ignore[no-untyped-def]
    """Whether every cell of the disk round ``(i, j)`` is walkable (``grids.erode``: free and
    not taken, or open floor outside the room; beyond the grid is not)."""
    nx, ny = free.shape
    for n in range(len(disk)):
        di, h = disk[n, 0], disk[n, 1]
        if i - di < 0 or i + di >= nx or j - h < 0 or j + h >= ny:
            return False
        for r in (i - di, i + di):
            for c in range(j - h, j + h + 1):
                if not ((free[r, c] and not taken[r, c]) or (open_floor[r, c]
                                                             and not inside[r, c])):
                    return False
    return True


@compiled
def _from_door(walk, free, taken, door):  # type: ignore[no-untyped-def]
    """The cells of the eroded floor (``walk``, free and not taken) joined by sides to one of
    its door cells (``grids.reachable``'s labels that hold a door cell)."""
    nx, ny = walk.shape
    reached = np.zeros((nx, ny), dtype=np.bool_)
    rows = np.empty(nx * ny, dtype=np.int64)
    cols = np.empty(nx * ny, dtype=np.int64)
    top = 0
    for i in range(nx):
        for j in range(ny):
            if door[i, j] and walk[i, j] and free[i, j] and not taken[i, j]:
                reached[i, j] = True
                rows[top], cols[top] = i, j
                top += 1
    while top > 0:
        top -= 1
        i, j = rows[top], cols[top]
        for r, c in ((i - 1, j), (i + 1, j), (i, j - 1), (i, j + 1)):
            if 0 <= r < nx and 0 <= c < ny and not reached[r, c] and walk[r, c] \
                    and free[r, c] and not taken[r, c]:
                reached[r, c] = True
                rows[top], cols[top] = r, c
                top += 1
    return reached


@compiled
def _nan_min(a, b):  # type: ignore[no-untyped-def]
    """``np.minimum``: a NaN wins."""
    if a != a:
        return a
    if b != b:
        return b
    return a if a <= b else b


@compiled
def _nan_max(a, b):  # type: ignore[no-untyped-def]
    """``np.maximum``: a NaN wins."""
    if a != a:
        return a
    if b != b:
        return b
    return a if a >= b else b


@compiled
def segments_hit_boxes(p0, p1, boxes):  # type: ignore[no-untyped-def]
    """``(M,)``: does segment ``p0[m] -> p1[m]`` pass through any of ``boxes`` (``(K, 2, 3)``)?
    The boxes first narrowed to those meeting the segments' common bounds, then the slab
    test per pair, each product and comparison as numpy's ``segments_hit_boxes`` makes it."""
    m = p0.shape[0]
    out = np.zeros(m, dtype=np.bool_)
    lo = np.empty(3)
    hi = np.empty(3)
    for k in range(3):
        lo[k], hi[k] = p0[0, k], p0[0, k]
        for r in range(m):
            for v in (p0[r, k], p1[r, k]):
                if v != v:  # numpy's bounds are NaN: no box is near
                    return out
                lo[k] = min(lo[k], v)
                hi[k] = max(hi[k], v)
    near = np.empty(len(boxes), dtype=np.int64)
    count = 0
    for b in range(len(boxes)):
        if boxes[b, 0, 0] <= hi[0] and boxes[b, 1, 0] >= lo[0] and boxes[b, 0, 1] <= hi[1] \
                and boxes[b, 1, 1] >= lo[1] and boxes[b, 0, 2] <= hi[2] \
                and boxes[b, 1, 2] >= lo[2]:
            near[count] = b
            count += 1
    if count == 0:
        return out
    fix = np.zeros(3, dtype=np.bool_)  # an axis some segment's 1 / d is not finite on
    for k in range(3):
        for r in range(m):
            if not np.isfinite(1.0 / (p1[r, k] - p0[r, k])):
                fix[k] = True
    for r in range(m):
        for n in range(count):
            b = near[n]
            enter, leave = 0.0, 0.0
            for k in range(3):
                d = p1[r, k] - p0[r, k]
                inv = 1.0 / d
                t_a = (boxes[b, 0, k] - p0[r, k]) * inv
                t_b = (boxes[b, 1, k] - p0[r, k]) * inv
                t_near, t_far = _nan_min(t_a, t_b), _nan_max(t_a, t_b)
                if fix[k]:
                    if t_a != t_a:
                        t_near = -np.inf
                    if t_b != t_b:
                        t_far = np.inf
                    if d == 0.0:  # parallel: inside the slab or never in it
                        within = p0[r, k] >= boxes[b, 0, k] and p0[r, k] <= boxes[b, 1, k]
                        t_near = -np.inf if within else np.inf
                        t_far = np.inf if within else -np.inf
                if k == 0:
                    enter, leave = t_near, t_far
                else:
                    enter, leave = _nan_max(enter, t_near), _nan_min(leave, t_far)
            if enter <= leave and leave >= 0.0 and enter <= 1.0:
                out[r] = True
                break
    return out


@compiled
def within(points, lo, hi, axes):  # type: ignore[no-untyped-def]
    """``(N, K)``: whether ``points[n]``'s first ``axes`` coordinates lie in the box ``lo[k]``
    .. ``hi[k]`` (bounds included): the comparisons numpy broadcasts, pair by pair."""
    out = np.zeros((len(points), len(lo)), dtype=np.bool_)
    for n in range(len(points)):
        for k in range(len(lo)):
            inside = True
            for a in range(axes):
                if not (points[n, a] >= lo[k, a] and points[n, a] <= hi[k, a]):
                    inside = False
                    break
            out[n, k] = inside
    return out
