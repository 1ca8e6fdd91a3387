"""The mission schema's building blocks: strict models and checked numbers."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import AfterValidator, BaseModel, ConfigDict, Field

from astralis_des.kinds import KINDS, known_kind

# Every number is finite: no .inf time limits, no .nan positions; and no coordinate beyond
# what any site holds (1,000 km), so arithmetic on it cannot overflow.
Finite = Annotated[float, Field(allow_inf_nan=False, ge=-1e6, le=1e6)]
PositiveFloat = Annotated[float, Field(gt=0, allow_inf_nan=False)]
MAX_SPEED = 100.0  # m/s: faster than any robot of a search team (a speed of 1e308 overflowed)
NonNegativeFloat = Annotated[float, Field(ge=0, allow_inf_nan=False)]
Vec3 = tuple[Finite, Finite, Finite]
# a registered robot kind (the paper's three, or one a plug-in adds: astralis_des.kinds)
Kind = Annotated[str, AfterValidator(known_kind),
                 Field(json_schema_extra=lambda schema: schema.update(enum=list(KINDS)))]
Unit = Annotated[float, Field(ge=0.0, le=1.0)]
Sound = Literal["minimal", "moderate", "loud"]
NAME_MAX = 200  # characters of a name that becomes a folder (file systems allow 255 bytes)


def _plain(name: str) -> str:
    if name in (".", ".."):  # out/.. is the working folder itself
        raise ValueError(f"'{name}' is not a plain file name: it names the output folder "
                         "(out/NAME); use letters, digits, _ . -")
    return name


# A name that becomes a folder: a plain file name, never a path (no /, not . or ..).
FileName = Annotated[str, Field(pattern=r"^[A-Za-z0-9_.-]+$", max_length=NAME_MAX),
                     AfterValidator(_plain)]


class Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
