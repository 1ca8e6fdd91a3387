"""``inside_polygon`` tests only the points within a polygon's bounds; beyond them the even-odd
rule says outside anyway. The answer is the rule's on every point, also on the outline and at
its corners, for grids of a building's cells and scattered points alike."""

from __future__ import annotations

import numpy as np
import pytest

from astralis_des.world.geometry import BOUNDED, inside_polygon


def even_odd(points: np.ndarray, polygon: np.ndarray) -> np.ndarray:
    """The rule point by point, edge by edge: the reference."""
    a, b = polygon, np.roll(polygon, -1, axis=0)
    x, y = points[:, 0:1], points[:, 1:2]
    spans = (a[:, 1] > y) != (b[:, 1] > y)
    dy = np.where(b[:, 1] == a[:, 1], 1.0, b[:, 1] - a[:, 1])
    cross_x = a[:, 0] + (y - a[:, 1]) * (b[:, 0] - a[:, 0]) / dy
    return (np.sum(spans & (x < cross_x), axis=1) % 2) == 1


def polygons(rng: np.random.Generator) -> list[np.ndarray]:
    square = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 3.0], [0.0, 3.0]])
    ell = np.array([[1.0, 1.0], [6.0, 1.0], [6.0, 2.5], [2.5, 2.5], [2.5, 5.0], [1.0, 5.0]])
    star = np.array([(np.cos(t) * r + 3, np.sin(t) * r + 2) for t, r in
                     zip(np.linspace(0, 2 * np.pi, 14, endpoint=False), [2.5, 1.0] * 7,
                         strict=True)])
    far = square * 0.37 + np.array([512_345.678, 5_123_456.789])  # UTM-sized coordinates
    scattered = [rng.uniform(-1, 7, size=(int(rng.integers(3, 12)), 2)) for _ in range(40)]
    return [square, ell, star, far, *scattered]


@pytest.mark.parametrize("seed", range(3))
def test_the_rule_on_every_point(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for polygon in polygons(rng):
        lo, hi = polygon.min(axis=0) - 1.0, polygon.max(axis=0) + 1.0
        step = (hi - lo) / 97
        i, j = np.indices((97, 97))
        grid = np.column_stack([i.ravel(), j.ravel()]) * step + lo  # on the corners' rows too
        points = np.concatenate([grid, polygon, (polygon + np.roll(polygon, -1, axis=0)) / 2,
                                 rng.uniform(lo, hi, size=(500, 2))])
        scattered = rng.uniform(lo, hi, size=(BOUNDED + 50, 2))  # a row each
        for these in (points, scattered):
            assert len(these) > BOUNDED
            expected = even_odd(these, polygon)
            assert expected.any() and not expected.all()
            np.testing.assert_array_equal(inside_polygon(these, polygon), expected)


def test_few_points_and_none_inside() -> None:
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    assert inside_polygon(np.array([[0.5, 0.5]]), square).tolist() == [True]
    away = np.full((BOUNDED + 10, 2), 5.0)
    assert not inside_polygon(away, square).any()
