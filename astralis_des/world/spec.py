"""The world file's schema (``worlds/*.yaml``), validated at the edge."""

from __future__ import annotations

from typing import Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
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


class SiteSpec(Strict):
    size: tuple[PositiveFloat, PositiveFloat] = Field(description="outdoor area, metres")


class WorldSpec(Strict):
    name: str
    site: SiteSpec
    buildings: list[BuildingSpec] = Field(min_length=1)
    obstacles: list[ObstacleSpec] = Field(default_factory=list)
    roads: list[RoadSpec] = Field(default_factory=list)

    @field_validator("buildings")
    @classmethod
    def _unique_ids(cls, buildings: list[BuildingSpec]) -> list[BuildingSpec]:
        ids = [b.id for b in buildings]
        if len(ids) != len(set(ids)):
            raise ValueError(f"building ids must be unique, got {ids}")
        return buildings
