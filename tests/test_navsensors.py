"""GNSS, barometer and magnetometer: what a user would check of each, in both fidelities."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pymap3d
import pytest

from astralis_des import Simulation
from astralis_des.mission.loader import Mission
from astralis_des.navsensors import (
    Barometer,
    Gnss,
    Magnetometer,
    Origin,
    altitude_of,
    motion_poses,
    pressure_at,
    yaw_rotation,
)
from astralis_des.world.model import World

ORIGIN = Origin(44.0582, -123.0684, 130.0)
FIELD = (19.47, 5.07, 47.41)  # microtesla north, east, down: the default site's


def sensed(mission: Mission, fidelity: str = "kinematic") -> Mission:
    """The mission with every pose sensor on its UAVs and UGV."""
    team = mission.spec.model_dump(mode="json")["team"]
    for member in team:
        if member["kind"] in ("uav", "ugv"):
            member["sensors"] = {"gnss": {}, "barometer": {}, "magnetometer": {}}
    return mission.with_changes(team=team, fidelity=fidelity)


def test_the_fix_is_within_its_noise_in_the_street_and_lost_under_a_slab(world: World) -> None:
    """In the street (open sky) every fix is within 4 sigma of the true position, back in the
    site's frame; in the middle of a first-floor room of building A (a slab above) there is
    no fix at all; at the entrance the fix degrades before it drops out."""
    rng = np.random.default_rng(0)
    gnss = Gnss(world, ORIGIN, rng)
    street = np.tile([90.0, 60.0, 1.5], (200, 1))
    got = gnss.read(np.arange(200.0), street, yaw_rotation(np.zeros(200)))
    assert set(got.columns["status"]) == {"fix"}
    e, n, u = pymap3d.geodetic2enu(got.columns["latitude"], got.columns["longitude"],
                                   got.columns["altitude"], *vars(ORIGIN).values())
    error = np.column_stack([e, n, u]) - street
    assert np.all(np.abs(error[:, :2]) < 4 * 1.5) and np.all(np.abs(error[:, 2]) < 4 * 3.0)
    assert 0.5 < error[:, 0].std() < 2.5  # the noise is there, about its sigma
    room = world.rooms["A.1.1.2"]
    inside = np.array([[*room.box.center[:2], room.box.lo[2] + 1.5]])
    lost = gnss.read(np.zeros(1), inside, yaw_rotation(np.zeros(1)))
    assert lost.columns["status"][0] == "none" and math.isnan(lost.columns["latitude"][0])
    assert lost.columns["satellites"][0] < 4
    # along the way in: from the street to the corridor, the open sky only shrinks
    corridor = world.spaces["A.1.corridor"].box
    door = np.array([*corridor.center[:2], 1.5])
    way = np.linspace([90.0, 60.0, 1.5], door, 40)
    open_sky = gnss.read(np.arange(40.0), way, yaw_rotation(np.zeros(40))).columns["open_sky"]
    assert open_sky[0] > 0.9 and open_sky[-1] < 0.1


def test_the_barometer_tracks_the_height_within_its_noise_and_drift() -> None:
    """Climbing 0 -> 10 m over 100 s: the altitude it implies follows the height above the
    site's ground to within 4 sigma of its noise and drift (10 Pa: about 0.85 m)."""
    baro = Barometer(ORIGIN, np.random.default_rng(1))
    t = np.arange(1000) / 10.0
    heights = np.linspace(0.0, 10.0, 1000)
    got = baro.read(t, np.column_stack([np.zeros((1000, 2)), heights]), yaw_rotation(t * 0))
    error = got.columns["altitude"] - (ORIGIN.altitude + heights)
    assert np.abs(error).max() < 4 * (2.7 + 10.0) / 11.8  # Pa per metre near the ground
    assert float(altitude_of(pressure_at(1234.5))) == pytest.approx(1234.5, abs=1e-6)
    assert float(pressure_at(0.0)) == pytest.approx(101325.0)


@pytest.mark.parametrize("yaw_deg", [0.0, 30.0, 90.0, 135.0, 180.0, 270.0, 359.0])
def test_the_magnetometer_heading_matches_the_yaw(yaw_deg: float) -> None:
    """A level body at yaw y (counter-clockwise from east) heads 90 - y degrees clockwise from
    true north: the heading from the field, declination added back, says so within 1 degree;
    the field's size is the site's."""
    mag = Magnetometer(np.random.default_rng(2), FIELD, noise_std=0.05)
    turned = yaw_rotation(np.full(50, math.radians(yaw_deg)))
    got = mag.read(np.zeros(50), np.zeros((50, 3)), turned)
    heading = got.columns["heading"]
    off = np.abs((heading - (90.0 - yaw_deg)) % 360.0)
    assert np.all(np.minimum(off, 360.0 - off) < 1.0)
    assert np.linalg.norm(got.columns["field"], axis=1).mean() == pytest.approx(
        math.hypot(*FIELD), abs=0.1)


def test_poses_of_past_times_are_where_the_robots_were(urban_search: Mission) -> None:
    """The kinematic poses the sensors read at past times are the robots' positions at those
    times, as a probe asking during the run saw them."""
    sim = Simulation(urban_search)
    seen: list[tuple[str, float, np.ndarray]] = []

    def probe():  # type: ignore[no-untyped-def]
        while True:
            yield sim.env.timeout(0.37)
            seen.extend((rid, float(sim.env.now), r.position(sim.env.now).copy())
                        for rid, r in sim.robots.items())

    sim.start()
    sim.env.process(probe())
    result = sim.run()
    for rid, robot in sim.robots.items():
        rows = [(t, p) for r, t, p in seen if r == rid and t <= result.end_time - 1]
        times = np.array([t for t, _ in rows])
        positions, _ = motion_poses(robot, times)
        assert np.abs(positions - np.array([p for _, p in rows])).max() < 1e-9


@pytest.mark.parametrize("fidelity", ["kinematic", "physics"])
def test_readings_are_drawn_from_the_seed_and_follow_the_flight(urban_search: Mission,
                                                                  fidelity: str) -> None:
    """Two runs give the same readings to the bit; the UAV's barometer shows its climb to
    flight height (about 2 m) and its GNSS drops out inside building A."""
    mission = sensed(urban_search, fidelity)
    runs = [Simulation(mission) for _ in range(2)]
    for sim in runs:
        sim.run()
    first, second = (sim.pose_sensors for sim in runs)
    for rid, name in first.sensors:
        a, b = first.readings(rid, name), second.readings(rid, name)
        assert len(a) > 10 and np.array_equal(a.t, b.t)
        for column in a.columns:
            assert np.array_equal(a.columns[column], b.columns[column], equal_nan=True) \
                if a.columns[column].dtype.kind == "f" else \
                np.array_equal(a.columns[column], b.columns[column])
    altitude = first.readings("uav1", "barometer").columns["altitude"] - ORIGIN.altitude
    assert abs(np.median(altitude[100:-100]) - 1.975) < 0.6
    status = first.readings("uav1", "gnss").columns["status"]
    assert status[0] == "fix" and "none" in set(status)


def test_the_api_answers_a_robots_latest_reading(urban_search: Mission, tmp_path: Path) -> None:
    """``reading`` gives the latest GNSS fix, barometer and magnetometer reading of a robot
    (at or before now); a sensor it does not carry is refused in one line."""
    from astralis_des.api import ApiError, Client
    from astralis_des.api.local import Background

    mission = sensed(urban_search).with_changes(assignment={"auto": False, "search": ["A"]})
    server = Background(mission, running=False, out_dir=tmp_path / "out")
    server.start()
    try:
        with Client(server.address, timeout=5.0) as client:
            client.step(until=3.0)
            fix = client.reading("uav1", "gnss")["reading"]
            assert fix["status"] == "fix" and fix["t"] <= 3.0 and fix["satellites"] >= 4
            assert fix["latitude"] == pytest.approx(44.0582, abs=0.01)
            baro = client.reading("uav1", "barometer")["reading"]
            assert baro["altitude"] == pytest.approx(130.0, abs=3.0)
            assert len(client.reading("ugv1", "magnetometer")["reading"]["field"]) == 3
            with pytest.raises(ApiError, match="op1 carries no 'gnss'"):
                client.reading("op1", "gnss")
    finally:
        server.stop()


def test_an_imported_georeferenced_tile_gives_the_origin_its_crs_says(tmp_path: Path) -> None:
    """The Autzen LAS tile's header carries its coordinate system (NAD83 HARN, Oregon's
    Lambert conformal conic, in feet): the imported world's origin is the recentred
    ``offset`` taken to WGS 84 by that system (about 44.05 N, 123.07 W, near the stadium), and
    a GNSS on that world without a mission ``site`` is fixed there."""
    import laspy
    import yaml
    from pyproj import Transformer

    from astralis_des.importers import import_world
    from astralis_des.importers.options import ImportOptions
    from astralis_des.world.build import load_world

    root = Path(__file__).resolve().parents[1]
    out = tmp_path / "autzen.yaml"
    import_world(root / "data" / "real" / "autzen_trim.laz", out, ImportOptions(voxel=2.0))
    doc = yaml.safe_load(out.read_text(encoding="utf-8"))
    origin, offset = doc["site"]["origin"], doc["source"]["offset"]
    with laspy.open(root / "data" / "real" / "autzen_trim.laz") as f:
        crs = f.header.parse_crs()
    lon, lat = Transformer.from_crs(crs, "EPSG:4326", always_xy=True).transform(*offset[:2])
    assert origin["latitude"] == pytest.approx(lat, abs=1e-6)
    assert origin["longitude"] == pytest.approx(lon, abs=1e-6)
    assert 44.0 < lat < 44.1 and -123.1 < lon < -123.0
    assert origin["altitude"] == pytest.approx(offset[2] * 0.3048, abs=0.01)
    world = load_world(out)
    assert world.origin == pytest.approx((origin["latitude"], origin["longitude"],
                                          origin["altitude"]))
    fix = Gnss(world, Origin(*world.origin), np.random.default_rng(0), 0.0, 0.0).read(
        np.zeros(1), np.array([[0.0, 0.0, 30.0]]), yaw_rotation(np.zeros(1)))
    assert fix.columns["latitude"][0] == pytest.approx(lat, abs=1e-7)
