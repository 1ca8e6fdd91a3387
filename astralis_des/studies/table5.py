"""The paper's Table V: 1,000 random assignment problems, naive against mixed.

The paper reports how often the human is assigned to a high-risk room and the UGV to a
high-messiness room (shares of all scenarios). A figure of ours agrees with the paper's when
the two proportions are within sampling error of each other: a two-proportion z-test, at 95%,
counting the paper's own 1,000 scenarios as a sample too.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from astralis_des.studies.reports import REPORTS, TextTable, summary_report
from astralis_des.studies.table import Z95, format_estimate, two_proportion_z

if TYPE_CHECKING:
    from astralis_des.studies.results import StudyResult

PAPER_N = 1000
PAPER: dict[str, dict[str, float]] = {
    "naive": {"human_high_risk": 0.393, "ugv_high_mess": 0.360},
    "mixed": {"human_high_risk": 0.000, "ugv_high_mess": 0.059},
}
ROWS = {"human_high_risk": "Human assigned to high-risk area",
        "ugv_high_mess": "UGV assigned to high-messiness area"}
# The readings of the printed W1 = [0, 5, 10] and W2 = [5, 0, 10] ([human, UAV, UGV]) tried.
READINGS: dict[str, dict[str, dict[str, float]]] = {
    "as_printed": {"risk": {"human": 0, "uav": 5, "ugv": 10},
                   "messiness": {"human": 5, "uav": 0, "ugv": 10}},
    "w1_reversed": {"risk": {"human": 10, "uav": 5, "ugv": 0},
                    "messiness": {"human": 5, "uav": 0, "ugv": 10}},
    "w2_reversed": {"risk": {"human": 0, "uav": 5, "ugv": 10},
                    "messiness": {"human": 10, "uav": 0, "ugv": 5}},
    "both_reversed": {"risk": {"human": 10, "uav": 5, "ugv": 0},
                      "messiness": {"human": 10, "uav": 0, "ugv": 5}},
    "swapped": {"risk": {"human": 5, "uav": 0, "ugv": 10},
                "messiness": {"human": 0, "uav": 5, "ugv": 10}},
}


def z_score(k: int, n: int, paper: float, paper_n: int = PAPER_N) -> float:
    """Two-proportion z: our ``k / n`` against the paper's share of ``paper_n`` scenarios."""
    return two_proportion_z(k / n, n, paper, paper_n)


def agrees(k: int, n: int, paper: float, z: float = Z95) -> bool:
    """Within sampling error of the paper's figure (|z| <= 1.96 by default)."""
    return abs(z_score(k, n, paper)) <= z


def compare(result: StudyResult) -> list[dict[str, Any]]:
    """Per variant and Table V row: ours (count, n, interval) against the paper's figure for
    the variant's strategy."""
    entries = {(e["variant"], e["metric"]): e for e in result.summary()}
    out = []
    for variant in result.study.variants:
        paper = PAPER.get(variant.setting.strategy)
        for metric, text in ROWS.items():
            entry = entries.get((variant.name, metric))
            if entry is None or entry["n"] == 0:
                continue
            k = round(entry["estimate"] * entry["n"])
            ref = paper[metric] if paper else None
            out.append({"variant": variant.name, "strategy": variant.setting.strategy,
                        "row": text, "metric": metric, "k": k, "n": entry["n"],
                        "entry": entry, "paper": ref,
                        "z": z_score(k, entry["n"], ref) if ref is not None else None})
    return out


@REPORTS.register("table5")
def table5_report(result: StudyResult) -> list[TextTable]:
    """Table V as the paper prints it, ours beside it, then the study's summary."""
    rows = []
    for c in compare(result):
        paper = "-" if c["paper"] is None else f"{c['paper']:.1%}"
        verdict = "-" if c["z"] is None else (
            f"{'yes' if abs(c['z']) <= Z95 else 'NO'} (z = {c['z']:+.2f})")
        rows.append([c["row"], c["variant"], format_estimate(c["entry"]), paper, verdict])
    table = TextTable(
        "Table V: results for randomly initialized assignments",
        ["", "variant", "ours, 95% CI", "paper", "within sampling error"], rows,
        notes=["Shares of all scenarios; 'within sampling error' is a two-proportion z-test "
               f"against the paper's {PAPER_N:,} scenarios at 95%."], keys=2)
    return [table, *summary_report(result)]
