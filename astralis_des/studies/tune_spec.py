"""The tune file: a study, the parameters to search within bounds, and what to aim at.

    name: table5_fit
    study: table5.yaml                    # scenarios, draws, variants, as `astralis study`
    seed: 1
    trials: 60
    sampler: tpe                          # tpe | nsga2 | random | grid
    params:                               # study parameters, set for every variant
      w1.ugv: {low: 0, high: 10}
      high_risk: {low: 0.3, high: 0.7, step: 0.05}
      strategy: [mixed, greedy]           # a choice
    targets:                              # reproduce figures (variant.metric: value)
      mixed.ugv_high_mess: 0.059          # scored by the largest |z| (two-proportion test)
      mixed.human_high_risk: {value: 0.0, n: 1000}    # n: the figure's own sample size
    # or objectives: [{metric: mixed.time_to_find, direction: minimize}, ...]
    constraints:
      - {metric: mixed.human_high_risk, max: 0.0}

Every problem is an :class:`InputError` naming the file, line and key, as for studies.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from pydantic import Field, model_validator

from astralis_des.errors import InputError, suggest
from astralis_des.mission.spec import NAME_MAX, Finite, Strict
from astralis_des.studies.evaluation import EVALUATIONS
from astralis_des.studies.factors import FACTORS
from astralis_des.studies.spec import Study, load_study
from astralis_des.validation import validate
from astralis_des.yamlio import LocatedYaml, load_yaml

MAX_TRIALS = 100_000


class Interval(Strict):
    """A number between ``low`` and ``high`` (on a log scale): a falsify space's range."""

    low: Finite
    high: Finite
    log: bool = False

    @model_validator(mode="after")
    def _ordered(self) -> Interval:
        if not self.low < self.high:
            raise ValueError(f"empty or inverted bounds: low {self.low:g} must be below high "
                             f"{self.high:g}")
        if self.log and self.low <= 0:
            raise ValueError(f"a log scale needs low > 0 (got {self.low:g})")
        return self


class Bound(Interval):
    """A tune's parameter: an interval, or its values in steps of ``step``."""

    step: Finite | None = Field(None, gt=0)


class Target(Strict):
    value: Finite
    n: int | None = Field(None, ge=1, description="the figure's own sample size (default: "
                          "the study's scenarios)")


class Objective(Strict):
    metric: str
    direction: Literal["minimize", "maximize"] = "minimize"


class Constraint(Strict):
    metric: str
    min: Finite | None = None
    max: Finite | None = None

    @model_validator(mode="after")
    def _some(self) -> Constraint:
        if self.min is None and self.max is None:
            raise ValueError("give min, max or both")
        return self


class TuneSpec(Strict):
    name: str = Field(pattern=r"^[A-Za-z0-9_.-]+$", max_length=NAME_MAX)
    study: str = Field(description="the study file, relative to the tune file")
    seed: int = Field(0, ge=0, le=2**32 - 1)
    trials: int = Field(ge=1, le=MAX_TRIALS)
    sampler: Literal["tpe", "nsga2", "random", "grid"] = "tpe"
    scenarios: int | None = Field(None, ge=1, description="override the study's scenarios")
    params: dict[str, Bound | list[Any]] = Field(min_length=1)
    targets: dict[str, Finite | Target] = Field(default_factory=dict)
    objectives: list[Objective] = Field(default_factory=list)
    constraints: list[Constraint] = Field(default_factory=list)

    @model_validator(mode="after")
    def _one_aim(self) -> TuneSpec:
        if bool(self.targets) == bool(self.objectives):
            raise ValueError("give targets (figures to reproduce) or objectives (metrics to "
                             "minimise or maximise), one of the two")
        return self


@dataclass(frozen=True)
class Tune:
    """A validated tune: what :func:`astralis_des.studies.tune.run_tune` runs."""

    spec: TuneSpec
    study: Study
    text: str  # the tune file, copied into the output folder
    path: Path | None = None

    @property
    def name(self) -> str:
        return self.spec.name

    def targets(self) -> dict[str, Target]:
        return {k: v if isinstance(v, Target) else Target(value=v)
                for k, v in self.spec.targets.items()}

    def metrics(self) -> list[str]:
        """Every metric the tune reads (variant.metric), in file order."""
        return list(dict.fromkeys(metric for _, metric in metric_keys(self.spec)))


def load_tune(path: str | Path) -> Tune:
    """Read a tune file and its study; a problem names the file, line and key."""
    doc = load_yaml(path)
    spec = validate(TuneSpec, doc)
    study = load_study(doc.file_at(("study",), spec.study, "study file"))
    if spec.scenarios is not None:
        study = study.with_changes(scenarios=spec.scenarios)
    tune = Tune(spec, study, doc.file.read_text(encoding="utf-8"), doc.file)
    check_tune(tune, doc)
    return tune


def check_tune(tune: Tune, doc: LocatedYaml) -> None:
    """Every parameter a study can set and the study does not vary; every metric one the
    study reports, of one of its variants."""
    study = tune.study
    for name, space in tune.spec.params.items():
        if name not in FACTORS:
            raise doc.error(("params", name), f"unknown parameter '{name}'; "
                            f"{suggest(name, list(FACTORS))}")
        only = FACTORS.get(name).only
        if only is not None and only != study.spec.evaluate:
            raise doc.error(("params", name), f"'{name}' means nothing when the study's "
                            f"evaluate is '{study.spec.evaluate}' (only for {only})")
        if name in study.spec.vary:
            raise doc.error(("params", name), f"the study varies '{name}' already: tune it "
                            "or vary it, not both")
        if tune.spec.sampler == "grid" and isinstance(space, Bound) and space.step is None:
            raise doc.error(("params", name), "the grid sampler needs a step (or a list of "
                            "choices) for every parameter")
        if isinstance(space, list) and not space:
            raise doc.error(("params", name), "no choices: give at least one value")
        probe = space if isinstance(space, list) else [space.low, space.high]
        for i, value in enumerate(probe):
            try:
                FACTORS.get(name).adapter.validate_python(value)
            except Exception as exc:
                where = ("params", name, i) if isinstance(space, list) else (
                    "params", name, ("low", "high")[i])
                raise doc.error(where, f"{name} cannot be {value!r}: "
                                f"{str(exc).splitlines()[-1].strip()}") from None
    columns = [m.column for m in EVALUATIONS.get(study.spec.evaluate).metrics]
    variants = [v.name for v in study.variants]
    for place, metric in metric_keys(tune.spec):
        split_metric(metric, variants, columns, lambda msg, p=place: doc.error(p, msg))


def metric_keys(spec: TuneSpec) -> list[tuple[tuple[str | int, ...], str]]:
    """Each metric the file names, with the key that names it, in file order."""
    return [*((("targets", k), k) for k in spec.targets),
            *((("objectives", i, "metric"), o.metric) for i, o in enumerate(spec.objectives)),
            *((("constraints", i, "metric"), c.metric) for i, c in enumerate(spec.constraints))]


def split_metric(name: str, variants: list[str], columns: list[str],
                 error: Any = None) -> tuple[str, str]:
    """``variant.metric`` (or ``metric`` when the study has one variant) to its two parts."""
    def fail(message: str) -> InputError:
        return error(message) if error is not None else InputError(message)

    variant, _, column = name.rpartition(".")
    if not variant and len(variants) == 1:
        variant = variants[0]
    if variant not in variants:
        raise fail(f"'{name}': no variant '{variant}' in the study; name a metric as "
                   f"VARIANT.METRIC, with VARIANT one of: {', '.join(variants)}")
    if column not in columns:
        raise fail(f"'{name}': unknown metric '{column}'; {suggest(column, columns)}")
    return variant, column
