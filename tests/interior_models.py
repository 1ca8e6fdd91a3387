"""Public building models (``tests/data/interiors/``) as point clouds, with their floor plans'
truth, for ``tests/test_indoor_public.py`` and ``tools/render_interior_public.py``.

:func:`load_obj` reads a Wavefront OBJ's objects (vertices, triangles); :func:`sample_faces`
samples points on the triangles, uniformly by area (a Poisson count a triangle, at random in
it); :func:`score_plan` compares what :func:`find_interior` found with ``plan.yaml``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

from astralis_des.importers.indoor import Interior

INTERIORS = Path(__file__).resolve().parent / "data" / "interiors"


def load_obj(path: Path) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The vertices ``(N, 3)`` and each object's triangles ``(K, 3)`` (0-based) of an OBJ of
    triangles."""
    vertices: list[list[float]] = []
    faces: dict[str, list[list[int]]] = {}
    name = ""
    for line in path.read_text().splitlines():
        if line.startswith("o "):
            name = line[2:].strip()
            faces.setdefault(name, [])
        elif line.startswith("v "):
            vertices.append([float(t) for t in line.split()[1:4]])
        elif line.startswith("f "):
            faces.setdefault(name, []).append([int(t.split("/")[0]) - 1
                                               for t in line.split()[1:4]])
    return np.array(vertices), {k: np.array(v, dtype=np.int64) for k, v in faces.items()}


def sample_faces(vertices: np.ndarray, faces: np.ndarray, spacing: float,
                 seed: int = 0) -> np.ndarray:
    """``(N, 3)`` points on the triangles, one per ``spacing``² of area on average."""
    rng = np.random.default_rng(seed)
    tri = vertices[faces]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    which = np.repeat(np.arange(len(faces)), rng.poisson(area / spacing**2))
    s, t = np.sqrt(rng.random(len(which))), rng.random(len(which))
    tri = tri[which]
    return ((1 - s)[:, None] * tri[:, 0] + (s * (1 - t))[:, None] * tri[:, 1]
            + (s * t)[:, None] * tri[:, 2])


@dataclass
class PlanScore:
    iou: dict[str, float]  # each plan room: its best IoU with a found room
    matched: dict[str, str]  # plan room -> that found room's id
    door_error: dict[int, tuple[float, float, bool]]  # plan door -> nearest found door's
    # centre distance, width error, same normal axis


def load_plan(name: str) -> dict:
    with open(INTERIORS / name / "plan.yaml") as f:
        return dict(yaml.safe_load(f))


def score_plan(plan: dict, interior: Interior, storey: int = 1) -> PlanScore:
    """Each plan room's best IoU with a found room of ``storey`` (cells of the storey's plan,
    their centres in the room's rectangles), and each plan door's nearest found door."""
    grid = interior.plans[storey - 1]
    labels = interior.labels[storey - 1]
    ii, jj = np.meshgrid(np.arange(grid.shape[0]), np.arange(grid.shape[1]), indexing="ij")
    centres = interior.to_cloud(grid.centres(np.column_stack([ii.ravel(), jj.ravel()])))
    x, y = centres[:, 0].reshape(grid.shape), centres[:, 1].reshape(grid.shape)
    found = {r.id: labels == r.label for r in interior.rooms if r.storey == storey}
    iou, matched = {}, {}
    for room in plan["rooms"]:
        truth = np.zeros(grid.shape, bool)
        for x0, y0, x1, y1 in room["rects"]:
            truth |= (x >= x0) & (x < x1) & (y >= y0) & (y < y1)
        best = max(found, key=lambda k: np.count_nonzero(found[k] & truth)
                   / np.count_nonzero(found[k] | truth))
        iou[room["name"]] = float(np.count_nonzero(found[best] & truth)
                                  / np.count_nonzero(found[best] | truth))
        matched[room["name"]] = best
    door_error = {}
    doors = [d for d in interior.doors if d.storey == storey]
    for k, door in enumerate(plan["doors"]):
        centres_found = interior.to_cloud(np.array([d.centre for d in doors]))
        gaps = np.hypot(*(centres_found - np.asarray(door["centre"])).T)
        nearest = int(np.argmin(gaps))
        door_error[k] = (float(gaps[nearest]), abs(doors[nearest].width - door["width"]),
                         doors[nearest].normal_axis == door["normal_axis"])
    return PlanScore(iou, matched, door_error)
