"""The clutter catalogue: which furniture a room can hold, how big, and how much per messiness.

A catalogue file lists item types (``items:``), the door keep-out, the passage width a robot
needs and the bystander avatars with their allowed Table II attributes. Unknown keys and types
are refused with a "did you mean"; an attribute value outside Table II names its key.
"""

from __future__ import annotations

from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, StrictBool, ValidationInfo, field_validator

PositiveFloat = Annotated[float, Field(gt=0, allow_inf_nan=False)]
NonNegativeFloat = Annotated[float, Field(ge=0, allow_inf_nan=False)]
Size = tuple[PositiveFloat, PositiveFloat, PositiveFloat]

# The paper's Table II: what a human avatar may look like and do.
Activity = Literal["sitting", "laying", "patrolling", "idle"]
Color = Literal["yellow", "red", "purple", "blue"]
Gender = Literal["male", "female"]
Height = Literal["tall", "medium", "short"]

AVATAR_HEIGHTS: dict[str, float] = {"tall": 1.85, "medium": 1.72, "short": 1.58}
SITTING_HEIGHT = 1.3
AVATAR_FOOTPRINT = (0.5, 0.5)
LAYING_SIZE = (1.8, 0.6, 0.35)


class Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class ItemSpec(Strict):
    """One item type: sizes are width (along a wall) x depth x height, in metres."""

    size_min: Size
    size_max: Size
    per_10m2_at_full: NonNegativeFloat = Field(
        description="items per 10 m^2 of free floor at messiness 1")
    against_wall: StrictBool = Field(False, description="placed with its back to a wall")
    clearance: NonNegativeFloat = Field(0.1, description="m kept free around it")

    @field_validator("size_max")
    @classmethod
    def _not_below_min(cls, size_max: tuple[float, ...], info: ValidationInfo) -> tuple[float, ...]:
        size_min = info.data.get("size_min")
        if size_min is not None:
            bad = [f"{axis} {lo:g} > {hi:g}"
                   for axis, lo, hi in zip(("w", "d", "h"), size_min, size_max, strict=True)
                   if lo > hi]
            if bad:
                raise ValueError(f"size_max is below size_min ({', '.join(bad)})")
        return size_max


class ItemsSpec(Strict):
    """The item types a catalogue may list; a type left out is never placed."""

    cabinet: ItemSpec | None = None
    computer_desk: ItemSpec | None = None
    table: ItemSpec | None = None
    potted_plant: ItemSpec | None = None
    chair: ItemSpec | None = None

    def present(self) -> dict[str, ItemSpec]:
        """The listed types, in placement order: against-wall and large ones first."""
        listed = {name: getattr(self, name) for name in type(self).model_fields}
        return {name: spec for name, spec in listed.items() if spec is not None}


ITEM_KINDS: tuple[str, ...] = tuple(ItemsSpec.model_fields)


class AvatarAttributes(Strict):
    """Allowed values of each Table II attribute; a bystander draws one of each uniformly."""

    activity: tuple[Activity, ...] = Field(
        ("sitting", "laying", "patrolling", "idle"), min_length=1)
    color: tuple[Color, ...] = Field(("yellow", "red", "purple", "blue"), min_length=1)
    gender: tuple[Gender, ...] = Field(("male", "female"), min_length=1)
    height: tuple[Height, ...] = Field(("tall", "medium", "short"), min_length=1)
    tied_to_chair: tuple[StrictBool, ...] = Field((True, False), min_length=1)


def agree(values: dict[str, object], given: frozenset[str] = frozenset()) -> dict[str, object]:
    """Table II's attributes, drawn one by one, made to agree: only a sitting avatar is tied to
    a chair. What a file gave (``given``) stands; a drawn value gives way to it."""
    if values.get("tied_to_chair") and values.get("activity") != "sitting":
        if "tied_to_chair" in given and "activity" not in given:
            values["activity"] = "sitting"
        else:
            values["tied_to_chair"] = False
    return values


class AvatarsSpec(Strict):
    """Human bystanders: ``round(messiness * per_room_at_full)`` per room."""

    per_room_at_full: NonNegativeFloat = 1.0
    clearance: NonNegativeFloat = 0.2
    attributes: AvatarAttributes = Field(default_factory=AvatarAttributes)


class Catalogue(Strict):
    items: ItemsSpec
    door_keepout: tuple[PositiveFloat, PositiveFloat] = Field(
        (1.2, 1.4), description="depth into the room and width of the empty area at the door")
    passage: PositiveFloat = Field(
        0.7, description="m; every free region stays reachable from the door this wide")
    avatars: AvatarsSpec = Field(default_factory=AvatarsSpec)


def avatar_size(activity: str, height: str) -> tuple[float, float, float]:
    """Width x depth x height of a bystander doing ``activity``."""
    if activity == "laying":
        return LAYING_SIZE
    tall = SITTING_HEIGHT if activity == "sitting" else AVATAR_HEIGHTS[height]
    return (*AVATAR_FOOTPRINT, tall)


def load_catalogue(path: str | Path) -> Catalogue:
    """Read and validate a catalogue file (YAML or JSON)."""
    from astralis_des.validation import validate
    from astralis_des.yamlio import load_yaml

    return validate(Catalogue, load_yaml(path))


@lru_cache(maxsize=1)
def default_catalogue() -> Catalogue:
    """The packaged ``data/clutter_default.yaml``."""
    ref = resources.files("astralis_des") / "data" / "clutter_default.yaml"
    with resources.as_file(ref) as path:
        return load_catalogue(path)
