"""The study file: a base mission, what each scenario draws, what is set and what varies.

    name: table5
    mission: ../missions/urban_search.yaml
    seed: 2024
    scenarios: 1000
    evaluate: assignment            # or mission: a full run per scenario and variant
    draw: {positions: building}     # mission | building | outdoor
    vary: {strategy: [naive, mixed]}

Every problem is an :class:`InputError` naming the file, line and key, as for missions.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import yaml
from pydantic import Field, field_validator

from astralis_des.errors import InputError, suggest
from astralis_des.mission.loader import Mission, load_mission
from astralis_des.mission.spec import NAME_MAX, Strict
from astralis_des.registry import UnknownEntry
from astralis_des.studies.draws import FromMission, Positions, Sampler, Scenario, draw_scenario
from astralis_des.studies.factors import FACTORS, Setting, base_setting, label
from astralis_des.studies.registries import EVALUATIONS, REPORTS
from astralis_des.validation import validate
from astralis_des.yamlio import KeyPath, LocatedYaml, load_yaml

MAX_SCENARIOS = 10_000_000


class DrawSpec(Strict):
    """What each scenario draws from its seed, besides each room's risk and messiness."""

    positions: Positions = Field(default_factory=FromMission,
                                 description="where agents start: mission, building, outdoor")
    segment: str = Field("random", description="assignment studies: the segment whose rooms "
                         "are matched, or random (one of the mission's searched segments)")

    @field_validator("positions", mode="before")
    @classmethod
    def _short(cls, value: Any) -> Any:
        return {"type": value} if isinstance(value, str) else value


class StudyOutputs(Strict):
    recordings: bool = Field(False, description="write each mission's outputs under the "
                             "study folder (scenarios/INDEX/VARIANT/)")
    plots: bool = True


class StudySpec(Strict):
    name: str = Field(pattern=r"^[A-Za-z0-9_.-]+$", max_length=NAME_MAX)
    mission: str = Field(description="the base mission file, relative to the study file")
    seed: int = 0
    scenarios: int = Field(description="random scenarios, each run under every variant")
    evaluate: str = Field("mission", description="assignment (one matching per scenario) or "
                          "mission (a full run)")
    draw: DrawSpec = Field(default_factory=DrawSpec)
    set: dict[str, Any] = Field(default_factory=dict, description="parameters for every variant")
    vary: dict[str, Any] = Field(default_factory=dict,
                                 description="parameter: [values] or {name: value}, crossed")
    report: str = Field("summary", description="summary, or table5 (the paper's Table V)")
    outputs: StudyOutputs = Field(default_factory=StudyOutputs)

    @field_validator("scenarios")
    @classmethod
    def _some(cls, n: int) -> int:
        if not 1 <= n <= MAX_SCENARIOS:
            raise ValueError(f"give between 1 and {MAX_SCENARIOS:,} scenarios (got {n})")
        return n


@dataclass(frozen=True)
class Variant:
    """One combination of the varied parameters: its name, its table columns, its setting."""

    index: int
    name: str
    columns: dict[str, Any]
    setting: Setting


@dataclass(frozen=True)
class Study:
    """A validated study: what :func:`astralis_des.studies.run_study` runs."""

    spec: StudySpec
    mission: Mission
    variants: tuple[Variant, ...]
    sampler: Sampler
    segments: tuple[str, ...]
    text: str  # the study file, copied into the output folder
    path: Path | None = None
    # the study this one was made from by with_changes, and the changes (not pickled: a pool
    # holding the origin is sent the changes alone)
    origin: tuple[Study, dict[str, Any]] | None = field(default=None, compare=False, repr=False)

    def __getstate__(self) -> dict[str, Any]:
        return {**self.__dict__, "origin": None}

    @property
    def name(self) -> str:
        return self.spec.name

    @property
    def scenarios(self) -> int:
        return self.spec.scenarios

    def scenario(self, index: int) -> Scenario:
        """The draws of scenario ``index`` (0-based); the same on any worker."""
        return draw_scenario(self.mission, self.sampler, list(self.segments), self.spec.seed,
                             index)

    def variant(self, name: str) -> Variant:
        for v in self.variants:
            if v.name == name:
                return v
        raise InputError(f"no variant '{name}'; "
                         f"{suggest(name, [v.name for v in self.variants])}", key="--variant")

    def with_changes(self, **changes: Any) -> Study:
        """A copy with top-level study fields replaced (e.g. ``scenarios=100``), checked."""
        data = self.spec.model_dump(mode="json")
        data.update(changes)
        doc = LocatedYaml(data, {}, self.path or Path("<study>"))
        note = "".join(f"# changed for this run: {k}: {v!r}\n" for k, v in changes.items())
        return replace(_build(validate(StudySpec, doc), self.mission, doc, self.text + note),
                       path=self.path, origin=(self, dict(changes)))


def load_study(path: str | Path) -> Study:
    """Read a study file and its base mission; a problem names the file, line and key."""
    doc = load_yaml(path)
    spec = validate(StudySpec, doc)
    mission_path = doc.file_at(("mission",), spec.mission, "mission file")
    text = doc.file.read_text(encoding="utf-8")
    return _build(spec, load_mission(mission_path), doc, text)


def make_study(mission: Mission | str | Path, *, name: str, scenarios: int,
               **fields: Any) -> Study:
    """A study from Python: ``make_study(mission, name="s", scenarios=100, seed=1,
    evaluate="mission", vary={"strategy": ["naive", "mixed"]})``."""
    if not isinstance(mission, Mission):
        mission = load_mission(mission)
    data = {"name": name, "mission": str(mission.path or "<mission>"), "scenarios": scenarios,
            **fields}
    doc = LocatedYaml(data, {}, Path("<study>"))
    spec = validate(StudySpec, doc)
    return _build(spec, mission, doc, yaml.safe_dump(data, sort_keys=False))


def _build(spec: StudySpec, mission: Mission, doc: LocatedYaml, text: str) -> Study:
    for key, registry in (("evaluate", EVALUATIONS), ("report", REPORTS)):
        try:
            registry.get(getattr(spec, key))
        except UnknownEntry as exc:
            raise doc.error((key,), str(exc)) from None
    segments = tuple(mission.searched_segments())
    if spec.draw.segment != "random" and spec.draw.segment not in segments:
        raise doc.error(("draw", "segment"), f"'{spec.draw.segment}' is not a segment the "
                        f"mission searches; {suggest(spec.draw.segment, [*segments, 'random'])}")
    setting = base_setting(mission)
    for name, value in spec.set.items():
        setting = _factor(spec, doc, ("set", name)).apply(
            setting, _check(spec, doc, ("set", name), value))
    if spec.draw.segment != "random":
        segments = (spec.draw.segment,)
    variants = _variants(spec, doc, setting)
    study = Study(spec, mission, variants, spec.draw.positions.sampler(mission), segments, text,
                  None if str(doc.file).startswith("<") else doc.file)
    if spec.evaluate == "mission":
        _check_timeline_robots(study, doc)
    return study


def _check_timeline_robots(study: Study, doc: LocatedYaml) -> None:
    """Each robot the mission's timeline names has a member in every variant's team (its
    fault or command would otherwise fail every scenario)."""
    from astralis_des.studies.teams import unmatched_robots

    for variant in study.variants:
        missing = unmatched_robots(study.mission.spec, variant.setting.team)
        if missing:
            team = ", ".join(f"{n} {k}" for k, n in variant.setting.team.items() if n)
            raise doc.error(("mission",), f"the mission's timeline names {', '.join(missing)}, "
                            f"and variant '{variant.name}' has no such member (its team: "
                            f"{team or 'none'}); give the study a team with it, or drop those "
                            "events from the mission")


def _factor(spec: StudySpec, doc: LocatedYaml, path: KeyPath) -> Any:
    name = str(path[-1])
    try:
        found = FACTORS.get(name)
    except UnknownEntry:
        raise doc.error(path, f"unknown parameter '{name}' to {path[0]}; "
                        f"{suggest(name, list(FACTORS))}") from None
    if found.only is not None and found.only != spec.evaluate:
        raise doc.error(path, f"'{name}' means nothing when evaluate is '{spec.evaluate}' "
                        f"(only for {found.only})")
    return found


def _check(spec: StudySpec, doc: LocatedYaml, path: KeyPath, value: Any) -> Any:
    """The parameter's value, validated; an error points at its line."""
    factor = _factor(spec, doc, path[:2])
    from pydantic import ValidationError

    try:
        return factor.adapter.validate_python(value)
    except ValidationError as exc:
        error = max(exc.errors(), key=lambda e: len(e["loc"]))
        where = (*path, *(p for p in error["loc"] if isinstance(p, str | int)))
        message = str(error["msg"]).removeprefix("Value error, ")
        if error["type"] == "extra_forbidden":
            message = f"unknown key '{where[-1]}'"
        elif "input" in error and isinstance(error["input"], str | int | float | bool):
            message += f" (got {error['input']!r})"
        raise doc.error(where, f"{factor.name}: {message}") from None


def _variants(spec: StudySpec, doc: LocatedYaml, base: Setting) -> tuple[Variant, ...]:
    """The cross product of the varied parameters' values, in file order."""
    axes: list[list[tuple[str, str, Any, Any]]] = []  # per parameter: (name, label, col, value)
    for name, values in spec.vary.items():
        path: KeyPath = ("vary", name)
        _factor(spec, doc, path)
        if isinstance(values, list):
            items = [(i, label(v), v) for i, v in enumerate(values)]
        elif isinstance(values, dict):
            items = [(k, str(k), v) for k, v in values.items()]
        else:
            raise doc.error(path, f"give a list of values or a mapping of names to values "
                            f"(got {values!r})")
        if not items:
            raise doc.error(path, "empty range: give at least one value")
        axis = []
        for key, text, raw in items:
            value = _check(spec, doc, (*path, key), raw)
            column = value if isinstance(value, str | int | float | bool) else text
            axis.append((name, label(value) if isinstance(values, list) else text, column,
                         value))
        labels = [a[1] for a in axis]
        twice = next((t for t in labels if labels.count(t) > 1), None)
        if twice is not None:
            raise doc.error(path, f"the value '{twice}' is given twice")
        axes.append(axis)
    variants = []
    for index, combo in enumerate(itertools.product(*axes)):
        setting = base
        for name, _, _, value in combo:
            setting = FACTORS.get(name).apply(setting, value)
        name = (combo[0][1] if len(combo) == 1
                else ",".join(f"{n}={t}" for n, t, _, _ in combo) or "base")
        variants.append(Variant(index, name, {n: c for n, _, c, _ in combo}, setting))
    return tuple(variants)
