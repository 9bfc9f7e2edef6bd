"""Algorithm 2 as a sparse matrix, against a literal transcription."""

from __future__ import annotations

import numpy as np
import pytest

from gnngarment.geometry.graph import edge_index_from_faces
from gnngarment.geometry.pooling import pool
from gnngarment.geometry.unpooling import unpooling_matrix
from tests.meshes import grid, random_disk, tube, union


def brute_force_unpool(edge_index: np.ndarray, num_vertices: int, kept: np.ndarray,
                       coarse_features: np.ndarray) -> np.ndarray:
    """Algorithm 2 as printed, with an explicit adjacency matrix and loops."""
    adjacency = np.zeros((num_vertices, num_vertices))
    adjacency[edge_index[0], edge_index[1]] = 1
    is_kept = np.zeros(num_vertices, dtype=bool)
    is_kept[kept] = True
    coarse_of = {int(v): k for k, v in enumerate(kept)}
    fine = np.zeros((num_vertices, coarse_features.shape[1]))
    for v in kept:
        fine[v] = coarse_features[coarse_of[int(v)]]
    for i in np.flatnonzero(~is_kept):
        kept_neighbours = [j for j in np.flatnonzero(adjacency[i]) if is_kept[j]]
        raw = {}
        for j in kept_neighbours:
            dropped_of_j = [r for r in np.flatnonzero(adjacency[:, j]) if not is_kept[r]]
            raw[j] = adjacency[i, j] / sum(adjacency[r, j] for r in dropped_of_j)
        total = sum(raw.values())
        fine[i] = sum(raw[j] / total * coarse_features[coarse_of[j]] for j in kept_neighbours)
    return fine


@pytest.mark.parametrize("seed", range(6))
def test_unpooling_matches_algorithm_2(seed: int) -> None:
    pos, faces = union(random_disk(40 + 10 * seed, seed), tube(4, 7))
    edge_index = edge_index_from_faces(faces, len(pos))
    pooled = pool(edge_index, len(pos))
    features = np.random.default_rng(seed).normal(size=(len(pooled.kept), 3))

    matrix = unpooling_matrix(edge_index, len(pos), pooled.kept)

    expected = brute_force_unpool(edge_index, len(pos), pooled.kept, features)
    np.testing.assert_allclose(matrix @ features, expected, atol=1e-12)


def test_rows_sum_to_one_kept_rows_one_hot_and_constants_reproduced() -> None:
    pos, faces = random_disk(500, seed=1)
    edge_index = edge_index_from_faces(faces, len(pos))
    pooled = pool(edge_index, len(pos))
    matrix = unpooling_matrix(edge_index, len(pos), pooled.kept)

    assert matrix.shape == (len(pos), len(pooled.kept))
    np.testing.assert_allclose(np.asarray(matrix.sum(axis=1)).ravel(), 1.0, atol=1e-12)
    kept_rows = matrix[pooled.kept].toarray()
    np.testing.assert_array_equal(kept_rows, np.eye(len(pooled.kept)))
    assert (matrix.data > 0).all()
    constant = np.full((len(pooled.kept), 2), 3.25)
    np.testing.assert_allclose(matrix @ constant, 3.25, atol=1e-12)


def test_dropped_vertex_weights_only_its_kept_neighbours() -> None:
    pos, faces = grid(5, 5)
    edge_index = edge_index_from_faces(faces, len(pos))
    pooled = pool(edge_index, len(pos))
    matrix = unpooling_matrix(edge_index, len(pos), pooled.kept).tocoo()
    neighbours = set(map(tuple, edge_index.T.tolist()))
    dropped = set(range(len(pos))) - set(pooled.kept.tolist())
    for row, col in zip(matrix.row, matrix.col, strict=True):
        if row in dropped:
            assert (int(row), int(pooled.kept[col])) in neighbours


def test_rejects_a_vertex_set_that_is_not_a_pooling() -> None:
    pos, faces = grid(4, 4)
    edge_index = edge_index_from_faces(faces, len(pos))
    with pytest.raises(ValueError, match="no kept neighbour"):
        unpooling_matrix(edge_index, len(pos), np.array([0]))
