"""A study's plots (matplotlib, PNG and SVG), by registry: each one says when it applies."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from astralis_des.registry import Registry

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from astralis_des.studies.results import StudyResult

Summary = list[dict[str, Any]]


@dataclass(frozen=True)
class Plot:
    draw: Callable[[StudyResult, Summary], Figure]
    applies: Callable[[StudyResult], bool]


PLOTS: Registry[str, Plot] = Registry("study plot")


def plot(name: str, applies: Callable[[StudyResult], bool] = lambda r: True
         ) -> Callable[[Callable[[StudyResult, Summary], Figure]],
                       Callable[[StudyResult, Summary], Figure]]:
    def add(draw: Callable[[StudyResult, Summary], Figure]
            ) -> Callable[[StudyResult, Summary], Figure]:
        PLOTS.register(name)(Plot(draw, applies))
        return draw

    return add


def write_plots(result: StudyResult, summary: Summary, folder: Path) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    folder.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    if result.interrupted or not any(row.get("status") == "ok" for row in result.rows):
        # An interrupted study writes its rows at once (a signal gives a few seconds, and
        # drawing takes them); one whose rows all failed has nothing to draw.
        return written
    for name in PLOTS:
        entry = PLOTS.get(name)
        if not entry.applies(result):
            continue
        figure = entry.draw(result, summary)
        for ext in ("png", "svg"):
            path = folder / f"{name}.{ext}"
            # A fixed date and no software tag keep the SVG the same from run to run.
            figure.savefig(path, dpi=110, metadata={"Date": None} if ext == "svg" else None)
            written.append(path)
        plt.close(figure)
    return written


def _scale(entry: dict[str, Any]) -> float:
    return 100.0 if entry["kind"] == "rate" else 1.0


def _err(entries: list[dict[str, Any]], k: float) -> list[list[float]]:
    """Error bars below and above each estimate (none where an interval is undefined)."""
    def gap(a: float, b: float) -> float:
        return 0.0 if math.isnan(a) or math.isnan(b) else max(0.0, (b - a) * k)

    return [[gap(e["low"], e["estimate"]) for e in entries],
            [gap(e["estimate"], e["high"]) for e in entries]]


def _unit(entry: dict[str, Any]) -> str:
    return "%" if entry["kind"] == "rate" else entry["unit"]


@plot("metrics")
def metrics_plot(result: StudyResult, summary: Summary) -> Figure:
    """One panel per metric: a bar per variant with its 95% interval."""
    import matplotlib.pyplot as plt

    metrics = list(dict.fromkeys(e["metric"] for e in summary))
    variants = [v.name for v in result.study.variants]
    cols = min(3, len(metrics))
    rows = math.ceil(len(metrics) / cols)
    width = max(3.2, 0.45 * len(variants) + 1.5)
    fig, axes = plt.subplots(rows, cols, figsize=(width * cols, 3.2 * rows), squeeze=False)
    for ax, metric in zip(axes.flat, metrics, strict=False):
        mine = [e for e in summary if e["metric"] == metric]
        k = _scale(mine[0])
        est = [e["estimate"] * k for e in mine]
        ax.bar(range(len(mine)), est, yerr=_err(mine, k), capsize=3, color="#4c72b0")
        ax.set_xticks(range(len(mine)), variants, rotation=45 if len(variants) > 3 else 0,
                      ha="right" if len(variants) > 3 else "center", fontsize=8)
        unit = _unit(mine[0])
        ax.set_title(mine[0]["label"] + (f" ({unit})" if unit else ""), fontsize=9)
        ax.grid(axis="y", alpha=0.3)
    for ax in list(axes.flat)[len(metrics):]:
        ax.set_visible(False)
    fig.suptitle(f"{result.study.name}: {result.study.scenarios:,} scenarios, 95% intervals",
                 fontsize=10)
    fig.tight_layout()
    return fig


@plot("tradeoff", applies=lambda r: len(r.study.variants) > 1)
def tradeoff_plot(result: StudyResult, summary: Summary) -> Figure:
    """The evaluation's two costs against each other, a point per variant (a weights sweep
    traces the trade-off); for missions, coloured by the mean time to find."""
    import matplotlib.pyplot as plt

    from astralis_des.studies.scenarios import evaluation_of

    x_col, y_col = evaluation_of(result.study).tradeoff
    by = {(e["variant"], e["metric"]): e for e in summary}
    variants = [v.name for v in result.study.variants]
    xs = [by[(v, x_col)] for v in variants]
    ys = [by[(v, y_col)] for v in variants]
    colour = [by.get((v, "time_to_find")) for v in variants]
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    kx, ky = _scale(xs[0]), _scale(ys[0])
    ax.errorbar([x["estimate"] * kx for x in xs], [y["estimate"] * ky for y in ys],
                xerr=_err(xs, kx), yerr=_err(ys, ky), fmt="none", ecolor="#999999",
                elinewidth=0.8, capsize=2)
    values = [c["estimate"] if c else 0.0 for c in colour]
    style: dict[str, Any] = {"c": values, "cmap": "viridis"} if all(colour) else {}
    dots = ax.scatter([x["estimate"] * kx for x in xs], [y["estimate"] * ky for y in ys],
                      zorder=3, **style)
    if all(colour):
        fig.colorbar(dots, ax=ax, label="mean time to find (s)")
    names, legend = _short_names(result)
    for name, x, y in zip(names, xs, ys, strict=True):
        ax.annotate(name, (x["estimate"] * kx, y["estimate"] * ky), fontsize=7,
                    xytext=(4, 3), textcoords="offset points")
    if legend:
        ax.text(0.99, 0.99, f"labels: {legend}", transform=ax.transAxes, ha="right",
                va="top", fontsize=7, color="#555555")
    ax.set_xlabel(f"{xs[0]['label']} ({_unit(xs[0])})")
    ax.set_ylabel(f"{ys[0]['label']} ({_unit(ys[0])})")
    ax.set_title(f"{result.study.name}: trade-off, means with 95% intervals", fontsize=10)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def _short_names(result: StudyResult) -> tuple[list[str], str]:
    """Variant labels for a crowded plot: the values alone when several parameters vary."""
    variants = result.study.variants
    keys = list(variants[0].columns)
    if len(keys) < 2:
        return [v.name for v in variants], ""
    return ([",".join(f"{c:g}" if isinstance(c, float) else str(c) for c in v.columns.values())
             for v in variants], ",".join(keys))


def _grid_axes(result: StudyResult) -> tuple[str, str] | None:
    """The two varied parameters of a sweep, when exactly two vary, both numbers."""
    columns = result.study.variants[0].columns
    numeric = [k for k, v in columns.items() if isinstance(v, int | float)
               and not isinstance(v, bool)]
    return (numeric[0], numeric[1]) if len(columns) == 2 and len(numeric) == 2 else None


@plot("grid", applies=lambda r: _grid_axes(r) is not None)
def grid_plot(result: StudyResult, summary: Summary) -> Figure:
    """A two-parameter sweep as heat maps: the trade-off's costs (and the time to find),
    one cell per combination, its mean written in."""
    import matplotlib.pyplot as plt
    import numpy as np

    from astralis_des.studies.scenarios import evaluation_of

    axes_names = _grid_axes(result)
    assert axes_names is not None
    rows_key, cols_key = axes_names
    variants = result.study.variants
    rows = sorted({v.columns[rows_key] for v in variants})
    cols = sorted({v.columns[cols_key] for v in variants})
    metrics = list(evaluation_of(result.study).tradeoff)
    if any(e["metric"] == "time_to_find" for e in summary):
        metrics.append("time_to_find")
    by = {(e["variant"], e["metric"]): e for e in summary}
    fig, panels = plt.subplots(1, len(metrics), figsize=(4.2 * len(metrics), 3.8),
                               squeeze=False)
    for ax, metric in zip(panels[0], metrics, strict=True):
        cells = np.full((len(rows), len(cols)), np.nan)
        first = None
        for v in variants:
            entry = by[(v.name, metric)]
            first = first or entry
            cells[rows.index(v.columns[rows_key]), cols.index(v.columns[cols_key])] = (
                entry["estimate"] * _scale(entry))
        image = ax.imshow(cells, origin="lower", cmap="magma_r", aspect="auto")
        for (i, j), value in np.ndenumerate(cells):
            ax.text(j, i, f"{value:.1f}", ha="center", va="center", fontsize=8,
                    color="white" if value > np.nanmean(cells) else "black")
        ax.set_xticks(range(len(cols)), [f"{c:g}" for c in cols])
        ax.set_yticks(range(len(rows)), [f"{r:g}" for r in rows])
        ax.set_xlabel(cols_key)
        ax.set_ylabel(rows_key)
        assert first is not None
        ax.set_title(f"{first['label']} ({_unit(first)})", fontsize=9)
        fig.colorbar(image, ax=ax, shrink=0.8)
    fig.suptitle(f"{result.study.name}: means over {result.study.scenarios:,} scenarios",
                 fontsize=10)
    fig.tight_layout()
    return fig


@plot("time_to_find", applies=lambda r: r.study.spec.evaluate == "mission"
      and len(r.study.variants) <= 8)
def time_to_find_plot(result: StudyResult, summary: Summary) -> Figure:
    """The share of scenarios whose target is found by each time (an ECDF per variant)."""
    import matplotlib.pyplot as plt
    import numpy as np

    data = result.table.to_pydict()
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for v in result.study.variants:
        mine = [i for i, name in enumerate(data["variant"]) if name == v.name
                and data["status"][i] == "ok"]
        times = np.sort([data["time_to_find"][i] for i in mine
                         if data["time_to_find"][i] is not None])
        if not mine:
            continue
        share = np.arange(1, len(times) + 1) / len(mine)
        ax.step(np.concatenate([[0.0], times]), np.concatenate([[0.0], share]), where="post",
                label=f"{v.name} ({len(times) / len(mine):.0%} found)")
    ax.set_xlabel("time to find (s)")
    ax.set_ylabel("share of scenarios found")
    ax.set_ylim(0, 1)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(f"{result.study.name}: time to find the target", fontsize=10)
    fig.tight_layout()
    return fig
