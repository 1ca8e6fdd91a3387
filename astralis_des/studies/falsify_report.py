"""A falsify report: the worst scenarios, the optimiser's curve against random search's, and
which parameters drive failure: Optuna's PED-ANOVA importance, which asks what sets the worst
tenth of the trials apart from the rest (fANOVA would need scikit-learn)."""

from __future__ import annotations

import logging
import math
from pathlib import Path
from typing import Any

from astralis_des.studies.falsify import SEARCHES, FalsifyResult
from astralis_des.studies.falsify_space import describe
from astralis_des.studies.reports import TextTable

log = logging.getLogger(__name__)
SHOWN_PARAMS = 12  # parameters the importance table and plot show
IMPORTANCE_MIN = 20  # random trials that make a sample to rank the parameters on


def _fmt(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.4g}" if math.isfinite(value) else str(value)
    return "" if value is None else str(value)


def best_so_far(result: FalsifyResult, search: str) -> list[float | None]:
    """The worst score found after each trial of ``search`` (None before the first)."""
    best: float | None = None
    out: list[float | None] = []
    for row in (r for r in result.rows if r["search"] == search):
        if row["score"] is not None and (best is None or row["score"] > best):
            best = row["score"]
        out.append(best)
    return out


def importance(result: FalsifyResult) -> dict[str, float]:
    """Each parameter's importance to landing in the worst tenth of the trials (PED-ANOVA):
    over the random search's trials, an even sample of the space (the optimiser's crowd
    where it found the worst, which hides what took it there), else over the optimiser's;
    empty when too few."""
    import optuna
    from optuna.importance import PedAnovaImportanceEvaluator, get_param_importances

    f = result.falsify
    spaces = f.space.distributions()
    scored = [r for r in result.rows if r["score"] is not None]
    even = [r for r in scored if r["search"] == SEARCHES[1]]
    scored = even if len(even) >= IMPORTANCE_MIN else scored
    if len({r["score"] for r in scored}) < 2:
        return {}
    study = optuna.create_study(direction="maximize")
    for r in scored:
        params = {k: r[f"param.{k}"] for k in spaces}
        study.add_trial(optuna.trial.create_trial(params=params, distributions=spaces,
                                                  value=r["score"]))
    try:
        found = get_param_importances(study, evaluator=PedAnovaImportanceEvaluator())
    except (ValueError, RuntimeError) as exc:  # too few distinct trials
        log.warning("no importance ranking: %s", exc)
        return {}
    return dict(found)


def score_label(result: FalsifyResult) -> str:
    f = result.falsify
    if f.against:
        return f"{f.metric}: {f.strategy} worse than {f.against} by"
    return f"{f.metric} of {f.strategy}" + ("" if f.largest else " (negated)")


def report_markdown(result: FalsifyResult, chosen: list[dict[str, Any]],
                    ranks: dict[str, float], command: str = "") -> str:
    f = result.falsify
    blocks: list[str | TextTable] = [
        f"# Falsify {f.mission.name}: {f.strategy} on {f.metric}"
        + (f" against {f.against}" if f.against else ""),
        f"{f.trials} trials asked of the {f.sampler} sampler (seed {f.seed}, batches of "
        f"{f.batch})" + (", and as many drawn at random" if f.baseline else "") + "; "
        f"the {'largest' if f.largest else 'smallest'} {f.metric} is the worst"
        + ("; interrupted" if result.interrupted else "") + "."]
    if command:
        blocks.append(f"The same trials again: `{command}`")
    if result.base:
        blocks.append(f"The mission as given: {f.metric} = {_fmt(result.base.get(f.metric))} "
                      f"under {f.strategy}.")
    blocks += ["## The worst scenarios", _worst_table(result, chosen)]
    blocks += ["## The optimiser against random search", "![convergence](plots/convergence.png)",
               _searches_table(result)]
    blocks += ["## What drives failure"]
    if ranks:
        blocks += ["PED-ANOVA importance of each parameter: how much its values in the worst "
                   "tenth of the random search's trials (an even sample of the space; without "
                   "it, the optimiser's) differ from its values in all of them; the first "
                   "ones:", "![importance](plots/importance.png)",
                   TextTable("", ["parameter", "importance"],
                             [[k, f"{v:.3f}"] for k, v in list(ranks.items())[:SHOWN_PARAMS]])]
    else:
        blocks.append("Too few trials with distinct scores to rank the parameters.")
    blocks += ["## The space", TextTable("", ["parameter", "range"],
                                         [list(r) for r in describe(f.space)])]
    return "\n".join(b if isinstance(b, str) else b.markdown() for b in
                     [x for b in blocks for x in (b, "")])


def _worst_table(result: FalsifyResult, chosen: list[dict[str, Any]]) -> TextTable | str:
    f = result.falsify
    if not chosen:
        return "No trial ran to the end."
    head = ["file", "search", "trial", f.strategy] + ([f.against, "gap"] if f.against else [])
    head += ["target", "fault"]
    rows = []
    for rank, r in enumerate(chosen, 1):
        target = r["changes"]["target"]
        fault = next((f"{e['robot']} at {e['at']:g} s" for e in r["changes"]["timeline"]
                      if e.get("reason") == "falsify"), "none")
        rows.append([f"worst/{rank:02d}.yaml", r["search"], str(r["trial"]), _fmt(r["value"])]
                    + ([_fmt(r["value_against"]), _fmt(r["score"])] if f.against else [])
                    + [f"{target['room']} ({target['avatar'].get('activity', '?')})", fault])
    return TextTable("", head, rows)


def _searches_table(result: FalsifyResult) -> TextTable:
    rows = []
    for search in SEARCHES:
        mine = [r for r in result.rows if r["search"] == search]
        if not mine:
            continue
        curve = best_so_far(result, search)
        best = curve[-1]
        first = next((i for i, v in enumerate(curve) if v is not None and v == best), None)
        rows.append([search, str(len(mine)), _fmt(best),
                     "" if first is None else str(first + 1),
                     f"{result.wall_time.get(search, 0.0):.1f}",
                     str(sum(r["status"] != "ok" for r in mine))])
    return TextTable("", ["search", "trials", f"worst score ({score_label(result)})",
                          "found at trial", "wall s", "failed"], rows)


def write_plots(result: FalsifyResult, folder: Path, ranks: dict[str, float]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    folder.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(6, 4))
    for search, colour in zip(SEARCHES, ("tab:red", "tab:grey"), strict=True):
        curve = best_so_far(result, search)
        if curve:
            ax.step(range(1, len(curve) + 1), [math.nan if v is None else v for v in curve],
                    where="post", color=colour,
                    label=result.falsify.sampler if search == "optimiser" else "random")
            scores = [r["score"] for r in result.rows if r["search"] == search]
            ax.scatter(range(1, len(scores) + 1),
                       [math.nan if v is None else v for v in scores], s=6, color=colour,
                       alpha=0.35)
    ax.set_xlabel("trials")
    ax.set_ylabel("worst score so far (dots: each trial)")
    ax.set_title(f"score: {score_label(result)}", fontsize=9)
    ax.legend()
    fig.tight_layout()
    fig.savefig(folder / "convergence.png", dpi=110)
    plt.close(fig)
    top = list(ranks.items())[:SHOWN_PARAMS]
    if top:
        fig, ax = plt.subplots(figsize=(6, 0.3 * len(top) + 1.2))
        ax.barh([k for k, _ in top][::-1], [v for _, v in top][::-1], color="tab:red")
        ax.set_xlabel("PED-ANOVA importance (worst tenth of the trials)")
        fig.tight_layout()
        fig.savefig(folder / "importance.png", dpi=110)
        plt.close(fig)
