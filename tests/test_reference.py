"""docs/missions.md and docs/world.md are made from the schemas and are up to date."""

from __future__ import annotations

from pathlib import Path

from astralis_des.mission.reference import EXAMPLE, WORLD_EXAMPLE, reference, world_reference
from astralis_des.mission.spec import MissionSpec
from astralis_des.plugins import STRATEGIES
from astralis_des.world.spec import WorldSpec

ROOT = Path(__file__).resolve().parents[1]


def test_the_mission_reference_is_the_schemas() -> None:
    made = reference(ROOT / EXAMPLE)
    assert (ROOT / "docs" / "missions.md").read_text(encoding="utf-8") == made, (
        "docs/missions.md is out of date: astralis schema --markdown -o docs/missions.md")


def test_every_key_is_in_it_with_its_default_and_an_example() -> None:
    made = reference(ROOT / EXAMPLE)
    for key in MissionSpec.model_fields:
        assert f"| `{key}` |" in made
    assert ("| `team[].speed` | number (> 0, <= 100) \\| null | null | m/s; default by kind |"
            in made)
    assert "| `seed` | integer (>= 0) | 0 | every random draw derives from it | 42 |" in made
    assert "| `timeline[event=command].params` |" in made
    assert "| `outputs.mcap` | boolean | false |" in made


def test_the_strategies_are_listed_with_the_options_they_read() -> None:
    """``assignment.strategy`` says what it may be; each strategy's row names its options."""
    made = reference(ROOT / EXAMPLE)
    [row] = [line for line in made.splitlines() if line.startswith("| `assignment.strategy` |")]
    for name, _ in STRATEGIES.registered():
        assert f"`{name}`" in row
        assert f"| `{name}` |" in made
    assert ("| `cbba` | the mission's, queued | `bundle`, `comm_range`, `discount` |" in made)
    assert "| `mixed` | a segment's, one an agent | none |" in made
    assert '| `bid` | "marginal" \\| "finish" | "marginal" | `auction` |' in made


def test_the_weights_per_kind_show_the_defaults_they_have() -> None:
    """A kind's weight shows the mission's default (W1 UGV 3), and what a partial map gives."""
    made = reference(ROOT / EXAMPLE)
    assert ("| `assignment.weights.risk.ugv` | number (>= 0) | 3.0 | 0.0 if "
            "`assignment.weights.risk` is given without it |") in made
    assert "| `assignment.weights.messiness.human` | number (>= 0) | 5.0 |" in made
    assert "| `assignment.weights.messiness.uav` | number (>= 0) | 0.0 |  |" in made


def test_the_world_reference_is_the_schemas() -> None:
    """docs/world.md is made from the world schema, every key in it with an example."""
    made = world_reference(ROOT / WORLD_EXAMPLE)
    assert (ROOT / "docs" / "world.md").read_text(encoding="utf-8") == made, (
        "docs/world.md is out of date: python tools/world_reference.py")
    for key in WorldSpec.model_fields:
        assert f"| `{key}` |" in made
    assert ("| `buildings[].segments[].rooms` | integer (> 0) | required | rooms in this "
            "segment, laid along the corridor | 3 |") in made
