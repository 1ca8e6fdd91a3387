"""Two runs' recordings as Rerun chunks: read back, checked to be of one world, and B's
re-pathed under ``ghost/`` with its robots drawn pale and translucent, so that one recording
shows A as it was and B beside it (:mod:`astralis_des.compare.recording` writes it).

Chunks are re-sent as they are, not logged again: reading a default-mission recording and
re-pathing its 55 chunks takes about 20 ms."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from astralis_des.errors import InputError
from astralis_des.sinks import paths
from astralis_des.sinks.rrd_check import broken

GHOST = "ghost"  # B's entities go under ghost/...
GHOST_WHITE, GHOST_MIX, GHOST_ALPHA = 240.0, 0.6, 170  # B's colours: toward white, see-through
WORLD_SHAPES = ("/world/roads", "/world/blocks", "/world/mesh", "/world/cloud")
B_WORLD = ("/world/target", "/world/movers")  # of B's world, what B's seed may move
B_SKIPPED = ("camera", "lidar", "imu")  # B's sensor data: heavy, and not shown


def read_chunks(path: Path) -> list[Any]:
    """The chunks of the recording at ``path`` (an :class:`InputError` if it is not whole or
    cannot be decoded), the recording's properties left out."""
    from rerun.chunk import RrdReader

    try:
        reason = broken(path)
    except OSError as exc:
        raise InputError(f"cannot be read ({exc.strerror or exc})", file=path) from None
    if reason is not None:
        raise InputError(f"not a whole Rerun recording ({reason})", file=path)
    try:
        chunks = RrdReader(path).stream().to_chunks()
    except (ValueError, RuntimeError, OSError) as exc:
        raise InputError(f"not a Rerun recording this version reads ({exc})", file=path) \
            from None
    return [c for c in chunks if not c.entity_path.startswith("/__")]


def _world_shape(chunk: Any) -> bool:
    path = chunk.entity_path
    return chunk.is_static and (path.startswith(WORLD_SHAPES) or
                                (path.startswith("/world/") and path.endswith("/solids")))


def world_of(chunks: Sequence[Any]) -> dict[str, dict[str, Any]]:
    """The world's fixed geometry (walls, slabs, roads, an imported world's parts): entity path
    -> component -> values. Furniture is left out: it is placed by the seed."""
    shapes: dict[str, dict[str, Any]] = {}
    for chunk in chunks:
        if _world_shape(chunk):
            batch = chunk.to_record_batch()
            shapes[chunk.entity_path] = {f.name: batch.column(i) for i, f in
                                         enumerate(batch.schema) if _is_data(f)}
    return shapes


def same_world(a: Sequence[Any], b: Sequence[Any]) -> bool:
    wa, wb = world_of(a), world_of(b)
    return wa.keys() == wb.keys() and all(
        wa[p].keys() == wb[p].keys() and all(wa[p][k].equals(wb[p][k]) for k in wa[p])
        for p in wa)


def _is_data(field: Any) -> bool:
    return (field.metadata or {}).get(b"rerun:kind") == b"data"


def ghost_color(packed: np.ndarray) -> np.ndarray:
    """Packed RGBA colours (``0xRRGGBBAA``) made pale and see-through: a ghost's."""
    rgb = np.stack([(packed >> s) & 0xFF for s in (24, 16, 8)], axis=-1).astype(float)
    pale = np.round(rgb + (GHOST_WHITE - rgb) * GHOST_MIX).astype(np.uint32)
    alpha = np.minimum(packed & 0xFF, GHOST_ALPHA).astype(np.uint32)
    return (pale[..., 0] << 24) | (pale[..., 1] << 16) | (pale[..., 2] << 8) | alpha


@dataclass(frozen=True)
class Restyle:
    """How a chunk's components change as it is re-sent: colours, labels, series names."""

    colors: Callable[[np.ndarray], np.ndarray] | None = None
    label: str = ""  # appended to each label
    series: str = ""  # put before each series name

    @property
    def changes(self) -> bool:
        return self.colors is not None or bool(self.label or self.series)


def resent(chunk: Any, path: str, style: Restyle) -> list[Any]:
    """``chunk`` under ``path`` (a fresh chunk id), restyled."""
    import pyarrow as pa
    from rerun.chunk import Chunk

    if not style.changes:
        return [chunk.with_entity_path(path)]
    batch = chunk.to_record_batch()
    batch = batch.replace_schema_metadata({  # the path given, not the one it came with
        k: v for k, v in (batch.schema.metadata or {}).items()
        if k not in (b"rerun:entity_path", b"rerun:id")})
    for i, field in enumerate(batch.schema):
        column = batch.column(i)
        name = field.name
        if not _is_data(field):
            continue
        if name.endswith(":colors") and style.colors is not None:
            values = pa.array(style.colors(column.values.to_numpy(zero_copy_only=False)),
                              pa.uint32())
        elif name.endswith(":labels") and style.label:
            values = pa.array([f"{v}{style.label}" for v in column.values.to_pylist()])
        elif name.endswith(":names") and style.series:
            values = pa.array([f"{style.series}{v}" for v in column.values.to_pylist()])
        else:
            continue
        batch = batch.set_column(i, field, pa.ListArray.from_arrays(
            column.offsets, values, mask=column.is_null()))
    if chunk.is_static:
        return list(Chunk.from_record_batch(batch, index=None, entity_path=path))
    return list(Chunk.from_record_batch(batch, entity_path=path))


def a_side(chunks: Sequence[Any]) -> list[Any]:
    """A's chunks as they are, its metrics' series named ``A ...``."""
    named = Restyle(series="A ")
    return [part for c in chunks for part in (
        resent(c, c.entity_path, named) if c.entity_path.startswith(f"/{paths.MISSION_METRICS}")
        and c.is_static else [c])]


def b_side(chunks: Sequence[Any]) -> list[Any]:
    """B's chunks under ``ghost/``: its robots, target, movers and detections pale and
    labelled ``(B)``, its lanes, event log and rounds as they are, its metrics named
    ``B ...``; its world's fixed parts and its sensor data left out."""
    pale = Restyle(colors=ghost_color, label=" (B)")
    out: list[Any] = []
    for chunk in chunks:
        path = chunk.entity_path
        parts = path.strip("/").split("/")
        if path.startswith("/world/") and not path.startswith(B_WORLD):
            continue
        if parts[0] == "robots" and len(parts) > 2 and parts[2] in B_SKIPPED:
            continue
        lane = parts[0] == "robots" and len(parts) > 2 and parts[2] in ("state", "task")
        if path.startswith(f"/{paths.MISSION_METRICS}"):
            style = Restyle(series="B ")
        elif (parts[0] in ("robots", "world") and not lane) or \
                path == f"/{paths.MISSION_DETECTIONS}":
            style = pale
        else:
            style = Restyle()
        out += resent(chunk, f"/{GHOST}{path}", style)
    return out
