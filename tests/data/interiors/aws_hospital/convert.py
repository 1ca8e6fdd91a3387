"""How ``hospital_floor1.obj`` was made (run once; kept to show the conversion, not run by the
tests): the COLLADA collision meshes of the AWS RoboMaker hospital world's first floor
(walls, floor, ceiling) read with the standard library's XML parser, placed at the poses the
repository's ``worlds/hospital.world`` gives them, written as one Wavefront OBJ in metres, z up,
one object per COLLADA node.

Units: the files say ``<unit meter="0.01"/>`` and ``<up_axis>Y_UP``, but their vertices times
the nodes' transforms (translate, rotate, scale; applied in document order) come out in
centimetres with z already up, the way Gazebo shows them; so the unit's 0.01 is applied and the
up axis is not turned again (turning it would lay the walls on their side).

    python convert.py /path/to/aws-robomaker-hospital-world > hospital_floor1.obj
"""

from __future__ import annotations

import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

NS = {"c": "http://www.collada.org/2005/11/COLLADASchema"}
MODELS = {  # model -> its pose (x, y, yaw) in worlds/hospital.world
    "aws_robomaker_hospital_floor_01_walls": (-0.013823, -0.013783),
    "aws_robomaker_hospital_floor_01_floor": (-0.001425, -0.014447),
    "aws_robomaker_hospital_floor_01_ceiling": (0.016552, 0.050728),
}


def _rotation(axis: list[float], degrees: float) -> np.ndarray:
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    t = np.radians(degrees)
    out = np.eye(4)
    out[:3, :3] = np.eye(3) + np.sin(t) * k + (1 - np.cos(t)) * k @ k
    return out


def _transform(node: ET.Element) -> np.ndarray:
    m = np.eye(4)
    for el in node:
        tag = el.tag.split("}")[1]
        vals = [float(t) for t in (el.text or "").split()]
        if tag == "matrix":
            m = m @ np.array(vals).reshape(4, 4)
        elif tag == "translate":
            step = np.eye(4)
            step[:3, 3] = vals
            m = m @ step
        elif tag == "rotate":
            m = m @ _rotation(vals[:3], vals[3])
        elif tag == "scale":
            m = m @ np.diag([*vals, 1.0])
    return m


def _geometries(root: ET.Element) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    out = {}
    for geometry in root.iterfind("c:library_geometries/c:geometry", NS):
        mesh = geometry.find("c:mesh", NS)
        assert mesh is not None
        sources = {s.get("id"): np.array(s.find("c:float_array", NS).text.split(), float)
                   for s in mesh.iterfind("c:source", NS)}
        ref = mesh.find("c:vertices/c:input[@semantic='POSITION']", NS).get("source")
        positions = sources[ref[1:]].reshape(-1, 3)
        faces = []
        for prim in mesh:
            tag = prim.tag.split("}")[1]
            p_el = prim.find("c:p", NS)
            if tag not in ("triangles", "polylist") or p_el is None or not p_el.text:
                continue
            inputs = prim.findall("c:input", NS)
            stride = max(int(i.get("offset")) for i in inputs) + 1
            offset = int(next(i for i in inputs if i.get("semantic") == "VERTEX").get("offset"))
            p = np.array(p_el.text.split(), int).reshape(-1, stride)[:, offset]
            if tag == "triangles":
                faces.append(p.reshape(-1, 3))
                continue
            k = 0
            for n in np.array(prim.find("c:vcount", NS).text.split(), int):
                poly = p[k:k + n]
                k += n
                faces += [np.array([[poly[0], poly[t], poly[t + 1]]]) for t in range(1, n - 1)]
        out[geometry.get("id")] = (positions, np.concatenate(faces))
    return out


def read(path: Path) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each node's vertices (metres) and triangles."""
    root = ET.parse(path).getroot()
    unit = float(root.find("c:asset/c:unit", NS).get("meter"))
    geometries = _geometries(root)
    out = {}

    def walk(node: ET.Element, parent: np.ndarray) -> None:
        m = parent @ _transform(node)
        for instance in node.findall("c:instance_geometry", NS):
            v, f = geometries[instance.get("url")[1:]]
            out[node.get("name")] = ((v @ m[:3, :3].T + m[:3, 3]) * unit, f)
        for child in node.findall("c:node", NS):
            walk(child, m)

    for scene in root.iterfind("c:library_visual_scenes/c:visual_scene", NS):
        for node in scene.findall("c:node", NS):
            walk(node, np.eye(4))
    return out


def main(repo: Path) -> None:
    print("# AWS RoboMaker hospital world, first floor: walls, floor and ceiling "
          "(collision meshes); metres, z up; see SOURCE.md")
    base = 1
    for model, (x, y) in MODELS.items():
        path = repo / "models" / model / "meshes" / f"{model}_collision.dae"
        for name, (v, f) in read(path).items():
            print(f"o {name.removeprefix('aws_robomaker_hospital_').removesuffix('_collision')}")
            for px, py, pz in v + [x, y, 0.0]:
                print(f"v {px:.4f} {py:.4f} {pz:.4f}")
            for a, b, c in f + base:
                print(f"f {a} {b} {c}")
            base += len(v)


if __name__ == "__main__":
    main(Path(sys.argv[1]))
