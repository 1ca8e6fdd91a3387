"""Run a tune: trials proposed by an Optuna sampler, each a run of the study with the trial's
parameters set for every variant, scored against the tune's targets or objectives.

Trials run one after another (each study on the workers, as ``astralis study`` runs it); the
sampler of trial N is seeded from (seed, N) alone, so a tune is the same from its seed, on any
backend and worker count, and a resumed tune goes on exactly as an unbroken one would. Each
trial is a line of ``trials.jsonl`` as soon as it ends: Ctrl-C keeps the trials done, and
``resume`` starts after them.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from astralis_des.errors import InputError
from astralis_des.outdir import journal_dumps, journal_loads, usable
from astralis_des.studies.backends import Backend, make_backend
from astralis_des.studies.runner import run_study
from astralis_des.studies.table import Z95, two_proportion_z
from astralis_des.studies.tune_output import JOURNAL, TUNE_FILES, TuneResult, write_tune
from astralis_des.studies.tune_spec import Bound, Tune, split_metric

Progress = Callable[[int, int], None]  # (trials done, trials in all)


def run_tune(tune: Tune, *, workers: int | None = None, backend: str = "local",
             address: str | None = None, out: str | Path | None = None, resume: bool = False,
             progress: Progress | None = None) -> TuneResult:
    """Run the tune's trials (after those ``out`` holds, with ``resume``); write ``out``."""
    import optuna

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    folder = Path(out) if out is not None else None
    done = _start(tune, folder, resume)
    study = optuna.create_study(directions=_directions(tune))
    spaces = distributions(tune)
    for record in done:
        study.add_trial(optuna.trial.create_trial(
            params=record["params"], distributions=spaces, values=record["values"],
            state=optuna.trial.TrialState[record["optuna_state"]],
            system_attrs=record["system_attrs"], user_attrs=record["user_attrs"]))
    rows = [r["row"] for r in done]
    t0, ran, interrupted = time.perf_counter(), 0, False
    points = _grid_points(tune) if tune.spec.sampler == "grid" else None
    total = min(tune.spec.trials, len(points)) if points is not None else tune.spec.trials
    # one set of workers for every trial, holding the base study and what they cache on its
    # world (free floor, furnished rooms): a trial sends its parameters alone
    runner = make_backend(backend, workers or os.cpu_count() or 1, address)
    try:
        runner.hold(tune.study)
        for number in range(len(done), total):
            study.sampler = _sampler(tune, number)
            if points is not None:  # the grid in order: each point once
                study.enqueue_trial(points[number])
            trial = study.ask(spaces)
            row, values, constraints = evaluate(tune, trial.params, runner)
            ran += row.pop("_rows")
            row["trial"] = number
            for i, value in enumerate(constraints):  # <= 0: met; the samplers read these
                trial.set_constraint(f"c{i}", value)
            state = optuna.trial.TrialState.COMPLETE if values else optuna.trial.TrialState.FAIL
            study.tell(trial, values or None, state=state)
            frozen = study.trials[-1]
            rows.append(row)
            _append(folder, {"row": row, "params": frozen.params, "values": values or None,
                             "optuna_state": state.name, "system_attrs": frozen.system_attrs,
                             "user_attrs": frozen.user_attrs})
            if progress is not None:
                progress(number + 1, total)
    except KeyboardInterrupt:
        interrupted = True
    finally:
        runner.close()
    result = TuneResult(tune, rows, interrupted, time.perf_counter() - t0, ran)
    result.best = _best(result)
    if folder is not None:
        write_tune(result, folder)
    return result


# -- one trial -------------------------------------------------------------------------------
def evaluate(tune: Tune, params: dict[str, Any],
             runner: Backend) -> tuple[dict[str, Any], list[float], list[float]]:
    """Run the study with ``params`` set; the trial's row, its objective values (empty if
    the study failed) and its constraint values (<= 0 is feasible)."""
    base = tune.study
    values_set = {k: _unplain(tune, k, v) for k, v in params.items()}
    study = base.with_changes(set={**base.spec.set, **values_set})
    t0 = time.perf_counter()
    result = run_study(study, backend=runner)
    if result.interrupted:
        raise KeyboardInterrupt
    entries = {(e["variant"], e["metric"]): e for e in result.summary()}
    variants = [v.name for v in study.variants]
    columns = sorted({m for _, m in entries})
    row: dict[str, Any] = {f"param.{k}": v for k, v in params.items()}
    values: list[float] = []
    z_all: list[float] = []
    for name in tune.metrics():
        entry = entries[split_metric(name, variants, columns)]
        row[name] = entry["estimate"]
        if name in tune.spec.targets:
            z = z_score(entry, tune.targets()[name].value,
                        tune.targets()[name].n or study.scenarios)
            row[f"z.{name}"] = z
            z_all.append(abs(z))
    constraints = []
    for c in tune.spec.constraints:
        est = row[c.metric]
        excess = max((c.min - est) if c.min is not None else -math.inf,
                     (est - c.max) if c.max is not None else -math.inf)
        constraints.append(excess if not math.isnan(excess) else math.inf)  # no value: broken
    values = ([max(z_all)] if tune.spec.targets
              else [row[o.metric] for o in tune.spec.objectives])
    failed = result.failed
    ok = not failed and all(math.isfinite(v) for v in values)
    row.update(score=values[0] if len(values) == 1 else None, state="ok" if ok else "failed",
               feasible=all(c <= 0 for c in constraints), failed_runs=failed,
               seconds=round(time.perf_counter() - t0, 3), _rows=len(result.rows))
    return row, values if ok else [], constraints


def z_score(entry: dict[str, Any], target: float, n_target: int) -> float:
    """How far the study's estimate is from ``target``: a rate by the two-proportion z-test
    (pooled), a mean by its standard error; 0 when both are exact and equal."""
    est, n = entry["estimate"], entry["n"]
    if not n or math.isnan(est):
        return math.inf
    if entry["kind"] == "rate":
        return two_proportion_z(est, n, target, n_target)
    se = (entry["high"] - entry["low"]) / (2 * Z95) if math.isfinite(entry["high"]) else 0
    if se == 0:
        return 0.0 if est == target else math.copysign(math.inf, est - target)
    return (est - target) / se


# -- Optuna ------------------------------------------------------------------------------------
def distributions(tune: Tune) -> dict[str, Any]:
    from optuna.distributions import (
        CategoricalDistribution,
        FloatDistribution,
        IntDistribution,
    )

    out: dict[str, Any] = {}
    for name, space in tune.spec.params.items():
        if isinstance(space, list):
            out[name] = CategoricalDistribution([_plain(v) for v in space])
        elif space.step is not None and float(space.step).is_integer() and \
                float(space.low).is_integer():
            out[name] = IntDistribution(int(space.low), int(space.high), step=int(space.step))
        else:
            out[name] = FloatDistribution(space.low, space.high, log=space.log, step=space.step)
    return out


def _plain(value: Any) -> Any:
    """A categorical choice Optuna can store: a scalar, or a mapping as its JSON text."""
    return value if value is None or isinstance(value, str | int | float | bool) else \
        json.dumps(value, sort_keys=True)


def _unplain(tune: Tune, name: str, value: Any) -> Any:
    space = tune.spec.params[name]
    if isinstance(space, list):
        return next((v for v in space if _plain(v) == value), value)
    return value


def _directions(tune: Tune) -> list[Any]:
    if tune.spec.targets:
        return ["minimize"]
    return [o.direction for o in tune.spec.objectives]


def _sampler(tune: Tune, number: int) -> Any:
    import optuna

    seed = int.from_bytes(hashlib.sha256(f"{tune.spec.seed}:{number}".encode()).digest()[:4],
                          "little")
    kind = tune.spec.sampler
    if kind in ("random", "grid"):  # grid: its points are enqueued
        return optuna.samplers.RandomSampler(seed=seed)
    if kind == "nsga2":  # generations of a quarter of the trials (Optuna's 50 would leave
        # a tune of 40 trials at its random first generation)
        return optuna.samplers.NSGAIISampler(
            population_size=max(4, min(50, tune.spec.trials // 4)), seed=seed)
    return optuna.samplers.TPESampler(seed=seed)


def _grid_points(tune: Tune) -> list[dict[str, Any]]:
    """Every combination of the grid's values, in file order (the last parameter fastest)."""
    axes = grid(tune)
    return [dict(zip(axes, combo, strict=True)) for combo in itertools.product(*axes.values())]


def grid(tune: Tune) -> dict[str, list[Any]]:
    """The grid's values of each parameter: the choices, or low to high in steps."""
    out: dict[str, list[Any]] = {}
    for name, space in tune.spec.params.items():
        if isinstance(space, list):
            out[name] = [_plain(v) for v in space]
            continue
        assert isinstance(space, Bound) and space.step is not None
        count = math.floor((space.high - space.low) / space.step + 1e-9) + 1
        values = [space.low + i * space.step for i in range(count)]
        out[name] = [int(v) if float(v).is_integer() and float(space.step).is_integer()
                     else round(v, 12) for v in values]
    return out


def _best(result: TuneResult) -> list[dict[str, Any]]:
    ok = [r for r in result.rows if r["state"] == "ok"]
    feasible = [r for r in ok if r["feasible"]] or ok
    if not feasible:
        return []
    spec = result.tune.spec
    if spec.targets:
        return [min(feasible, key=lambda r: (r["score"], r["trial"]))]
    signs = [1 if o.direction == "minimize" else -1 for o in spec.objectives]

    def key(r: dict[str, Any]) -> list[float]:
        return [s * r[o.metric] for s, o in zip(signs, spec.objectives, strict=True)]

    front = [r for r in feasible if not any(_dominates(key(o), key(r)) for o in feasible)]
    return sorted(front, key=lambda r: (key(r), r["trial"]))


def _dominates(a: list[float], b: list[float]) -> bool:
    return all(x <= y for x, y in zip(a, b, strict=True)) and a != b


# -- the journal -----------------------------------------------------------------------------
def _fingerprint(tune: Tune) -> str:
    return hashlib.sha256((tune.text + "\0" + tune.study.text).encode()).hexdigest()


def _start(tune: Tune, folder: Path | None, resume: bool) -> list[dict[str, Any]]:
    """The trials to keep (resume), after the folder is made ready for this tune."""
    if folder is None:
        if resume:
            raise InputError("resuming needs the output folder of the tune", key="--resume")
        return []
    usable(folder)
    journal = folder / JOURNAL
    header = {"tune": tune.name, "fingerprint": _fingerprint(tune)}
    if resume and journal.is_file():
        lines = journal.read_text(encoding="utf-8").splitlines()
        first = journal_loads(lines[0]) if lines else {}
        if first.get("fingerprint") != header["fingerprint"]:
            raise InputError(f"{journal} is of another tune (or of this one before its file "
                             "or its study's changed): run without --resume, or give "
                             "another --out", key="--resume")
        done = []
        for line in lines[1:]:
            try:
                done.append(journal_loads(line))
            except json.JSONDecodeError:  # the last line of a killed run
                break
        done = done[:tune.spec.trials]
        journal.write_text("".join(journal_dumps(r) + "\n" for r in [header, *done]),
                           encoding="utf-8")
        return done
    folder.mkdir(parents=True, exist_ok=True)
    for name in TUNE_FILES:  # never a file of an earlier tune beside this one's
        path = folder / name
        if path.is_dir():
            import shutil

            shutil.rmtree(path)
        else:
            path.unlink(missing_ok=True)
    journal.write_text(journal_dumps(header) + "\n", encoding="utf-8")
    return []


def _append(folder: Path | None, record: dict[str, Any]) -> None:
    if folder is None:
        return
    with (folder / JOURNAL).open("a", encoding="utf-8") as f:
        f.write(journal_dumps(record) + "\n")
