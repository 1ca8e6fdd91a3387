"""Physics parameters out of range are refused at validation, naming the key."""

from __future__ import annotations

from pathlib import Path

import pytest

from astralis_des.cli import main

ROOT = Path(__file__).resolve().parents[1]


def mission_with(tmp_path: Path, physics: str) -> Path:
    text = (ROOT / "missions" / "fig7.yaml").read_text(encoding="utf-8")
    text = text.replace("world: ../worlds/urban_default.yaml",
                        f"world: {ROOT / 'worlds' / 'urban_default.yaml'}")
    path = tmp_path / "mission.yaml"
    path.write_text(text + "fidelity: physics\nphysics:\n" + physics, encoding="utf-8")
    return path


@pytest.mark.parametrize(("physics", "key", "says"), [
    ("  uav: {mass: -1.5}\n", "physics.uav.mass", "greater than 0"),
    ("  rate: 240\n  control_rate: 100\n", "physics", "does not divide the physics rate"),
    ("  rate: 240\n  control_rate: 480\n", "physics", "controller period is shorter than dt"),
    ("  rate: 0\n", "physics.rate", "greater than or equal to 30"),
    ("  uav: {max_rotor_speed: 300}\n", "physics.uav", "not enough for 1.5 kg"),
    ("  stuck_timeout: -2\n", "physics.stuck_timeout", "greater than 0"),
    ("  uav: {mas: 2}\n", "physics.uav", "did you mean 'mass'"),
    ("  rate: 240\n  control_rate: 10\n", "physics.control_rate",
     "the IMU of uav1 reads at 20 Hz, faster than the physics control_rate 10 Hz"),
])
def test_bad_physics_parameters_are_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                            physics: str, key: str, says: str) -> None:
    """One line naming the key, exit 2, nothing written."""
    path = mission_with(tmp_path, physics)
    code = main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1
    assert f": {key}" in err and says in err, err
    assert not (tmp_path / "out").exists()


def test_a_good_physics_section_validates(tmp_path: Path,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    """The defaults written out explicitly are accepted."""
    path = mission_with(tmp_path, "  rate: 240\n  control_rate: 80\n  log_rate: 10\n")
    assert main(["validate", str(path)]) == 0
    assert capsys.readouterr().out.startswith("ok: ")


@pytest.mark.parametrize(("member", "key", "says"), [
    ("{id: uav9, kind: uav, start: [90, 60, 0], sensors: {camera: {width: 0}}}",
     "team[4].sensors.camera.width", "greater than 0"),
    ("{id: uav9, kind: uav, start: [90, 60, 0], sensors: {camera: {height: -4}}}",
     "team[4].sensors.camera.height", "greater than 0"),
    ("{id: uav9, kind: uav, start: [90, 60, 0], sensors: {camera: {fov_deg: 180}}}",
     "team[4].sensors.camera.fov_deg", "less than 180"),
    ("{id: uav9, kind: uav, start: [90, 60, 0], sensors: {camera: {fov_deg: 0}}}",
     "team[4].sensors.camera.fov_deg", "greater than 0"),
    ("{id: uav9, kind: uav, start: [90, 60, 0], sensors: {lidar: {beams: 0}}}",
     "team[4].sensors.lidar.beams", "greater than or equal to 1"),
    ("{id: op9, kind: human, start: [96, 66, 0], sensors: {lidar: {}}}",
     "team[4]", "sensors.lidar: a human cannot carry a lidar; it carries: camera"),
    ("{id: uav9, kind: uav, start: [90, 60, 0], sensors: {imu: {rate: 100}}}",
     "team[4].sensors.imu.rate", "faster than the physics control_rate 60 Hz"),
    ("{id: uav9, kind: uav, start: [90, 60, 0], sensors: {camera: {pitch_deg: 95}}}",
     "team[4].sensors.camera.pitch_deg", "less than or equal to 90"),
    ("{id: uav9, kind: uav, start: [90, 60, 0], sensors: {camera: {range: 0}}}",
     "team[4].sensors.camera.range", "greater than 0"),
    ("{id: uav9, kind: uav, start: [90, 60, 0], sensors: {camera: {min_pixels: 0}}}",
     "team[4].sensors.camera.min_pixels", "greater than or equal to 1"),
    ("{id: uav9, kind: uav, start: [90, 60, 0], sensors: {camera: {rate: 0}}}",
     "team[4].sensors.camera.rate", "greater than 0"),
    ("{id: uav9, kind: uav, start: [90, 60, 0], sensors: {lidar: {range: -3}}}",
     "team[4].sensors.lidar.range", "greater than 0"),
    ("{id: uav9, kind: uav, start: [90, 60, 0], sensors: {camera: {fov: 60}}}",
     "team[4].sensors.camera", "did you mean 'fov_deg'"),
])
def test_bad_sensors_are_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                 member: str, key: str, says: str) -> None:
    """Impossible sensors: one line naming the key, exit 2."""
    text = (ROOT / "missions" / "fig7.yaml").read_text(encoding="utf-8").replace(
        "world: ../worlds/urban_default.yaml", f"world: {ROOT / 'worlds' / 'urban_default.yaml'}")
    text = text.replace("  - {id: op1, kind: human, start: [100, 40, 0]}",
                        f"  - {{id: op1, kind: human, start: [100, 40, 0]}}\n  - {member}")
    path = tmp_path / "mission.yaml"
    path.write_text(text, encoding="utf-8")
    assert main(["validate", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert f": {key}" in err and says in err, err


def test_sensors_a_kind_can_carry_are_accepted(tmp_path: Path) -> None:
    """A UGV with camera, lidar and IMU, and a human with a camera, validate."""
    text = (ROOT / "missions" / "fig7.yaml").read_text(encoding="utf-8").replace(
        "world: ../worlds/urban_default.yaml", f"world: {ROOT / 'worlds' / 'urban_default.yaml'}")
    text = text.replace("  - {id: ugv1, kind: ugv, start: [73, 78.25, 0]}",
                        "  - {id: ugv1, kind: ugv, start: [73, 78.25, 0], sensors: "
                        "{camera: {width: 160, height: 120}, lidar: {beams: 180}, imu: {}}}")
    path = tmp_path / "mission.yaml"
    path.write_text(text, encoding="utf-8")
    assert main(["validate", str(path)]) == 0
