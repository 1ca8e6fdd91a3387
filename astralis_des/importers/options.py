"""What an import is asked to do (:class:`ImportOptions`), what it makes before anything is
written (:class:`Built`), and what it reports (:class:`ImportReport`)."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from astralis_des.errors import InputError
from astralis_des.importers.areas import Area
from astralis_des.importers.source import UNITS
from astralis_des.world.geometry import FloatArray

FILLS = ("auto", "columns", "none")
COLLISIONS = ("auto", "boxes", "concave", "convex")
UPS = ("auto", "y", "z")
GROUNDS = ("auto", "classification", "grid", "ransac")


@dataclass(frozen=True)
class ImportOptions:
    units: str = "auto"  # auto (the file's CRS, else guessed) | m | ft | us-ft
    crs: str | None = None  # the file's coordinate system, over what the file says
    voxel: float | None = None  # m; None: from the points' spacing (clouds), 0.2 (meshes)
    ground: str = "auto"  # auto | classification | grid | ransac (clouds)
    fill: str = "auto"  # columns | none | auto: columns for LAS/LAZ (aerial), none otherwise
    up: str = "auto"  # the file's up axis (meshes): auto | y | z
    scale: float = 1.0  # times the units
    collision: str = "auto"  # boxes (clouds) | concave (meshes, auto) | convex
    areas: int = 4  # search areas to place
    area_size: float = 20.0  # m, their side
    margin: float = 2.0  # m of site around the geometry
    cloud_points: int = 50_000  # points kept for the replay
    seed: int = 0  # of every random draw (RANSAC, downsampling)
    name: str | None = None  # the world's name; default: the output file's stem
    format: str | None = None  # read the file as this format, whatever its extension
    partial: bool = False  # import what a truncated file holds
    max_points: int | None = None  # keep at most this many points (evenly); None: by memory
    keep_strays: bool = False  # keep points far from the rest of the cloud
    indoor: bool = False  # find storeys, rooms and doors (an indoor scan or model)
    group: str = "A"  # the id of the building an indoor import finds
    door_max: float = 1.4  # m, the widest passage that still parts two rooms (indoor)

    def check(self) -> None:
        """Refuse nonsense at the edge, naming the option."""
        def need(ok: bool, key: str, message: str) -> None:
            if not ok:
                raise InputError(message, key=key)

        for key, value, valid in (("--units", self.units, ("auto", *UNITS)),
                                  ("--ground", self.ground, GROUNDS),
                                  ("--fill", self.fill, FILLS), ("--up", self.up, UPS),
                                  ("--collision", self.collision, COLLISIONS)):
            need(value in valid, key, f"'{value}' is not one of: {', '.join(valid)}")
        for key, number in (("--voxel", self.voxel), ("--scale", self.scale),
                            ("--area-size", self.area_size), ("--door-max", self.door_max)):
            if number is not None:
                need(math.isfinite(number) and number > 0, key,
                     f"must be a positive number, got {number:g}")
        if self.voxel is not None:
            need(self.voxel <= 10.0, "--voxel", f"{self.voxel:g} m is coarser than 10 m")
        need(self.max_points is None or self.max_points >= 1, "--max-points",
             "must be at least 1")
        need(math.isfinite(self.margin) and self.margin >= 0, "--margin",
             f"must be 0 or more, got {self.margin:g}")
        need(self.areas >= 0, "--areas", f"must be 0 or more, got {self.areas}")
        need(self.cloud_points >= 0, "--cloud-points", "must be 0 or more")
        need(re.fullmatch(r"[A-Za-z][A-Za-z0-9]*", self.group) is not None, "--group",
             f"'{self.group}' is no building id: a letter, then letters or digits")


@dataclass
class Built:
    """An imported world before it is written: world-frame geometry and the world file's
    ``source`` and ``geometry`` facts."""

    kind: str  # cloud | mesh
    site: tuple[float, float]
    voxel: float
    boxes: NDArray[np.int64]  # (K, 6) voxel index ranges
    areas: list[Area]
    source: dict[str, Any]
    collision: str
    floors: list[float] = field(default_factory=list)
    vertices: FloatArray | None = None  # world frame
    faces: NDArray[np.int64] | None = None
    parts: list[tuple[FloatArray, NDArray[np.int64]]] | None = None  # convex parts
    cloud: NDArray[np.float32] | None = None  # (N, 3), world frame
    cloud_colors: NDArray[np.uint8] | None = None
    stats: dict[str, Any] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)  # what was chosen, guessed or left out
    interior: dict[str, Any] | None = None  # the world file's interior: section (indoor)


@dataclass(frozen=True)
class ImportReport:
    """What an import wrote and found, for a person (the CLI) or a test."""

    world: Path
    files: tuple[Path, ...]
    kind: str
    points: int  # points read (cloud) or faces (mesh)
    dropped: int  # with NaN or infinite coordinates
    units: str
    scale: float
    site: tuple[float, float]
    blocks: int
    areas: tuple[str, ...]
    floors: tuple[float, ...]
    ground: str | None = None
    ground_share: float | None = None
    classified_share: float | None = None  # class 2 in the file, when it says
    seconds: float = 0.0
    extra: dict[str, Any] = field(default_factory=dict)
    notes: tuple[str, ...] = ()  # what was chosen, guessed or left out, a line each
    voxel: float = 0.0
    rooms: int = 0  # rooms found indoors (searched)
    doors: int = 0
