"""The scene's per-edge bending stiffness (no Newton run)."""

from __future__ import annotations

import numpy as np

from data_prep.simulate.scene import bending_stiffness_per_edge


def test_bending_stiffness_of_a_rhombus_edge() -> None:
    # Two equilateral triangles of side L sharing edge (0, 1): k = 3·B·L / A_e, A_e = √3/2·L².
    side, bend = 0.02, 4e-5
    pos = np.array([[0, 0, 0], [side, 0, 0], [side / 2, side * np.sqrt(3) / 2, 0],
                    [side / 2, -side * np.sqrt(3) / 2, 0]])
    edges = np.array([[2, 3, 0, 1], [-1, 3, 0, 2]])  # interior edge, then a boundary edge
    stiffness = bending_stiffness_per_edge(pos, edges, bend)
    np.testing.assert_allclose(stiffness, [3 * bend * side / (np.sqrt(3) / 2 * side**2), 0.0])
