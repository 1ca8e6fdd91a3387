"""A falsify folder: the worst scenarios as mission files, every trial, a report with plots.

    worst/01.yaml ...     the k worst scenarios, complete missions (``astralis run`` them)
    trials.parquet, .csv  one row per trial, optimiser's and random's
    report.md             the worst, the optimiser against random, what drives failure
    plots/convergence.png plots/importance.png
    recordings/01/S/      with ``--recordings``: each worst mission's run folder, per strategy
    meta.json             written last: the folder is a whole result

All of it is written into a staging folder the caller puts in place (:class:`Staging`).
"""

from __future__ import annotations

import json
import os
import platform
from pathlib import Path
from typing import Any

import yaml

from astralis_des.outdir import dumps, finite, result_files, write_file
from astralis_des.studies.falsify import SEARCHES, FalsifyResult
from astralis_des.studies.falsify_eval import trial_mission
from astralis_des.studies.falsify_report import importance, report_markdown, write_plots
from astralis_des.studies.table import write_table

FALSIFY_FILES = result_files("worst", "trials.csv", "trials.parquet", "report.md", "plots",
                             "recordings", "meta.json", key="meta.json")
WORST = "worst"


def write_falsify(result: FalsifyResult, folder: Path, final: Path, *, worst: int,
                  recordings: bool = False, command: str = "") -> list[dict[str, Any]]:
    """Fill ``folder`` (staged; ``final``: where it will be put); the worst rows written."""
    import pyarrow as pa

    from astralis_des.version import __version__

    chosen = result.worst(worst)
    ranks = importance(result)
    (folder / WORST).mkdir(parents=True, exist_ok=True)
    for rank, row in enumerate(chosen, 1):
        write_file(folder / WORST / f"{rank:02d}.yaml",
                   mission_text(result, row, rank, final / WORST))
    if result.rows:
        rows = [{**{k: v for k, v in r.items() if k != "changes"},
                 "mission": json.dumps(r["changes"], sort_keys=True)} for r in result.rows]
        columns = list(dict.fromkeys(k for r in rows for k in r))
        write_table(pa.Table.from_pylist([{c: r.get(c) for c in columns} for r in rows]),
                    folder, "trials")
        write_plots(result, folder / "plots", ranks)
    write_file(folder / "report.md", report_markdown(result, chosen, ranks, command))
    if recordings:
        record(result, chosen, folder / "recordings")
    f = result.falsify
    meta = {"astralis_des": __version__, "mission": str(f.mission.path or f.mission.name),
            "strategy": f.strategy, "against": f.against, "metric": f.metric,
            "worst_is": "largest" if f.largest else "smallest", "sampler": f.sampler,
            "seed": f.seed, "batch": f.batch, "trials_asked": f.trials,
            "trials": {s: sum(r["search"] == s for r in result.rows) for s in SEARCHES},
            "wall_time_s": {k: round(v, 3) for k, v in result.wall_time.items()},
            "interrupted": result.interrupted, "worst": len(chosen), "command": command,
            "python": platform.python_version()}
    write_file(folder / "meta.json", dumps(finite(meta), indent=2) + "\n")
    return chosen


def mission_text(result: FalsifyResult, row: dict[str, Any], rank: int, where: Path) -> str:
    """A worst scenario as a standalone mission file for ``where`` (its folder once in
    place): the base mission with every drawn value set, paths made relative to ``where``,
    and a header with the value and the command that reproduces it."""
    f = result.falsify
    base = f.mission
    data = base.spec.model_dump(mode="json", exclude_unset=True)
    data.update(row["changes"])
    data["name"] = f"{base.name}_worst{rank:02d}"
    data["assignment"] = {**row["changes"]["assignment"], "strategy": f.strategy}
    outputs = dict(data.get("outputs", {}))
    outputs.pop("dir", None)  # out/<its name>
    if outputs:
        data["outputs"] = outputs
    if base.path is not None:
        here = base.path.parent
        data["world"] = _relative(here / base.spec.world, where)
        if base.spec.scene.catalogue is not None:
            data["scene"]["catalogue"] = _relative(here / base.spec.scene.catalogue, where)
        data["plugins"] = [_relative(here / p, where) if p.endswith(".py") else p
                           for p in base.spec.plugins] or None
        if data["plugins"] is None:
            data.pop("plugins")
    order = ["name", "world", "seed"]
    data = {**{k: data[k] for k in order if k in data},
            **{k: v for k, v in data.items() if k not in order}}
    body = yaml.safe_dump(data, sort_keys=False, default_flow_style=None, width=96)
    return header(result, row, rank, where) + body


def header(result: FalsifyResult, row: dict[str, Any], rank: int, where: Path) -> str:
    f = result.falsify
    value = json.dumps(row["value"])
    lines = [f"astralis falsify: worst scenario {rank} for strategy {f.strategy} on {f.metric} "
             f"({'largest' if f.largest else 'smallest'} is worst)",
             f"{f.metric} = {value} under {f.strategy}"
             + ("" if row["value"] is not None or f.metric != "time_to_find" else
                f" (not found: counted as the time limit, {f.mission.spec.time_limit:g} s)")]
    if f.against:
        lines.append(f"{f.metric} = {json.dumps(row['value_against'])} under {f.against}; "
                     f"the gap (worse for {f.strategy}) is {row['score']:.6g}")
    lines += [f"found by the {row['search']} search, trial {row['trial']}",
              f"reproduce: astralis run {_shown(where / f'{rank:02d}.yaml')} (summary.json: "
              + ("not metrics.found)" if f.metric == "not_found" else f"metrics.{f.metric})")]
    return "".join(f"# {line}\n" for line in lines)


def _relative(path: Path, where: Path) -> str:
    """``path`` as ``where`` reaches it: relative where they share a folder below the root,
    else absolute (no ``../../..`` up to ``/``)."""
    full, here = path.resolve(), where.resolve()
    if os.path.commonpath([full, here]) == full.anchor:
        return str(full)
    return os.path.relpath(full, here)


def _shown(path: Path) -> str:
    """A path as a person types it: relative to the working folder when below it."""
    try:
        return str(path.resolve().relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(path)


def record(result: FalsifyResult, chosen: list[dict[str, Any]], folder: Path) -> None:
    """Each worst mission run again with its outputs on, under each strategy."""
    from astralis_des.simulation import Simulation

    f = result.falsify
    for rank, row in enumerate(chosen, 1):
        for strategy in f.strategies:
            mission = trial_mission(f.mission, row["changes"], strategy, True)
            Simulation(mission, out_dir=folder / f"{rank:02d}" / strategy).run()
