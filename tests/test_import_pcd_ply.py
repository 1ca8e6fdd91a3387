"""The PCD and PLY readers on real files (PDAL's test corpus in data/scans) and on files the
tests write: what each file gives (points, their first coordinates, colours, classes), and
the one line a file that cannot be read is refused with."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from numpy.lib import recfunctions

from astralis_des.errors import InputError
from astralis_des.importers.pcd import read_pcd
from astralis_des.importers.ply import read_ply
from astralis_des.importers.pointcloud import read_text
from astralis_des.importers.source import Cloud, Mesh, Reader, ReadRequest

SCANS = Path(__file__).resolve().parents[1] / "data" / "scans"
PCD, PLY = SCANS / "pcd", SCANS / "ply"
WHOLE, PARTIAL = ReadRequest(), ReadRequest(partial=True)


def cloud(read: Reader, path: Path, request: ReadRequest = WHOLE) -> Cloud:
    data = read(path, request)
    assert isinstance(data, Cloud)
    return data


def refusal(read: Reader, path: Path, request: ReadRequest = WHOLE) -> str:
    with pytest.raises(InputError) as caught:
        read(path, request)
    return str(caught.value)


def first_row(path: Path, after: str) -> list[float]:
    """The numbers of the first data row of a text file, after its header's last line."""
    lines = path.read_text(encoding="ascii").splitlines()
    row = lines[next(i for i, ln in enumerate(lines) if ln.strip().startswith(after)) + 1]
    return [float(v) for v in row.replace(",", " ").split()]


def pcd_header(fields: str, sizes: str, types: str, points: int, data: str,
               counts: str | None = None, height: int = 1) -> bytes:
    counts = counts or " ".join("1" for _ in fields.split())
    return (f"# .PCD v0.7\nVERSION 0.7\nFIELDS {fields}\nSIZE {sizes}\nTYPE {types}\n"
            f"COUNT {counts}\nWIDTH {points // height}\nHEIGHT {height}\n"
            f"VIEWPOINT 0 0 0 1 0 0 0\nPOINTS {points}\nDATA {data}\n").encode()


def ply_header(fmt: str, *elements: tuple[str, int, list[str]]) -> bytes:
    text = f"ply\nformat {fmt} 1.0\ncomment written by the test\n"
    for name, count, properties in elements:
        text += f"element {name} {count}\n" + "".join(f"property {p}\n" for p in properties)
    return (text + "end_header\n").encode()


def scan_records(n: int = 200) -> np.ndarray:
    """x, y, z, a packed colour (PCL's float rgb) and a class for ``n`` points on a grid,
    values that LZF compresses."""
    records = np.zeros(n, dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("rgb", "<u4"),
                                 ("classification", "u1")])
    records["x"], records["y"], records["z"] = np.arange(n) % 20, np.arange(n) // 20, 100.0
    records["rgb"] = np.where(np.arange(n) % 2, 0xFF0080FF, 0xFFFF0010)
    records["classification"] = np.where(np.arange(n) < n // 2, 2, 6)
    return records


SCAN_FIELDS = ("x y z rgb classification", "4 4 4 4 1", "F F F F U")


# --- PCD: the corpus ---------------------------------------------------------------------

def test_autzen_pcd_reads_its_upper_case_fields() -> None:
    """PDAL's binary autzen-utm.pcd (fields X Y Z ... Classification ... Red Green Blue, in
    capitals) gives its 1,065 points, classes 1 and 2 and 8-bit colours from 16-bit fields."""
    data = cloud(read_pcd, PCD / "autzen-utm.pcd")
    assert len(data.xyz) == 1065
    assert data.xyz[0].tolist() == pytest.approx([494428.61, 4877455.58, 131.57])
    assert data.classification is not None and set(data.classification.tolist()) == {1, 2}
    assert data.colors is not None and data.colors[:2].tolist() == [[68, 77, 88], [54, 66, 68]]


@pytest.mark.parametrize("name", ["utm17_comma.pcd", "utm17_space.pcd", "utm17_tab.pcd"])
def test_ascii_pcd_rows_with_any_delimiter(name: str) -> None:
    """ASCII rows separated by commas, spaces or tabs give the file's 10 points, the first
    as its text says."""
    data = cloud(read_pcd, PCD / name)
    assert len(data.xyz) == 10
    assert data.xyz[0].tolist() == first_row(PCD / name, "DATA")
    assert data.xyz[0].tolist() == pytest.approx([289814.15, 4320978.61, 170.76])


def test_semicolon_rows(tmp_path: Path) -> None:
    """Values separated by semicolons are read too."""
    path = tmp_path / "semi.pcd"
    path.write_bytes(pcd_header("x y z", "4 4 4", "F F F", 2, "ascii") + b"1;2;3\n4;5;6\n")
    assert cloud(read_pcd, path).xyz.tolist() == [[1, 2, 3], [4, 5, 6]]


def test_pcd_without_a_header_is_refused_with_a_way_out() -> None:
    """missingheader.pcd, rows of numbers only, is refused with the --format xyz way out."""
    path = PCD / "missingheader.pcd"
    assert refusal(read_pcd, path) == (f"{path}:1: no PCD header: the file starts with rows "
                                       "of numbers; to read them as x y z, pass --format xyz")


def test_pcd_header_without_data_line(tmp_path: Path) -> None:
    """A header that stops before its DATA line is refused on the line where it stops."""
    path = tmp_path / "nodata.pcd"
    path.write_bytes(pcd_header("x y z", "4 4 4", "F F F", 1, "ascii")
                     .replace(b"DATA ascii\n", b""))
    assert refusal(read_pcd, path) == (f"{path}:10: the header ends without a DATA line "
                                       "(DATA ascii, binary or binary_compressed)")


# --- PCD: binary_compressed, organised clouds, colours --------------------------------------

@pytest.mark.parametrize("padding", ["none", "left out", "kept"])
def test_binary_compressed_reads_as_the_same_cloud_written_binary(tmp_path: Path,
                                                                  padding: str) -> None:
    """LZF-compressed fields, one after another, give the points, colours and classes of the
    same cloud written binary; a padding field "_" may be left out of the data (as PCL
    does) or kept (as pypcd4 does)."""
    records = scan_records()
    fields, sizes, types = SCAN_FIELDS
    if padding != "none":
        fields, sizes, types = fields + " _", sizes + " 4", types + " U"
        records = recfunctions.append_fields(records, "pad", np.zeros(len(records), "<u4"),
                                             usemask=False)
    (tmp_path / "scan.pcd").write_bytes(pcd_header(fields, sizes, types, len(records),
                                                   "binary") + records.tobytes())
    import lzf

    columns = [n for n in records.dtype.names or () if n != "pad" or padding == "kept"]
    raw = b"".join(np.ascontiguousarray(records[n]).tobytes() for n in columns)
    packed = lzf.compress(raw)
    assert packed is not None and len(packed) < len(raw)
    (tmp_path / "packed.pcd").write_bytes(
        pcd_header(fields, sizes, types, len(records), "binary_compressed")
        + np.array([len(packed), len(raw)], "<u4").tobytes() + packed)
    binary = cloud(read_pcd, tmp_path / "scan.pcd")
    compressed = cloud(read_pcd, tmp_path / "packed.pcd")
    assert len(compressed.xyz) == 200 and compressed.xyz.tolist() == binary.xyz.tolist()
    assert compressed.colors is not None and binary.colors is not None
    assert compressed.colors.tolist() == binary.colors.tolist()
    assert compressed.colors[:2].tolist() == [[255, 0, 16], [0, 128, 255]]
    assert compressed.classification is not None
    assert np.bincount(compressed.classification).tolist() == [0, 0, 100, 0, 0, 0, 100]


def test_binary_compressed_written_by_pypcd4(tmp_path: Path) -> None:
    """A binary_compressed file another tool (pypcd4) wrote gives its points and colours."""
    pypcd4 = pytest.importorskip("pypcd4")
    grid = np.column_stack([np.arange(300) % 20 * 0.5, np.arange(300) // 20 * 0.5,
                            np.zeros(300)])
    rgb = np.tile(np.array([[255, 0, 10], [0, 128, 255]], np.uint8), (150, 1))
    points = np.column_stack([grid, pypcd4.PointCloud.encode_rgb(rgb)]).astype(np.float32)
    path = tmp_path / "pypcd4.pcd"
    pypcd4.PointCloud.from_xyzrgb_points(points).save(
        path, encoding=pypcd4.Encoding.BINARY_COMPRESSED)
    assert b"DATA binary_compressed\n" in path.read_bytes()[:300]
    data = cloud(read_pcd, path)
    assert data.xyz.tolist() == grid.tolist()
    assert data.colors is not None and data.colors.tolist() == rgb.tolist()


def test_organised_cloud_keeps_its_nan_points(tmp_path: Path) -> None:
    """A WIDTH x HEIGHT cloud (a depth camera's) gives all its points, NaN ones included:
    the import drops and counts those."""
    records = np.zeros(32, dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4")])
    records["x"] = np.arange(32)
    records["x"][::4] = np.nan
    path = tmp_path / "organised.pcd"
    path.write_bytes(pcd_header("x y z", "4 4 4", "F F F", 32, "binary", height=4)
                     + records.tobytes())
    data = cloud(read_pcd, path)
    assert len(data.xyz) == 32 and int(np.isnan(data.xyz[:, 0]).sum()) == 8


def test_pcd_colours_from_separate_16_bit_fields(tmp_path: Path) -> None:
    """red, green and blue fields of 16 bits (as PDAL writes them) are scaled to 8 bits."""
    path = tmp_path / "rgb16.pcd"
    path.write_bytes(pcd_header("x y z red green blue", "4 4 4 2 2 2", "F F F U U U", 2,
                                "ascii") + b"1 2 3 65535 32896 0\n4 5 6 0 257 65535\n")
    colors = cloud(read_pcd, path).colors
    assert colors is not None and colors.tolist() == [[255, 128, 0], [0, 1, 255]]


@pytest.mark.parametrize("written", ["4278190335", "2.3418052e-38"])
def test_ascii_packed_rgb_as_integer_or_as_float(tmp_path: Path, written: str) -> None:
    """An ASCII rgb field holds PCL's packed colour as an integer (PCL today) or as the float
    of the same bits (older writers): both are the colour."""
    path = tmp_path / "rgb.pcd"
    path.write_bytes(pcd_header("x y z rgb", "4 4 4 4", "F F F F", 1, "ascii")
                     + f"1 2 3 {written}\n".encode())
    colors = cloud(read_pcd, path).colors
    expected = [0, 0, 255] if written.startswith("42") else [255, 0, 0]
    assert colors is not None and colors.tolist() == [expected]


# --- PCD: truncated files ------------------------------------------------------------------

def test_truncated_binary_pcd_refused_or_read_in_part(tmp_path: Path) -> None:
    """A binary PCD cut inside its points is refused with what it announces and holds; with
    partial, its whole points are read."""
    records = scan_records()
    whole = pcd_header(*SCAN_FIELDS, len(records), "binary") + records.tobytes()
    path = tmp_path / "cut.pcd"
    path.write_bytes(whole[:-40])
    assert refusal(read_pcd, path) == (f"{path}: truncated: 200 points of 17 bytes need 3,400 "
                                       "bytes, the file holds 3,360; pass --partial to import "
                                       "the 197 it holds")
    data = cloud(read_pcd, path, PARTIAL)
    assert len(data.xyz) == 197 and data.xyz[-1].tolist() == [16, 9, 100]
    assert data.notes == ["--partial: read the 197 whole points before the file ends, of "
                          "the 200 its header announces"]


def test_truncated_ascii_pcd_refused_or_read_in_part(tmp_path: Path) -> None:
    """An ASCII PCD cut inside a row is refused; with partial, the rows before it are read."""
    rows = "".join(f"{i} {i} 0\n" for i in range(1200))
    path = tmp_path / "cut.pcd"
    path.write_bytes(pcd_header("x y z", "4 4 4", "F F F", 1200, "ascii") + rows.encode()[:-4])
    assert refusal(read_pcd, path) == (f"{path}: truncated: the header announces 1,200 points, "
                                       "the file holds 1,199; pass --partial to import the "
                                       "1,199 it holds")
    assert len(cloud(read_pcd, path, PARTIAL).xyz) == 1199


def test_truncated_binary_compressed_cannot_be_read_in_part(tmp_path: Path) -> None:
    """Compressed fields come one after another, so a cut file holds no whole point: refused
    even with partial."""
    import lzf

    raw = b"".join(np.ascontiguousarray(scan_records()[n]).tobytes()
                   for n in SCAN_FIELDS[0].split())
    packed = lzf.compress(raw)
    path = tmp_path / "cut.pcd"
    path.write_bytes(pcd_header(*SCAN_FIELDS, 200, "binary_compressed")
                     + np.array([len(packed), len(raw)], "<u4").tobytes() + packed[:-10])
    line = refusal(read_pcd, path, PARTIAL)
    assert line == (f"{path}: truncated: the compressed points need {len(packed):,} bytes, the "
                    f"file holds {len(packed) - 10:,}; compressed points cannot be read in part")


# --- PLY: the corpus -----------------------------------------------------------------------

@pytest.mark.parametrize("name,points", [("simple_text.ply", 3), ("issue_2421.ply", 1),
                                         ("text_extradim.ply", 1)])
def test_ascii_ply_clouds(name: str, points: int) -> None:
    """ASCII clouds (float64 and int32 properties, a face element of 0 faces, a char blue)
    give their points, the first as the file's text says."""
    data = cloud(read_ply, PLY / name)
    assert len(data.xyz) == points
    assert data.xyz[0].tolist() == pytest.approx(first_row(PLY / name, "end_header")[:3],
                                                 rel=1e-7)


def test_ply_colours_from_the_file() -> None:
    """text_extradim.ply's red, green and (char) blue give its point's colour."""
    data = cloud(read_ply, PLY / "text_extradim.ply")
    assert data.colors is not None and data.colors.tolist() == [[63, 200, 64]]


def test_binary_ply_cloud() -> None:
    """simple_binary.ply (CloudCompare's, little-endian floats) gives its 3 points."""
    data = cloud(read_ply, PLY / "simple_binary.ply")
    assert data.xyz.tolist() == [[-1, 0, 0], [0, 1, 0], [1, 0, 0]]


@pytest.mark.parametrize("name", ["mesh.ply", "mesh_fixed.ply"])
def test_ply_meshes(name: str) -> None:
    """A PLY with faces (lists of uint8 length and uint32 indices) is a mesh of 4 vertices
    and 2 triangles."""
    data = read_ply(PLY / name, WHOLE)
    assert isinstance(data, Mesh)
    assert data.vertices.tolist() == [[1, 1, 0], [2, 1, 0], [1, 2, 0], [2, 2, 2]]
    assert data.faces.tolist() == [[0, 1, 2], [1, 2, 3]]


def test_ply_without_vertices_is_refused() -> None:
    """no_vertex.ply, a header of no elements, is refused in one line."""
    path = PLY / "no_vertex.ply"
    assert refusal(read_ply, path) == (f"{path}: no vertex element (the header declares no "
                                       "elements)")


@pytest.mark.parametrize("name,properties", [("sized_dims.ply", "x, y, j, i"),
                                             ("unsized_dims.ply", "y, x, i, j")])
def test_ply_without_z_is_refused(name: str, properties: str) -> None:
    """Vertices with x and y but no z are refused, naming the properties they have."""
    path = PLY / name
    assert refusal(read_ply, path) == (f"{path}:4: the vertices have no z (properties: "
                                       f"{properties})")


# --- PLY: files the tests write ------------------------------------------------------------

PLY_PROPERTIES = ["float x", "float y", "float z", "ushort Red", "ushort GREEN", "ushort blue",
                  "uchar Classification"]


def ply_records(n: int = 10) -> np.ndarray:
    records = np.zeros(n, dtype=[("x", "f4"), ("y", "f4"), ("z", "f4"), ("r", "u2"),
                                 ("g", "u2"), ("b", "u2"), ("c", "u1")])
    records["x"], records["y"], records["z"] = np.arange(n), 2, 3
    records["r"], records["g"], records["b"], records["c"] = 65535, 32896, 257, 6
    return records


@pytest.mark.parametrize("fmt,order", [("binary_little_endian", "<"),
                                       ("binary_big_endian", ">"), ("ascii", "")])
def test_ply_in_each_encoding_with_16_bit_colours_and_classes(tmp_path: Path, fmt: str,
                                                               order: str) -> None:
    """Little- and big-endian binary and ASCII give the same points; 16-bit colours (any
    case) are scaled to 8 bits and a Classification property gives the classes."""
    records = ply_records()
    if order == ">":
        records = records.astype(records.dtype.newbyteorder(">"))
    body = records.tobytes() if order else "".join(
        " ".join(str(v) for v in r) + "\n" for r in records.tolist()).encode()
    path = tmp_path / "scan.ply"
    path.write_bytes(ply_header(fmt, ("vertex", 10, PLY_PROPERTIES)) + body)
    data = cloud(read_ply, path)
    assert data.xyz[:, 0].tolist() == list(range(10)) and data.xyz[0].tolist() == [0, 2, 3]
    assert data.colors is not None and data.colors[0].tolist() == [255, 128, 1]
    assert data.classification is not None and data.classification.tolist() == [6] * 10


@pytest.mark.parametrize("fmt", ["binary_little_endian", "ascii"])
def test_truncated_ply_refused_or_read_in_part(tmp_path: Path, fmt: str) -> None:
    """A PLY cloud cut inside its vertices is refused with what it announces and holds; with
    partial, its whole vertices are read."""
    records = ply_records()
    body = records.tobytes() if fmt != "ascii" else "".join(
        " ".join(str(v) for v in r) + "\n" for r in records.tolist()).encode()
    path = tmp_path / "cut.ply"
    path.write_bytes(ply_header(fmt, ("vertex", 10, PLY_PROPERTIES)) + body[:-25])
    held = 8 if fmt != "ascii" else 9
    assert refusal(read_ply, path) == (f"{path}: truncated: the file ends before its data does "
                                       f"(the header announces 10 vertices, the file holds "
                                       f"{held}); pass --partial to import the {held} it holds")
    assert len(cloud(read_ply, path, PARTIAL).xyz) == held


def binary_mesh(faces: list[tuple[int, ...]]) -> bytes:
    corners = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0], [2, 1, 0]])
    data = ply_header("binary_little_endian", ("vertex", 6, ["double x", "double y",
                                                             "double z"]),
                      ("face", len(faces), ["list uchar uint vertex_indices"]))
    data += corners.astype("<f8").tobytes()
    for face in faces:
        data += bytes([len(face)]) + np.array(face, "<u4").tobytes()
    return data


def test_binary_mesh_of_triangles_and_quads(tmp_path: Path) -> None:
    """A binary mesh whose faces mix triangles and quads (as Blender writes) is read, its
    quads as two triangles each."""
    path = tmp_path / "mixed.ply"
    path.write_bytes(binary_mesh([(0, 1, 2), (0, 2, 3), (1, 4, 5, 2)]))
    data = read_ply(path, WHOLE)
    assert isinstance(data, Mesh) and len(data.vertices) == 6
    assert data.faces.tolist() == [[0, 1, 2], [0, 2, 3], [1, 4, 5], [1, 5, 2]]


def test_truncated_binary_mesh_names_its_faces(tmp_path: Path) -> None:
    """A binary mesh cut inside its faces says how many whole faces it holds."""
    path = tmp_path / "cut.ply"
    path.write_bytes(binary_mesh([(0, 1, 2), (0, 2, 3), (1, 4, 5, 2)])[:-3])
    assert refusal(read_ply, path) == (f"{path}: truncated: the file ends before its data does "
                                       "(the header announces 3 faces, the file holds 2)")


def test_truncated_ascii_mesh(tmp_path: Path) -> None:
    """An ASCII mesh with fewer rows than its header announces is refused (trimesh would read
    what there is without a word)."""
    path = tmp_path / "cut.ply"
    rows = b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"
    path.write_bytes(ply_header("ascii", ("vertex", 3, ["float x", "float y", "float z"]),
                                ("face", 2, ["list uchar int vertex_indices"])) + rows)
    assert refusal(read_ply, path) == (f"{path}: truncated: the file ends before its data does "
                                       "(the header announces 3 vertices and 2 faces: 5 rows; "
                                       "the file holds 4)")


def test_faces_naming_a_missing_vertex_are_refused(tmp_path: Path) -> None:
    """Faces whose corners go past the vertices (as 1-based indices do) are refused."""
    path = tmp_path / "one_based.ply"
    path.write_bytes(ply_header("ascii", ("vertex", 3, ["float x", "float y", "float z"]),
                                ("face", 1, ["list uchar int vertex_indices"]))
                     + b"0 0 0\n1 0 0\n0 1 0\n3 1 2 3\n")
    assert refusal(read_ply, path) == f"{path}: faces use vertex 3, of 3 vertices numbered from 0"


# --- text ----------------------------------------------------------------------------------

def test_text_header_names_in_any_case(tmp_path: Path) -> None:
    """A CSV header row in capitals (X,Y,Z,Red,Green,Blue,Classification) says the columns."""
    path = tmp_path / "scan.csv"
    path.write_text("X,Y,Z,Red,Green,Blue,Classification\n1,2,3,255,0,0,2\n4,5,6,0,255,0,6\n",
                    encoding="utf-8")
    data = cloud(read_text, path)
    assert data.xyz.tolist() == [[1, 2, 3], [4, 5, 6]]
    assert data.colors is not None and data.colors.tolist() == [[255, 0, 0], [0, 255, 0]]
    assert data.classification is not None and data.classification.tolist() == [2, 6]
