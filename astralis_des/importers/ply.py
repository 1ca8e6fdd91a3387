"""PLY: clouds and meshes, ASCII and binary (either byte order), sized and unsized types.

The header is parsed here first, so that a file without a vertex element, without z or with
faces that are no lists is refused with what is wrong. A cloud (no faces) is then read with
numpy: binary vertices as records of a structured dtype, ASCII ones with ``np.loadtxt``, so a
truncated file says how many vertices it holds and ``--partial`` reads them. A mesh is read by
trimesh; a binary one whose faces mix triangles and quads, which trimesh refuses, is walked
face by face here.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np
from numpy.typing import NDArray

from astralis_des.errors import InputError
from astralis_des.importers.pointcloud import (
    classes_from,
    colors_from,
    library_error,
    partial_hint,
    read_rows,
    truncated_note,
)
from astralis_des.importers.source import Cloud, Mesh, ReadRequest, reader

PLY_TYPES = {"char": "i1", "uchar": "u1", "short": "i2", "ushort": "u2", "int": "i4",
             "uint": "u4", "float": "f4", "double": "f8", "int8": "i1", "uint8": "u1",
             "int16": "i2", "uint16": "u2", "int32": "i4", "uint32": "u4", "float32": "f4",
             "float64": "f8"}
PLY_FORMATS = {"ascii": "", "binary_little_endian": "<", "binary_big_endian": ">"}
PLY_FACE_LISTS = ("vertex_indices", "vertex_index")
MAX_PLY_HEADER_LINES = 10_000


@dataclass
class PlyProperty:
    name: str
    kind: str  # numpy type without byte order: "f4", "u1", ...
    count: str | None = None  # a list's length type; None for a single value


@dataclass
class PlyElement:
    name: str
    count: int
    line: int
    properties: list[PlyProperty] = field(default_factory=list)

    def has_lists(self) -> bool:
        return any(p.count is not None for p in self.properties)

    def record(self, endian: str) -> np.dtype:
        """One item as packed binary (an element without lists)."""
        return np.dtype([(f"p{i}", endian + p.kind) for i, p in enumerate(self.properties)])


@dataclass
class PlyHeader:
    endian: str = ""  # "<" or ">" for binary, "" for ASCII
    elements: dict[str, PlyElement] = field(default_factory=dict)
    lines: int = 0  # the data starts on the next line (ASCII) ...
    size: int = 0  # ... or after this many bytes (binary)


@reader("ply", memory_per_byte=8.0)
def read_ply(path: Path, request: ReadRequest) -> Cloud | Mesh:
    """A PLY of vertices only (or of no faces) is a cloud; with faces, a mesh."""
    with path.open("rb") as raw:
        header = _ply_header(path, raw)
        vertex = _ply_vertex(path, header)
        face = header.elements.get("face")
        if face is not None and face.count:
            _ply_face_list(path, face)
            return _ply_mesh(path, header)
        if vertex.has_lists() or next(iter(header.elements)) != "vertex":
            # rare (lists in vertices, elements before them): trimesh reads those
            return Cloud(np.asarray(_ply_trimesh(path).vertices, dtype=np.float64))
        return _ply_cloud(path, raw, header, request)


def _ply_header(path: Path, raw: BinaryIO) -> PlyHeader:
    if raw.readline(64).strip() != b"ply":
        raise InputError("not a readable PLY file (it does not start with a line 'ply')",
                         file=path, line=1)
    header = PlyHeader()
    for number in range(2, MAX_PLY_HEADER_LINES):
        line = raw.readline(1 << 16)
        words = line.decode("ascii", "replace").split()
        if not line:
            break
        if words[:1] == ["end_header"]:
            header.lines, header.size = number, raw.tell()
            return header
        if words:
            _ply_header_line(path, number, words, header)
    raise InputError("the header has no end_header line", file=path)


def _ply_header_line(path: Path, number: int, words: list[str], header: PlyHeader) -> None:
    if words[0] == "format":
        if len(words) < 2 or words[1] not in PLY_FORMATS:
            raise InputError(f"format '{' '.join(words[1:2])}' is not one of: "
                             f"{', '.join(PLY_FORMATS)}", file=path, line=number)
        header.endian = PLY_FORMATS[words[1]]
    elif words[0] == "element":
        if len(words) != 3 or not words[2].isdigit():
            raise InputError("an element line is 'element NAME COUNT'", file=path, line=number)
        header.elements[words[1]] = PlyElement(words[1], int(words[2]), number)
    elif words[0] == "property":
        if not header.elements:
            raise InputError("a property before any element", file=path, line=number)
        element = next(reversed(header.elements.values()))
        element.properties.append(_ply_property(path, number, words))
    # comment, obj_info and other writers' own lines say nothing about the data


def _ply_property(path: Path, number: int, words: list[str]) -> PlyProperty:
    if len(words) == 5 and words[1] == "list":
        count, kind, name = words[2:]
    elif len(words) == 3:
        count, kind, name = None, words[1], words[2]
    else:
        raise InputError("a property line is 'property TYPE NAME' or 'property list "
                         "LENGTH_TYPE TYPE NAME'", file=path, line=number)
    for value in (kind, count):
        if value is not None and value not in PLY_TYPES:
            raise InputError(f"property {name}: '{value}' is not a PLY type; valid: "
                             f"{', '.join(PLY_TYPES)}", file=path, line=number)
    if count is not None and PLY_TYPES[count][0] == "f":
        raise InputError(f"property {name}: a list's length type must be an integer type, "
                         f"not {count}", file=path, line=number)
    return PlyProperty(name, PLY_TYPES[kind], None if count is None else PLY_TYPES[count])


def _ply_vertex(path: Path, header: PlyHeader) -> PlyElement:
    vertex = header.elements.get("vertex")
    if vertex is None:
        declared = f"elements: {', '.join(header.elements)}" if header.elements else \
            "the header declares no elements"
        raise InputError(f"no vertex element ({declared})", file=path)
    names = {p.name.lower() for p in vertex.properties if p.count is None}
    missing = [a for a in "xyz" if a not in names]
    if missing:
        found = ", ".join(p.name for p in vertex.properties) or "none"
        raise InputError(f"the vertices have no {' or '.join(missing)} (properties: {found})",
                         file=path, line=vertex.line)
    return vertex


def _ply_face_list(path: Path, face: PlyElement) -> None:
    lists = [p.name for p in face.properties if p.count is not None]
    if not (set(lists) & set(PLY_FACE_LISTS) or len(lists) == 1):
        found = ", ".join(p.name for p in face.properties) or "none"
        raise InputError(f"the faces have no vertex_indices list (properties: {found})",
                         file=path, line=face.line)


def _ply_cloud(path: Path, raw: BinaryIO, header: PlyHeader, request: ReadRequest) -> Cloud:
    vertex = header.elements["vertex"]
    columns = _ply_vertices(path, raw, header, vertex)
    held = len(columns["x"])
    notes = []
    if held < vertex.count:
        if not request.partial:
            raise _ply_cut(path, vertex, held, partial_hint(held))
        notes.append(truncated_note(held, vertex.count, "vertices"))
    xyz = np.column_stack([columns[a].astype(np.float64) for a in "xyz"])
    kinds = {p.name.lower(): p.kind for p in vertex.properties}
    return Cloud(xyz, classes_from(columns), colors_from(columns, kinds), notes=notes)


def _ply_vertices(path: Path, raw: BinaryIO, header: PlyHeader, vertex: PlyElement
                  ) -> dict[str, np.ndarray]:
    """The vertex properties by lower-case name, of as many whole vertices as the file holds
    (``raw`` stands at the vertices and is left after them)."""
    if header.endian:
        record = vertex.record(header.endian)
        body = raw.read(vertex.count * record.itemsize)
        records = np.frombuffer(body, record, count=len(body) // record.itemsize)
        values = [records[f"p{i}"] for i in range(len(vertex.properties))]
    else:
        values = list(read_rows(path, raw, delimiter=None, width=len(vertex.properties),
                                rows=vertex.count, skip=header.lines).table.T)
    columns: dict[str, np.ndarray] = {}
    for prop, column in zip(vertex.properties, values, strict=True):
        columns.setdefault(prop.name.lower(), column)
    return columns


def _ply_mesh(path: Path, header: PlyHeader) -> Mesh:
    import trimesh

    if not header.endian:
        _ply_ascii_rows(path, header)
    try:
        loaded = _ply_trimesh(path)
    except InputError:
        if not header.endian or list(header.elements)[:2] != ["vertex", "face"] or \
                header.elements["vertex"].has_lists():
            raise
        loaded = trimesh.Trimesh(*_ply_binary_mesh(path, header), process=False)
    vertices = np.asarray(loaded.vertices, dtype=np.float64)
    faces = np.asarray(loaded.faces, dtype=np.int64)
    if faces.size and not 0 <= faces.min() <= faces.max() < len(vertices):
        raise InputError(f"faces use vertex {faces.max() if faces.min() >= 0 else faces.min()}"
                         f", of {len(vertices):,} vertices numbered from 0", file=path)
    return Mesh(vertices, faces, watertight=bool(loaded.is_watertight))


def _ply_trimesh(path: Path) -> Any:
    """trimesh's reading of the file: a Trimesh, or a PointCloud."""
    import trimesh

    try:
        loaded = trimesh.load(path, file_type="ply", process=False)
    except Exception as exc:  # trimesh raises many kinds for a file it cannot read
        raise library_error(path, "PLY", exc) from None
    if not isinstance(loaded, trimesh.Trimesh | trimesh.PointCloud):
        raise InputError(f"not a readable PLY file (trimesh made a {type(loaded).__name__})",
                         file=path)
    return loaded


def _ply_ascii_rows(path: Path, header: PlyHeader) -> None:
    """Refuse an ASCII PLY with fewer rows than its header announces: trimesh would read
    what there is without a word."""
    with path.open("rb") as raw:
        raw.seek(header.size)
        held = sum(1 for line in raw if line.strip())
    announced = sum(e.count for e in header.elements.values())
    if held < announced:
        items = " and ".join(_items(e.count, e.name) for e in header.elements.values() if e.count)
        raise InputError(f"truncated: the file ends before its data does (the header "
                         f"announces {items}: {announced:,} rows; the file holds {held:,})",
                         file=path)


def _ply_binary_mesh(path: Path, header: PlyHeader) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles of a binary PLY of vertices, then faces."""
    vertex, face = header.elements["vertex"], header.elements["face"]
    with path.open("rb") as raw:
        raw.seek(header.size)
        columns = _ply_vertices(path, raw, header, vertex)
        if len(columns["x"]) < vertex.count:
            raise _ply_cut(path, vertex, len(columns["x"]))
        data = raw.read()
    flat, sizes = _ply_binary_faces(path, data, face, header.endian)
    return np.column_stack([columns[a] for a in "xyz"]), _fan(flat, sizes)


def _ply_binary_faces(path: Path, data: bytes, face: PlyElement, endian: str
                      ) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """The faces' corners one after another and how many each has, walked face by face:
    trimesh reads only faces of as many corners as the first (not Blender's quads and
    triangles)."""
    names = [p.name for p in face.properties if p.count is not None]
    corners = next((n for n in PLY_FACE_LISTS if n in names), names[0])
    flat: list[np.ndarray] = []
    offset = 0
    for done in range(face.count):
        for prop in face.properties:
            single, n = np.dtype(endian + prop.kind), 1
            if prop.count is not None:
                length = np.dtype(endian + prop.count)
                if offset + length.itemsize > len(data):
                    raise _ply_cut(path, face, done)
                n = int(np.frombuffer(data, length, count=1, offset=offset)[0])
                offset += length.itemsize
            if offset + n * single.itemsize > len(data):
                raise _ply_cut(path, face, done)
            if prop.name == corners:
                flat.append(np.frombuffer(data, single, count=n, offset=offset))
            offset += n * single.itemsize
    sizes = np.array([len(f) for f in flat], dtype=np.int64)
    return np.concatenate(flat).astype(np.int64), sizes


def _ply_cut(path: Path, element: PlyElement, whole: int, hint: str = "") -> InputError:
    return InputError(f"truncated: the file ends before its data does (the header announces "
                      f"{_items(element.count, element.name)}, the file holds {whole:,})"
                      + hint, file=path)


def _items(count: int, name: str) -> str:
    return f"{count:,} " + {"vertex": "vertices", "face": "faces"}.get(name, f"{name} items")


def _fan(flat: NDArray[np.int64], sizes: NDArray[np.int64]) -> NDArray[np.int64]:
    """Polygons (their corners one after another, and how many each has) as fans of
    triangles; fewer than three corners make none."""
    fans = np.clip(sizes - 2, 0, None)
    starts = np.repeat(np.cumsum(sizes) - sizes, fans)
    step = np.arange(int(fans.sum())) - np.repeat(np.cumsum(fans) - fans, fans) + 1
    return np.column_stack([flat[starts], flat[starts + step], flat[starts + step + 1]])
