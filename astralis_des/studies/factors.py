"""What a study may set or vary, by registry: each parameter checks its value and applies it to
a :class:`Setting`, everything a variant decides about how a scenario is run.

    set:  {fidelity: physics}                  # every variant
    vary: {strategy: [naive, mixed, greedy]}   # crossed: one variant per combination
    vary: {weights: {printed: {...}, reversed: {...}}}   # a mapping names its values
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Annotated, Any, Literal

from pydantic import AfterValidator, BaseModel, Field, TypeAdapter, model_validator

from astralis_des.kinds import KINDS
from astralis_des.mission.spec import (
    NonNegativeFloat,
    PositiveFloat,
    StrategyOptions,
    Strict,
    Unit,
    WeightsSpec,
)
from astralis_des.registry import Registry, UnknownEntry
from astralis_des.studies.draws import Dist, Uniform

WeightTable = dict[str, dict[str, float]]  # {"risk": {kind: W1}, "messiness": {kind: W2}}
WEIGHT_OF = {"w1": "risk", "w2": "messiness"}


@dataclass(frozen=True)
class Setting:
    """How a variant runs its scenarios."""

    strategy: str
    weights: WeightTable
    team: dict[str, int]  # agents per kind
    risk: Any  # a Dist
    messiness: Any
    fidelity: str
    high_risk: float
    high_messiness: float
    time_limit: float
    options: dict[str, Any] = field(default_factory=dict)  # the baselines' (assignment.options)
    # each scenario's mission changes, given instead of drawn (astralis falsify's trials)
    given: tuple[dict[str, Any], ...] = ()


@dataclass(frozen=True)
class Factor:
    name: str
    adapter: TypeAdapter[Any]
    apply: Callable[[Setting, Any], Setting]
    only: str | None  # the evaluation it means something for; None: all
    help: str


FACTORS: Registry[str, Factor] = Registry("parameter to vary")


def factor(name: str, value_type: Any, *, only: str | None = None,
           help: str = "") -> Callable[[Callable[[Setting, Any], Setting]],
                                       Callable[[Setting, Any], Setting]]:
    def add(apply: Callable[[Setting, Any], Setting]) -> Callable[[Setting, Any], Setting]:
        FACTORS.register(name)(Factor(name, TypeAdapter(value_type), apply, only,
                                      help or (apply.__doc__ or "").strip()))
        return apply

    return add


def _known_strategy(name: str) -> str:
    from astralis_des.assignment.strategies import STRATEGIES

    try:
        STRATEGIES.get(name)
    except UnknownEntry as exc:
        raise ValueError(str(exc)) from None
    return name


class TeamMix(Strict):
    """Agents per kind, e.g. ``{uav: 2, ugv: 1, human: 1}``; ids are uav1, uav2, ugv1, ..."""

    uav: Annotated[int, Field(ge=0, le=20)] = 0
    ugv: Annotated[int, Field(ge=0, le=20)] = 0
    human: Annotated[int, Field(ge=0, le=20)] = 0

    @model_validator(mode="after")
    def _someone(self) -> TeamMix:
        if self.uav + self.ugv + self.human == 0:
            raise ValueError("a team needs at least one agent")
        return self


@factor("strategy", Annotated[str, AfterValidator(_known_strategy)])
def _strategy(s: Setting, value: str) -> Setting:
    """the assignment strategy (mixed, naive, greedy, hard, random, auction, cbba, milp)"""
    return replace(s, strategy=value)


@factor("options", StrategyOptions)
def _options(s: Setting, value: StrategyOptions) -> Setting:
    """the baselines' parameters: {bundle, comm_range, discount, bid, objective, ...}"""
    return replace(s, options=value.model_dump())


@factor("weights", WeightsSpec)
def _weights(s: Setting, value: WeightsSpec) -> Setting:
    """W1 and W2 as a whole: {risk: {human, uav, ugv}, messiness: {...}}"""
    return replace(s, weights={"risk": value.risk.model_dump(),
                               "messiness": value.messiness.model_dump()})


def _one_weight(which: str, kind: str) -> Callable[[Setting, float], Setting]:
    def apply(s: Setting, value: float) -> Setting:
        table = {k: dict(v) for k, v in s.weights.items()}
        table[WEIGHT_OF[which]][kind] = value
        return replace(s, weights=table)

    return apply


def _scaled(which: str) -> Callable[[Setting, float], Setting]:
    def apply(s: Setting, value: float) -> Setting:
        table = {k: dict(v) for k, v in s.weights.items()}
        table[WEIGHT_OF[which]] = {k: w * value for k, w in table[WEIGHT_OF[which]].items()}
        return replace(s, weights=table)

    return apply


for _which, _on in WEIGHT_OF.items():
    for _kind in KINDS:
        factor(f"{_which}.{_kind}", NonNegativeFloat,
               help=f"one weight: {_which.upper()} (on {_on}) of the {_kind}")(
                   _one_weight(_which, _kind))
    factor(f"{_which}_scale", NonNegativeFloat,
           help=f"{_which.upper()} (on {_on}) times this, every kind")(_scaled(_which))


@factor("team", TeamMix)
def _team(s: Setting, value: TeamMix) -> Setting:
    """the team mix: agents per kind"""
    return replace(s, team=value.model_dump())


def _sets(field: str) -> Callable[[Setting, Any], Setting]:
    """Apply a value by setting the field of the same name."""
    def apply(s: Setting, value: Any) -> Setting:
        return replace(s, **{field: value})

    return apply


for _name, _type, _only, _help in (
        ("risk", Dist, None, "the distribution of each room's risk"),
        ("messiness", Dist, None, "the distribution of each room's messiness"),
        ("fidelity", Literal["kinematic", "physics"], "mission", "kinematic or physics"),
        ("time_limit", PositiveFloat, "mission", "the mission's time limit, s"),
        ("high_risk", Unit, None, "risk from which a room is high-risk (the paper: 0.5)"),
        ("high_messiness", Unit, None,
         "messiness from which a room is high-messiness (the paper: 0.5)")):
    factor(_name, _type, only=_only, help=_help)(_sets(_name))


def base_setting(mission: Any, risk: Any = None, messiness: Any = None) -> Setting:
    """The base mission's own setting; room values uniform on [0, 1] unless given."""
    spec = mission.spec
    cfg = spec.assignment
    team = {kind: sum(m.kind == kind for m in spec.team) for kind in KINDS}
    return Setting(cfg.strategy, {"risk": cfg.weights.risk.model_dump(),
                                  "messiness": cfg.weights.messiness.model_dump()},
                   team, risk or Uniform(), messiness or Uniform(), spec.fidelity,
                   cfg.high_risk, cfg.high_messiness, spec.time_limit,
                   cfg.options.model_dump())


def label(value: Any) -> str:
    """How a value reads in a variant's name: ``0.5``, ``naive``, ``beta(a=2, b=5)``."""
    if isinstance(value, float):
        return f"{value:g}"
    named = getattr(value, "label", None)
    if isinstance(value, BaseModel) and callable(named):
        return str(named())  # the model says how it reads
    if isinstance(value, BaseModel):
        data = value.model_dump(exclude_defaults=False)
        head = data.pop("dist", None) or data.pop("type", None) or ""
        inner = ", ".join(f"{k}={label(v)}" for k, v in data.items())
        return f"{head}({inner})" if head else inner
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k}: {label(v)}" for k, v in value.items()) + "}"
    return str(value)
