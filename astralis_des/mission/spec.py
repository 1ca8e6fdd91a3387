"""The mission file's schema. Unknown keys are refused; defaults are what a user expects."""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import ConfigDict, Field, field_validator, model_validator

from astralis_des.kinds import known_kind
from astralis_des.mission.sensor_spec import (  # noqa: F401  (re-exported)
    _DEFAULT_SPECS,
    POSE_SENSORS,
    SENSORS,
    BarometerSpec,
    CameraSpec,
    GnssSpec,
    ImuSpec,
    Lidar3dSpec,
    LidarSpec,
    MagnetometerSpec,
    SensorsSpec,
    SiteSpec,
    carries,
)
from astralis_des.mission.types import (  # noqa: F401  (re-exported)
    MAX_SPEED,
    NAME_MAX,
    FileName,
    Finite,
    Kind,
    NonNegativeFloat,
    PositiveFloat,
    Sound,
    Strict,
    Unit,
    Vec3,
)
from astralis_des.plugins import ACTIONS


class MemberSpec(Strict):
    """One agent of the team."""

    id: str = Field(pattern=r"^[A-Za-z][A-Za-z0-9_-]*$")
    kind: Kind
    start: Vec3 | str = Field(description="[x, y, z] in metres (on the site, clear of solids "
                              "by its body), or a room id")
    speed: PositiveFloat | None = Field(None, le=MAX_SPEED,
                                        description="m/s; default by kind")
    height: PositiveFloat | None = Field(
        None, description="m above the floor of its sensor (UAV: flight altitude)")
    sensors: SensorsSpec | None = Field(None, description="default: the kind's sensor set")

    @model_validator(mode="after")
    def _can_carry(self) -> MemberSpec:
        for name in SENSORS:
            if self.sensors is not None and getattr(self.sensors, name) is not None \
                    and name not in carries(self.kind):
                raise ValueError(f"sensors.{name}: a {self.kind} cannot carry a {name}; it "
                                 f"carries: {', '.join(carries(self.kind))}")
        return self

    @property
    def sensor_set(self) -> SensorsSpec:
        """The sensors this member carries, its kind's set when the mission names none."""
        if self.sensors is not None:
            return self.sensors
        from astralis_des.kinds import KIND_DEFAULTS

        carried = KIND_DEFAULTS[self.kind].sensors
        return SensorsSpec(**{n: _DEFAULT_SPECS.get(n) if n in carried else None
                              for n in SENSORS})


class RoomProps(Strict):
    risk: Unit | None = None
    messiness: Unit | None = None
    sound: Sound | None = None


class RoomsSpec(Strict):
    """Room properties: drawn from the mission seed (uniform in [0, 1]), then overridden."""

    set: dict[str, RoomProps] = Field(default_factory=dict)


class AvatarSpec(Strict):
    """The target's attributes (the paper's Table II); unset ones are drawn from the seed."""

    activity: Literal["sitting", "laying", "patrolling", "idle"] | None = None
    color: Literal["yellow", "red", "purple", "blue"] | None = None
    gender: Literal["male", "female"] | None = None
    height: Literal["tall", "medium", "short"] | None = None
    tied_to_chair: bool | None = None


class TargetSpec(Strict):
    room: str | None = Field(None, description="room id; drawn from the searched rooms if unset")
    position: Vec3 | None = Field(None, description="drawn inside the room if unset")
    avatar: AvatarSpec = Field(default_factory=AvatarSpec)


class KindWeights(Strict):
    """A weight per kind, a plug-in's kind too (unset, it reads its record's ``weights``)."""

    model_config = ConfigDict(extra="allow", frozen=True)
    __pydantic_extra__: dict[str, NonNegativeFloat] = Field(init=False)

    human: NonNegativeFloat = 0.0
    uav: NonNegativeFloat = 0.0
    ugv: NonNegativeFloat = 0.0

    @model_validator(mode="after")
    def _known_kinds(self) -> KindWeights:
        for kind in self.model_extra or {}:
            known_kind(kind)
        return self


class WeightsSpec(Strict):
    """Eq. 1's W1 (on risk) and W2 (on messiness), per agent kind.

    The paper prints W1 = [0, 5, 10] and W2 = [5, 0, 10] in the order [human, UAV, UGV]; read
    that way, the human is sent to high-risk rooms more often than by the naive baseline. W1
    read in reverse order (human 10, UAV 5, UGV 0) keeps the human out of them, as the paper
    reports, and lets the UGV take high-risk rooms, as its text says, but sends the UGV into
    clutter twice as often as Table V. The default is that reading with the UGV's risk weight
    3: the smallest change to it that reproduces all four Table V figures
    (``astralis tune tunes/table5_ugv.yaml``: 2 to 4 fit; docs/studies.md).
    """

    risk: KindWeights = KindWeights(human=10.0, uav=5.0, ugv=3.0)
    messiness: KindWeights = KindWeights(human=5.0, uav=0.0, ugv=10.0)


class StrategyOptions(Strict):
    """Parameters of the baseline strategies (astralis_des.assignment.baselines)."""

    bundle: int = Field(3, ge=1, le=100, description="cbba: rooms in an agent's bundle, at most")
    comm_range: PositiveFloat | None = Field(
        None, description="cbba: metres within which two agents talk; unset: all of them do")
    discount: float = Field(0.99, gt=0, lt=1, description="cbba: reward kept per second")
    bid: Literal["marginal", "finish"] = Field(
        "marginal", description="auction: bid what the room adds to the queue, or the queue's "
        "finish time with it")
    objective: Literal["makespan", "sum"] = Field(
        "makespan", description="milp: the latest finish, or the sum of completion times")
    time_limit: PositiveFloat = Field(1.0, description="milp: s of solver time a round")
    mip_gap: float = Field(0.01, ge=0, le=1, description="milp: relative gap to stop at")

    def label(self) -> str:
        """How a study names a variant with these options: what was set, ``bundle=1``."""
        return ", ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}"
                         for k, v in self.model_dump(exclude_unset=True).items()) or "defaults"


class AssignmentSpec(Strict):
    strategy: str = "mixed"
    options: StrategyOptions = Field(default_factory=StrategyOptions)
    weights: WeightsSpec = Field(default_factory=WeightsSpec)
    high_risk: Unit = 0.5
    high_messiness: Unit = 0.5
    solver: Literal["scipy", "networkx"] = "scipy"
    search: list[str] = Field(
        default_factory=lambda: ["A"], min_length=1,
        description="buildings or segment ids to search, in order; each round takes one segment")
    max_attempts: int = Field(2, ge=1, description="rounds a room may be tried in")
    min_coverage: Unit = Field(
        0.9, description="share of a room's free floor a search must see for the room to count "
        "as searched; below it the room goes back to the pending set, for an agent of a kind "
        "that has not searched it yet")
    start_at: NonNegativeFloat = Field(0.0, description="s the team waits before round 1")
    auto: bool = Field(True, description="run the rounds of `search` on their own; false: the "
                       "team waits for commands (astralis serve, chat)")


class _At(Strict):
    at: NonNegativeFloat = Field(description="simulated seconds from the start")


class FaultEvent(_At):
    event: Literal["fault"]
    robot: str
    reason: str = "fault"


class RecoverEvent(_At):
    event: Literal["recover"]
    robot: str


class RoomChangeEvent(_At):
    event: Literal["room_change"]
    room: str
    risk: Unit | None = None
    messiness: Unit | None = None
    sound: Sound | None = None


def _params_by_action(schema: dict[str, Any]) -> None:
    """The params each kind's action takes, from the actions' records (when the schema is
    made, so the actions are registered)."""
    schema["x-action-params"] = {
        f"{kind}/{name}": {"type": "object", "additionalProperties": False,
                           "properties": spec.fields()}
        for (kind, name), spec in ACTIONS.registered()}


class CommandEvent(_At):
    event: Literal["command"]
    robot: str
    action: str
    room: str | None = None
    params: dict[str, float | str] = Field(
        default_factory=dict, json_schema_extra=_params_by_action,
        description="the action's own (docs/missions.md lists them per kind; this schema's "
        "x-action-params: the model of each kind/action's)")
    preempt: bool = Field(False, description="run now, interrupting the current task")


class CancelEvent(_At):
    event: Literal["cancel"]
    robot: str


TimelineEvent = Annotated[
    FaultEvent | RecoverEvent | RoomChangeEvent | CommandEvent | CancelEvent,
    Field(discriminator="event"),
]


class HexacopterSpec(Strict):
    """A Firefly-like hexacopter (RotorS constants): six rotors on arms, thrust k_f w^2 per
    rotor, drag torque k_m x thrust, rotor speeds limited; a cascaded controller flies it."""

    mass: PositiveFloat = 1.5
    arm_length: PositiveFloat = 0.215
    inertia: tuple[PositiveFloat, PositiveFloat, PositiveFloat] = (0.0347563, 0.0458929, 0.0977)
    thrust_constant: PositiveFloat = Field(8.54858e-06, description="k_f, N/(rad/s)^2")
    moment_constant: PositiveFloat = Field(0.016, description="k_m, m: drag torque/thrust")
    max_rotor_speed: PositiveFloat = Field(838.0, description="rad/s")
    motor_time_constant: NonNegativeFloat = 0.0125
    max_tilt_deg: Annotated[float, Field(gt=0, lt=60)] = 25.0
    max_accel: PositiveFloat = Field(3.5, description="m/s^2, commanded horizontal")
    radius: PositiveFloat = Field(0.3, description="m, collision cylinder (rotor tips)")

    @model_validator(mode="after")
    def _can_lift(self) -> HexacopterSpec:
        lift = 6 * self.thrust_constant * self.max_rotor_speed**2
        if lift <= self.mass * 9.81 * 1.2:
            raise ValueError(f"six rotors lift {lift:.1f} N at most: not enough for "
                             f"{self.mass} kg with a margin (needs {self.mass * 9.81 * 1.2:.1f})")
        return self


class PhysicsSpec(Strict):
    """The physics fidelity: a PyBullet co-simulation, stepped at ``rate`` Hz."""

    rate: Annotated[int, Field(ge=30, le=2000)] = Field(240, description="physics steps per s")
    control_rate: Annotated[int, Field(ge=10, le=2000)] = Field(
        60, description="controller updates per s; must divide rate")
    log_rate: PositiveFloat = Field(10.0, description="pose samples per s in the recording")
    stuck_timeout: PositiveFloat = Field(15.0, description="s without progress: the action fails")
    solver_iterations: Annotated[int, Field(ge=1, le=200)] = 20
    sleep_idle: bool = Field(
        True, description="an idle UGV sleeps in Bullet once settled, woken by a command or a "
        "touch: a standing Husky costs Bullet nothing (false: it is stepped as if it drove; "
        "trajectories differ by millimetres)")
    uav: HexacopterSpec = Field(default_factory=HexacopterSpec)

    @model_validator(mode="after")
    def _rates(self) -> PhysicsSpec:
        if self.control_rate > self.rate:
            raise ValueError(f"control_rate {self.control_rate} Hz is faster than the physics "
                             f"rate {self.rate} Hz: a controller period is shorter than dt")
        if self.rate % self.control_rate:
            raise ValueError(f"control_rate {self.control_rate} Hz does not divide the physics "
                             f"rate {self.rate} Hz")
        return self

    @property
    def dt(self) -> float:
        return 1.0 / self.rate


class PlanningSpec(Strict):
    """How robots find their way: ``graph`` (the rooms-and-doors graph, straight legs),
    ``map`` (the graph's way, with every blocked leg planned around furniture on the
    occupancy map), or ``auto`` (graph in kinematic fidelity, map in physics)."""

    method: Literal["auto", "graph", "map"] = "auto"
    budget: NonNegativeFloat = Field(0.2, description="s of planning allowed per leg")
    uav_planner: Literal["rrtconnect", "informed_rrtstar"] = "rrtconnect"
    ugv_space: Literal["reedsshepp", "dubins"] = "reedsshepp"
    turning_radius: PositiveFloat = Field(0.4, description="m, the UGV's tightest turn")
    margin: NonNegativeFloat = Field(
        0.05, description="m of clearance beyond the body (a 1 m door leaves a UAV 0.1 m)")


class SceneSpec(Strict):
    """What the mission adds to its world: furniture and avatars by each room's messiness
    (from the catalogue), and moving obstacles wandering in the corridors."""

    clutter: bool = True
    catalogue: str | None = Field(None, description="catalogue file, relative to the mission")
    furnish_outdoors: bool = Field(False, description="furniture in the search areas out in "
                                   "the open too (else only their bystanders)")
    movers: int = Field(0, ge=0, le=100, description="moving obstacles in corridors")
    mover_speed: PositiveFloat = Field(0.6, le=MAX_SPEED, description="m/s")


class OutputsSpec(Strict):
    dir: str | None = Field(None, description="default: out/<mission name>")
    events: bool = True
    summary: bool = True
    recording: bool = True
    mcap: bool = Field(False, description="also run.mcap: ROS 2 messages and the decisions as "
                       "JSON, for ros2 bag, Foxglove and Rerun")


class MissionSpec(Strict):
    name: FileName = Field(description="a plain file name (letters, digits and _ . -; not . "
                           "or ..): also the output folder's name (out/NAME)")
    world: str = Field(description="world file, relative to the mission file")
    plugins: list[str] = Field(default_factory=list, description="modules imported before "
                               "the mission is read, whose actions, strategies, sensors and "
                               "event kinds it may name: a .py file (relative to the mission "
                               "file) or a module on the path (docs/architecture.md)")
    seed: int = Field(0, ge=0, description="every random draw derives from it")
    fidelity: Literal["kinematic", "physics"] = "kinematic"
    time_limit: PositiveFloat = 3600.0
    team: list[MemberSpec] = Field(min_length=1)
    rooms: RoomsSpec = Field(default_factory=RoomsSpec)
    target: TargetSpec = Field(default_factory=TargetSpec)
    assignment: AssignmentSpec = Field(default_factory=AssignmentSpec)
    timeline: list[TimelineEvent] = Field(default_factory=list)
    scene: SceneSpec = Field(default_factory=SceneSpec)
    planning: PlanningSpec = Field(default_factory=PlanningSpec)
    physics: PhysicsSpec = Field(default_factory=PhysicsSpec)
    outputs: OutputsSpec = Field(default_factory=OutputsSpec)
    site: SiteSpec = Field(default_factory=SiteSpec)

    @field_validator("team")
    @classmethod
    def _unique_ids(cls, team: list[MemberSpec]) -> list[MemberSpec]:
        ids = [m.id for m in team]
        duplicates = sorted({i for i in ids if ids.count(i) > 1})
        if duplicates:
            raise ValueError(f"team ids must be unique; repeated: {', '.join(duplicates)}")
        return team
