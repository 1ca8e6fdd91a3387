"""The world file's schema (``worlds/*.yaml``), validated at the edge."""

from __future__ import annotations

from typing import Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    NonNegativeInt,
    PositiveFloat,
    PositiveInt,
    field_validator,
    model_validator,
)

Vec2 = tuple[float, float]
Vec3 = tuple[float, float, float]
Kind = Literal["uav", "ugv", "human"]
KINDS: tuple[Kind, ...] = ("uav", "ugv", "human")


class Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


MAX_ROOMS = 10_000  # rooms of a world: about 0.5 s to build; 200,000 took 42 s


class SegmentSpec(Strict):
    side: Literal["north", "south"]
    rooms: PositiveInt = Field(description="rooms in this segment, laid along the corridor")


class BuildingSpec(Strict):
    id: str = Field(pattern=r"^[A-Za-z][A-Za-z0-9]*$", description="letter(s) used in room ids")
    origin: Vec2 = Field(description="south-west corner of the footprint, metres")
    floors: PositiveInt
    floor_height: PositiveFloat = 3.5
    wall_thickness: PositiveFloat = 0.2
    room_size: tuple[PositiveFloat, PositiveFloat] = Field(
        (4.0, 7.0), description="room width along the corridor and depth away from it")
    corridor_width: PositiveFloat = 2.5
    stairwell_width: PositiveFloat = 4.0
    lobby_length: PositiveFloat = 4.0
    door_width: PositiveFloat = 1.0
    door_height: PositiveFloat = 2.1
    stairs_passable_by: list[Kind] = Field(
        default_factory=lambda: list(KINDS),
        description="who can change floors (stairs with a vehicle ramp by default)")
    segments: list[SegmentSpec] = Field(min_length=1)

    @model_validator(mode="after")
    def _not_too_big(self) -> BuildingSpec:
        rooms = self.floors * sum(s.rooms for s in self.segments)
        if rooms > MAX_ROOMS:  # refused before anything is built
            raise ValueError(f"building {self.id} has {rooms:,} rooms; a world holds at most "
                             f"{MAX_ROOMS:,}")
        return self

    @model_validator(mode="after")
    def _door_fits(self) -> BuildingSpec:
        if self.door_width >= self.room_size[0]:
            raise ValueError("door_width must be smaller than the room width")
        if self.door_height >= self.floor_height:
            raise ValueError("door_height must be lower than floor_height")
        return self


class ObstacleSpec(Strict):
    kind: str = Field(description="what it is (tree, vehicle, lamp_post, ...), shown in replays")
    center: Vec2
    size: Vec3 = Field(description="box extent x, y, z in metres")


class RoadSpec(Strict):
    """A straight stretch of road between two points: ground surface, not an obstacle."""

    start: Vec2
    end: Vec2
    width: PositiveFloat = 7.0


class GeoOrigin(Strict):
    """Where the site's (0, 0, 0) lies on the Earth (WGS 84): an imported scan's, from its
    coordinate system."""

    latitude: float = Field(ge=-90, le=90, description="degrees north")
    longitude: float = Field(ge=-180, le=180, description="degrees east")
    altitude: float = Field(0.0, ge=-500, le=9000, description="m, of the ground")


class SiteSpec(Strict):
    size: tuple[PositiveFloat, PositiveFloat] = Field(description="outdoor area, metres")
    origin: GeoOrigin | None = Field(None, description="where (0, 0, 0) lies on the Earth; "
                                     "the GNSS's origin unless the mission gives its own site")


AREA_ID = r"^[A-Za-z][A-Za-z0-9]*\.[1-9][0-9]*\.[1-9][0-9]*\.[1-9][0-9]*$"
Side = Literal["south", "west", "north", "east"]


class AreaSpec(Strict):
    """A search area: a box the team searches like a room, entered from one of its sides."""

    id: str = Field(pattern=AREA_ID, description="GROUP.LEVEL.SEGMENT.AREA, like a room id; "
                    "a mission's assignment.search names the group or a segment")
    box: tuple[Vec3, Vec3] = Field(description="[[x0, y0, floor], [x1, y1, top]], metres")
    entry: Side = Field("south", description="the side the team comes in from (its door)")

    @model_validator(mode="after")
    def _box_has_volume(self) -> AreaSpec:
        lo, hi = self.box
        if not all(a < b for a, b in zip(lo, hi, strict=True)):
            raise ValueError(f"box: each coordinate of {list(lo)} must be below {list(hi)}")
        return self


class SourceSpec(Strict):
    """Where an imported world came from, written by ``astralis world import``."""

    file: str = Field(description="the imported file, relative to the world file")
    format: str
    kind: Literal["cloud", "mesh"]
    bytes: NonNegativeInt
    sha256: str = Field(pattern=r"^[0-9a-f]{64}$")
    points: NonNegativeInt | None = Field(None, description="points read (a cloud)")
    faces: NonNegativeInt | None = Field(None, description="triangles read (a mesh)")
    dropped: NonNegativeInt = Field(0, description="points or vertices with NaN or infinite "
                                    "coordinates, left out")
    strays: NonNegativeInt = Field(0, description="points left out for lying far from the "
                                   "rest of the cloud")
    kept: NonNegativeInt | None = Field(None, description="points kept, when the cloud was "
                                        "thinned evenly to fit (--max-points)")
    units: str = Field(description="the file's unit and where it was found")
    scale: PositiveFloat = Field(description="metres per unit of the file")
    up: Literal["y", "z"] = "z"
    offset: Vec3 = Field(description="the file's coordinates (its units and axes) of this "
                         "world's origin")
    ground: str | None = Field(None, description="how the ground was found (a cloud)")
    ground_share: float | None = Field(None, ge=0, le=1)
    relief: float | None = Field(None, ge=0, description="m of ground relief flattened")


class GeometrySpec(Strict):
    """An imported world's geometry, in files beside the world file."""

    voxel: PositiveFloat = Field(0.2, description="m: the blocks' voxel and the planner's map")
    blocks: str | None = Field(None, description=".npz of merged voxel boxes: what blocks "
                               "sight and routes, and (collision: boxes) collides")
    mesh: str | None = Field(None, description=".obj of the imported mesh, in world "
                             "coordinates: the replay, floors, and (concave) collision")
    collision: Literal["boxes", "concave", "convex"] = "boxes"
    parts: str | None = Field(None, description=".obj of convex parts (collision: convex)")
    cloud: str | None = Field(None, description=".npz of a downsampled cloud for the replay")
    floors: list[float] = Field(default_factory=list, description="floor heights found, m")

    @model_validator(mode="after")
    def _files_for_collision(self) -> GeometrySpec:
        need = {"boxes": "blocks", "concave": "mesh", "convex": "parts"}[self.collision]
        if getattr(self, need) is None:
            raise ValueError(f"collision '{self.collision}' needs the file '{need}'")
        return self


class WorldSpec(Strict):
    name: str
    site: SiteSpec
    buildings: list[BuildingSpec] = Field(default_factory=list)
    areas: list[AreaSpec] = Field(default_factory=list)
    obstacles: list[ObstacleSpec] = Field(default_factory=list)
    roads: list[RoadSpec] = Field(default_factory=list)
    source: SourceSpec | None = None
    geometry: GeometrySpec | None = None

    @field_validator("buildings")
    @classmethod
    def _unique_ids(cls, buildings: list[BuildingSpec]) -> list[BuildingSpec]:
        ids = [b.id for b in buildings]
        if len(ids) != len(set(ids)):
            raise ValueError(f"building ids must be unique, got {ids}")
        rooms = sum(b.floors * sum(s.rooms for s in b.segments) for b in buildings)
        if rooms > MAX_ROOMS:  # each building may be under the bound, all of them not
            raise ValueError(f"the buildings have {rooms:,} rooms; a world holds at most "
                             f"{MAX_ROOMS:,}")
        return buildings

    @model_validator(mode="after")
    def _something_to_search(self) -> WorldSpec:
        if not self.buildings and not self.areas:
            raise ValueError("a world needs buildings or areas: there is nothing to search")
        return self
