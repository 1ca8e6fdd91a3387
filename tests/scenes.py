"""Small scenes the import tests write themselves: a cloud of a building on flat ground, in
every cloud format, and a mesh of a platform and a house on a ground quad, in every mesh
format. Shapes and numbers are chosen so that a test can say what the world must hold."""

from __future__ import annotations

from pathlib import Path

import numpy as np

GROUND_Z = 100.0  # the scene's ground, in the file's units (recentred away on import)
BUILDING = ((10.0, 10.0), (18.0, 16.0), 5.0)  # footprint corners and height, file frame
SIZE = (40.0, 30.0)  # extent of the ground
STEP = 0.3  # point spacing
FT_WKT = ('PROJCS["NAD83 / Oregon GIC Lambert (ft)",GEOGCS["NAD83",DATUM["NAD83",SPHEROID['
          '"GRS 1980",6378137,298.257222101]],PRIMEM["Greenwich",0],UNIT["degree",'
          '0.0174532925199433]],PROJECTION["Lambert_Conformal_Conic_2SP"],UNIT["foot",0.3048]]')


def cloud_points() -> tuple[np.ndarray, np.ndarray]:
    """``(N, 3)`` points and their ASPRS classes: ground (2) and a building's roof and walls
    (6), the walls from 0.3 above the ground."""
    gx, gy = np.meshgrid(np.arange(0, SIZE[0] + 1e-9, STEP), np.arange(0, SIZE[1] + 1e-9, STEP))
    ground = np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, GROUND_Z)])
    (x0, y0), (x1, y1), h = BUILDING
    rx, ry = np.meshgrid(np.arange(x0, x1 + 1e-9, STEP), np.arange(y0, y1 + 1e-9, STEP))
    roof = np.column_stack([rx.ravel(), ry.ravel(), np.full(rx.size, GROUND_Z + h)])
    zs = np.arange(0.3, h, STEP) + GROUND_Z
    walls = []
    for xs, ys in ((np.arange(x0, x1, STEP), [y0]), (np.arange(x0, x1, STEP), [y1]),
                   ([x0], np.arange(y0, y1, STEP)), ([x1], np.arange(y0, y1, STEP))):
        wx, wy, wz = np.meshgrid(xs, ys, zs)
        walls.append(np.column_stack([wx.ravel(), wy.ravel(), wz.ravel()]))
    building = np.vstack([roof, *walls])
    points = np.vstack([ground, building])
    classes = np.concatenate([np.full(len(ground), 2), np.full(len(building), 6)]).astype(np.uint8)
    return points, classes


def write_las(path: Path, points: np.ndarray, classes: np.ndarray | None = None,
              wkt: str | None = None) -> Path:
    import laspy

    header = laspy.LasHeader(point_format=3, version="1.4")
    header.scales = [0.01, 0.01, 0.01]
    header.offsets = [0.0, 0.0, 0.0]
    if wkt is not None:
        header.vlrs.append(laspy.vlrs.known.WktCoordinateSystemVlr(wkt))
        header.global_encoding.wkt = True
    las = laspy.LasData(header)
    las.x, las.y, las.z = points[:, 0], points[:, 1], points[:, 2]
    if classes is not None:
        las.classification = classes
    las.write(path)
    return path


def write_ply(path: Path, points: np.ndarray, ascii: bool) -> Path:
    import trimesh

    cloud = trimesh.PointCloud(points)
    path.write_bytes(cloud.export(file_type="ply", encoding="ascii" if ascii else "binary"))
    return path


def write_pcd(path: Path, points: np.ndarray, binary: bool) -> Path:
    header = ("# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\n"
              "SIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
              f"WIDTH {len(points)}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {len(points)}\n"
              f"DATA {'binary' if binary else 'ascii'}\n")
    body = points.astype("<f4").tobytes() if binary else "".join(
        f"{x:.3f} {y:.3f} {z:.3f}\n" for x, y, z in points).encode()
    path.write_bytes(header.encode() + body)
    return path


def write_text(path: Path, points: np.ndarray, header: str | None = None,
               delimiter: str = " ") -> Path:
    np.savetxt(path, points, fmt="%.3f", delimiter=delimiter,
               header=header or "", comments="")
    return path


def scene_mesh():  # type: ignore[no-untyped-def]
    """A 30 m x 30 m ground quad, a 10 m x 10 m platform 1 m high (a floor at 1 m) and a
    closed 6 m x 6 m house 4 m high (a roof at 4 m), Z up, in metres."""
    import trimesh

    ground = trimesh.Trimesh([[0, 0, 0], [30, 0, 0], [30, 30, 0], [0, 30, 0]],
                             [[0, 1, 2], [0, 2, 3]], process=False)
    platform = trimesh.creation.box((10, 10, 1))
    platform.apply_translation((10, 10, 0.5))
    house = trimesh.creation.box((6, 6, 4))
    house.apply_translation((23, 23, 2))
    return trimesh.util.concatenate([ground, platform, house])


def y_up(mesh):  # type: ignore[no-untyped-def]
    """The mesh turned Y-up, as glTF files are: (x, y, z) -> (x, z, -y)."""
    turned = mesh.copy()
    v = turned.vertices
    turned.vertices = np.column_stack([v[:, 0], v[:, 2], -v[:, 1]])
    return turned


def write_mesh(path: Path, mesh) -> Path:  # type: ignore[no-untyped-def]
    kind = path.suffix.lstrip(".").lower()
    if kind == "gltf":  # buffers embedded, so that the file stands alone
        import trimesh

        data = trimesh.exchange.gltf.export_gltf(trimesh.Scene(mesh), embed_buffers=True)
        path.write_bytes(data["model.gltf"])
        return path
    exported = mesh.export(file_type=kind)
    path.write_bytes(exported if isinstance(exported, bytes) else exported.encode())
    return path
