"""A report's tables on the terminal: within its width, every value whole."""

from __future__ import annotations

import io
import re

import pytest
from rich.console import Console

from astralis_des.studies.reports import TextTable
from astralis_des.studies.terminal import fitted

# The old summary of a mission study: 17 columns, long headers, values with intervals.
HEADERS = ["variant", "runs", "failed", "found", "time to find",
           "human searching high-risk rooms", "UGV searching high-messiness rooms",
           "rooms searched", "distance (team)", "makespan (last search ends)",
           "sum of completion times", "infeasible rounds", "workload Gini (rooms per robot)",
           "rounds: human to a high-risk room", "rounds: UGV to a high-messiness room",
           "closest moving robot to the human", "human within 1.2 m of a moving robot"]
ROWS = [[name, "20", "0", "100.0% [83.9, 100.0]", "183.9 s [118.1, 249.8]",
         *(f"{k}.5 s [{k}.2, 1{k}.8]" for k in range(12))]
        for name in ("naive", "mixed heuristic, weights as printed", "greedy")]


def drawn(table: TextTable, width: int) -> str:
    console = Console(file=io.StringIO(), width=width, color_system=None)
    for part in fitted(table, width):
        console.print(part)
    return console.file.getvalue()  # type: ignore[attr-defined]


@pytest.mark.parametrize("width", [120, 100, 80, 60])
def test_a_wide_table_fits_with_every_value_whole(width: int) -> None:
    """No line is wider than the terminal, nothing is cut to "…", and every value shows
    whole, each value's interval at worst on the line under it; each part names its rows."""
    text = drawn(TextTable("a study", HEADERS, ROWS), width)
    assert max(len(line) for line in text.splitlines()) <= width
    assert "…" not in text
    cells = re.findall(r"│([^│┃\n]*)(?=│)", text)
    shown = {c.strip() for c in cells}
    for row in ROWS:
        for value in row[1:]:
            estimate, _, interval = value.partition(" [")
            assert value in shown or {estimate, f"[{interval}"} <= shown, value
    parts = text.count("┏")
    assert parts > 1 and text.count("│ naive ") == parts  # each part repeats the variant


def test_a_table_that_fits_is_drawn_as_it_is() -> None:
    """One part, one line a row, the title as given."""
    table = TextTable("Table V", ["", "variant", "ours"],
                      [["Human assigned to high-risk area", "mixed", "0.0% [0.0, 1.9]"]],
                      notes=["Shares of all scenarios."], keys=2)
    text = drawn(table, 100)
    assert text.count("┏") == 1
    assert "│ Human assigned to high-risk area │ mixed   │ 0.0% [0.0, 1.9] │" in text
    assert text.splitlines()[0].strip() == "Table V"
    assert "Shares of all scenarios." in text


def test_a_long_row_name_wraps_at_its_words_before_values_do() -> None:
    """A name too long for the width wraps; the value beside it stays on one line."""
    table = TextTable("", ["", "variant", "ours, 95% CI", "paper", "within sampling error"],
                      [["UGV assigned to high-messiness area", "naive", "35.0% [28.7, 41.8]",
                        "36.0%", "yes (z = -0.27)"]], keys=2)
    text = drawn(table, 90)
    assert max(len(line) for line in text.splitlines()) <= 90
    assert "│ UGV assigned to          │" in text and "│ high-messiness area      │" in text
    assert "35.0% [28.7, 41.8]" in text
