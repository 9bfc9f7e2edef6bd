"""Per-corner texture coordinates: validation, and the seam split glTF needs."""

from __future__ import annotations

import numpy as np
import pytest

from gnngarment.geometry.texture_coordinates import split_uv_seams
from gnngarment.io.obj import check_texture_coordinates
from tests.inference.animations import rest_garment, tube_uv

# Two triangles sharing the edge 1–2, cut along it in UV space: each side has its own
# copy of vertices 1 and 2 (uv 1, 2 on the left, uv 4, 5 on the right).
FACES = np.array([[0, 1, 2], [2, 1, 3]])
UV = np.array([[0.0, 0.0], [0.4, 0.0], [0.4, 1.0], [0.0, 0.0], [0.6, 0.0], [0.6, 1.0],
               [1.0, 0.5]])
UV_FACES = np.array([[0, 1, 2], [5, 4, 6]])


def test_a_cut_edge_duplicates_its_two_vertices_and_nothing_else() -> None:
    split = split_uv_seams(FACES, UV, UV_FACES, 4)
    assert split.source.tolist() == [0, 1, 2, 3, 2, 1]
    assert split.seam_vertices == 2
    # Vertices 0..3 keep their index; the right triangle uses the two duplicates.
    assert split.faces.tolist() == [[0, 1, 2], [4, 5, 3]]
    np.testing.assert_array_equal(split.uv[split.faces], UV[UV_FACES])
    np.testing.assert_array_equal(split.source[split.faces], FACES)


def test_equal_uv_values_under_different_indices_are_not_a_seam() -> None:
    uv = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]])
    # The second triangle names vt 5 and 6, copies of vt 2 and 3.
    split = split_uv_seams(FACES, uv, np.array([[0, 1, 2], [5, 4, 3]]), 4)
    assert split.seam_vertices == 0
    np.testing.assert_array_equal(split.faces, FACES)


def test_tube_unwrap_splits_the_seam_column_and_keeps_unused_vertices() -> None:
    pos, faces = rest_garment()
    uv, uv_faces = tube_uv()
    count = len(pos) + 1  # one vertex no triangle uses
    split = split_uv_seams(faces, uv, uv_faces, count)
    assert split.seam_vertices == 8  # one per ring: the column at u = 0 / u = 1
    assert sorted(split.source[count:].tolist()) == [20 * r for r in range(8)]
    np.testing.assert_array_equal(split.source[:count], np.arange(count))
    np.testing.assert_allclose(split.uv[split.faces], uv[uv_faces])
    np.testing.assert_array_equal(split.source[split.faces], faces)
    np.testing.assert_array_equal(split.uv[count - 1], [0.0, 0.0])


@pytest.mark.parametrize(("uv", "uv_faces", "message"), [
    (np.zeros((3, 3)), np.zeros((2, 3), np.int64), r"uv must be \(K, 2\)"),
    (np.full((3, 2), np.nan), np.zeros((2, 3), np.int64), "finite floats"),
    (np.zeros((3, 2)), np.zeros((1, 3), np.int64), r"uv_faces must be \(2, 3\)"),
    (np.zeros((3, 2)), np.zeros((2, 3)), "integers"),
    (np.zeros((3, 2)), np.array([[0, 1, 2], [0, 1, 3]]), "outside"),
    (np.zeros((3, 2)), np.array([[0, 1, 2], [0, -1, 2]]), "outside"),
])
def test_inconsistent_texture_coordinates_are_rejected(uv, uv_faces, message) -> None:
    with pytest.raises(ValueError, match=message):
        check_texture_coordinates(uv, uv_faces, 2)
    with pytest.raises(ValueError, match=message):
        split_uv_seams(FACES, uv, uv_faces, 4)


def test_faces_outside_the_vertices_are_rejected() -> None:
    with pytest.raises(ValueError, match="faces index"):
        split_uv_seams(FACES, UV, UV_FACES, 3)
