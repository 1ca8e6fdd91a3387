"""The compiled kernels (numba) give what the numpy path gives; a single run never imports them."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from astralis_des import Simulation, compiled, load_mission
from astralis_des.streams import stream
from astralis_des.world.build import load_world
from astralis_des.world.catalogue import default_catalogue
from astralis_des.world.clutter import free_spot, place_room
from astralis_des.world.geometry import segments_hit_boxes

ROOT = Path(__file__).resolve().parents[1]
WORLDS = ("urban_default", "hospital", "fig4_offices")


@pytest.fixture
def kernels() -> Iterator[None]:
    """The compiled kernels available (skipped without numba), the numpy path afterwards."""
    pytest.importorskip("numba")
    assert compiled.enable()
    compiled.disable()
    yield
    compiled.disable()


def both(make):  # type: ignore[no-untyped-def]
    """``make()`` on the numpy path, then on the compiled one."""
    compiled.disable()
    plain = make()
    compiled.enable()
    fast = make()
    compiled.disable()
    return plain, fast


@pytest.mark.parametrize("name", WORLDS)
def test_furnished_rooms_are_the_same(kernels: None, name: str) -> None:
    """Every room of a world, furnished at three levels and five seeds: the same items at the
    same places, and the same items skipped for the same reasons."""
    world = load_world(ROOT / "worlds" / f"{name}.yaml")
    catalogue = default_catalogue()
    rooms = sorted(world.rooms)
    placed = 0
    for seed in range(5):
        for index, room in enumerate(rooms):
            for level in (0.3, 0.7, 1.0):
                plain, fast = both(lambda r=room, i=index, s=seed, m=level: place_room(
                    world, r, m, stream(s, "clutter", i), catalogue))
                assert fast == plain, (room, seed, level)
                placed += len(plain.placed)
    assert placed > 10 * len(rooms)  # furnished rooms compared, not empty ones


def test_free_spots_are_the_same(kernels: None) -> None:
    """A target's free spot in a furnished room (stamped by hand, then placed)."""
    world = load_world(ROOT / "worlds" / "urban_default.yaml")
    catalogue = default_catalogue()
    for seed, room in enumerate(sorted(world.rooms)[:12]):
        clutter = place_room(world, room, 1.0, stream(seed, "clutter", 0), catalogue)
        plain, fast = both(lambda r=room, c=clutter, s=seed: free_spot(
            world, r, c, (1.8, 0.6), stream(s, "target", 1), catalogue))
        assert fast == plain


def test_sight_lines_are_the_same(kernels: None) -> None:
    """Segments against boxes: random ones, and the edge cases of the slab test (a segment
    along a face, parallel to an axis, touching a corner, of zero length, with a NaN)."""
    rng = np.random.default_rng(7)
    lo = rng.uniform(0, 8, (40, 3))
    boxes = np.stack([lo, lo + rng.uniform(0.1, 2, (40, 3))], axis=1)
    p0, p1 = rng.uniform(-1, 10, (500, 3)), rng.uniform(-1, 10, (500, 3))
    p1[::7, 0] = p0[::7, 0]  # parallel to the x slabs
    p1[::11, 1:] = p0[::11, 1:]  # along x alone
    p1[::13] = p0[::13]  # of zero length
    p0[5], p1[5] = boxes[0, 0], boxes[0, 0] + [1.0, 0.0, 0.0]  # from a corner along an edge
    p0[6], p1[6] = boxes[1, 1] + 1.0, boxes[1, 1]  # ends on a corner
    p1[8, 2] = p0[8, 2] + 1e-310  # a direction whose inverse is infinite
    for cut in (slice(None), slice(0, 1), slice(0, 8), slice(100, 109)):
        plain, fast = both(lambda c=cut: segments_hit_boxes(p0[c], p1[c], boxes))
        assert fast.dtype == plain.dtype and (fast == plain).all()
    assert 0 < segments_hit_boxes(p0, p1, boxes).sum() < len(p0)
    nan = p0.copy()
    nan[3, 1] = np.nan
    plain, fast = both(lambda: segments_hit_boxes(nan, p1, boxes))
    assert (fast == plain).all() and not plain.any()


def test_rooms_of_points_are_the_same(kernels: None) -> None:
    """The rooms points lie in, a point's room (bounds included, and 1e-6 beyond)."""
    world = load_world(ROOT / "worlds" / "urban_default.yaml")
    boxes = world.room_boxes
    rng = np.random.default_rng(3)
    corners = boxes.reshape(-1, 3)
    points = np.concatenate([rng.uniform(boxes[:, 0].min(axis=0), boxes[:, 1].max(axis=0),
                                         (300, 3)), corners, corners + 1e-6, corners - 2e-6])
    scene = Simulation(load_mission(ROOT / "missions" / "urban_search.yaml")).scene
    for cut in (slice(0, 1), slice(0, 40), slice(300, 340), slice(None)):
        plain, fast = both(lambda c=cut: scene.rooms_at(points[c]))
        assert fast == plain
    plain, fast = both(lambda: [world.room_at(p) for p in points])
    assert fast == plain and any(r is not None for r in plain)


@pytest.mark.parametrize(("mission", "seeds"), [("urban_search", range(4)),
                                                ("hospital_search", range(2))])
def test_missions_log_the_same_events(kernels: None, mission: str, seeds: range) -> None:
    """Whole missions with new seeds: the same events, field for field."""
    base = load_mission(ROOT / "missions" / f"{mission}.yaml")
    for seed in seeds:
        plain, fast = both(lambda s=seed: Simulation(base.with_changes(seed=s)).run())
        assert fast.events == plain.events
        assert fast.outcome == plain.outcome


def test_a_single_run_does_not_import_numba(tmp_path: Path) -> None:
    """``astralis run`` takes the numpy path: numba's import would cost more than the run."""
    script = ("import sys\nfrom astralis_des.cli import main\n"
              "try:\n    main(sys.argv[1:])\nexcept SystemExit:\n    pass\n"
              "print('numba' in sys.modules, 'astralis_des.compiled.loops' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", script, "run", "missions/urban_search.yaml",
                           "--out", str(tmp_path / "run"), "--quiet", "--no-recording"],
                          capture_output=True, text=True, cwd=ROOT, check=True)
    assert done.stdout.split()[-2:] == ["False", "False"]
    assert (tmp_path / "run" / "events.jsonl").stat().st_size > 0


def test_without_numba_the_numpy_path_runs(tmp_path: Path) -> None:
    """Where numba is not installed, enabling says so and missions run on the numpy path."""
    script = ("import sys\nsys.modules['numba'] = None  # as if not installed\n"
              "from pathlib import Path\nfrom astralis_des import Simulation, compiled, "
              "load_mission\n"
              "print(compiled.enable(), compiled.kernels() is None)\n"
              "print(Simulation(load_mission(Path('missions/urban_search.yaml'))).run().outcome)")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          cwd=ROOT, check=True)
    assert done.stdout.split() == ["False", "True", "found"]


def test_where_numba_cannot_keep_its_machine_code_the_numpy_path_runs() -> None:
    """A read-only install and home: numba refuses to compile with ``cache=True`` (its
    RuntimeError, "no locator available"); enabling says so in one line and stays on numpy's
    path instead of failing a study's workers."""
    script = ("import sys, types\n"
              "fake = types.ModuleType('numba')\n"
              "def njit(**options):\n"
              "    def compile(function):\n"
              "        raise RuntimeError('cannot cache function: no locator available')\n"
              "    return compile\n"
              "fake.njit = njit\n"
              "sys.modules['numba'] = fake\n"
              "from astralis_des import compiled\n"
              "print(compiled.enable(), compiled.kernels() is None)")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          check=True)
    assert done.stdout.split() == ["False", "True"]
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "compiled kernels not enabled" in lines[0] \
        and "NUMBA_CACHE_DIR" in lines[0]
