"""docs/missions.md is made from the schema and is up to date (issue 24)."""

from __future__ import annotations

from pathlib import Path

from astralis_des.mission.reference import EXAMPLE, reference
from astralis_des.mission.spec import MissionSpec

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
