"""Tests for Table IV of the paper: the action an assigned agent takes in a room."""

from __future__ import annotations

import pytest

from astralis_des.assignment import table4_action

# (risk, messiness): the four cells of Table IV, with values well inside each cell.
LOW_LOW, HIGH_LOW, LOW_HIGH, HIGH_HIGH = (0.1, 0.2), (0.9, 0.2), (0.1, 0.8), (0.9, 0.8)


@pytest.mark.parametrize(("cell", "uav", "ugv"), [
    (LOW_LOW, "spiral_outward", "sneak_peek"),
    (HIGH_LOW, "spiral_inward", "observe_corridor"),
    (LOW_HIGH, "sweep_horizontal", "observe_corridor"),
    (HIGH_HIGH, "spiral_inward", "observe_corridor"),
], ids=["low-low", "high-risk", "high-mess", "high-high"])
def test_table4_cells(cell: tuple[float, float], uav: str, ugv: str) -> None:
    """Each cell of Table IV gives the paper's UAV and UGV actions."""
    risk, mess = cell
    assert table4_action("uav", risk, mess) == uav
    assert table4_action("ugv", risk, mess) == ugv


@pytest.mark.parametrize("cell", [LOW_LOW, HIGH_LOW, LOW_HIGH, HIGH_HIGH])
def test_human_inspects(cell: tuple[float, float]) -> None:
    """The human operator (no row in Table IV) always inspects."""
    assert table4_action("human", *cell) == "inspect"


@pytest.mark.parametrize(("risk", "mess", "uav", "ugv"), [
    (0.5, 0.0, "spiral_inward", "observe_corridor"),  # risk 0.5 is high
    (0.0, 0.5, "sweep_horizontal", "observe_corridor"),  # messiness 0.5 is high
    (0.5, 0.5, "spiral_inward", "observe_corridor"),
    (0.4999, 0.4999, "spiral_outward", "sneak_peek"),  # just under: low
])
def test_threshold_is_inclusive(risk: float, mess: float, uav: str, ugv: str) -> None:
    """A value equal to the threshold (0.5) counts as high; just below counts as low."""
    assert table4_action("uav", risk, mess) == uav
    assert table4_action("ugv", risk, mess) == ugv


def test_bounds_of_the_unit_interval() -> None:
    """Risk and messiness 0 are low, 1 are high."""
    assert table4_action("uav", 0.0, 0.0) == "spiral_outward"
    assert table4_action("uav", 1.0, 0.0) == "spiral_inward"
    assert table4_action("uav", 0.0, 1.0) == "sweep_horizontal"
    assert table4_action("ugv", 0.0, 0.0) == "sneak_peek"
    assert table4_action("ugv", 1.0, 1.0) == "observe_corridor"


def test_custom_risk_threshold() -> None:
    """With ``high_risk=0.3`` a risk of 0.3 is high and 0.6 with ``high_risk=0.7`` is low."""
    assert table4_action("uav", 0.3, 0.0, high_risk=0.3) == "spiral_inward"
    assert table4_action("ugv", 0.3, 0.0, high_risk=0.3) == "observe_corridor"
    assert table4_action("uav", 0.6, 0.0, high_risk=0.7) == "spiral_outward"
    assert table4_action("ugv", 0.6, 0.0, high_risk=0.7) == "sneak_peek"


def test_custom_messiness_threshold() -> None:
    """With ``high_messiness=0.8`` a messiness of 0.7 is low and 0.8 is high."""
    assert table4_action("uav", 0.0, 0.7, high_messiness=0.8) == "spiral_outward"
    assert table4_action("uav", 0.0, 0.8, high_messiness=0.8) == "sweep_horizontal"
    assert table4_action("ugv", 0.0, 0.7, high_messiness=0.8) == "sneak_peek"
    assert table4_action("ugv", 0.0, 0.8, high_messiness=0.8) == "observe_corridor"


def test_thresholds_are_independent() -> None:
    """Raising the risk threshold does not move the messiness one, and the other way round."""
    assert table4_action("uav", 0.6, 0.6, high_risk=0.9) == "sweep_horizontal"
    assert table4_action("uav", 0.6, 0.6, high_messiness=0.9) == "spiral_inward"
    assert table4_action("uav", 0.6, 0.6, high_risk=0.9, high_messiness=0.9) == \
        "spiral_outward"
