"""Issue 38: every file of PDAL's test corpus (data/scans, 66 real clouds and meshes) becomes a
world, or is refused in one line that names the file and what is wrong; every world runs a
mission in which two UAVs starting in its first area search all its areas.

The table is what a user sees: points read, the site and voxel chosen, the areas placed, or
the refusal. Files are imported in this process, one after another, as a user's session
would.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
import yaml

from astralis_des import Simulation, load_mission
from astralis_des.errors import InputError
from astralis_des.importers import ImportOptions, ImportReport, import_world
from astralis_des.world.build import load_world

ROOT = Path(__file__).resolve().parents[1]
SCANS = ROOT / "data" / "scans"
TOO_SMALL = "too small for a search area: "
MESH_TOO_SMALL = ("no free floor of at least 4 m x 4 m for a search area: the mesh spans 1.0 x "
                  "1.0 x 2.0 m, the site 5.2 x 5.2 m with --margin 2; a wider --margin gives "
                  "areas on the ground around it")
SMALL_END = ("; an area needs at least 4 x 4 m of ground the scan saw, and nothing smaller "
             "is searched")


@dataclass(frozen=True)
class World:
    points: int
    site: tuple[float, float]
    voxel: float
    areas: int


@dataclass(frozen=True)
class Refused:
    message: str


OUTCOMES: dict[str, World | Refused] = {
    "las/1.2-empty-geotiff-vlrs.las": World(43, (250, 110), 10, 2),
    "las/1.2-with-color-clipped.las": Refused(
        "truncated: the header announces 1,065 points, the file holds 1,064; pass --partial "
        "to import the 1,064 it holds"),
    "las/1.2-with-color.las": World(1065, (3370, 4640), 10, 4),
    "las/100-points.las": World(100, (3240, 4540), 10, 4),
    "las/4_6_crop.las": World(23875, (65, 65), 0.5, 1),
    "las/autzen_trim.las": World(110000, (363, 176), 1, 4),
    "las/autzen_trim_7.las": World(110000, (363, 176), 1, 4),
    "las/bad-geotiff-keys.las": Refused(TOO_SMALL + '10 points over 4.3 x 2.0 m'),
    "las/bad_vlr_count.las": Refused(TOO_SMALL + '10 points over 4.3 x 2.0 m'),
    "las/epsg_4326.las": World(5380, (2190, 1180), 10, 4),
    "las/extrabytes.las": World(1065, (3370, 4640), 10, 4),
    "las/garbage_nVariableLength.las": Refused(
        "truncated: the header announces 719 points, the file holds 718; pass --partial to "
        "import the 718 it holds"),
    "las/gps-time-nan.las": Refused(TOO_SMALL + '1 point over 0.0 x 0.0 m'),
    "las/hextest.las": Refused(TOO_SMALL + '8 points over 2.0 x 2.3 m'),
    "las/interesting.las": World(1065, (1030, 1420), 10, 4),
    "las/lots_of_vlr.las": Refused(TOO_SMALL + '1 point over 0.0 x 0.0 m'),
    "las/mvk-thin.las": World(6280, (1530, 1530), 10, 4),
    "las/no-points.las": Refused('the cloud has no points'),
    "las/noise-clean.las": World(1065, (3370, 4640), 10, 4),
    "las/noise-dirty.las": World(1065, (3370, 4640), 10, 4),
    "las/permutations/1.0_0.las": Refused(TOO_SMALL + '1 point over 0.0 x 0.0 m'),
    "las/permutations/1.0_1.las": Refused(TOO_SMALL + '1 point over 0.0 x 0.0 m'),
    "las/permutations/1.1_0.las": Refused(TOO_SMALL + '1 point over 0.0 x 0.0 m'),
    "las/permutations/1.1_1.las": Refused(TOO_SMALL + '1 point over 0.0 x 0.0 m'),
    "las/permutations/1.2-no-points.las": Refused(
        'truncated: the header announces 1,065 points, the file holds 0'),
    "las/permutations/1.2_0.las": Refused(TOO_SMALL + '1 point over 0.0 x 0.0 m'),
    "las/permutations/1.2_1.las": Refused(TOO_SMALL + '1 point over 0.0 x 0.0 m'),
    "las/permutations/1.2_2.las": Refused(TOO_SMALL + '1 point over 0.0 x 0.0 m'),
    "las/permutations/1.2_3.las": Refused(TOO_SMALL + '1 point over 0.0 x 0.0 m'),
    "las/prec3.las": World(110, (360, 160), 10, 4),
    "las/sample_c.las": World(14408, (87.5, 79), 0.5, 4),
    "las/sample_c_thin.las": World(2732, (88, 80), 2, 4),
    "las/sample_nc.las": World(14408, (87.5, 79), 0.5, 4),
    "las/simple.las": World(1065, (3370, 4640), 10, 4),
    "las/spec_3.las": Refused(TOO_SMALL + '10 points over 4.3 x 2.0 m'),
    "las/spurious.las": World(1065, (1010, 1400), 10, 4),
    "las/synthetic_test.las": Refused(TOO_SMALL + '1 point over 0.0 x 0.0 m'),
    "las/test1_4.las": Refused(TOO_SMALL + '1,000 points over 152.8 x 1.6 m'),
    "las/test_epsg_4047.las": Refused(TOO_SMALL + '10 points over 8.6 x 0.0 m'),
    "las/test_epsg_4326.las": Refused(TOO_SMALL + '10 points over 8.7 x 0.0 m'),
    "las/test_epsg_4326_axis.las": Refused(TOO_SMALL + '10 points over 0.0 x 11.2 m'),
    "las/test_epsg_4326x3.las": Refused(TOO_SMALL + '30 points over 8.7 x 0.0 m'),
    "las/test_utm16.las": Refused(TOO_SMALL + '10 points over 4.2 x 2.3 m'),
    "las/test_utm17.las": Refused(TOO_SMALL + '10 points over 4.3 x 2.0 m'),
    "las/utm15.las": Refused(TOO_SMALL + '1 point over 0.0 x 0.0 m'),
    "las/utm17.las": Refused(TOO_SMALL + '10 points over 4.3 x 2.0 m'),
    "las/warsaw_small.las": World(3000, (38, 37), 1, 2),
    "las/wontcompress3.las": World(1000, (60, 38), 1, 4),
    "laz/autzen_trim.laz": World(110000, (363, 176), 1, 4),
    "laz/las_with_several_extra_byte_bloc.laz": World(697721, (355, 374.5), 0.5, 4),
    "laz/simple-laszip-compressor-version-1.2r0.laz": World(1065, (3370, 4640), 10, 4),
    "laz/simple.laz": World(1065, (3370, 4640), 10, 4),
    "pcd/autzen-utm.pcd": World(1065, (1010, 1400), 10, 4),
    "pcd/missingheader.pcd": Refused(
        "no PCD header: the file starts with rows of numbers; to read them as x y z, pass "
        "--format xyz"),
    "pcd/utm17_comma.pcd": Refused(TOO_SMALL + '10 points over 4.3 x 2.0 m'),
    "pcd/utm17_space.pcd": Refused(TOO_SMALL + '10 points over 4.3 x 2.0 m'),
    "pcd/utm17_tab.pcd": Refused(TOO_SMALL + '10 points over 4.3 x 2.0 m'),
    "ply/issue_2421.ply": Refused(  # z = 1,234,567,890.12345
        "coordinates reach 1.23e+09 m, no place on the Earth: check the file's scale and "
        "offset, or its units (--units, --crs)"),
    "ply/mesh.ply": Refused(
        MESH_TOO_SMALL),
    "ply/mesh_fixed.ply": Refused(
        MESH_TOO_SMALL),
    "ply/no_vertex.ply": Refused('no vertex element (the header declares no elements)'),
    "ply/simple_binary.ply": Refused(TOO_SMALL + '3 points over 2.0 x 1.0 m'),
    "ply/simple_text.ply": Refused(TOO_SMALL + '3 points over 2.0 x 1.0 m'),
    "ply/sized_dims.ply": Refused('the vertices have no z (properties: x, y, j, i)'),
    "ply/text_extradim.ply": Refused(TOO_SMALL + '1 point over 0.0 x 0.0 m'),
    "ply/unsized_dims.ply": Refused('the vertices have no z (properties: y, x, i, j)'),
}


def test_the_table_covers_the_corpus() -> None:
    """Every file in data/scans has its outcome here, and nothing else does."""
    files = {str(p.relative_to(SCANS)) for p in SCANS.rglob("*")
             if p.suffix in (".las", ".laz", ".pcd", ".ply")}
    assert len(files) == 66 and files == set(OUTCOMES)
    worlds = [f for f, o in OUTCOMES.items() if isinstance(o, World)]
    assert len(worlds) == 25


def search_mission(world: Path) -> Path:
    """Two UAVs start in the first area and search group S; the target is in the last area,
    so they search every area before they find it."""
    areas = yaml.safe_load(world.read_text(encoding="utf-8"))["areas"]
    (x0, y0, _), (x1, y1, _) = areas[0]["box"]
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    mission = world.with_name("search.yaml")
    mission.write_text(f"""name: corpus_search
world: {world.name}
seed: 1
time_limit: 3600
team:
  - {{id: uav1, kind: uav, start: [{cx - 1}, {cy}, 0], height: 4}}
  - {{id: uav2, kind: uav, start: [{cx + 1}, {cy}, 0], height: 4}}
target: {{room: {areas[-1]["id"]}}}
assignment: {{search: [S]}}
""", encoding="utf-8")
    return mission


@pytest.mark.parametrize("name", sorted(OUTCOMES))
def test_corpus_file(name: str, tmp_path: Path) -> None:
    """The file becomes the world in the table, and two UAVs search it to the end; or it is
    refused with the table's line, naming the file, and nothing is written."""
    expected = OUTCOMES[name]
    out = tmp_path / "twin.yaml"
    if isinstance(expected, Refused):
        with pytest.raises(InputError) as caught:
            import_world(SCANS / name, out)
        message = expected.message + (SMALL_END if expected.message.startswith(TOO_SMALL)
                                      else "")
        assert caught.value.message == message
        assert caught.value.file == str(SCANS / name)
        assert not any(tmp_path.iterdir())
        return
    report = import_world(SCANS / name, out)
    assert (report.points, report.site, report.voxel, len(report.areas)) == (
        expected.points, pytest.approx(expected.site), expected.voxel, expected.areas)
    result = Simulation(load_mission(search_mission(out))).run()
    assert result.outcome == "found" and result.target["room"] == report.areas[-1]
    assert result.rounds[0]["segment"] == "S.1.1"
    assert all(r.tasks_failed == 0 for r in result.robots.values())
    assert result.end_time < 1800


def imported(name: str, tmp_path: Path, **options: object) -> tuple[ImportReport, dict]:
    out = tmp_path / f"{Path(name).stem}.yaml"
    report = import_world(SCANS / name, out, ImportOptions(**options))  # type: ignore[arg-type]
    return report, yaml.safe_load(out.read_text(encoding="utf-8"))


def test_degrees_are_projected_never_taken_as_metres(tmp_path: Path) -> None:
    """epsg_4326.las: 5,380 points over 0.023 x 0.011 degrees in EPSG 4326 become a site of
    about 1.9 x 1.2 km (plus margins), projected at the cloud's middle; the world's origin
    lies at the cloud's south-west corner, in Texas."""
    report, doc = imported("las/epsg_4326.las", tmp_path)
    assert report.site == pytest.approx((2190.0, 1180.0))
    assert report.units.startswith("degrees of WGS 84 (from the file's coordinate system), "
                                   "projected onto a transverse Mercator plane")
    origin = doc["site"]["origin"]
    assert origin["latitude"] == pytest.approx(31.0369, abs=2e-4)
    assert origin["longitude"] == pytest.approx(-94.6834, abs=2e-4)


def test_feet_and_us_survey_feet_come_from_the_crs(tmp_path: Path) -> None:
    """interesting.las is in feet (GeoTIFF keys), mvk-thin.las in US survey feet; simple.las,
    the same points as interesting.las without a CRS, is guessed to be metres and says how to
    override the guess, and --units ft makes it the same site as interesting.las."""
    feet, _ = imported("las/interesting.las", tmp_path)
    assert feet.scale == pytest.approx(0.3048) and feet.units.startswith("ft (EPSG 9002")
    survey, _ = imported("las/mvk-thin.las", tmp_path)
    assert survey.scale == pytest.approx(1200 / 3937) and "US survey ft" in survey.units
    guessed, _ = imported("las/simple.las", tmp_path)
    assert guessed.units == ("m (guessed: no coordinate system in the file; pass --units m, "
                             "ft or us-ft, or --crs (e.g. EPSG:32617) if it is not in metres)")
    told, _ = imported("las/simple.las", tmp_path, units="ft")
    assert told.site == feet.site and told.units == "ft (given)"


def test_a_stray_point_80_km_away_is_left_out_and_counted(tmp_path: Path) -> None:
    """spurious.las holds one point a degree west of the rest: it is left out (the site is
    1 x 1.4 km, not 80 km wide) and counted; --keep-strays keeps it."""
    report, doc = imported("las/spurious.las", tmp_path)
    assert report.site == pytest.approx((1010.0, 1400.0)) and doc["source"]["strays"] == 1
    assert "left out 1 stray point up to 79,555 m from the rest along x (more than 1,850 m of " \
        "nothing between); --keep-strays keeps them" in report.notes
    kept, _ = imported("las/spurious.las", tmp_path, keep_strays=True, areas=1)
    assert kept.site[0] > 80_000


def test_broken_headers_are_mended_and_partial_files_read_with_partial(tmp_path: Path) -> None:
    """garbage_nVariableLength.las claims 1,069,128,089 VLRs where none fit and is 6 bytes
    short of its 719th point; 1.2-with-color-clipped.las is one point short. --partial
    reads what each holds: the first is then too small (its points lie in a metre cube), the
    second a world of 1,064 points."""
    with pytest.raises(InputError, match=r"too small for a search area: 718 points over 1.0 x "
                                         r"1.0 m"):
        imported("las/garbage_nVariableLength.las", tmp_path, partial=True)
    clipped, _ = imported("las/1.2-with-color-clipped.las", tmp_path, partial=True)
    assert clipped.notes[0] == ("--partial: read the 1,064 whole points the file holds, of the "
                                "1,065 its header announces")
    assert clipped.points == 1_064 and len(clipped.areas) == 4


def test_the_same_points_in_every_format_and_compressor_make_the_same_world(
        tmp_path: Path) -> None:
    """autzen_trim as LAS 1.2 (format 3), LAS 1.4 (format 7) and LAZ; simple.las as LAZ from
    lazrs and from LASzip 1.2's point-wise compressor (read by laspy's laszip backend): the
    same blocks."""
    def blocks(name: str) -> np.ndarray:
        out = tmp_path / name.replace("/", "_")
        import_world(SCANS / name, out.with_suffix(".yaml"))
        return load_world(out.with_suffix(".yaml").resolve()).block_array

    autzen = blocks("laz/autzen_trim.laz")
    assert np.array_equal(blocks("las/autzen_trim.las"), autzen)
    assert np.array_equal(blocks("las/autzen_trim_7.las"), autzen)
    simple = blocks("las/simple.las")
    assert np.array_equal(blocks("laz/simple.laz"), simple)
    assert np.array_equal(blocks("laz/simple-laszip-compressor-version-1.2r0.laz"), simple)


def test_the_command_says_what_it_guessed_chose_and_warns_of(
        capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """`astralis world import simple.las`: the units it guessed and how to override them, the
    voxel it chose and why, and that the world is coarse; exit 0."""
    from astralis_des.cli import main

    assert main(["world", "import", str(SCANS / "las" / "simple.las"), "-o",
                 str(tmp_path / "simple.yaml")]) == 0
    said = " ".join(capsys.readouterr().out.split())
    assert "1,065 points, site 3370 x 4640 m, voxel 10 m, 497 blocks" in said
    assert "units: m (guessed: no coordinate system in the file; pass --units m, ft or us-ft, " \
        "or --crs (e.g. EPSG:32617) if it is not in metres)" in said
    assert "voxel 10 m, the coarsest, though the points lie further apart (one point per " \
        "119 m: 1,065 points over the 15,204,352 m^2 they cover); --voxel to choose" in said
    assert "warning: a sparse cloud, so a coarse world" in said
