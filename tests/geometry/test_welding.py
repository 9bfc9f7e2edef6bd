"""Welding coincident vertices (STL exports, UV-split OBJs)."""

from __future__ import annotations

import numpy as np

from gnngarment.geometry.welding import weld_vertices
from tests.meshes import grid


def test_soup_welds_back_to_the_mesh_in_first_seen_order() -> None:
    pos, faces = grid(4, 5, spacing=0.01)
    soup_pos = pos[faces.reshape(-1)] + np.random.default_rng(0).normal(scale=1e-8,
                                                                          size=(faces.size, 3))
    welded = weld_vertices(soup_pos, np.arange(faces.size).reshape(-1, 3))
    assert len(welded.pos) == len(np.unique(faces)) and welded.merged == faces.size - len(pos)
    np.testing.assert_allclose(welded.pos[welded.index], soup_pos, atol=1e-7)
    # Same triangles on the same points (the numbering is first-seen order).
    assert {tuple(sorted(map(tuple, welded.pos[f].round(6)))) for f in welded.faces} == \
        {tuple(sorted(map(tuple, pos[f].round(6)))) for f in faces}


def test_a_welded_mesh_is_unchanged_and_near_vertices_stay_apart() -> None:
    pos, faces = grid(3, 3, spacing=1e-5)       # 10 µm apart: distinct vertices
    welded = weld_vertices(pos, faces)
    assert welded.merged == 0
    np.testing.assert_array_equal(welded.faces, faces)
    np.testing.assert_array_equal(welded.index, np.arange(len(pos)))


def test_collapsed_triangles_are_dropped() -> None:
    pos = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0]])
    faces = np.array([[0, 1, 2], [0, 1, 3]])
    welded = weld_vertices(pos, faces)
    np.testing.assert_array_equal(welded.faces, [[0, 1, 2]])
    np.testing.assert_array_equal(welded.index, [0, 1, 2, 1])
