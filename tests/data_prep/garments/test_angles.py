"""`vector_angles` and `corner_angles`: tiny cases with known angles."""

from __future__ import annotations

import numpy as np

from data_prep.garments.angles import corner_angles, vector_angles


def test_vector_angles_of_known_pairs() -> None:
    u = np.array([[1.0, 0, 0], [2.0, 0, 0], [1.0, 0, 0], [1.0, 1, 0], [0.0, 0, 0]])
    v = np.array([[0.0, 3, 0], [5.0, 0, 0], [-1.0, 0, 0], [1.0, 0, 0], [1.0, 0, 0]])
    expected = [np.pi / 2, 0.0, np.pi, np.pi / 4, np.pi / 2]  # a zero vector: π/2, no NaN
    np.testing.assert_allclose(vector_angles(u, v), expected, atol=1e-7)


def test_corner_angles_of_a_right_triangle_sum_to_pi() -> None:
    pos = np.array([[0.0, 0, 0], [1.0, 0, 0], [0.0, 1, 0], [0.5, np.sqrt(3) / 2, 0]])
    faces = np.array([[0, 1, 2], [0, 1, 3]])
    angles = corner_angles(pos, faces)
    assert angles.shape == (2, 3)
    np.testing.assert_allclose(angles[0], [np.pi / 2, np.pi / 4, np.pi / 4])
    np.testing.assert_allclose(angles[1], [np.pi / 3] * 3)
