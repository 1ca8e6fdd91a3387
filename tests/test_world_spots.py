"""``astralis world spots``: free start points, each one a mission's validator accepts, the
nearest first."""

from __future__ import annotations

import contextlib
import io
import math
import re
from pathlib import Path

import pytest
import yaml

from astralis_des.cli import main
from astralis_des.kinds import KINDS

ROOT = Path(__file__).resolve().parents[1]
WORLD = ROOT / "worlds" / "urban_default.yaml"
ROW = re.compile(r"^(\[[^\]]+\])\s+(\S+)\s+(\d+\.\d)$")


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(argv))
    return code, out.getvalue(), err.getvalue()


def spots(*argv: str) -> list[tuple[list[float], str, float]]:
    """The listed points, their places and distances."""
    code, out, err = run_cli("world", "spots", str(WORLD), *argv)
    assert code == 0, err
    lines = out.splitlines()
    assert lines[1].split() == ["start", "place", "m", "away"]
    rows = [ROW.match(line) for line in lines[2:]]
    assert all(rows), lines
    return [(yaml.safe_load(m[1]), m[2], float(m[3])) for m in rows if m]


def validate(tmp_path: Path, points: list[list[float]]) -> tuple[int, str]:
    """``astralis validate`` on a mission with a robot of every kind at every point."""
    team = [{"id": f"{kind}{i}", "kind": kind, "start": point}
            for i, point in enumerate(points) for kind in KINDS]
    mission = tmp_path / "spots.yaml"
    mission.write_text(yaml.safe_dump({"name": "spots", "world": str(WORLD), "team": team,
                                       "assignment": {"search": ["A"]}}), encoding="utf-8")
    code, out, err = run_cli("validate", str(mission))
    return code, out + err


@pytest.mark.parametrize("argv", [[], ["--outdoor", "--near", "200", "170"],
                                  ["--indoor", "-n", "30"], ["--near", "140", "80"]],
                         ids=["default", "outdoor-corner", "indoor", "building-b"])
def test_every_listed_spot_validates_as_a_start(tmp_path: Path, argv: list[str]) -> None:
    """A mission starting a UAV, a UGV and a human at each listed point validates."""
    found = spots(*argv)
    n = int(argv[argv.index("-n") + 1]) if "-n" in argv else 10
    assert len(found) == n
    code, said = validate(tmp_path, [point for point, _, _ in found])
    assert code == 0, said
    assert said.startswith(f"ok: {tmp_path / 'spots.yaml'}: mission 'spots', {3 * n} agents")


def test_a_start_in_a_wall_is_refused(tmp_path: Path) -> None:
    """The check above can fail: a point in the wall between two rooms is refused."""
    code, said = validate(tmp_path, [[68.0, 83.0, 0.0]])
    assert code == 2 and "is inside a wall of building A" in said, said


def test_near_orders_by_distance() -> None:
    """Distances from --near, as printed, never decrease; the first spot is the nearest of
    the free points of building B (x 134 to 146) and of the site round it."""
    found = spots("--near", "140", "80", "-n", "12")
    distances = [d for _, _, d in found]
    assert distances == sorted(distances)
    for point, _, d in found:
        assert math.hypot(point[0] - 140, point[1] - 80) == pytest.approx(d, abs=0.05)
    assert found[0][1].startswith("B.1.")  # a room of building B's ground floor
    far = spots("--near", "10", "10", "-n", "3")
    assert [place for _, place, _ in far] == ["outdoor"] * 3
    assert far[0][2] <= math.hypot(2, 2)  # on the 2 m grid, within a cell of the point


def test_outdoor_and_indoor_keep_to_their_places() -> None:
    """--outdoor: only outdoors, inside the site; --indoor: rooms and corridors only."""
    outdoor = spots("--outdoor", "-n", "20")
    assert {place for _, place, _ in outdoor} == {"outdoor"}
    assert all(0 < p[0] < 220 and 0 < p[1] < 175 and p[2] == 0 for p, _, _ in outdoor)
    indoor = spots("--indoor", "-n", "40")
    assert all(re.fullmatch(r"[AB]\.\d\.(\d\.\d|corridor)", place) for _, place, _ in indoor)
    assert {p[2] for p, _, _ in indoor} == {0.0, 3.5, 7.0}  # every storey of building A


def test_an_unknown_kind_is_a_one_line_error() -> None:
    code, out, err = run_cli("world", "spots", str(WORLD), "--kind", "ugb")
    assert (code, out) == (2, "")
    assert err.startswith("error: --kind: unknown robot kind 'ugb'; known: 'uav', 'ugv'")
    assert len(err.splitlines()) == 1
