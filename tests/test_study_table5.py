"""The paper's Table V from ``studies/table5.yaml``: the figures, their intervals, the readings.

Tolerances come from the sample sizes: our share of n scenarios and the paper's of 1,000 are
both samples, so they may differ by z * sqrt(p (1 - p) (1/n + 1/1000)); z = 2.58 (99%).
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from astralis_des.studies import StudyResult, load_study, run_study
from astralis_des.studies.table import mean_ci, wilson
from astralis_des.studies.table5 import PAPER, READINGS, agrees, compare, table5_report, z_score

ROOT = Path(__file__).parents[1]
TABLE5 = ROOT / "studies" / "table5.yaml"
N = 400
Z99 = 2.576


def tolerance(p: float, n: int, paper_n: int = 1000, z: float = Z99) -> float:
    return z * math.sqrt(p * (1 - p) * (1 / n + 1 / paper_n))


def shares(result: StudyResult) -> dict[tuple[str, str], float]:
    return {(e["variant"], e["metric"]): e["estimate"] for e in result.summary()}


@pytest.fixture(scope="module")
def small() -> dict[tuple[str, str], float]:
    """Table V on 400 scenarios, naive and mixed (the default weights)."""
    return shares(run_study(load_study(TABLE5).with_changes(scenarios=N), workers=1))


@pytest.fixture(scope="module")
def full() -> StudyResult:
    """The study as shipped: 1,000 scenarios (about half a second)."""
    return run_study(load_study(TABLE5), workers=1)


@pytest.mark.parametrize("metric", ["human_high_risk", "ugv_high_mess"])
def test_naive_reproduces_the_paper(small: dict[tuple[str, str], float], metric: str) -> None:
    """The naive baseline's two figures are within sampling error of 39.3% and 36.0%."""
    paper = PAPER["naive"][metric]
    assert abs(small[("naive", metric)] - paper) <= tolerance(paper, N)


def test_mixed_never_sends_the_human_into_high_risk(small: dict[tuple[str, str], float]) -> None:
    """The mixed heuristic's human-to-high-risk share is 0.0%, as in the paper."""
    assert small[("mixed", "human_high_risk")] == 0.0


def test_mixed_ugv_figure_is_the_papers_with_the_default_weights(
        small: dict[tuple[str, str], float]) -> None:
    """With the default weights (W1 reversed, the UGV's risk weight 3: issue 20's fit), the
    UGV goes to a high-messiness room within sampling error of the paper's 5.9%."""
    ugv = small[("mixed", "ugv_high_mess")]
    assert abs(ugv - 0.059) <= tolerance(0.059, N)


def test_w1_reversed_alone_sends_the_ugv_into_clutter_twice_as_often() -> None:
    """The printed numbers with W1 read in reverse (UGV risk weight 0) give about 12.7%, not
    5.9% (docs/studies.md): within our own sampling error of 12.7%, outside that of 5.9%."""
    study = load_study(TABLE5).with_changes(
        scenarios=N, vary={"strategy": ["mixed"],
                           "weights": {"w1_reversed": READINGS["w1_reversed"]}})
    ugv = shares(run_study(study, workers=1))[
        ("strategy=mixed,weights=w1_reversed", "ugv_high_mess")]
    assert abs(ugv - 0.127) <= tolerance(0.127, N)
    assert abs(ugv - 0.059) > tolerance(0.059, N)


def test_unassigned_agents_under_mixed(small: dict[tuple[str, str], float]) -> None:
    """Under mixed, the agent left out is the human or the UGV (the paper's text), about
    four times in five the human; a UAV almost never."""
    human, uav, ugv = (small[("mixed", f"{k}_unassigned")] for k in ("human", "uav", "ugv"))
    assert human + uav + ugv == pytest.approx(1.0)  # one agent left out of 4 for 3 rooms
    assert abs(human - 0.79) <= tolerance(0.79, N)
    assert uav <= 0.01


def test_shipped_study_gives_the_documented_figures(full: StudyResult) -> None:
    """docs/studies.md quotes these figures of ``astralis study studies/table5.yaml``."""
    got = {k: round(v * 1000) for k, v in shares(full).items()}
    assert (got[("naive", "human_high_risk")], got[("naive", "ugv_high_mess")]) == (380, 377)
    assert (got[("mixed", "human_high_risk")], got[("mixed", "ugv_high_mess")]) == (0, 60)
    assert [got[("naive", f"{k}_unassigned")] for k in ("human", "uav", "ugv")] == [226, 533, 241]
    assert [got[("mixed", f"{k}_unassigned")] for k in ("human", "uav", "ugv")] == [792, 0, 208]


def test_report_compares_with_the_paper(full: StudyResult) -> None:
    """The Table V report puts each figure beside the paper's with a verdict."""
    rows = table5_report(full)[0].rows
    assert rows[0] == ["Human assigned to high-risk area", "naive", "38.0% [35.0, 41.0]",
                       "39.3%", "yes (z = -0.60)"]
    assert rows[3] == ["UGV assigned to high-messiness area", "mixed", "6.0% [4.7, 7.6]",
                       "5.9%", "yes (z = +0.09)"]
    assert [c["strategy"] for c in compare(full)] == ["naive", "naive", "mixed", "mixed"]
    assert [row[4].split()[0] for row in rows[:4]] == ["yes"] * 4  # all four, default weights


def test_weights_as_printed_send_the_human_into_high_risk() -> None:
    """Read as printed ([human, UAV, UGV]: human W1 = 0), the mixed heuristic sends the human
    into a high-risk room in about three scenarios in four and never uses the UGV."""
    study = load_study(TABLE5).with_changes(
        scenarios=N, vary={"strategy": ["mixed"], "weights": READINGS})
    got = shares(run_study(study, workers=1))
    printed = "strategy=mixed,weights=as_printed"
    assert abs(got[(printed, "human_high_risk")] - 0.75) <= tolerance(0.75, N)
    assert got[(printed, "ugv_unassigned")] == 1.0
    assert got[("strategy=mixed,weights=w1_reversed", "human_high_risk")] == 0.0


def test_two_proportion_z() -> None:
    """The z-test against the paper counts both samples; equal shares give 0."""
    assert z_score(393, 1000, 0.393) == pytest.approx(0.0)
    assert z_score(0, 1000, 0.0) == 0.0
    # 127/1000 against 59/1000: pooled p = 0.093, se = sqrt(0.093 * 0.907 * 2 / 1000)
    assert z_score(127, 1000, 0.059) == pytest.approx(0.068 / math.sqrt(0.093 * 0.907 * 0.002))
    assert agrees(380, 1000, 0.393) and not agrees(127, 1000, 0.059)


def test_intervals() -> None:
    """Wilson intervals (sound at 0%) and Student-t intervals of a mean, by hand."""
    p, lo, hi = wilson(393, 1000)
    assert (p, round(lo, 4), round(hi, 4)) == (0.393, 0.3632, 0.4236)
    assert wilson(0, 1000)[2] == pytest.approx(1.95996**2 / (1000 + 1.95996**2), rel=1e-4)
    mean, lo, hi = mean_ci([1.0, 2.0, 3.0, 4.0])  # sd 1.291, t(3) = 3.182
    assert (mean, round(lo, 3), round(hi, 3)) == (2.5, 0.446, 4.554)
