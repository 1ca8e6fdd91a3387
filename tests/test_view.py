"""A camera's axes: right, down and forward, orthonormal, the down axis np.cross's to the bit."""

from __future__ import annotations

import math

import numpy as np

from astralis_des.view import View


def test_the_down_axis_is_forward_cross_right_bit_for_bit() -> None:
    """Every heading's down axis has np.cross's bits (signed zeros too), for a level, a
    pitched and a straight-down camera."""
    headings = np.concatenate([[0.0, math.pi, -math.pi / 2, math.pi / 2],
                               np.random.default_rng(0).uniform(-7.0, 7.0, 60)])
    for pitch in (0.0, 35.0, 90.0):
        view = View(None, 60.0, 4 / 3, pitch)
        right, down, forward = view.axes(headings)
        assert down.tobytes() == np.cross(forward, right).tobytes()
        assert np.allclose(np.einsum("ij,ij->i", down, down), 1.0)
