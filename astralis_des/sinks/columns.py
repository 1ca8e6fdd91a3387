"""A recording's components built straight into Arrow arrays (the types Rerun's components
declare) and sent as one chunk an entity, without Rerun's archetype classes.

An archetype checks and converts each of its fields in Python: 0.05 to 0.3 ms a ``log`` or
``send_columns`` call, about 20 ms of a default run's 60 calls, more than the simulation of
its tasks. Built here from numpy and plain lists, a call costs 0.02 to 0.05 ms. What reaches
the file is the same: the same entities, components (archetype, field and type), timelines
and values; ``tests/test_recording_columns.py`` holds each builder to its archetype.

``send`` hands the arrays to the SDK's own chunk call (``rerun_bindings.send_arrow_chunk``,
what ``RecordingStream.send_columns`` calls once it has converted its columns); a static
chunk is one with no time column, as ``log(..., static=True)`` makes."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from functools import cache, lru_cache
from typing import Any

import numpy as np
import pyarrow as pa

from astralis_des.sinks import paths

FLOAT = pa.float32()
SOLID = pa.array([3], pa.uint8())  # Boxes3D's fill mode: rr.components.FillMode.Solid
# A component's values, one row of them a list (the columns ``send`` takes): descriptor -> rows
Columns = Mapping[Any, pa.Array]


@cache
def vector_type(size: int) -> pa.DataType:
    """A Position3D's, Vector3D's, HalfSize2D's ... type: ``size`` floats, none null."""
    return pa.list_(pa.field("item", FLOAT, nullable=False), size)


@cache
def descriptor(archetype: str, field: str) -> Any:
    """The component descriptor of an archetype's field (``Points3D``, ``positions``),
    Rerun's own."""
    import rerun as rr

    return getattr(getattr(rr, archetype), f"descriptor_{field}")()


def vectors(values: Any, size: int) -> pa.Array:
    """Vectors of ``size`` floats (positions, sizes, quaternions) from an (n, size) array."""
    flat = np.ascontiguousarray(values, dtype=np.float32).reshape(-1)
    return pa.FixedSizeListArray.from_arrays(pa.array(flat, FLOAT), type=vector_type(size))


def floats(values: Any) -> pa.Array:
    """Radii, draw orders (float32)."""
    return pa.array(np.asarray(values, dtype=np.float32).reshape(-1), FLOAT)


def doubles(values: Any) -> pa.Array:
    """Scalars (float64)."""
    return pa.array(np.asarray(values, dtype=np.float64).reshape(-1), pa.float64())


def texts(values: Sequence[str]) -> pa.Array:
    return pa.array(values, pa.utf8())


def flags(values: Sequence[bool]) -> pa.Array:
    return pa.array(values, pa.bool_())


def colors(values: Any) -> pa.Array:
    """Colours as Rerun packs them, ``0xRRGGBBAA`` (RGB: opaque) from (n, 3 or 4) integers."""
    if not len(values):
        return pa.array([], pa.uint32())
    if not isinstance(values, np.ndarray):  # tuples of 3 and of 4 may be mixed
        values = [(*c, 255) if len(c) == 3 else c for c in values]
    rgba = np.asarray(values, dtype=np.uint32).reshape(len(values), -1)
    if rgba.shape[1] == 3:
        rgba = np.column_stack([rgba, np.full(len(rgba), 255, dtype=np.uint32)])
    packed = (rgba[:, 0] << 24) | (rgba[:, 1] << 16) | (rgba[:, 2] << 8) | rgba[:, 3]
    return pa.array(packed.astype(np.uint32), pa.uint32())


def offsets(lengths: Sequence[int] | np.ndarray) -> pa.Array:
    """A list array's offsets for lists of ``lengths``: 0, then their running sums."""
    out = np.zeros(len(lengths) + 1, dtype=np.int32)
    np.cumsum(lengths, out=out[1:])
    return pa.array(out, pa.int32())


@lru_cache(maxsize=1024)
def _each_one(n: int) -> pa.Array:
    """The offsets of ``n`` lists of one value each (Arrow arrays do not change: kept)."""
    return pa.array(np.arange(n + 1, dtype=np.int32), pa.int32())


@lru_cache(maxsize=1024)
def _all_in_one(n: int) -> pa.Array:
    """The offsets of one list of ``n`` values."""
    return pa.array(np.array([0, n], dtype=np.int32), pa.int32())


def rows(values: pa.Array, lengths: Sequence[int] | np.ndarray | None = None) -> pa.Array:
    """``values`` as rows: one value a row, or ``lengths`` of them in each."""
    if lengths is None:
        return pa.ListArray.from_arrays(_each_one(len(values)), values)
    return pa.ListArray.from_arrays(offsets(lengths), values)


def one_row(values: pa.Array) -> pa.Array:
    """All of ``values`` in a single row (a static component, a log call's batch)."""
    return pa.ListArray.from_arrays(_all_in_one(len(values)), values)


def strips(points: Sequence[np.ndarray]) -> pa.Array:
    """Line strips (LineStrip3D): each a list of 3-D points, none null."""
    flat = vectors(np.vstack(points) if points else np.empty((0, 3)), 3)
    return pa.ListArray.from_arrays(offsets([len(p) for p in points]), flat,
                                    type=pa.list_(pa.field("item", vector_type(3),
                                                           nullable=False)))


def times(seconds: Any) -> pa.Array:
    """The simulated time column, in nanoseconds as ``rr.TimeColumn`` makes it from what it is
    given: a numpy array's cut, a list's rounded (half to even, as Python's ``round``)."""
    if isinstance(seconds, np.ndarray):
        nanos = (seconds * 1e9).astype("timedelta64[ns]")
    else:
        nanos = np.round(np.asarray(seconds, dtype=np.float64) * 1e9).astype(
            np.int64).astype("timedelta64[ns]")
    return pa.array(nanos, pa.duration("ns"))


def send(rec: Any, entity: str, index: pa.Array | None, columns: Columns) -> None:
    """One chunk of ``entity``: its rows at the times ``index`` (``None``: static, one row)."""
    import rerun_bindings

    rerun_bindings.send_arrow_chunk(entity, timelines={} if index is None else
                                    {paths.TIMELINE: index}, components=dict(columns),
                                    recording=rec.to_native())


def static_columns(archetype: str, **fields: pa.Array) -> dict[Any, pa.Array]:
    """The columns of a static chunk of ``archetype`` (each field's values, one row)."""
    return {descriptor(archetype, name): one_row(values) for name, values in fields.items()}


def send_static(rec: Any, entity: str, archetype: str, **fields: pa.Array) -> None:
    """``entity``'s static components of ``archetype`` (each field's values, one row)."""
    send(rec, entity, None, static_columns(archetype, **fields))
