"""Graph geodesics and farthest-point sampling on tiny meshes with analytic answers."""

from __future__ import annotations

import numpy as np
import pytest

from gnngarment.geometry.geodesics import farthest_point_sampling, geodesic_distances


def edge_index_of(faces: np.ndarray, num_vertices: int) -> np.ndarray:
    """Unique undirected triangle edges, both directions: the library's convention."""
    pairs = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    pairs = np.unique(np.sort(pairs, axis=1), axis=0)
    return np.concatenate([pairs.T, pairs[:, ::-1].T], axis=1).astype(np.int64)


def grid(nx: int, ny: int, spacing: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Flat z=0 grid, vertex (i, j) at index j*nx + i, diagonals (i, j)-(i+1, j+1)."""
    x, y = np.meshgrid(np.arange(nx) * spacing, np.arange(ny) * spacing)
    pos = np.stack([x.ravel(), y.ravel(), np.zeros(nx * ny)], axis=1)
    j, i = np.meshgrid(np.arange(ny - 1), np.arange(nx - 1), indexing="ij")
    a = (j * nx + i).ravel()
    faces = np.concatenate(
        [np.stack([a, a + 1, a + nx + 1], 1), np.stack([a, a + nx + 1, a + nx], 1)]
    )
    return pos, faces


def polyline(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points on the x axis joined in order; edge index with both directions."""
    pos = np.stack([x, np.zeros_like(x), np.zeros_like(x)], axis=1)
    i = np.arange(len(x) - 1)
    return pos, np.stack([np.concatenate([i, i + 1]), np.concatenate([i + 1, i])])


def two_grids() -> tuple[np.ndarray, np.ndarray, int]:
    """Two 4x3 grids 10 apart in x; returns pos, edge_index, vertices per grid."""
    pos, faces = grid(4, 3)
    n = len(pos)
    pos2 = np.concatenate([pos, pos + np.array([10.0, 0.0, 0.0])])
    faces2 = np.concatenate([faces, faces + n])
    return pos2, edge_index_of(faces2, 2 * n), n


# ----------------------------------------------------------------- geodesic distances


def test_straight_grid_paths_match_euclidean() -> None:
    spacing = 0.3
    pos, faces = grid(5, 4, spacing)
    dist = geodesic_distances(pos, edge_index_of(faces, len(pos)), np.array([0]))[0]
    for i in range(5):  # along the first row: i edges of length `spacing`
        assert dist[i] == pytest.approx(i * spacing)
    for k in range(4):  # along the triangulation's diagonal: k diagonals
        assert dist[k * 5 + k] == pytest.approx(k * spacing * np.sqrt(2))


def test_polyline_distance_is_arc_length() -> None:
    x = np.array([0.0, 0.1, 0.35, 0.4, 1.2])
    pos, edge_index = polyline(x)
    dist = geodesic_distances(pos, edge_index, np.array([0, 4]))
    np.testing.assert_allclose(dist[0], x - x[0])
    np.testing.assert_allclose(dist[1], x[-1] - x)


def test_distances_symmetric_and_zero_at_source() -> None:
    rng = np.random.default_rng(3)
    pos, faces = grid(6, 5, 0.1)
    pos = pos + rng.normal(scale=0.02, size=pos.shape)  # irregular, non-planar
    sources = np.arange(len(pos))
    dist = geodesic_distances(pos, edge_index_of(faces, len(pos)), sources)
    assert dist.shape == (len(pos), len(pos))
    np.testing.assert_allclose(dist, dist.T, rtol=1e-12)
    np.testing.assert_array_equal(np.diag(dist), 0.0)
    assert (dist[~np.eye(len(pos), dtype=bool)] > 0).all()


def test_other_component_is_infinite() -> None:
    pos, edge_index, n = two_grids()
    dist = geodesic_distances(pos, edge_index, np.array([0, n]))
    assert np.isfinite(dist[0, :n]).all() and np.isinf(dist[0, n:]).all()
    assert np.isinf(dist[1, :n]).all() and np.isfinite(dist[1, n:]).all()


def test_duplicate_and_one_directional_edges_do_not_change_lengths() -> None:
    pos, edge_index = polyline(np.array([0.0, 1.0, 3.0]))
    reference = geodesic_distances(pos, edge_index, np.array([0]))
    # Repeated pairs must not be summed into longer edges.
    doubled = np.concatenate([edge_index, edge_index], axis=1)
    np.testing.assert_array_equal(geodesic_distances(pos, doubled, np.array([0])), reference)
    one_way = edge_index[:, :2]
    np.testing.assert_array_equal(geodesic_distances(pos, one_way, np.array([0])), reference)


def test_coincident_connected_vertices_are_at_distance_zero() -> None:
    pos, edge_index = polyline(np.array([0.0, 0.0, 1.0]))  # zero-length first edge
    dist = geodesic_distances(pos, edge_index, np.array([0]))[0]
    np.testing.assert_array_equal(dist, [0.0, 0.0, 1.0])


def test_empty_sources() -> None:
    pos, edge_index = polyline(np.array([0.0, 1.0]))
    assert geodesic_distances(pos, edge_index, np.array([], dtype=np.int64)).shape == (0, 2)


# ------------------------------------------------------------ farthest-point sampling


def test_fps_on_polyline_is_analytic() -> None:
    pos, edge_index = polyline(np.arange(5.0))
    landmarks, dist = farthest_point_sampling(pos, edge_index, 5)
    # start: 0 and 4 tie as farthest from the centroid -> lowest index; then the other
    # end, the middle, and the two quarter points (tie -> lowest index first).
    np.testing.assert_array_equal(landmarks, [0, 4, 2, 1, 3])
    np.testing.assert_allclose(dist, geodesic_distances(pos, edge_index, landmarks))


def test_fps_deterministic_distinct_and_reuses_rows() -> None:
    pos, faces = grid(7, 6, 0.05)
    edge_index = edge_index_of(faces, len(pos))
    first = farthest_point_sampling(pos, edge_index, 12)
    second = farthest_point_sampling(pos, edge_index, 12)
    np.testing.assert_array_equal(first[0], second[0])
    np.testing.assert_array_equal(first[1], second[1])
    assert len(np.unique(first[0])) == 12
    assert first[0].dtype == np.int64 and first[1].shape == (12, len(pos))
    np.testing.assert_allclose(first[1], geodesic_distances(pos, edge_index, first[0]))


def test_fps_each_pick_is_farthest_from_previous() -> None:
    pos, faces = grid(6, 6, 0.1)
    landmarks, dist = farthest_point_sampling(pos, edge_index_of(faces, len(pos)), 6, start=7)
    assert landmarks[0] == 7
    for k in range(1, 6):
        nearest = dist[:k].min(axis=0)
        assert nearest[landmarks[k]] == pytest.approx(nearest.max())


def test_fps_default_start_is_farthest_from_centroid() -> None:
    pos, edge_index = polyline(np.array([0.0, 1.0, 2.0, 10.0]))
    landmarks, _ = farthest_point_sampling(pos, edge_index, 1)
    assert landmarks[0] == 3


def test_fps_covers_every_component() -> None:
    pos, edge_index, n = two_grids()
    landmarks, dist = farthest_point_sampling(pos, edge_index, 2)
    assert (landmarks < n).sum() == 1 and (landmarks >= n).sum() == 1
    # The unreachable component is entered at its lowest index.
    assert landmarks[1] == (n if landmarks[0] < n else 0)
    assert np.isfinite(dist.min(axis=0)).all()
    landmarks, _ = farthest_point_sampling(pos, edge_index, 7, start=2 * n - 1)
    assert landmarks[1] == 0  # infinite distance is picked before any finite one


def test_fps_distinct_with_coincident_vertices() -> None:
    pos, edge_index = polyline(np.array([0.0, 0.0, 0.0]))
    landmarks, _ = farthest_point_sampling(pos, edge_index, 3)
    assert sorted(landmarks.tolist()) == [0, 1, 2]


# ------------------------------------------------------------------------ validators


@pytest.mark.parametrize(
    ("pos", "match"),
    [
        (np.zeros((3, 2)), r"pos must have shape \(N, 3\)"),
        (np.zeros(3), r"pos must have shape \(N, 3\)"),
        (np.array([[0.0, 0.0, np.nan], [1.0, 0.0, 0.0]]), "NaN"),
        (np.array([[0.0, 0.0, np.inf], [1.0, 0.0, 0.0]]), "NaN or infinite"),
        (np.zeros((2, 3), dtype=complex), "real-valued"),
    ],
)
def test_geodesic_rejects_bad_pos(pos: np.ndarray, match: str) -> None:
    edge_index = np.array([[0], [1]])
    with pytest.raises(ValueError, match=match):
        geodesic_distances(pos, edge_index, np.array([0]))
    with pytest.raises(ValueError, match=match):
        farthest_point_sampling(pos, edge_index, 1)


@pytest.mark.parametrize(
    ("edge_index", "match"),
    [
        (np.array([0, 1]), r"edge_index must have shape \(2, E\)"),
        (np.zeros((3, 1), dtype=np.int64), r"edge_index must have shape \(2, E\)"),
        (np.array([[0.0], [1.0]]), "edge_index must be an integer array"),
        (np.array([[0], [2]]), r"outside \[0, 1\]"),
        (np.array([[-1], [1]]), r"outside \[0, 1\]"),
    ],
)
def test_geodesic_rejects_bad_edge_index(edge_index: np.ndarray, match: str) -> None:
    pos = np.zeros((2, 3))
    with pytest.raises(ValueError, match=match):
        geodesic_distances(pos, edge_index, np.array([0]))
    with pytest.raises(ValueError, match=match):
        farthest_point_sampling(pos, edge_index, 1)


@pytest.mark.parametrize(
    ("sources", "match"),
    [
        (np.array([[0]]), r"sources must be an integer array of shape \(K,\)"),
        (np.array([0.0]), r"sources must be an integer array of shape \(K,\)"),
        (np.array([2]), r"sources holds vertex indices .* outside \[0, 1\]"),
        (np.array([-1]), r"sources holds vertex indices .* outside \[0, 1\]"),
    ],
)
def test_geodesic_rejects_bad_sources(sources: np.ndarray, match: str) -> None:
    pos, edge_index = polyline(np.array([0.0, 1.0]))
    with pytest.raises(ValueError, match=match):
        geodesic_distances(pos, edge_index, sources)


@pytest.mark.parametrize(
    ("count", "start", "match"),
    [
        (4, None, "cannot sample count=4 distinct landmarks .* N=3"),
        (0, None, "count must be >= 1"),
        (2.0, None, "count must be an int"),
        (True, None, "count must be an int"),
        (1, 3, "start=3 out of range"),
        (1, -1, "start=-1 out of range"),
        (1, 1.0, "start must be an int or None"),
    ],
)
def test_fps_rejects_bad_count_or_start(count: object, start: object, match: str) -> None:
    pos, edge_index = polyline(np.array([0.0, 1.0, 2.0]))
    with pytest.raises(ValueError, match=match):
        farthest_point_sampling(pos, edge_index, count, start=start)  # type: ignore[arg-type]
