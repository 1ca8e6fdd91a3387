"""Shared fixtures: the repository's folders and the default world and mission."""

from __future__ import annotations

from pathlib import Path

import pytest

from astralis_des import Mission, load_mission
from astralis_des.world.build import load_world
from astralis_des.world.model import World

ROOT = Path(__file__).resolve().parents[1]
MISSIONS = ROOT / "missions"
DEFAULT_WORLD = ROOT / "worlds" / "urban_default.yaml"


@pytest.fixture(scope="session")
def world() -> World:
    return load_world(DEFAULT_WORLD)


@pytest.fixture(scope="session")
def urban_search() -> Mission:
    return load_mission(MISSIONS / "urban_search.yaml")
