"""The LAS, LAZ and COPC reader (astralis_des/importers/las.py, lasfile.py, lazfile.py): every
version and point format as laspy reads it, the header and chunk problems real files have
mended or refused in one line (without the memory or time they claim), thinning to
--max-points, --partial on a LAZ cut short, LASzip's point-wise compressor, COPC octrees read
level by level, and bad input refused at once."""

from __future__ import annotations

import os
import signal
import struct
import subprocess
import sys
import time
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import laspy
import numpy as np
import pytest
from scenes import FT_WKT, cloud_points, write_las

from astralis_des.cli import main
from astralis_des.errors import InputError
from astralis_des.importers import ImportOptions, import_world, las
from astralis_des.importers.las import read_las
from astralis_des.importers.source import ReadRequest

ROOT = Path(__file__).resolve().parents[1]
SCANS = ROOT / "data" / "scans"
AUTZEN = ROOT / "data" / "real" / "autzen_trim.laz"
FORMATS = {"1.0": (0, 1), "1.1": (0, 1), "1.2": (0, 1, 2, 3), "1.3": (0, 1, 2, 3, 4, 5),
           "1.4": tuple(range(11))}
CASES = [(v, f, e) for v, fs in FORMATS.items() for f in fs for e in ("las", "laz")]


@contextmanager
def deadline(seconds: int) -> Iterator[None]:
    """Fail instead of waiting for ever (a FIFO's open blocks until a writer comes, laspy
    walks a COPC octree that loops for ever)."""
    def fire(_signum: int, _frame: Any) -> None:
        raise TimeoutError(f"no answer in {seconds} s")

    old = signal.signal(signal.SIGALRM, fire)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def random_las(path: Path, version: str, point_format: int, n: int = 3_000,
               extra: list[laspy.ExtraBytesParams] | None = None) -> laspy.LasData:
    """``n`` random points in ``point_format`` with every field the tests compare filled
    (classes, 16-bit colours, waveform packets), written as ``path`` (LAS or LAZ by its
    suffix). laspy writes no LAS 1.0: a 1.1 file is marked 1.0 (the headers are alike)."""
    rng = np.random.default_rng(point_format)
    header = laspy.LasHeader(point_format=point_format,
                             version="1.1" if version == "1.0" else version)
    header.scales, header.offsets = [0.001, 0.01, 0.1], [1000.0, 2000.0, 30.0]
    if extra:
        header.add_extra_dims(extra)
    data = laspy.LasData(header)
    data.x, data.y = rng.uniform(1000, 1100, n), rng.uniform(2000, 2050, n)
    data.z = rng.uniform(30, 90, n)
    names = set(data.point_format.dimension_names)
    data.classification = rng.integers(0, 32 if point_format < 6 else 256, n)
    if "red" in names:
        for name in ("red", "green", "blue"):
            data[name] = rng.integers(0, 65536, n)
    if "wavepacket_index" in names:
        data.wavepacket_index = rng.integers(1, 255, n)
        data.wavepacket_offset = rng.integers(0, 2**40, n)
        data.wavepacket_size = rng.integers(1, 2**31, n)
        data.return_point_wave_location = rng.uniform(0, 1, n)
        data.x_t, data.y_t, data.z_t = (rng.uniform(-1, 1, n) for _ in range(3))
    data.write(path)
    if version == "1.0":
        raw = bytearray(path.read_bytes())
        raw[25] = 0
        path.write_bytes(raw)
    return data


def assert_reads_as_laspy(path: Path) -> None:
    """read_las gives laspy's coordinates, classes and colours (8 bits of 16), and keeps the
    file's integers with its scales and offsets."""
    cloud = read_las(path, ReadRequest())
    truth = laspy.read(path)
    assert cloud.xyz.dtype == np.int32
    assert np.array_equal(cloud.xyz, np.column_stack([truth.X, truth.Y, truth.Z]))
    assert np.array_equal(cloud.step, truth.header.scales)
    assert np.array_equal(cloud.ref, truth.header.offsets)
    assert np.array_equal(cloud.coordinates(0, len(cloud)),
                          np.column_stack([truth.x, truth.y, truth.z]))
    assert np.array_equal(cloud.classification, np.asarray(truth.classification))
    if "red" in truth.point_format.dimension_names:
        rgb = np.column_stack([truth.red, truth.green, truth.blue]) >> 8
        assert cloud.colors is not None and np.array_equal(cloud.colors, rgb)
    else:
        assert cloud.colors is None
    assert cloud.notes == [] and cloud.held is None


@pytest.mark.parametrize("version,point_format,ext", CASES)
def test_every_version_and_point_format_reads_as_laspy_reads_it(
        tmp_path: Path, version: str, point_format: int, ext: str) -> None:
    """Each point format of each LAS version, as LAS and LAZ, reads as laspy reads it."""
    path = tmp_path / f"v{version}_f{point_format}.{ext}"
    random_las(path, version, point_format)
    assert path.read_bytes()[24:26] == bytes([1, int(version[-1])])
    assert_reads_as_laspy(path)


@pytest.mark.parametrize("ext", ["las", "laz"])
def test_extra_bytes_are_read_past(tmp_path: Path, ext: str) -> None:
    """Points with 21 extra bytes (a double, a byte, three int32s) read as laspy reads them."""
    extra = [laspy.ExtraBytesParams("height", "f8"), laspy.ExtraBytesParams("tag", "u1"),
             laspy.ExtraBytesParams("triple", "3i4")]
    data = random_las(tmp_path / f"extra.{ext}", "1.4", 7, extra=extra)
    assert data.header.point_format.size == 36 + 21
    assert_reads_as_laspy(tmp_path / f"extra.{ext}")


def evlr_file(path: Path) -> bytes:
    """A LAS 1.4 file whose coordinate system (feet) is a WKT in an EVLR, as bytes."""
    data = random_las(path, "1.4", 6)
    data.header.global_encoding.wkt = True
    data.evlrs = laspy.vlrs.vlrlist.VLRList([laspy.vlrs.known.WktCoordinateSystemVlr(FT_WKT)])
    data.write(path)
    raw = path.read_bytes()
    assert struct.unpack_from("<I", raw, 243)[0] == 1  # one EVLR
    return raw


def test_a_wkt_in_an_evlr_gives_the_units(tmp_path: Path) -> None:
    """A coordinate system in an EVLR says feet, as one in a VLR would."""
    evlr_file(tmp_path / "evlr.las")
    cloud = read_las(tmp_path / "evlr.las", ReadRequest())
    assert len(cloud) == 3_000 and cloud.notes == []
    assert cloud.crs_scale == pytest.approx(0.3048)
    assert cloud.crs_note == "foot (0.3048 m, from the header's WKT)"
    assert cloud.crs_wkt is not None and "Oregon GIC Lambert (ft)" in cloud.crs_wkt


def test_evlrs_past_the_end_of_the_file_are_left_out(tmp_path: Path) -> None:
    """EVLRs said to start past the end of the file are left out, with a note."""
    raw = bytearray(evlr_file(tmp_path / "evlr.las"))
    struct.pack_into("<Q", raw, 235, len(raw) + 1_000)
    (tmp_path / "past.las").write_bytes(raw)
    cloud = read_las(tmp_path / "past.las", ReadRequest())
    assert len(cloud) == 3_000 and cloud.crs_wkt is None
    assert cloud.notes == ["the header's 1 EVLRs start past the end of the file: left out"]


def test_an_evlr_longer_than_the_file_is_left_out(tmp_path: Path) -> None:
    """An EVLR whose length says an exabyte is left out at once, with a note."""
    raw = bytearray(evlr_file(tmp_path / "evlr.las"))
    start = struct.unpack_from("<Q", raw, 235)[0]
    struct.pack_into("<Q", raw, start + 20, 2**60)
    (tmp_path / "long.las").write_bytes(raw)
    began = time.perf_counter()
    cloud = read_las(tmp_path / "long.las", ReadRequest())
    assert time.perf_counter() - began < 1.0
    assert len(cloud) == 3_000 and cloud.crs_wkt is None
    assert cloud.notes == ["the header counts 1 EVLRs, 0 fit in the file: read those"]


@pytest.mark.parametrize("ext", ["las", "laz"])
@pytest.mark.parametrize("claimed", [5, 4_000_000_000])
def test_a_vlr_count_beyond_what_fits_reads_those_that_fit(tmp_path: Path, ext: str,
                                                           claimed: int) -> None:
    """A header counting 5 or 4 billion VLRs reads those that fit, at once, with a note."""
    points, classes = cloud_points()
    raw = bytearray(write_las(tmp_path / f"s.{ext}", points, classes, wkt=FT_WKT).read_bytes())
    fit = struct.unpack_from("<I", raw, 100)[0]
    assert fit == (1 if ext == "las" else 2)
    struct.pack_into("<I", raw, 100, claimed)
    (tmp_path / f"vlrs.{ext}").write_bytes(raw)
    began = time.perf_counter()
    cloud = read_las(tmp_path / f"vlrs.{ext}", ReadRequest())
    assert time.perf_counter() - began < 0.5
    assert len(cloud) == len(points) and cloud.crs_scale == pytest.approx(0.3048)
    assert cloud.notes == [f"the header counts {claimed:,} VLRs, {fit} fit before the points: "
                           "read those"]


def test_a_las_14_with_only_its_legacy_count_reads_its_points(tmp_path: Path) -> None:
    """A LAS 1.4 whose 64-bit point count is 0 reads its legacy count of points, with a note."""
    random_las(tmp_path / "v14.las", "1.4", 1)
    raw = bytearray((tmp_path / "v14.las").read_bytes())
    struct.pack_into("<I", raw, 107, 3_000)
    struct.pack_into("<Q", raw, 247, 0)
    (tmp_path / "legacy.las").write_bytes(raw)
    cloud = read_las(tmp_path / "legacy.las", ReadRequest())
    assert len(cloud) == 3_000
    assert cloud.notes == ["the header's 64-bit point count is 0, its legacy count 3,000: read "
                           "those"]


def test_the_old_laszip_mark_reads_as_laz(tmp_path: Path) -> None:
    """A LAZ marked compressed by bit 6 of its point format (early LASzip) reads as LAZ."""
    random_las(tmp_path / "new.laz", "1.2", 3)
    raw = bytearray((tmp_path / "new.laz").read_bytes())
    assert raw[104] == 0x83
    raw[104] = 0x43
    (tmp_path / "old.laz").write_bytes(raw)
    cloud = read_las(tmp_path / "old.laz", ReadRequest())
    assert np.array_equal(cloud.xyz, read_las(tmp_path / "new.laz", ReadRequest()).xyz)


IN_1_GB = """
import resource, sys
resource.setrlimit(resource.RLIMIT_AS, (1 << 30, 1 << 30))
from astralis_des.cli import main
sys.exit(main(["world", "import", *sys.argv[1:]]))
"""  # the CLI in a process that may not use more than 1 GB of address space


@pytest.mark.parametrize("ext,message", [
    ("las", "truncated: the header announces 1,000,000,000,000 points, the file holds 15,605; "
            "pass --partial to import the 15,605 it holds"),
    ("laz", "truncated: the header announces 1,000,000,000,000 points, more than the 1 chunk "
            "of 50,000 its chunk table lists can hold")], ids=["las", "laz"])
def test_a_header_of_a_trillion_points_is_refused_at_once(tmp_path: Path, ext: str,
                                                          message: str) -> None:
    """A header of 10^12 points is refused as truncated in one line, in 1 GB, in seconds."""
    points, classes = cloud_points()
    raw = bytearray(write_las(tmp_path / f"s.{ext}", points, classes).read_bytes())
    struct.pack_into("<Q", raw, 247, 10**12)
    (tmp_path / f"tera.{ext}").write_bytes(raw)
    began = time.perf_counter()
    run = subprocess.run([sys.executable, "-c", IN_1_GB, str(tmp_path / f"tera.{ext}"), "-o",
                          str(tmp_path / "out" / "w.yaml")], capture_output=True, text=True,
                         timeout=60, cwd=ROOT)
    assert time.perf_counter() - began < 20
    assert (run.returncode, run.stderr) == (2, f"error: {tmp_path / f'tera.{ext}'}: {message}\n")
    assert not (tmp_path / "out").exists()


def numbered(path: Path, n: int, point_format: int = 1) -> Path:
    """A LAS or LAZ of ``n`` points whose X is its index (which points were kept shows), the
    rest random (so that a LAZ's chunks are many bytes)."""
    header = laspy.LasHeader(point_format=point_format,
                             version="1.4" if point_format > 5 else "1.2")
    header.scales, header.offsets = [1.0, 1.0, 1.0], [0.0, 0.0, 0.0]
    data = laspy.LasData(header)
    data.X = np.arange(n)
    data.Y, data.Z = np.random.default_rng(1).integers(0, 10**6, (2, n))
    data.write(path)
    return path


@pytest.mark.parametrize("ext", ["las", "laz"])
def test_max_points_keeps_every_kth_point(tmp_path: Path, ext: str,
                                          monkeypatch: pytest.MonkeyPatch) -> None:
    """--max-points keeps every k-th point across batches, the same each time, with a note."""
    monkeypatch.setattr(las, "CHUNK", 700)  # 15 batches: the stride carries across them
    path = numbered(tmp_path / f"n.{ext}", 10_000)
    cloud = read_las(path, ReadRequest(max_points=3_000))
    assert np.array_equal(cloud.xyz[:, 0], np.arange(0, 10_000, 4))
    assert cloud.held == 10_000
    assert cloud.notes == ["kept every 4th point (2,500 of 10,000) to stay within --max-points "
                           "3,000"]
    again = read_las(path, ReadRequest(max_points=3_000))
    assert np.array_equal(again.xyz, cloud.xyz) and again.notes == cloud.notes


def chunked_laz(path: Path, point_format: int) -> tuple[bytes, list[tuple[int, int]], int]:
    """A LAZ of 120,000 points in chunks of 50,000: its bytes, its chunk table ((points,
    bytes) a chunk, by lazrs) and where its first chunk starts."""
    import lazrs

    raw = numbered(path, 120_000, point_format).read_bytes()
    offset = struct.unpack_from("<I", raw, 96)[0]
    with laspy.open(path) as opened:
        record = opened.header.vlrs.get("LasZipVlr")[0].record_data
    with path.open("rb") as file:
        file.seek(offset)
        table = [(int(p), int(b)) for p, b in lazrs.read_chunk_table(file, lazrs.LazVlr(record))]
    assert [p for p, _ in table] == [50_000] * 3
    return raw, table, offset + 8


CUT_NOTES = {  # chunks read until one ends early | chunks whose layers say where they end
    1: "--partial: read the {held:,} points before the file ends, of the 120,000 its header "
       "announces",
    7: "--partial: read the {held:,} whole points the file holds, of the 120,000 its header "
       "announces"}


@pytest.mark.parametrize("point_format", sorted(CUT_NOTES))
def test_partial_reads_the_whole_chunks_of_a_cut_laz(tmp_path: Path, point_format: int
                                                     ) -> None:
    """A LAZ cut short is refused with its whole chunks' count; --partial reads them."""
    raw, table, start = chunked_laz(tmp_path / "whole.laz", point_format)
    whole = read_las(tmp_path / "whole.laz", ReadRequest())
    for chunks, held in ((1, 50_000), (2, 100_000)):
        cut = start + sum(b for _, b in table[:chunks]) + table[chunks][1] // 2
        path = tmp_path / f"cut{chunks}.laz"
        path.write_bytes(raw[:cut])
        with pytest.raises(InputError) as refused:
            read_las(path, ReadRequest())
        assert refused.value.one_line() == (
            f"{path}: truncated: the header announces 120,000 points, the file holds "
            f"{held:,}; pass --partial to import the {held:,} it holds")
        cloud = read_las(path, ReadRequest(partial=True))
        assert np.array_equal(cloud.xyz, whole.xyz[:held])
        assert cloud.notes == [CUT_NOTES[point_format].format(held=held)]


def test_a_laz_chunk_whose_layers_claim_gigabytes_is_refused(tmp_path: Path) -> None:
    """A LAZ chunk whose layers claim 4 GB is refused as damaged in 1 GB; --partial reads before."""
    raw, table, start = chunked_laz(tmp_path / "whole.laz", 6)
    raw = bytearray(raw)
    second = start + table[0][1]
    # a chunk: its first point raw (30 bytes), its count, its layers' sizes (xy first, then z)
    struct.pack_into("<I", raw, second + 30 + 4 + 4, 0xFFFFFFF0)
    (tmp_path / "layers.laz").write_bytes(raw)
    out = str(tmp_path / "out" / "w.yaml")
    run = subprocess.run([sys.executable, "-c", IN_1_GB, str(tmp_path / "layers.laz"), "-o", out],
                         capture_output=True, text=True, timeout=60, cwd=ROOT)
    assert (run.returncode, run.stderr) == (2, (
        f"error: {tmp_path / 'layers.laz'}: damaged after 50,000 of its 120,000 points (chunk 2 "
        "of 3 cannot be read); pass --partial to import the 50,000 it holds\n"))
    cloud = read_las(tmp_path / "layers.laz", ReadRequest(partial=True))
    assert np.array_equal(cloud.xyz[:, 0], np.arange(50_000))


def test_laszips_point_wise_compressor_is_read_by_laszip(
        capfd: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    """LASzip's point-wise compressor is read by laszip, silently; with lazrs alone, refused."""
    pointwise = read_las(SCANS / "laz" / "simple-laszip-compressor-version-1.2r0.laz",
                         ReadRequest())
    chunked = read_las(SCANS / "laz" / "simple.laz", ReadRequest())
    assert len(pointwise) == 1_065 and np.array_equal(pointwise.xyz, chunked.xyz)
    assert np.array_equal(pointwise.classification, chunked.classification)
    assert np.array_equal(pointwise.colors, chunked.colors)
    assert capfd.readouterr() == ("", "")  # lazrs would panic on it, printing a backtrace
    lazrs = [laspy.LazBackend.LazrsParallel, laspy.LazBackend.Lazrs]
    monkeypatch.setattr(laspy.LazBackend, "detect_available", staticmethod(lambda: lazrs))
    with pytest.raises(InputError) as refused:
        read_las(SCANS / "laz" / "simple-laszip-compressor-version-1.2r0.laz", ReadRequest())
    assert refused.value.message == ("compressed by LASzip 1's point-wise compressor, which "
                                     "only laspy's laszip backend reads: pip install laszip")
    assert capfd.readouterr() == ("", "")


def write_copc(path: Path, levels: int = 4) -> laspy.LasData:
    """autzen_trim's 110,000 points as a COPC (by copclib) of ``levels`` octree levels: a
    random 1/64 of the points in the root, 1/8 down to level 1, 1/2 down to level 2, the rest
    in level 3, each node's points inside its voxel. Returns the points (format 7)."""
    import copclib

    source = laspy.convert(laspy.read(AUTZEN), point_format_id=7, file_version="1.4")
    n = len(source.points)
    xyz = np.column_stack([source.x, source.y, source.z])
    low = xyz.min(axis=0)
    side = float((xyz.max(axis=0) - low).max()) * 1.0001
    config = copclib.CopcConfigWriter(7, copclib.Vector3(*source.header.scales),
                                      copclib.Vector3(*source.header.offsets),
                                      source.header.parse_crs().to_wkt())
    config.las_header.min = copclib.Vector3(*xyz.min(axis=0))
    config.las_header.max = copclib.Vector3(*xyz.max(axis=0))
    config.copc_info.center_x, config.copc_info.center_y, config.copc_info.center_z = (
        float(c) for c in low + side / 2)
    config.copc_info.halfsize, config.copc_info.spacing = side / 2, side / 64
    writer = copclib.FileWriter(str(path), config)
    order = np.random.default_rng(7).permutation(n)
    bounds = [0, n // 64, n // 8, n // 2, n][:levels] + [n]
    for level in range(levels):
        chosen = order[bounds[level]:bounds[level + 1]]
        cells = np.minimum(((xyz[chosen] - low) / side * 2**level).astype(int), 2**level - 1)
        keys, which = np.unique(cells, axis=0, return_inverse=True)
        for k, key in enumerate(keys):
            records = source.points.array[chosen[which.ravel() == k]].tobytes()
            writer.AddNode(copclib.VoxelKey(level, *(int(c) for c in key)),
                           copclib.VectorChar(np.frombuffer(records, dtype=np.int8)))
    writer.Close()
    return source


@pytest.fixture(scope="module")
def copc(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, laspy.LasData]:
    path = tmp_path_factory.mktemp("copc") / "autzen.copc.laz"
    return path, write_copc(path)


def rows(xyz: np.ndarray) -> np.ndarray:
    return xyz[np.lexsort(xyz.T[::-1])]


def test_a_copc_reads_whole(copc: tuple[Path, laspy.LasData]) -> None:
    """A COPC within --max-points reads all its points, in the feet of its WKT EVLR."""
    path, source = copc
    with laspy.CopcReader.open(path) as reader:
        assert reader.header.point_count == 110_000 and len(reader.query(level=0)) == 1_718
    cloud = read_las(path, ReadRequest())
    assert len(cloud) == 110_000 and cloud.held is None and cloud.notes == []
    assert np.array_equal(rows(cloud.xyz), rows(np.column_stack([source.X, source.Y,
                                                                 source.Z])))
    assert cloud.crs_scale == pytest.approx(0.3048)


def test_a_copc_beyond_max_points_reads_its_top_levels(copc: tuple[Path, laspy.LasData]
                                                       ) -> None:
    """A COPC beyond --max-points reads its top levels, over its whole extent, with a note."""
    path, source = copc
    cloud = read_las(path, ReadRequest(max_points=20_000))
    assert len(cloud) == 13_750 and cloud.held == 110_000
    assert cloud.notes == ["COPC: read octree levels 0 to 1 of 4 (13,750 of 110,000 points, "
                           "spaced about 9.2 file units): within --max-points 20,000"]
    xyz = cloud.coordinates(0, len(cloud))
    full = np.column_stack([source.x, source.y, source.z])
    span = np.ptp(xyz, axis=0)[:2] / np.ptp(full, axis=0)[:2]
    assert (span > 0.98).all()
    assert cloud.crs_scale == pytest.approx(0.3048)
    root = read_las(path, ReadRequest(max_points=1_000))
    assert len(root) == 859
    assert root.notes == ["COPC: read octree levels 0 to 0 of 4 (859 of 110,000 points, every "
                          "2nd point of them, spaced about 18.4 file units): within "
                          "--max-points 1,000"]


def test_a_copc_cut_short_reads_its_whole_chunks_with_partial(
        copc: tuple[Path, laspy.LasData], tmp_path: Path) -> None:
    """A COPC cut short is refused with its whole chunks' count; --partial reads them."""
    from laspy.copc import load_octree_for_query

    raw = copc[0].read_bytes()
    cut = len(raw) // 2
    with laspy.CopcReader.open(copc[0]) as reader:
        nodes = load_octree_for_query(reader.source, reader.copc_info, reader.root_page)
    held = sum(n.point_count for n in nodes if n.offset + n.byte_size <= cut)
    assert 40_000 < held < 70_000
    path = tmp_path / "cut.copc.laz"
    path.write_bytes(raw[:cut])
    with pytest.raises(InputError) as refused:
        read_las(path, ReadRequest())
    assert refused.value.message == (f"truncated: the header announces 110,000 points, the file "
                                     f"holds {held:,}; pass --partial to import the {held:,} it "
                                     "holds")
    cloud = read_las(path, ReadRequest(partial=True))
    whole = read_las(copc[0], ReadRequest())
    assert np.array_equal(cloud.xyz, whole.xyz[:held])
    assert cloud.notes == ["the header's 2 EVLRs start past the end of the file: left out",
                           f"--partial: read the {held:,} whole points the file holds, of the "
                           "110,000 its header announces"]


def test_a_copc_becomes_a_world(copc: tuple[Path, laspy.LasData], tmp_path: Path) -> None:
    """A COPC imported within --max-points 20,000 makes autzen_trim's site from 2 levels."""
    path, _ = copc
    report = import_world(path, tmp_path / "copc.yaml", ImportOptions(max_points=20_000))
    assert report.points == 110_000 and report.extra["kept"] == 13_750
    assert report.scale == pytest.approx(0.3048)
    assert report.site == pytest.approx((363.0, 176.0), abs=1.0) and len(report.areas) == 4
    assert report.notes[0].startswith("COPC: read octree levels 0 to 1 of 4")


def root_entry(raw: bytes) -> tuple[int, int, int]:
    """Where a COPC's root hierarchy page is, its size, and where in it the root node's entry
    (key 0-0-0-0) is."""
    info = raw.index(b"copc\0") - 2 + 54  # the COPC info VLR's data
    at, size = struct.unpack_from("<QQ", raw, info + 40)
    for entry in range(at, at + size, 32):
        if struct.unpack_from("<4i", raw, entry) == (0, 0, 0, 0):
            return at, size, entry
    raise AssertionError("no root node")


@pytest.mark.parametrize("damage,message", [
    ("loop", "its octree loops: the hierarchy page at byte {at:,} is reached twice"),
    ("empty", "its octree holds no points, its header announces 110,000")])
def test_a_copc_whose_octree_is_damaged_is_refused_at_once(
        copc: tuple[Path, laspy.LasData], tmp_path: Path, damage: str, message: str) -> None:
    """A COPC whose octree loops or holds no points is refused in one line, at once."""
    raw = bytearray(copc[0].read_bytes())
    at, size, entry = root_entry(raw)
    if damage == "loop":
        struct.pack_into("<Qii", raw, entry + 16, at, size, -1)
    else:
        struct.pack_into("<Qii", raw, entry + 16, 0, 0, 0)
        raw[entry:entry + 4] = struct.pack("<i", 9)  # and no root at all
    (tmp_path / "bad.copc.laz").write_bytes(raw)
    with deadline(10), pytest.raises(InputError) as refused:
        read_las(tmp_path / "bad.copc.laz", ReadRequest(max_points=20_000))
    assert refused.value.message == f"not a readable COPC file ({message.format(at=at)})"


def bad_file(kind: str, tmp_path: Path) -> tuple[str, list[str], str]:
    """A bad input of ``kind``: its path, more options, and the refusal it must get."""
    points, classes = cloud_points()
    target = tmp_path / "scan.las"
    if kind == "folder":
        target.mkdir()
        return str(target), [], "a folder, not a file"
    if kind == "fifo":
        os.mkfifo(target)
        return str(target), [], "a FIFO, not a regular file: import reads files it can measure"
    if kind == "dev-zero":
        return "/dev/zero", ["--format", "las"], ("a device, not a regular file: import reads "
                                                  "files it can measure")
    whole = write_las(tmp_path / "whole.las", points, classes).read_bytes()
    if kind in ("nan-scales", "overflowing-scale"):
        raw = bytearray(whole)
        scales = [float("nan")] * 3 if kind == "nan-scales" else [1e306, 0.01, 0.01]
        struct.pack_into("<3d", raw, 131, *scales)
        target.write_bytes(raw)
        return str(target), [], (f"not a readable LAS file (its scale factors "
                                 f"{', '.join(f'{s:g}' for s in scales)} and offsets 0, 0, 0 "
                                 "give no finite coordinates)")
    if kind == "header-only":
        data = laspy.read(tmp_path / "whole.las")
        data = laspy.convert(data, file_version="1.2")
        data.write(tmp_path / "v12.las")
        target.write_bytes((tmp_path / "v12.las").read_bytes()[:227])
        assert struct.unpack_from("<HI", target.read_bytes(), 94) == (227, 227)
        return str(target), [], "truncated: the header announces 15,605 points, the file holds 0"
    if kind == "random-laz":
        target = tmp_path / "scan.laz"
        target.write_bytes(np.random.default_rng(0).bytes(5_000))
        return str(target), [], r"not a readable LAS file (it starts with b'_\x82\xc2\xd9', " \
            "not b'LASF')"
    assert kind == "no-laszip-vlr"
    raw = bytearray(write_las(tmp_path / "whole.laz", points, classes).read_bytes())
    offset, count = struct.unpack_from("<II", raw, 96)
    assert raw[375 + 2:375 + 16] == b"laszip encoded" and count == 1
    length = 54 + struct.unpack_from("<H", raw, 375 + 20)[0]
    raw[375:375 + length] = b""
    struct.pack_into("<II", raw, 96, offset - length, 0)
    target = tmp_path / "scan.laz"
    target.write_bytes(raw)
    return str(target), [], ("not a readable LAZ file (its points are compressed, but it has no "
                             "LASzip VLR to say how)")


@pytest.mark.parametrize("kind", ["folder", "fifo", "dev-zero", "nan-scales",
                                  "overflowing-scale", "header-only", "random-laz",
                                  "no-laszip-vlr"])
def test_bad_input_is_refused_at_once_in_one_line(capsys: pytest.CaptureFixture[str],
                                                  tmp_path: Path, kind: str) -> None:
    """Bad input: exit code 2 within seconds, one line naming the file, nothing written."""
    path, options, message = bad_file(kind, tmp_path)
    out = tmp_path / "out"
    began = time.perf_counter()
    with deadline(10), warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")  # a warning would print before the line
        code = main(["world", "import", path, "-o", str(out / "twin.yaml"), *options])
    assert time.perf_counter() - began < 5
    assert (code, capsys.readouterr().err, caught) == (2, f"error: {path}: {message}\n", [])
    assert not out.exists() or not any(out.iterdir())
