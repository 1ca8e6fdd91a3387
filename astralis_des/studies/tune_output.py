"""A tune's folder: the trials table (CSV, Parquet), the best trial or the front (JSON), plots
of each aim against each parameter and of the front, a report, the tune file and its meta.

The journal (``trials.jsonl``) is written as trials end; these files when the tune ends or is
interrupted, all in a staging folder put in place at the end (``astralis tune``: a killed tune
leaves its journal there, and ``--resume`` goes on from it).
"""

from __future__ import annotations

import math
import platform
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from astralis_des.outdir import dumps, finite, result_files, write_file
from astralis_des.studies.reports import TextTable
from astralis_des.studies.table import Z95, write_table
from astralis_des.studies.tune_spec import Tune

JOURNAL = "trials.jsonl"
TUNE_FILES = result_files(JOURNAL, "trials.csv", "trials.parquet", "best.json", "report.md",
                          "tune.yaml", "meta.json", "plots", key="meta.json")


@dataclass
class TuneResult:
    tune: Tune
    rows: list[dict[str, Any]]  # one per trial, in trial order
    interrupted: bool = False
    wall_time: float = 0.0
    study_rows: int = 0  # study rows run by this call (resumed trials not counted)
    best: list[dict[str, Any]] = field(default_factory=list)  # best trial, or the front

    def fits(self) -> list[dict[str, Any]]:
        """Targets: every feasible trial that reproduces all targets within sampling error."""
        return [r for r in self.rows if r["state"] == "ok" and r["feasible"]
                and r["score"] <= Z95]


def write_tune(result: TuneResult, folder: Path) -> None:
    import pyarrow as pa

    from astralis_des.version import __version__

    folder.mkdir(parents=True, exist_ok=True)
    if result.rows:
        columns = list(dict.fromkeys(["trial", *(k for r in result.rows for k in r)]))
        table = pa.Table.from_pylist([{c: r.get(c) for c in columns} for r in result.rows])
        write_table(table, folder, "trials")
    write_file(folder / "best.json", dumps(finite(result.best), indent=2) + "\n")
    write_file(folder / "report.md", report_markdown(result))
    write_file(folder / "tune.yaml", result.tune.text)
    meta = {"astralis_des": __version__, "tune": result.tune.name, "seed": result.tune.spec.seed,
            "sampler": result.tune.spec.sampler, "trials": len(result.rows),
            "trials_asked": result.tune.spec.trials, "interrupted": result.interrupted,
            "scenarios": result.tune.study.scenarios, "wall_time_s": round(result.wall_time, 3),
            "python": platform.python_version()}
    write_file(folder / "meta.json", dumps(meta, indent=2) + "\n")
    if result.rows:
        write_plots(result, folder / "plots")


def _fmt(value: Any) -> str:
    if isinstance(value, float):
        return "inf" if math.isinf(value) else f"{value:.4g}"
    return str(value)


Block = str | TextTable  # a paragraph or heading (Markdown), or a table


def report_markdown(result: TuneResult) -> str:
    """``report.md``: the report's blocks, a blank line between them."""
    return "\n".join(b if isinstance(b, str) else b.markdown() for b in
                     _spaced(report(result)))


def _spaced(blocks: list[Block]) -> list[Block]:
    out: list[Block] = []
    for block in blocks:
        out += [block, ""] if isinstance(block, str) else [block]
    return out


def report(result: TuneResult) -> list[Block]:
    """The report: what was searched, the best (or the front), the fit."""
    spec = result.tune.spec
    params = list(spec.params)
    ok = [r for r in result.rows if r["state"] == "ok"]
    blocks: list[Block] = [
        f"# Tune {spec.name}",
        f"{len(result.rows)} of {spec.trials} trials ({spec.sampler}, seed {spec.seed}), "
        f"{result.tune.study.scenarios:,} scenarios a trial"
        + ("; interrupted" if result.interrupted else "") + "."]
    if not result.best:
        return [*blocks, "No trial ran to the end."]
    if spec.targets:
        best = result.best[0]
        blocks += ["## Best trial", f"Trial {best['trial']}: largest |z| {_fmt(best['score'])}.",
                   TextTable("", ["parameter", "value"],
                             [[p, _fmt(best[f"param.{p}"])] for p in params]),
                   TextTable("", ["target", "ours", "wanted", "z"],
                             [[m, _fmt(best[m]), _fmt(t.value), f"{best[f'z.{m}']:+.2f}"]
                              for m, t in result.tune.targets().items()])]
        fits = result.fits()
        blocks += ["## The weights that fit",
                   f"{len(fits)} of {len(ok)} trials reproduce every target within sampling "
                   f"error (|z| <= {Z95:.2f}) and meet the constraints."
                   + (" Over them, each parameter ranges:" if fits else "")]
        if fits:
            blocks.append(TextTable("", ["parameter", "min", "max"],
                                    [_range(p, [r[f"param.{p}"] for r in fits])
                                     for p in params]))
        return blocks
    aims = [o.metric for o in spec.objectives]
    return [*blocks, "## Front" if len(aims) > 1 else "## Best trial",
            TextTable("", ["trial", *params, *aims],
                      [[str(r["trial"]), *(_fmt(r[k]) for k in
                                           [*(f"param.{p}" for p in params), *aims])]
                       for r in result.best])]


def _range(param: str, values: list[Any]) -> list[str]:
    """A parameter's least and greatest value over trials; a category's values, in order."""
    if all(isinstance(v, int | float) for v in values):
        return [param, _fmt(min(values)), _fmt(max(values))]
    return [param, ", ".join(sorted(set(map(str, values)))), ""]


def write_plots(result: TuneResult, folder: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    folder.mkdir(parents=True, exist_ok=True)
    spec = result.tune.spec
    ok = [r for r in result.rows if r["state"] == "ok"]
    aims = (["score"] if spec.targets else [o.metric for o in spec.objectives])
    params = list(spec.params)
    cols = min(3, len(params))
    rows_per_aim = -(-len(params) // cols)
    fig, axes = plt.subplots(len(aims) * rows_per_aim, cols, squeeze=False,
                             figsize=(3.6 * cols, 2.8 * len(aims) * rows_per_aim))
    for ax in axes.flat[len(aims) * len(params):]:
        ax.set_visible(False)
    for i, aim in enumerate(aims):
        for j, p in enumerate(params):
            ax = axes[i * rows_per_aim + j // cols][j % cols]
            xs = [r[f"param.{p}"] for r in ok]
            ys = [min(max(r[aim], 0.05), 1e6) if aim == "score" else r[aim] for r in ok]
            colours = ["tab:green" if r["feasible"] else "tab:red" for r in ok]
            ax.scatter([str(x) if isinstance(x, str) else x for x in xs], ys, s=12, c=colours)
            ax.set_xlabel(p)
            if j % cols == 0:
                ax.set_ylabel("largest |z|" if aim == "score" else aim)
            if aim == "score":
                ax.set_yscale("log")  # |z| from 0.05 (below: drawn at 0.05)
                ax.axhline(Z95, color="grey", lw=0.8, ls="--")
    fig.suptitle(f"{spec.name}: each trial (red: a constraint not met)")
    fig.tight_layout()
    fig.savefig(folder / "params.png", dpi=110)
    plt.close(fig)
    if len(aims) == 2:
        fig, ax = plt.subplots(figsize=(5, 4))
        ax.scatter([r[aims[0]] for r in ok], [r[aims[1]] for r in ok], s=12, c="lightgrey",
                   label="trials")
        front = sorted(result.best, key=lambda r: r[aims[0]])
        ax.plot([r[aims[0]] for r in front], [r[aims[1]] for r in front], "o-",
                color="tab:blue", label="front")
        ax.set_xlabel(aims[0])
        ax.set_ylabel(aims[1])
        ax.legend()
        fig.tight_layout()
        fig.savefig(folder / "front.png", dpi=110)
        plt.close(fig)
