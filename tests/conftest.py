"""Shared fixtures: the repository's folders and the default world and mission."""

from __future__ import annotations

import atexit
import os
import shutil
import signal
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from astralis_des import Mission, load_mission
from astralis_des.world.build import load_world
from astralis_des.world.model import World

# The Ctrl-C tests send SIGINT to the commands they start, as a terminal does. A suite started
# in the background of a non-interactive shell (a CI runner's `cmd &`) inherits SIGINT ignored,
# and so would every command it starts; a terminal's foreground job has it at its default. So
# the suite takes it back: a handler here is reset to the default in each command started.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

# The commands the tests start import the package anew. Where PYTHONDONTWRITEBYTECODE is set
# (CI machines often set it), each would compile what it imports from source, a few tenths of
# a second a command; they share one bytecode cache instead, in a temporary folder (the
# checkout is left as it is), as a user's machine caches it.
if os.environ.pop("PYTHONDONTWRITEBYTECODE", None) and "PYTHONPYCACHEPREFIX" not in os.environ:
    _BYTECODE = tempfile.mkdtemp(prefix="astralis-tests-bytecode-")
    os.environ["PYTHONPYCACHEPREFIX"] = _BYTECODE
    atexit.register(shutil.rmtree, _BYTECODE, ignore_errors=True)

if TYPE_CHECKING:
    from astralis_des.api.client import Client
    from astralis_des.physics.client import PhysicsClient

ROOT = Path(__file__).resolve().parents[1]
MISSIONS = ROOT / "missions"
DEFAULT_WORLD = ROOT / "worlds" / "urban_default.yaml"


@pytest.fixture(scope="session")
def world() -> World:
    return load_world(DEFAULT_WORLD)


@pytest.fixture()
def physics_client(world: World) -> Iterator[PhysicsClient]:
    """A bare physics client of the default world, at the physics' default rates."""
    from astralis_des.mission.spec import PhysicsSpec
    from astralis_des.physics.client import PhysicsClient

    spec = PhysicsSpec()
    client = PhysicsClient(world, spec.dt, spec.rate // spec.control_rate, spec.solver_iterations)
    yield client
    client.close()


@pytest.fixture(scope="session")
def urban_search() -> Mission:
    return load_mission(MISSIONS / "urban_search.yaml")


@pytest.fixture
def address(mission: Mission, tmp_path: Path) -> Iterator[str]:
    """A fresh server of the module's ``mission``, its clock paused: time moves only when a
    test steps it."""
    from astralis_des.api.local import serving

    with serving(mission, running=False, out_dir=tmp_path / "out") as address:
        yield address


@pytest.fixture
def client(address: str) -> Iterator[Client]:
    from astralis_des.api.client import Client

    with Client(address, timeout=5.0) as client:
        yield client
