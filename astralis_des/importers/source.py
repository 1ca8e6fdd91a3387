"""What a reader hands over (a cloud or a mesh, in the file's units), the checks every file
passes before a reader sees it, and the registry of readers by file extension."""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from astralis_des.errors import InputError
from astralis_des.registry import Registry, UnknownEntry
from astralis_des.world.geometry import FloatArray

FOOT = 0.3048  # m, the international foot
US_SURVEY_FOOT = 1200 / 3937  # m
UNITS = {"m": 1.0, "ft": FOOT}


@dataclass
class Cloud:
    """Points as read, in the file's units: ``xyz + ref`` are the file's coordinates (a reader
    may keep them as float32 offsets from ``ref`` to halve their memory)."""

    xyz: FloatArray  # (N, 3), float64 or float32
    classification: NDArray[np.uint8] | None = None  # ASPRS classes, when the file has them
    colors: NDArray[np.uint8] | None = None  # (N, 3)
    crs_scale: float | None = None  # m per horizontal unit, from the file's CRS
    crs_vertical: float | None = None  # m per vertical unit, when the CRS says
    crs_note: str = ""  # where the units came from, for the world file
    crs_wkt: str | None = None  # the file's coordinate system (WKT), when it has one
    ref: FloatArray = field(default_factory=lambda: np.zeros(3))  # file units
    resolution: float | None = None  # the file's coordinate step (a LAS scale factor)
    held: int | None = None  # points the file holds, when more than were kept
    notes: list[str] = field(default_factory=list)  # what the reader did about the file


@dataclass
class Mesh:
    """Triangles as read, in the file's units and axes."""

    vertices: FloatArray  # (V, 3)
    faces: NDArray[np.int64]  # (F, 3)
    up: str | None = None  # the axis pointing up when the format says ("y" for glTF)
    watertight: bool = False
    extra: dict[str, object] = field(default_factory=dict)


@dataclass(frozen=True)
class ReadRequest:
    """What a reader is asked besides the file."""

    partial: bool = False  # read a truncated file as far as it goes, instead of refusing it
    max_points: int | None = None  # keep at most this many (evenly); None: what memory allows
    progress: Callable[[int, int], None] | None = None  # (points read, points in all)


Reader = Callable[[Path, ReadRequest], Cloud | Mesh]
READERS: Registry[str, Reader] = Registry("file format")
# Bytes of memory a file needs per byte on disk (or per point, for LAS/LAZ) while imported.
MEMORY_PER_BYTE: dict[str, float] = {}


def reader(*extensions: str, memory_per_byte: float) -> Callable[[Reader], Reader]:
    """Register a reader for these extensions (lower case, no dot)."""
    def add(fn: Reader) -> Reader:
        for ext in extensions:
            READERS.register(ext)(fn)
            MEMORY_PER_BYTE[ext] = memory_per_byte
        return fn

    return add


def extension(path: Path) -> str:
    return path.suffix.lower().lstrip(".")


def lookup(path: Path) -> Reader:
    try:
        return READERS.get(extension(path))
    except UnknownEntry:
        known = ", ".join(f".{e}" for e in READERS)
        raise InputError(f"unknown format '{path.suffix or '(no extension)'}'; "
                         f"known: {known}", file=path) from None


def check_file(path: Path) -> None:
    """A file that exists, is not empty and fits in memory, or an :class:`InputError`."""
    if not path.exists():
        raise InputError("no such file", file=path)
    if not path.is_file():
        raise InputError("not a file", file=path)
    size = path.stat().st_size
    if size == 0:
        raise InputError("the file is empty", file=path)
    need = size * MEMORY_PER_BYTE.get(extension(path), 10.0)
    check_memory(path, need, f"a {size / 1e6:,.0f} MB file")


def check_memory(path: Path, need: float, what: str) -> None:
    have = available_memory()
    if need > have:
        raise InputError(f"{what} needs about {need / 1e9:,.1f} GB of memory to import; "
                         f"{have / 1e9:,.1f} GB is available", file=path)


def available_memory() -> float:
    """Bytes this process may still allocate: the system's available memory, or less under a
    resource limit."""
    import resource

    have = float("inf")
    try:
        with open("/proc/meminfo", encoding="ascii") as info:
            for line in info:
                if line.startswith("MemAvailable:"):
                    have = float(line.split()[1]) * 1024
    except OSError:
        pages = os.sysconf("SC_AVPHYS_PAGES") if hasattr(os, "sysconf") else -1
        if pages > 0:
            have = float(pages * os.sysconf("SC_PAGE_SIZE"))
    soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    if soft != resource.RLIM_INFINITY:
        have = min(have, float(soft))
    return have


def unit_scale(units: str, crs_scale: float | None) -> float:
    """Metres per unit: the file's CRS (``auto``) or the given unit."""
    if units == "auto":
        return crs_scale if crs_scale is not None else 1.0
    if units not in UNITS:
        raise InputError(f"unknown units '{units}'; valid: auto, {', '.join(UNITS)}",
                         key="--units")
    return UNITS[units]


def finite_rows(xyz: FloatArray) -> NDArray[np.bool_]:
    return np.asarray(np.isfinite(xyz).all(axis=1))
