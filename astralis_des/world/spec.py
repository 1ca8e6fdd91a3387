"""The world file's schema (``worlds/*.yaml``), validated at the edge."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Field,
    NonNegativeInt,
    PositiveInt,
    ValidationInfo,
    field_validator,
    model_validator,
)

from astralis_des.kinds import KIND_DEFAULTS, KINDS, known_kind, largest

# Every number is finite (no .nan origin, no .inf size) and no coordinate or size is beyond
# what any site holds (1,000 km, as in missions), so that arithmetic on them cannot overflow.
MAX_EXTENT = 1_000_000.0  # m
Coordinate = Annotated[float, Field(allow_inf_nan=False, ge=-MAX_EXTENT, le=MAX_EXTENT)]
Length = Annotated[float, Field(gt=0, le=MAX_EXTENT, allow_inf_nan=False)]
Finite = Annotated[float, Field(allow_inf_nan=False)]
Vec2 = tuple[Coordinate, Coordinate]
Vec3 = tuple[Coordinate, Coordinate, Coordinate]
Size3 = tuple[Length, Length, Length]
# a registered robot kind (the paper's three, or one a plug-in adds)
Kind = Annotated[str, AfterValidator(known_kind),
                 Field(json_schema_extra=lambda schema: schema.update(enum=list(KINDS)))]


class Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


MIN_WALL = 0.05  # m: a wall 1e-9 m thick made rooms of triangles of no area
MAX_ROOMS = 10_000  # rooms of a world: loaded and routed in 0.6 s and 0.14 GB (bench_world)
def robot() -> tuple[str, float]:
    """The longest body's kind and length (m): a room or a corridor must hold it."""
    kind = largest()
    return kind, KIND_DEFAULTS[kind].length


def fits_a_robot(inside: tuple[float, ...]) -> bool:
    return min(inside) >= robot()[1]


class SegmentSpec(Strict):
    side: Literal["north", "south"]
    rooms: PositiveInt = Field(description="rooms in this segment, laid along the corridor")


class BuildingSpec(Strict):
    id: str = Field(pattern=r"^[A-Za-z][A-Za-z0-9]*$", description="letter(s) used in room ids")
    origin: Vec2 = Field(description="south-west corner of the footprint, metres")
    floors: PositiveInt
    floor_height: Length = 3.5
    wall_thickness: Length = Field(0.2, ge=MIN_WALL, description="m; at least 0.05 (a "
                                   "thinner wall is one no sensor or physics body can see)")
    room_size: tuple[Length, Length] = Field(
        (4.0, 7.0), validate_default=True, description="room width along the corridor and "
        "depth away from it, walls included: inside them, each side at least as long as the "
        "longest robot")
    corridor_width: Length = Field(2.5, validate_default=True,
                                   description="walls included, like room_size")
    stairwell_width: Length = 4.0
    lobby_length: Length = 4.0
    door_width: Length = 1.0
    door_height: Length = 2.1
    stairs_passable_by: list[Kind] = Field(
        default_factory=lambda: list(KINDS),
        description="who can change floors (stairs with a vehicle ramp by default)")
    segments: list[SegmentSpec] = Field(min_length=1)

    @field_validator("room_size", "corridor_width")
    @classmethod
    def _holds_a_robot(cls, size: tuple[float, float] | float,
                       info: ValidationInfo) -> tuple[float, float] | float:
        """Inside its walls, a room (or the corridor) holds the longest robot at any heading:
        a room 1e-9 m wide gave a search nothing to cover (NaN in the summary)."""
        t = info.data.get("wall_thickness")
        sides = size if isinstance(size, tuple) else (size,)
        if t is None or fits_a_robot(tuple(s - t for s in sides)):
            return size
        what = (f"rooms of {sides[0]:g} x {sides[1]:g} m are "
                f"{max(sides[0] - t, 0):.2f} x {max(sides[1] - t, 0):.2f} m" if len(sides) == 2
                else f"a corridor {sides[0]:g} m wide is {max(sides[0] - t, 0):.2f} m")
        kind, length = robot()
        raise ValueError(f"{what} inside their {t:g} m walls: smaller than a robot (a "
                         f"{kind} is {length:g} m long); make each at least {length + t:g} m")

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
    size: Size3 = Field(description="box extent x, y, z in metres")


class RoadSpec(Strict):
    """A straight stretch of road between two points: ground surface, not an obstacle."""

    start: Vec2
    end: Vec2
    width: Length = 7.0


class GeoOrigin(Strict):
    """Where the site's (0, 0, 0) lies on the Earth (WGS 84): an imported scan's, from its
    coordinate system."""

    latitude: Finite = Field(ge=-90, le=90, description="degrees north")
    longitude: Finite = Field(ge=-180, le=180, description="degrees east")
    altitude: Finite = Field(0.0, ge=-500, le=9000, description="m, of the ground")


class SiteSpec(Strict):
    size: tuple[Length, Length] = Field(description="outdoor area, metres")
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
        if not fits_a_robot((hi[0] - lo[0], hi[1] - lo[1])):
            kind, length = robot()
            raise ValueError(f"box: an area of {hi[0] - lo[0]:g} x {hi[1] - lo[1]:g} m is "
                             f"smaller than a robot (a {kind} is {length:g} m long)")
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
    scale: Length = Field(description="metres per unit of the file")
    up: Literal["y", "z"] = "z"
    offset: tuple[Finite, Finite, Finite] = Field(
        description="the file's coordinates (its units and axes) of this world's origin")
    ground: str | None = Field(None, description="how the ground was found (a cloud)")
    ground_share: float | None = Field(None, ge=0, le=1)
    relief: Finite | None = Field(None, ge=0, description="m of ground relief flattened")


class GeometrySpec(Strict):
    """An imported world's geometry, in files beside the world file."""

    voxel: Length = Field(0.2, description="m: the blocks' voxel and the planner's map")
    blocks: str | None = Field(None, description=".npz of merged voxel boxes: what blocks "
                               "sight and routes, and (collision: boxes) collides")
    mesh: str | None = Field(None, description=".obj of the imported mesh, in world "
                             "coordinates: the replay, floors, and (concave) collision")
    collision: Literal["boxes", "concave", "convex"] = "boxes"
    parts: str | None = Field(None, description=".obj of convex parts (collision: convex)")
    cloud: str | None = Field(None, description=".npz of a downsampled cloud for the replay")
    floors: list[Coordinate] = Field(default_factory=list, description="floor heights found, m")

    @model_validator(mode="after")
    def _files_for_collision(self) -> GeometrySpec:
        need = {"boxes": "blocks", "concave": "mesh", "convex": "parts"}[self.collision]
        if getattr(self, need) is None:
            raise ValueError(f"collision '{self.collision}' needs the file '{need}'")
        return self


# -- interior: a building found in a scan or model (``astralis world import --indoor``) ------
# A place is a room, a hall, a corridor or a stairwell, given by its outline on its storey's
# floor (a polygon, metres, walls left out). Rooms and halls are searched; corridors and
# stairwells are passages. Ids read GROUP.STOREY.SEGMENT.ROOM like the built-in buildings'
# rooms: a segment is the rooms off one corridor or hall; passages are segment 0.
PLACE_ID = r"^[A-Za-z][A-Za-z0-9]*\.[1-9][0-9]*\.[0-9]+\.[1-9][0-9]*$"
SEARCHED = ("room", "hall")  # the kinds of place a mission searches
PASSAGES = ("corridor", "stairwell")
OUTSIDE = "outside"  # a door's far side when it is an entrance


class StoreySpec(Strict):
    level: PositiveInt = Field(description="1 for the lowest; the STOREY of the places' ids")
    z: Coordinate = Field(description="m, the floor's height")
    height: Length = Field(description="m, floor to floor (the clear height of the top one)")


class PlaceSpec(Strict):
    id: str = Field(pattern=PLACE_ID, description="GROUP.STOREY.SEGMENT.ROOM; passages "
                    "(corridors, stairwells) are segment 0")
    kind: Literal["room", "hall", "corridor", "stairwell"] = Field(
        "room", description="rooms and halls are searched; corridors and stairwells are not")
    outline: list[Vec2] = Field(min_length=3, description="[[x, y], ...]: the floor's "
                                "outline inside the walls, metres")

    @property
    def storey(self) -> int:
        return int(self.id.split(".")[1])

    @property
    def searched(self) -> bool:
        return self.kind in SEARCHED

    @model_validator(mode="after")
    def _segment_fits_kind(self) -> PlaceSpec:
        passage = self.id.split(".")[2] == "0"
        if passage != (self.kind in PASSAGES):
            raise ValueError(f"a {self.kind}'s id has segment "
                             f"{'0' if self.kind in PASSAGES else '1 or more'}: "
                             f"'{self.id}'")
        return self


class DoorSpec(Strict):
    at: Vec2 = Field(description="[x, y]: the door's centre, in the middle of its wall")
    across: Literal["x", "y"] = Field(description="the way one walks through it: 'x' for a "
                                      "door in a wall along y")
    width: Length = Field(le=20.0, description="m, the free gap between its jambs")
    height: Length = Field(2.1, description="m, under its lintel")
    between: tuple[str, str] = Field(description="the places it joins: two ids, or an id and "
                                     f"'{OUTSIDE}' (an entrance)")


class StairSpec(Strict):
    between: tuple[str, str] = Field(description="two places on storeys one above the other "
                                     "(stairwells, or whatever holds the stairs)")
    passable_by: list[Kind] = Field(default_factory=lambda: list(KINDS),
                                    description="who can take them (all kinds by default)")


class InteriorSpec(Strict):
    """A building found in a scan or model; its places' ids start with ``group``."""

    group: str = Field(pattern=r"^[A-Za-z][A-Za-z0-9]*$", description="the building's letter(s)"
                       ": a mission's assignment.search names it")
    heading: float = Field(0.0, ge=-180, le=180, description="degrees the scan's walls ran "
                           "off its x axis: the world is the scan turned back by it, so that "
                           "they run along x and y (a point's xy in the file is the world's "
                           "turned by heading, plus source.offset)")
    storeys: list[StoreySpec] = Field(min_length=1, description="lowest first")
    places: list[PlaceSpec] = Field(min_length=1, description="rooms, halls, corridors and "
                                    "stairwells")
    doors: list[DoorSpec] = Field(default_factory=list, description="each room needs one")
    stairs: list[StairSpec] = Field(default_factory=list, description="between storeys")

    @field_validator("storeys")
    @classmethod
    def _levels_in_order(cls, storeys: list[StoreySpec]) -> list[StoreySpec]:
        levels = [s.level for s in storeys]
        if levels != list(range(1, len(levels) + 1)):
            raise ValueError(f"levels must be 1, 2, ... in order, got {levels}")
        heights = [s.z for s in storeys]
        if heights != sorted(heights) or len(set(heights)) != len(heights):
            raise ValueError(f"each storey's z must be above the one below, got {heights}")
        return storeys


class WorldSpec(Strict):
    name: str
    site: SiteSpec
    buildings: list[BuildingSpec] = Field(default_factory=list)
    areas: list[AreaSpec] = Field(default_factory=list)
    obstacles: list[ObstacleSpec] = Field(default_factory=list)
    roads: list[RoadSpec] = Field(default_factory=list)
    source: SourceSpec | None = None
    geometry: GeometrySpec | None = None
    interior: InteriorSpec | None = Field(None, description="a building found in an indoor "
                                          "scan or model (astralis world import --indoor)")

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
        if not self.buildings and not self.areas and self.interior is None:
            raise ValueError("a world needs buildings, areas or an interior: there is nothing "
                             "to search")
        return self
