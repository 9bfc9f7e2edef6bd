"""The quality measures and gates: edge stretch, gate failures (no Newton run)."""

from __future__ import annotations

import numpy as np
import pytest

from data_prep.simulate.quality import gate_failure, max_edge_stretch, unique_edges
from tests.meshes import grid


def test_edge_stretch_and_gates() -> None:
    pos, faces = grid(3, 3, spacing=0.1)
    edges = unique_edges(faces)
    assert len(edges) == 16
    rest = np.linalg.norm(pos[edges[:, 0]] - pos[edges[:, 1]], axis=1)
    assert max_edge_stretch(pos, edges, rest) == pytest.approx(1.0)
    assert max_edge_stretch(pos * [1.3, 1, 1], edges, rest) == pytest.approx(1.3)
    assert gate_failure(4, True, 1.2, 0.01, 1.5, 0.02) == ""
    assert "non-finite" in gate_failure(4, False, np.nan, np.nan, 1.5, 0.02)
    assert "frame 4: max edge stretch 1.600" in gate_failure(4, True, 1.6, 0.0, 1.5, 0.02)
    assert "3.00% of vertices inside" in gate_failure(4, True, 1.0, 0.03, 1.5, 0.02)
