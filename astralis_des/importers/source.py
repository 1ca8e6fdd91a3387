"""What a reader hands over (a cloud or a mesh, in the file's units), the checks every file
passes before a reader sees it, and the registry of readers by file extension."""

from __future__ import annotations

import os
import stat
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from astralis_des.errors import InputError
from astralis_des.registry import Registry, UnknownEntry
from astralis_des.world.geometry import FloatArray

FOOT = 0.3048  # m, the international foot
US_SURVEY_FOOT = 1200 / 3937  # m
UNITS = {"m": 1.0, "ft": FOOT, "us-ft": US_SURVEY_FOOT}


@dataclass
class Cloud:
    """Points as read: the file's coordinates are ``xyz * step + ref``. A LAS reader keeps the
    file's own integers with its scale and offset (12 bytes a point, exact); other readers keep
    floats, with a step of one and no offset."""

    xyz: NDArray[Any]  # (N, 3): int32 with step and ref, or float
    classification: NDArray[np.uint8] | None = None  # ASPRS classes, when the file has them
    colors: NDArray[np.uint8] | None = None  # (N, 3)
    crs_scale: float | None = None  # m per horizontal unit, from the file's CRS
    crs_vertical: float | None = None  # m per vertical unit, when the CRS says
    crs_note: str = ""  # where the units came from, for the world file
    crs_wkt: str | None = None  # the file's coordinate system (WKT), when it has one
    step: FloatArray = field(default_factory=lambda: np.ones(3))
    ref: FloatArray = field(default_factory=lambda: np.zeros(3))
    resolution: float | None = None  # the file's coordinate step (a LAS scale factor)
    held: int | None = None  # points the file holds, when not all were kept
    notes: list[str] = field(default_factory=list)  # what the reader did about the file

    def __len__(self) -> int:
        return len(self.xyz)

    def coordinates(self, lo: int, hi: int) -> FloatArray:
        """Rows ``lo:hi`` in the file's units, as float64 (as laspy scales them)."""
        block = self.xyz[lo:hi]
        if block.dtype.kind == "f" and not self.ref.any() and (self.step == 1).all():
            return np.asarray(block, dtype=np.float64)
        with np.errstate(over="ignore", invalid="ignore"):  # inf and NaN are left out later
            return np.asarray(block * self.step + self.ref, dtype=np.float64)


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
KEPT_POINT_BYTES = 64  # memory an imported point costs at the import's peak
DEFAULT_MAX_POINTS = 50_000_000  # beyond this a cloud is thinned unless --max-points says


def max_points(request: ReadRequest) -> int:
    """The most points to keep: as asked, else what half the available memory holds (at most
    ``DEFAULT_MAX_POINTS``)."""
    if request.max_points is not None:
        return max(request.max_points, 1)
    room = available_memory() / 2 / KEPT_POINT_BYTES
    return int(max(min(room, DEFAULT_MAX_POINTS), 1_000))
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


def lookup(path: Path, fmt: str) -> Reader:
    """The reader of format ``fmt`` (a file's extension, or ``--format``)."""
    try:
        return READERS.get(fmt.lower().lstrip("."))
    except UnknownEntry:
        known = ", ".join(f".{e}" for e in READERS)
        if fmt == extension(path):
            raise InputError(f"unknown format '{path.suffix or '(no extension)'}'; "
                             f"known: {known}; --format reads it as one of them",
                             file=path) from None
        raise InputError(f"unknown format '{fmt}'; known: {known}", key="--format") from None


def check_file(path: Path, fmt: str) -> None:
    """A regular file that is not empty and fits in memory, or an :class:`InputError`: a
    folder, a FIFO or a device (``/dev/zero``) is refused before anything reads it."""
    try:
        info = path.stat()
    except FileNotFoundError:
        raise InputError("no such file", file=path) from None
    except OSError as exc:
        raise InputError(f"cannot be read ({exc.strerror})", file=path) from None
    if stat.S_ISDIR(info.st_mode):
        raise InputError("a folder, not a file", file=path)
    if not stat.S_ISREG(info.st_mode):
        kind = "a FIFO" if stat.S_ISFIFO(info.st_mode) else "a device" if (
            stat.S_ISCHR(info.st_mode) or stat.S_ISBLK(info.st_mode)) else "a special file"
        raise InputError(f"{kind}, not a regular file: import reads files it can measure",
                         file=path)
    if not os.access(path, os.R_OK):
        raise InputError("cannot be read (permission denied)", file=path)
    size = info.st_size
    if size == 0:
        raise InputError("the file is empty", file=path)
    need = size * MEMORY_PER_BYTE.get(fmt.lower().lstrip("."), 10.0)
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
