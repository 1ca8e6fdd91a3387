"""Bad input to ``astralis world import``: one line naming the file and what is wrong, exit
code 2, and nothing written where the world was to go."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scenes import cloud_points, write_las, write_pcd, write_ply, write_text

from astralis_des.cli import main
from astralis_des.errors import InputError
from astralis_des.importers import ImportOptions, import_world, source
from astralis_des.world.build import load_world


def run(capsys: pytest.CaptureFixture[str], file: Path, out_dir: Path,
        *options: str) -> tuple[int, str]:
    code = main(["world", "import", str(file), "-o", str(out_dir / "twin.yaml"), *options])
    err = capsys.readouterr().err
    return code, err


def fails(capsys: pytest.CaptureFixture[str], file: Path, tmp_path: Path, *options: str) -> str:
    """The one error line of a failed import, after checking the exit code and that the
    output folder holds nothing."""
    out_dir = tmp_path / "worlds"
    code, err = run(capsys, file, out_dir, *options)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ")
    assert not out_dir.exists() or not any(out_dir.iterdir())
    return lines[0]


def test_missing_file(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """A file that is not there."""
    line = fails(capsys, tmp_path / "nowhere.laz", tmp_path)
    assert line == f"error: {tmp_path / 'nowhere.laz'}: no such file"


@pytest.mark.parametrize("name", ["empty.las", "empty.ply", "empty.obj", "empty.xyz"])
def test_empty_file(capsys: pytest.CaptureFixture[str], tmp_path: Path, name: str) -> None:
    """A file of no bytes."""
    (tmp_path / name).write_bytes(b"")
    assert fails(capsys, tmp_path / name, tmp_path).endswith(": the file is empty")


def test_unknown_extension(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """A format no reader is registered for: the known ones are listed."""
    (tmp_path / "scan.e57").write_bytes(b"ASTM-E57")
    line = fails(capsys, tmp_path / "scan.e57", tmp_path)
    assert "unknown format '.e57'; known: .csv, .glb, .gltf, .las, .laz, .obj" in line


def test_truncated_laz(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """A LAZ cut in the middle of its points."""
    points, classes = cloud_points()
    whole = write_las(tmp_path / "whole.laz", points, classes).read_bytes()
    (tmp_path / "cut.laz").write_bytes(whole[:len(whole) // 2])
    line = fails(capsys, tmp_path / "cut.laz", tmp_path)
    assert line.startswith(f"error: {tmp_path / 'cut.laz'}: ")
    assert "truncated" in line


@pytest.mark.parametrize("name,what", [("scan.las", "not a readable LAS file"),
                                       ("scan.ply", "not a readable PLY file"),
                                       ("scan.pcd", "is not a PCD header key: not a PCD file"),
                                       ("scan.glb", "not a readable GLB file"),
                                       ("scan.xyz", "not a text file (a NUL byte at offset 0)")])
def test_corrupt_file(capsys: pytest.CaptureFixture[str], tmp_path: Path, name: str,
                      what: str) -> None:
    """Bytes that are not what the extension says."""
    (tmp_path / name).write_bytes(b"\x00garbage\x17\x80" * 40)
    assert what in fails(capsys, tmp_path / name, tmp_path)


def test_truncated_binary_ply(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """A binary PLY whose points stop short of its header's count."""
    points, _ = cloud_points()
    data = write_ply(tmp_path / "whole.ply", points, ascii=False).read_bytes()
    (tmp_path / "cut.ply").write_bytes(data[:-1000])
    line = fails(capsys, tmp_path / "cut.ply", tmp_path)
    assert line.startswith(f"error: {tmp_path / 'cut.ply'}: truncated: the file ends before")


def test_truncated_binary_pcd(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """A binary PCD holding fewer points than its header announces."""
    points, _ = cloud_points()
    data = write_pcd(tmp_path / "whole.pcd", points, binary=True).read_bytes()
    (tmp_path / "cut.pcd").write_bytes(data[:-120])
    line = fails(capsys, tmp_path / "cut.pcd", tmp_path)
    assert f"truncated: {len(points):,} points of 12 bytes need {12 * len(points):,} bytes" in line


def test_text_row_with_a_word_names_its_line(capsys: pytest.CaptureFixture[str],
                                             tmp_path: Path) -> None:
    """A CSV row that is not numbers: the file, the line and the value."""
    (tmp_path / "bad.csv").write_text("x,y,z\n1,2,3\n4,five,6\n", encoding="utf-8")
    line = fails(capsys, tmp_path / "bad.csv", tmp_path)
    assert line == f"error: {tmp_path / 'bad.csv'}:3: 'five' is not a number"


def test_cloud_of_only_nan_points(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """NaN and infinite points are dropped and counted; with none left, nothing to import."""
    write_text(tmp_path / "nan.xyz", np.array([[np.nan, 0, 0], [0, np.inf, 1.0]]))
    assert fails(capsys, tmp_path / "nan.xyz", tmp_path).endswith(
        "no point has finite coordinates (2 dropped)")


def test_mesh_without_faces(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """An OBJ of vertices and no faces is no mesh."""
    (tmp_path / "points.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\n", encoding="utf-8")
    assert fails(capsys, tmp_path / "points.obj", tmp_path).endswith("the mesh has no faces")


def test_file_larger_than_memory_allows(capsys: pytest.CaptureFixture[str], tmp_path: Path,
                                        monkeypatch: pytest.MonkeyPatch) -> None:
    """A 100 GB text cloud (a sparse file: it takes no disk) is refused before it is read; a
    LAS with more points than memory holds is thinned evenly to what fits, and says so."""
    with (tmp_path / "huge.xyz").open("wb") as huge:
        huge.truncate(100 * 10**9)
    line = fails(capsys, tmp_path / "huge.xyz", tmp_path)
    assert "a 100,000 MB file needs about 600.0 GB of memory to import" in line
    points, classes = cloud_points()
    las = write_las(tmp_path / "scene.las", points, classes)
    monkeypatch.setattr(source, "available_memory", lambda: 5_000 * 2 * 64)  # 5,000 points
    report = import_world(las, tmp_path / "w" / "twin.yaml")
    assert report.points == len(points) and report.extra["kept"] == 3_902
    assert "kept every 4th point (3,902 of 15,605) to stay within --max-points 5,000" in \
        report.notes


@pytest.mark.parametrize("option,value,message", [
    ("--voxel", "-1", "--voxel: must be a positive number, got -1"),
    ("--units", "furlong", "--units: 'furlong' is not one of: auto, m, ft"),
    ("--ground", "magic", "--ground: 'magic' is not one of"),
    ("--up", "x", "--up: 'x' is not one of: auto, y, z"),
])
def test_bad_options(capsys: pytest.CaptureFixture[str], tmp_path: Path, option: str,
                     value: str, message: str) -> None:
    """Options are checked before the file is read."""
    points, classes = cloud_points()
    las = write_las(tmp_path / "scene.las", points, classes)
    assert message in fails(capsys, las, tmp_path, option, value)


def test_voxel_too_fine_for_the_cloud(tmp_path: Path) -> None:
    """A voxel far finer than the points (specks with gaps between them, not walls) is
    refused with the points' spacing and the finest voxel that works."""
    points, classes = cloud_points()
    las = write_las(tmp_path / "scene.las", points, classes)
    with pytest.raises(InputError, match=r"--voxel: 0.001 m is too fine for this cloud \(one "
                                         r"point per 0.282 m: 15,605 points .*\): pass "
                                         r"--voxel 0.029 or more"):
        import_world(las, tmp_path / "worlds" / "twin.yaml", ImportOptions(voxel=0.001))
    assert not (tmp_path / "worlds").exists() or not any((tmp_path / "worlds").iterdir())


def test_output_must_be_a_yaml_world(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """-o names the world file."""
    points, classes = cloud_points()
    las = write_las(tmp_path / "scene.las", points, classes)
    code = main(["world", "import", str(las), "-o", str(tmp_path / "twin.json")])
    assert code == 2
    assert "-o: a world file ends in .yaml, not '.json'" in capsys.readouterr().err


def test_a_broken_sidecar_is_named_when_the_world_loads(tmp_path: Path) -> None:
    """A world whose blocks file was lost or damaged: the loader names it and its key."""
    points, classes = cloud_points()
    import_world(write_las(tmp_path / "s.las", points, classes), tmp_path / "w" / "twin.yaml")
    (tmp_path / "w" / "twin.blocks.npz").write_bytes(b"not a zip")
    with pytest.raises(InputError, match=r"twin.yaml:\d+: geometry.blocks: twin.blocks.npz is "
                                         "not a readable .npz file"):
        load_world((tmp_path / "w" / "twin.yaml").resolve())
    (tmp_path / "w" / "twin.blocks.npz").unlink()
    with pytest.raises(InputError, match=r"geometry\.blocks: no such file"):
        load_world((tmp_path / "w" / "twin.yaml").resolve())


def test_a_failed_import_leaves_an_existing_world_whole(capsys: pytest.CaptureFixture[str],
                                                        tmp_path: Path) -> None:
    """Re-importing over a world with a bad file changes nothing of the old world."""
    points, classes = cloud_points()
    out_dir = tmp_path / "worlds"
    assert run(capsys, write_las(tmp_path / "s.las", points, classes), out_dir)[0] == 0
    before = {p.name: p.read_bytes() for p in out_dir.iterdir()}
    (tmp_path / "bad.las").write_bytes(b"garbage" * 100)
    assert run(capsys, tmp_path / "bad.las", out_dir)[0] == 2
    assert {p.name: p.read_bytes() for p in out_dir.iterdir()} == before
