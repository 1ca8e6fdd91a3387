"""``astralis falsify``: search a mission's scenario space for the worst cases of a strategy.

Each trial is a point of the space (:mod:`.falsify_space`): a complete mission, run under the
strategy (and, with ``against``, under the other on the same scenario) by the study machinery
(:mod:`.falsify_eval`, on the study backends: a pool that survives a killed worker, or Ray).
Its score is the metric oriented so that larger is worse (with ``against``: the gap, the
strategy's badness less the other's). An Optuna sampler, seeded, proposes trials in batches:
``batch`` are asked, run side by side, then told (TPE's constant liar keeps a batch's trials
apart). The same number of trials drawn at random is the baseline it must beat.

Trials depend on the seed, the sampler and the batch, never on the workers or the backend: a
command gives the same trials on any machine. A sampler blind to the results (random, QMC)
gives the same trials in any batches, and runs in larger ones.
"""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from astralis_des.errors import InputError, suggest
from astralis_des.mission.loader import Mission
from astralis_des.registry import Registry, UnknownEntry
from astralis_des.studies.backends import Backend, make_backend
from astralis_des.studies.falsify_eval import badness, metric_names, run_metrics
from astralis_des.studies.falsify_space import Space
from astralis_des.studies.runner import run_study
from astralis_des.studies.spec import Study, make_study

Progress = Callable[[int, int], None]  # (trials done, trials in all)
SEARCHES = ("optimiser", "random")

# -- samplers, by name -----------------------------------------------------------------------
# a sampler by name, made of the search's seed and its number of trials
SAMPLERS: Registry[str, Callable[[int, int], Any]] = Registry("sampler")


@SAMPLERS.register("tpe")
def _tpe(seed: int, trials: int) -> Any:
    """TPE one parameter at a time after a fifth of the trials drawn at random, constant liar
    across a batch: in a space of some 50 parameters and a few hundred trials it found worse
    cases than multivariate TPE after 10 random ones (docs/howto/falsify.md has the figures)."""
    import optuna

    return optuna.samplers.TPESampler(seed=seed, constant_liar=True, multivariate=False,
                                      n_startup_trials=max(STARTUP_MIN, trials // 5))


@SAMPLERS.register("tpe-multivariate")
def _tpe_multivariate(seed: int, trials: int) -> Any:
    """TPE over the joint space (multivariate, Optuna's default for one objective since 5.0)
    after 10 random trials, constant liar across a batch."""
    import optuna

    with warnings.catch_warnings():  # "experimental" in Optuna 4
        warnings.simplefilter("ignore")
        return optuna.samplers.TPESampler(seed=seed, constant_liar=True, multivariate=True)


@SAMPLERS.register("tpe-independent")
def _tpe_independent(seed: int, trials: int) -> Any:
    """TPE one parameter at a time after 10 random trials, constant liar across a batch."""
    import optuna

    return optuna.samplers.TPESampler(seed=seed, constant_liar=True, multivariate=False)


@SAMPLERS.register("random")
def _random(seed: int, trials: int) -> Any:
    import optuna

    return optuna.samplers.RandomSampler(seed=seed)


@SAMPLERS.register("qmc")
def _qmc(seed: int, trials: int) -> Any:
    """Scrambled Sobol points (scipy): random search spread evenly."""
    import optuna

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return optuna.samplers.QMCSampler(seed=seed, scramble=True)


@SAMPLERS.register("cmaes")
def _cmaes(seed: int, trials: int) -> Any:
    """CMA-ES on the numbers, TPE for the choices (needs the ``cmaes`` package)."""
    import optuna

    try:
        import cmaes  # noqa: F401
    except ImportError:
        raise InputError("the cmaes sampler needs the cmaes package: pip install cmaes",
                         key="--sampler") from None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return optuna.samplers.CmaEsSampler(
            seed=seed, warn_independent_sampling=False,
            independent_sampler=optuna.samplers.TPESampler(seed=seed, constant_liar=True))


DEFAULT_SAMPLER = "tpe"
STARTUP_MIN = 10  # random trials before TPE models the results (Optuna's own default)
TIE_BREAK = 1e-3  # the strategy's own badness in the optimiser's objective, beside a gap
BLIND = frozenset({"random", "qmc"})  # samplers whose trials do not depend on the results
BLIND_BATCH = 16  # ... so they run in larger batches: fewer waits for a batch's slowest run


# -- the request and its result --------------------------------------------------------------
@dataclass(frozen=True)
class Falsify:
    """What to search: a mission's space, for the worst of ``strategy`` on ``metric``."""

    mission: Mission
    space: Space
    strategy: str
    metric: str
    trials: int
    against: str | None = None
    largest: bool = True  # the metric's worst is its largest value
    sampler: str = DEFAULT_SAMPLER
    seed: int = 0
    batch: int = 4
    baseline: bool = True  # also a random search of as many trials

    @property
    def strategies(self) -> list[str]:
        return [self.strategy] + ([self.against] if self.against else [])


@dataclass
class FalsifyResult:
    falsify: Falsify
    rows: list[dict[str, Any]] = field(default_factory=list)  # each trial, by search then number
    wall_time: dict[str, float] = field(default_factory=dict)  # s per search
    base: dict[str, Any] = field(default_factory=dict)  # the mission as given: its metrics
    interrupted: bool = False

    def ranked(self) -> list[dict[str, Any]]:
        """The trials with a score, worst first (ties: the earlier search, then trial)."""
        scored = [r for r in self.rows if r["score"] is not None]
        return sorted(scored, key=lambda r: (-r["score"], SEARCHES.index(r["search"]),
                                             r["trial"]))

    def worst(self, k: int) -> list[dict[str, Any]]:
        """The ``k`` worst distinct scenarios (a scenario found twice counts once)."""
        out: list[dict[str, Any]] = []
        seen: set[str] = set()
        for row in self.ranked():
            key = repr(sorted(row["changes"].items()))
            if key not in seen:
                seen.add(key)
                out.append(row)
            if len(out) == k:
                break
        return out


def check_request(metric: str, strategy: str, against: str | None, sampler: str) -> None:
    """The metric, the strategies and the sampler exist; one line naming the option if not."""
    from astralis_des.assignment.strategies import STRATEGIES

    names = metric_names()
    if metric not in names:
        raise InputError(f"unknown metric '{metric}'; {suggest(metric, names)}",
                         key="--metric")
    for option, name in (("--strategy", strategy), ("--against", against)):
        if name is None:
            continue
        try:
            STRATEGIES.get(name)
        except UnknownEntry as exc:
            raise InputError(str(exc), key=option) from None
    if against == strategy:
        raise InputError(f"'{against}' is the strategy itself: compare it with another",
                         key="--against")
    try:
        SAMPLERS.get(sampler)
    except UnknownEntry as exc:
        raise InputError(str(exc), key="--sampler") from None


def base_study(mission: Mission, strategies: list[str]) -> Study:
    """The study every batch of trials is made from (its workers hold the mission)."""
    return make_study(mission, name="falsify", scenarios=1, evaluate="falsify",
                      vary={"strategy": strategies})


def base_run(mission: Mission, strategy: str) -> dict[str, Any]:
    """The mission as given, under ``strategy``: its metrics (and its end, the fault
    window's by default)."""
    from astralis_des.simulation import Simulation

    given = mission.with_changes(assignment={**mission.spec.assignment.model_dump(mode="json"),
                                             "strategy": strategy},
                                 outputs={"dir": None, "events": False, "summary": False,
                                          "recording": False})
    result = Simulation(given).run()
    return {"end_time": result.end_time, **run_metrics(result)}


def run_falsify(f: Falsify, *, workers: int = 1, backend: str | Backend = "local",
                address: str | None = None, progress: Progress | None = None,
                base: dict[str, Any] | None = None) -> FalsifyResult:
    """The optimiser's trials, then (``baseline``) as many random ones. Interrupted (Ctrl-C,
    SIGTERM), it returns the trials done with ``interrupted`` set."""
    import optuna

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    result = FalsifyResult(f, base=base or {})
    study = base_study(f.mission, f.strategies)
    runner = make_backend(backend, workers, address) if isinstance(backend, str) else backend
    searches = [(SEARCHES[0], f.sampler)] + ([(SEARCHES[1], "random")] if f.baseline else [])
    total = f.trials * len(searches)
    try:
        runner.hold(study)
        for k, (search, sampler) in enumerate(searches):
            t0 = time.perf_counter()

            def moved(n: int, before: int = k * f.trials) -> None:
                if progress is not None:
                    progress(before + n, total)

            done = _search(f, study, runner, search,
                           SAMPLERS.get(sampler)(search_seed(f, search), f.trials), result,
                           moved)
            result.wall_time[search] = time.perf_counter() - t0
            if not done:
                result.interrupted = True
                break
    except KeyboardInterrupt:
        result.interrupted = True
    finally:
        runner.close()
    return result


def search_seed(f: Falsify, search: str) -> int:
    """The seed of a search's sampler: from the seed and the search's name, so the random
    baseline never repeats the optimiser's first (random) trials."""
    import numpy as np

    return int(np.random.SeedSequence([f.seed, SEARCHES.index(search)]).generate_state(1)[0])


def _search(f: Falsify, study: Study, runner: Backend, search: str, sampler: Any,
            result: FalsifyResult, progress: Callable[[int], None]) -> bool:
    """One search's trials, batch by batch; False if interrupted."""
    import optuna

    opt = optuna.create_study(direction="maximize", sampler=sampler)
    spaces = f.space.distributions()
    blind = search == SEARCHES[1] or f.sampler in BLIND
    size = max(f.batch, BLIND_BATCH) if blind else f.batch  # the same trials, told later
    number = 0
    while number < f.trials:
        asked = [opt.ask(spaces) for _ in range(min(size, f.trials - number))]
        changes = [f.space.changes(t.params) for t in asked]
        batch = study.with_changes(scenarios=len(asked), set={"given": changes})
        ran = run_study(batch, backend=runner)
        if ran.interrupted:
            return False
        by_trial: dict[int, dict[str, dict[str, Any]]] = {}
        for row in ran.rows:
            by_trial.setdefault(row["scenario"], {})[row["variant"]] = row
        for i, trial in enumerate(asked):
            row = _row(f, search, number + i, number // size, trial.params, changes[i],
                       by_trial.get(i, {}))
            result.rows.append(row)
            if row["score"] is None:
                opt.tell(trial, state=optuna.trial.TrialState.FAIL)
            else:
                opt.tell(trial, objective(f, row))
        number += len(asked)
        progress(number)
    return True


def objective(f: Falsify, row: dict[str, Any]) -> float:
    """What the optimiser is told: the score, and with ``against`` a thousandth of the
    strategy's own badness besides. Many scenarios tie at a gap of 0 (both strategies do
    well); among them this leans to those where the strategy does worse, nearer a positive
    gap, where the bare gap would leave a plateau with nothing to climb."""
    score: float = row["score"]
    if not f.against:
        return score
    own = badness(f.metric, row["value"], f.mission.spec.time_limit, f.largest)
    return score + TIE_BREAK * (own or 0.0)


def _row(f: Falsify, search: str, number: int, batch: int, params: dict[str, Any],
         changes: dict[str, Any], runs: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """A trial's row: its parameters, each strategy's metrics, its value and score."""
    row: dict[str, Any] = {"search": search, "trial": number, "batch": batch,
                           "seed": changes.get("seed", f.mission.spec.seed)}
    errors = [f"{s}: {runs[s]['error']}" if s in runs else f"{s}: no result"
              for s in f.strategies if runs.get(s, {}).get("status") != "ok"]
    limit = f.mission.spec.time_limit
    scores = []
    for s in f.strategies:
        run = runs.get(s, {})
        for name in metric_names():
            row[f"{s}.{name}"] = run.get(name)
        scores.append(badness(f.metric, run.get(f.metric), limit, f.largest)
                      if not errors else None)
    row["value"] = row[f"{f.strategy}.{f.metric}"]
    if f.against:
        row["value_against"] = row[f"{f.against}.{f.metric}"]
    score: float | None = None
    known = [v for v in scores if v is not None]
    if len(known) == len(scores):
        score = known[0] - known[1] if f.against else known[0]
    row["score"] = score if score is None or math.isfinite(score) else None
    row["status"] = "failed" if errors else "ok"
    row["error"] = "; ".join(errors) or None
    row.update({f"param.{k}": v for k, v in params.items()})
    row["changes"] = changes
    return row
