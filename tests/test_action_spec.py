"""An action is one record: its params are checked from it, and the tables, the chat's verbs and
the mission reference are derived from it."""

from __future__ import annotations

import json
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from pydantic import Field

from astralis_des.action_spec import ActionParams, ActionSpec, Number
from astralis_des.actions import ACTIONS
from astralis_des.assignment.durations import seconds_per_m2
from astralis_des.assignment.rules import table4
from astralis_des.chat import robots
from astralis_des.cli import main
from astralis_des.env.layout import SEARCHES
from astralis_des.mission.reference import action_params
from astralis_des.plugins import check_params

ROOT = Path(__file__).parents[1]
WORLD = ROOT / "worlds" / "urban_default.yaml"
MISSION = ROOT / "missions" / "urban_search.yaml"


def _mission_with(tmp_path: Path, command: str) -> tuple[Path, int]:
    """urban_search.yaml with one timeline command appended; the file and the command's line."""
    text = re.sub(r"(?m)^world:.*$", f"world: {json.dumps(str(WORLD))}",
                  MISSION.read_text(encoding="utf-8"))
    assert "\ntimeline:" not in text
    text += f"timeline:\n  - {{at: 5, event: command, robot: uav1, {command}}}\n"
    path = tmp_path / "typo.yaml"
    path.write_text(text, encoding="utf-8")
    return path, len(text.splitlines())


def test_a_typo_in_a_mission_param_is_one_line_naming_file_line_and_key(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``spacng`` for ``spacing``: refused, the line says where and what the action takes."""
    path, line = _mission_with(tmp_path, "action: spiral_inward, room: A.1.1.2, "
                                         "params: {spacng: 2}")
    assert main(["validate", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"error: {path}:{line}: timeline[0].params.spacng: spiral_inward has no "
                   "parameter 'spacng' (its parameters: spacing)"]


def test_a_bad_value_is_refused_with_its_range() -> None:
    """A value out of the record's range, a bool or an unknown choice: one line each."""
    assert check_params("uav", "spiral_inward", {"spacing": 2}) == {"spacing": 2.0}
    cases = [
        ("uav", "spiral_inward", {"spacing": 0.01},
         "spiral_inward: spacing must be at least 0.1 (got 0.01)"),
        ("ugv", "sneak_peek", {"dwell": 601}, "sneak_peek: dwell must be at most 600 (got 601)"),
        ("human", "inspect", {"inset": True},
         "inspect: inset must be a finite number (got True)"),
        ("ugv", "move", {"point": "roof"},
         "move: point must be one of center, door (got 'roof')"),
        ("ugv", "move", {"x": None}, "move: x must be a number (got None)"),
        ("uav", "take_off", {"height": 2},
         "take_off has no parameter 'height' (its parameters: none)")]
    for kind, action, params, message in cases:
        with pytest.raises(ValueError, match=re.escape(message)):
            check_params(kind, action, params)


class _ReachParams(ActionParams):
    reach: Number = Field(1.0, ge=0.0, le=3.0, description="m of the arm")


class _AltitudeParams(ActionParams):
    altitude: Number = Field(2.0, ge=0.5, le=10.0, description="m above the floor")


@pytest.fixture
def probes() -> Iterator[None]:
    """A UAV's and a UGV's action both named ``probe``, each with its own schema."""
    def run(ctx: Any, robot: Any, task: Any) -> Any:
        yield ctx.env.timeout(1.0)

    ACTIONS.add(ActionSpec("probe", ("uav",), run, params=_AltitudeParams))
    ACTIONS.add(ActionSpec("probe", ("ugv",), run, params=_ReachParams))
    yield
    ACTIONS.remove(("uav", "probe"))
    ACTIONS.remove(("ugv", "probe"))


def test_two_kinds_may_have_an_action_of_one_name_with_two_schemas(probes: None) -> None:
    """The record is keyed by (kind, name): the UAV's probe takes altitude, the UGV's reach."""
    assert check_params("uav", "probe", {"altitude": 3}) == {"altitude": 3.0}
    assert check_params("ugv", "probe", {"reach": 2}) == {"reach": 2.0}
    with pytest.raises(ValueError, match=re.escape(
            "probe has no parameter 'reach' (its parameters: altitude)")):
        check_params("uav", "probe", {"reach": 2})
    doc = action_params()
    uav, ugv = doc.split("### ugv")[0], doc.split("### ugv")[1].split("### human")[0]
    assert "| `probe` | required | `altitude` | number (>= 0.5, <= 10) | 2.0 |" in uav
    assert "| `probe` | required | `reach` | number (>= 0, <= 3) | 1.0 |" in ugv
    assert "reach" not in uav and "altitude" not in ugv


def test_an_action_is_registered_once_per_kind() -> None:
    """A record registered twice for a kind is refused; ``move`` is one record for all."""
    spec = ACTIONS.get(("uav", "move"))
    assert ACTIONS.get(("ugv", "move")) is spec and ACTIONS.get(("human", "move")) is spec
    with pytest.raises(ValueError, match=re.escape(
            "action ('uav', 'hover') is registered twice")):
        ACTIONS.add(ActionSpec("hover", ("uav",), spec.run))


def test_the_reference_lists_every_param_of_every_action_per_kind() -> None:
    """docs/missions.md has a row for each kind's action and each of its params."""
    doc = (ROOT / "docs" / "missions.md").read_text(encoding="utf-8")
    assert "action_params.py" not in doc
    sections = dict(part.split("\n", 1) for part in doc.split("### ")[1:])
    for kind, name in ACTIONS:
        spec = ACTIONS.get((kind, name))
        fields = spec.fields()
        rows = [r for r in sections[kind].splitlines() if r.startswith(f"| `{name}` |")]
        assert len(rows) == max(len(fields), 1), (kind, name)
        for param in fields:
            assert any(f"| `{param}` |" in r for r in rows), (kind, name, param)
    assert "| `hover` | none | `duration` | number (>= 0, <= 86400) | 10.0 |" in sections["uav"]


def test_the_tables_are_derived_from_the_records() -> None:
    """Table IV, the planners' seconds per m^2, the environments' searches, the chat's verbs."""
    assert table4()[("uav", False, True)] == "sweep_horizontal"
    assert table4()[("ugv", False, False)] == "sneak_peek"
    assert len(table4()) == 12
    assert seconds_per_m2("ugv", "observe_corridor") == 0.753
    assert seconds_per_m2("uav", "sweep_vertical") == 0.5  # not measured
    assert SEARCHES == ("spiral_inward", "spiral_outward", "sweep_horizontal", "sweep_vertical",
                        "observe_corridor", "sneak_peek", "inspect")
    hover = robots.VERBS.get(("uav", "hover"))
    assert hover.help == "hold position and look around (default 10 s)"
    assert robots.VERBS.get(("uav", "search")).variants["outward"] == "spiral_outward"
    assert (robots.ANY_KIND, "move") in robots.VERBS


def test_a_task_holds_the_checked_params_whether_kept_or_not() -> None:
    """A task's params are ``check_params``'s, sorted, also when a plain value's answer is
    kept: an int is made a float, -0.0 stays itself, and a bad value is refused every time."""
    from astralis_des.simulation.core import checked_params

    for _ in range(2):
        assert checked_params("uav", "hover", {"duration": 10}) == (("duration", 10.0),)
        assert type(checked_params("uav", "hover", {"duration": 10})[0][1]) is float
        assert checked_params("uav", "move", {"point": "door"}) == tuple(
            sorted(check_params("uav", "move", {"point": "door"}).items()))
        assert str(checked_params("uav", "hover", {"duration": -0.0})[0][1]) == "-0.0"
        assert str(checked_params("uav", "hover", {"duration": 0.0})[0][1]) == "0.0"
        assert checked_params("uav", "spiral_inward", {}) == ()
        with pytest.raises(ValueError, match=r"spacing must be at least 0\.1"):
            checked_params("uav", "spiral_inward", {"spacing": 0.01})
