"""The registry idiom: duplicates refused, failed lookups list or suggest what exists."""

from __future__ import annotations

import pytest

from astralis_des.actions import ACTIONS, actions_for
from astralis_des.registry import Registry, UnknownEntry


def test_table_i_actions_are_registered_per_kind() -> None:
    """Every action of the paper's Table I, plus the human's move and inspect."""
    assert actions_for("uav") == ["hover", "land", "move", "spiral_inward", "spiral_outward",
                                  "sweep_horizontal", "sweep_vertical", "take_off"]
    assert actions_for("ugv") == ["move", "observe_corridor", "sneak_peek"]
    assert actions_for("human") == ["inspect", "move"]


def test_a_duplicate_registration_is_refused() -> None:
    """Registering the same key twice is a bug, caught at import time."""
    reg: Registry[str, int] = Registry("thing")
    reg.register("a")(1)
    with pytest.raises(ValueError, match="thing 'a' is registered twice"):
        reg.register("a")(2)


def test_an_unknown_action_suggests_the_nearest() -> None:
    """A typo gets a 'did you mean'."""
    with pytest.raises(UnknownEntry, match="did you mean 'uav/spiral_inward'"):
        ACTIONS.get(("uav", "spiral_inwrd"))


@pytest.mark.parametrize(("typo", "choices", "meant"), [
    ("uva1", ["ugv1", "uav1", "uav2"], "uav1"),  # two letters swapped: one edit
    ("stauts", ["stats", "status"], "status"),
    ("sed", ["seed", "set", "name"], "seed"),
    ("hovr", ["hover", "move"], "hover")])
def test_suggest_prefers_the_fewest_edits(typo: str, choices: list[str], meant: str) -> None:
    from astralis_des.errors import suggest

    assert suggest(typo, choices) == f"did you mean '{meant}'?"
