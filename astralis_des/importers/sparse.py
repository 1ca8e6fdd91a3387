"""Reductions over integer keys (cells, voxels, bins), chunk by chunk: what they cost follows
the keys that hold points, never the bounding box.

A key packs a cell's indices into one int64 (:func:`pack`); each accumulator folds a chunk's
keys into sorted distinct keys with one value each, and compacts as it goes.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

IntArray = NDArray[np.int64]
FloatArray = NDArray[np.float64]
BITS = 21  # per index in a packed key: cells from 0 to 2**21 - 1 along each of three axes


def pack(index: IntArray) -> IntArray:
    """``(N, 2 or 3)`` non-negative indices below ``2**BITS`` as one int64 key each, in the
    order of their rows sorted lexicographically."""
    key = np.zeros(len(index), dtype=np.int64)
    for axis in range(index.shape[1]):
        key = (key << BITS) | index[:, axis].astype(np.int64)
    return key


def unpack(keys: IntArray, axes: int) -> IntArray:
    mask = (1 << BITS) - 1
    return np.column_stack([(keys >> (BITS * (axes - 1 - a))) & mask
                            for a in range(axes)]).astype(np.int64)


UFUNCS = {"max": (np.maximum, -np.inf), "min": (np.minimum, np.inf), "sum": (np.add, 0.0)}
DENSE_SPAN = 1 << 22  # keys spanning fewer than this (or 4 a key) are reduced in an array


def keyed(keys: IntArray, values: FloatArray, how: str) -> tuple[IntArray, FloatArray]:
    """Distinct ``keys``, sorted, with the ``how`` ("max", "min" or "sum") of their values:
    in a scratch array over the keys' span when it is small, else by sorting."""
    if not len(keys):
        return np.zeros(0, dtype=np.int64), np.zeros(0)
    ufunc, identity = UFUNCS[how]
    low = int(keys.min())
    span = int(keys.max()) - low + 1
    if span <= max(DENSE_SPAN, 4 * len(keys)):
        offset = keys - low
        scratch = np.full(span, identity)
        ufunc.at(scratch, offset, values)
        present = np.bincount(offset, minlength=span) > 0
        where = np.flatnonzero(present)
        return where.astype(np.int64) + low, scratch[where]
    order = np.lexsort((values, keys))
    k, v = keys[order], values[order]
    first = np.ones(len(k), dtype=bool)
    first[1:] = k[1:] != k[:-1]
    starts = np.flatnonzero(first)
    return k[starts], ufunc.reduceat(v, starts)


class Keyed:
    """One value a key, folded in chunk by chunk (``how``: max, min or sum)."""

    def __init__(self, how: str) -> None:
        self.how = how
        self.keys: list[IntArray] = []
        self.values: list[FloatArray] = []
        self.held = 0
        self.compact_at = 1 << 20

    def add(self, keys: IntArray, values: FloatArray) -> None:
        if not len(keys):
            return
        k, v = keyed(np.asarray(keys, dtype=np.int64), np.asarray(values, dtype=float),
                     self.how)
        self.keys.append(k)
        self.values.append(v)
        self.held += len(k)
        if self.held > self.compact_at:
            self._compact()
            self.compact_at = max(self.compact_at, 2 * self.held)

    def _compact(self) -> None:
        k, v = keyed(np.concatenate(self.keys), np.concatenate(self.values), self.how)
        self.keys, self.values, self.held = [k], [v], len(k)

    def result(self) -> tuple[IntArray, FloatArray]:
        if not self.keys:
            return np.zeros(0, dtype=np.int64), np.zeros(0)
        self._compact()
        return self.keys[0], self.values[0]


class KeySet:
    """The distinct keys of every chunk."""

    def __init__(self) -> None:
        self.counts = Keyed("sum")

    def add(self, keys: IntArray) -> None:
        self.counts.add(keys, np.ones(len(keys)))

    def result(self) -> IntArray:
        return self.counts.result()[0]


def runs(keys: IntArray) -> list[tuple[int, int]]:
    """``[first, last]`` of each run of consecutive integers in sorted distinct ``keys``."""
    if not len(keys):
        return []
    breaks = np.flatnonzero(np.diff(keys) > 1)
    first = np.concatenate([[0], breaks + 1])
    last = np.concatenate([breaks, [len(keys) - 1]])
    return [(int(keys[a]), int(keys[b])) for a, b in zip(first, last, strict=True)]
