"""A map from boxes makes its distance field a layer at a time, as queries reach it."""

from __future__ import annotations

import numpy as np

from astralis_des.planning.occupancy import from_boxes

RES = 0.2


def boxes_map():  # type: ignore[no-untyped-def]
    rng = np.random.default_rng(7)
    lo = rng.uniform(0, 4, (15, 3))
    boxes = np.stack([lo, lo + rng.uniform(0.1, 1.5, (15, 3))], axis=1)
    return from_boxes(boxes, (0, 0, -0.4), (6, 6, 6), RES)


def test_a_query_makes_only_the_layers_it_reads() -> None:
    """Points at two heights make those two layers of the map's 32."""
    m = boxes_map()
    m.clearance(np.array([[1.0, 1.0, 0.5], [3.0, 2.0, 0.55], [2.0, 5.0, 3.1]]))
    assert sorted(m.layers.made) == [4, 17]
    assert m.layers.shape[2] == 32


def test_layer_by_layer_answers_are_the_whole_fields() -> None:
    """Clearance from layers made one by one equals the whole float32 distance field, bit for
    bit, inside the map; 0 outside it."""
    lazy, whole = boxes_map(), boxes_map()
    points = np.random.default_rng(3).uniform(-0.5, 6.5, (3000, 3))
    got = lazy.clearance(points)
    cells = whole.cell_of(points)
    inside = ((cells >= 0) & (cells < whole.distance.shape)).all(axis=1)
    expected = np.zeros(len(points))
    expected[inside] = whole.distance[tuple(cells[inside].T)]
    assert np.array_equal(got, expected)
