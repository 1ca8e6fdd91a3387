"""What a study draws for each scenario: room risk and messiness, agents' starts, a segment.

A scenario's seed comes from the study's seed and its index alone, so a scenario is the same
whichever worker runs it. Its draws are uniforms from its own streams; a distribution turns
them into values through its quantile function, so two variants that differ only in the
distribution of risk still share the underlying randomness (common random numbers).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Annotated, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field, model_validator

from astralis_des.kinds import KIND_DEFAULTS, KINDS
from astralis_des.mission.spec import PositiveFloat, Strict, Unit
from astralis_des.streams import stream
from astralis_des.world.placement import blocking

if TYPE_CHECKING:
    from astralis_des.mission.loader import Mission

Point = tuple[float, float, float]
# Keys within the "study" stream: one purpose each, so that drawing more for one never
# shifts another.
_RISK, _MESSINESS, _START, _SEGMENT = 1, 2, 3, 4


def scenario_seed(study_seed: int, index: int) -> int:
    """The seed of scenario ``index`` of a study seeded ``study_seed`` (also its mission's)."""
    return int(np.random.SeedSequence([study_seed, index]).generate_state(1)[0])


# -- distributions of a room's risk or messiness ----------------------------------------------
class Uniform(Strict):
    """Uniform on [low, high] (the paper: [0, 1])."""

    dist: Literal["uniform"] = "uniform"
    low: Unit = 0.0
    high: Unit = 1.0

    @model_validator(mode="after")
    def _ordered(self) -> Uniform:
        if self.low > self.high:
            raise ValueError(f"low {self.low} is above high {self.high}")
        return self

    def ppf(self, u: NDArray[np.float64]) -> NDArray[np.float64]:
        return self.low + u * (self.high - self.low)


class Beta(Strict):
    """Beta(a, b) on [0, 1]: a < b leans calm or tidy, a > b dangerous or cluttered."""

    dist: Literal["beta"]
    a: PositiveFloat
    b: PositiveFloat

    def ppf(self, u: NDArray[np.float64]) -> NDArray[np.float64]:
        from scipy.stats import beta

        return np.asarray(beta.ppf(u, self.a, self.b), dtype=float)


class Constant(Strict):
    """The same value in every room."""

    dist: Literal["constant"]
    value: Unit

    def ppf(self, u: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.full_like(u, self.value)


Dist = Annotated[Uniform | Beta | Constant, Field(discriminator="dist")]


# -- where the agents start ----------------------------------------------------------------
class Sampler:
    """Draws the start of the ``k``-th agent of a kind (picklable: workers get a copy)."""

    def __call__(self, gen: np.random.Generator, kind: str, k: int) -> Point | str:
        raise NotImplementedError


@dataclass(frozen=True)
class _MissionStarts(Sampler):
    by_kind: dict[str, list[Point | str]]

    def __call__(self, gen: np.random.Generator, kind: str, k: int) -> Point | str:
        starts = self.by_kind[kind]
        return starts[k % len(starts)]


@dataclass(frozen=True)
class _BoxStarts(Sampler):
    lo: NDArray[np.float64]  # (B, 3) floor corners of the boxes
    hi: NDArray[np.float64]
    cdf: NDArray[np.float64]  # cumulative shares of the floor area

    def __call__(self, gen: np.random.Generator, kind: str, k: int) -> Point:
        # What gen.choice(B, p=...) and gen.uniform(lo, hi) draw, bit for bit, in a tenth of
        # the time: Table V's 1,000 scenarios draw 4,000 starts.
        i = int(self.cdf.searchsorted(gen.random(), side="right"))
        x, y = self.lo[i, :2] + (self.hi[i, :2] - self.lo[i, :2]) * gen.random(2)
        return (float(x), float(y), float(self.lo[i, 2]))


@dataclass(frozen=True)
class _OutdoorStarts(Sampler):
    mission: Mission
    centre: tuple[float, float]
    radius: float

    def __call__(self, gen: np.random.Generator, kind: str, k: int) -> Point:
        cx, cy, r = *self.centre, self.radius
        for _ in range(200):
            x, y = gen.uniform([cx - r, cy - r], [cx + r, cy + r])
            p = (float(x), float(y), 0.0)
            if self.mission.world.contains(p) and _outdoors(self.mission, p) and \
                    _clear(self.mission, p, kind):
                return p
        raise RuntimeError(f"no clear outdoor spot within {r} m of {self.centre}")


class FromMission(Strict):
    """As the base mission says: the k-th agent of a kind starts where the mission's k-th
    agent of that kind does (cycling; a kind the mission lacks starts at its first agent)."""

    type: Literal["mission"] = "mission"

    def sampler(self, mission: Mission) -> Sampler:
        team = mission.spec.team

        def start(value: tuple[float, ...] | str) -> Point | str:
            return value if isinstance(value, str) else _point(value)

        return _MissionStarts({kind: [start(m.start) for m in team if m.kind == kind]
                               or [start(team[0].start)] for kind in KINDS})


class InBuilding(Strict):
    """Uniform over the floor of the searched buildings' rooms and corridors, any storey."""

    type: Literal["building"]
    margin: Annotated[float, Field(ge=0, le=1)] = 0.4  # m kept from the walls

    def sampler(self, mission: Mission) -> Sampler:
        world = mission.world
        buildings = {world.segments[s].building for s in mission.searched_segments()}
        boxes = [r.box for r in world.rooms.values() if r.building in buildings]
        boxes += [s.box for s in world.spaces.values()
                  if s.kind in ("corridor", "passage") and s.building in buildings]
        lo = np.array([b.lo for b in boxes]) + [self.margin, self.margin, 0.0]
        hi = np.array([b.hi for b in boxes]) - [self.margin, self.margin, 0.0]
        area = np.prod(np.maximum(hi - lo, 0.0)[:, :2], axis=1)
        cdf = np.cumsum(area)
        return _BoxStarts(lo, hi, cdf / cdf[-1])


class Outdoor(Strict):
    """Uniform outdoors within ``radius`` of the first searched building's entrance, clear of
    buildings and obstacles."""

    type: Literal["outdoor"]
    radius: PositiveFloat = 25.0

    def sampler(self, mission: Mission) -> Sampler:
        world = mission.world
        first = world.segments[mission.searched_segments()[0]].building
        if first not in world.entrances:
            from astralis_des.errors import InputError

            raise InputError(f"starts: outdoor starts are drawn round {first}'s entrance, and "
                             f"{first} has none (an interior found no door to the outside)",
                             key="starts")
        ex, ey, _ = world.entrances[first]
        return _OutdoorStarts(mission, (ex, ey), self.radius)


def _outdoors(mission: Mission, p: Point) -> bool:
    from astralis_des.errors import InputError

    try:
        return mission.world.router.place_of(p) == "outdoor"
    except InputError:  # inside an obstacle
        return False


def _clear(mission: Mission, p: Point, kind: str) -> bool:
    """Whether a robot of ``kind`` standing at ``p`` is clear of every solid by its body's
    radius, as the mission validator wants a start (a draw beside a wall made a failed run)."""
    which, _ = blocking(mission.world, np.array([p]), KIND_DEFAULTS[kind].radius)
    return bool(which[0] < 0)


Positions = Annotated[FromMission | InBuilding | Outdoor, Field(discriminator="type")]


def _point(v: tuple[float, ...]) -> Point:
    return (float(v[0]), float(v[1]), float(v[2]))


# -- one scenario ----------------------------------------------------------------------------
@dataclass
class Scenario:
    """The draws of one scenario, shared by every variant it is run under."""

    index: int
    seed: int
    rooms: tuple[str, ...]  # every room of the world, in id order
    u_risk: NDArray[np.float64]  # a uniform per room, turned into risk by a distribution
    u_messiness: NDArray[np.float64]
    segment: str  # the segment an assignment study matches to (unused by missions)
    sampler: Sampler = field(repr=False)
    _starts: dict[tuple[str, int], Point | str] = field(default_factory=dict, repr=False)

    def start(self, kind: str, k: int) -> Point | str:
        """Where the ``k``-th agent of ``kind`` starts (0-based): a point or a room id.

        Each (kind, k) has its own stream, so a larger team keeps the starts of a smaller one.
        """
        key = (kind, k)
        if key not in self._starts:
            gen = stream(self.seed, "study", _START, KINDS.index(kind), k)
            self._starts[key] = self.sampler(gen, kind, k)
        return self._starts[key]

    def values(self, risk: Dist, messiness: Dist) -> dict[str, tuple[float, float]]:
        """Each room's (risk, messiness) under these distributions."""
        r, m = risk.ppf(self.u_risk), messiness.ppf(self.u_messiness)
        return {room: (float(r[i]), float(m[i])) for i, room in enumerate(self.rooms)}


def draw_scenario(mission: Mission, sampler: Sampler, segments: list[str], study_seed: int,
                  index: int) -> Scenario:
    seed = scenario_seed(study_seed, index)
    rooms = tuple(sorted(mission.world.rooms))
    u_risk = stream(seed, "study", _RISK).uniform(size=len(rooms))
    u_mess = stream(seed, "study", _MESSINESS).uniform(size=len(rooms))
    segment = segments[int(stream(seed, "study", _SEGMENT).integers(len(segments)))]
    return Scenario(index, seed, rooms, u_risk, u_mess, segment, sampler)
