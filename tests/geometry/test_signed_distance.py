from __future__ import annotations

import numpy as np
import pytest
import trimesh

from gnngarment.geometry.signed_distance import (
    inside_by_parity,
    refit_mesh,
    signed_distance,
    surface_offsets,
    warp_mesh,
)
from tests.meshes import box_signed_distance, closed_box

HALF = np.array([0.2, 0.15, 0.3])  # box half extents [m]


def box() -> tuple[np.ndarray, np.ndarray]:
    vertices, faces = closed_box(HALF)
    assert trimesh.Trimesh(vertices, faces).is_watertight
    return vertices, faces


def box_distance(points: np.ndarray) -> np.ndarray:
    return box_signed_distance(points, HALF)


def test_offsets_match_the_exact_box_distance_inside_and_out() -> None:
    vertices, faces = box()
    points = np.random.default_rng(0).uniform(-0.45, 0.45, (500, 3))
    mesh = warp_mesh(vertices, faces)
    distance, closest, direction = surface_offsets(mesh, points)
    expected = box_distance(points)
    np.testing.assert_allclose(distance, expected, atol=1e-5)
    np.testing.assert_allclose(np.linalg.norm(direction, axis=1), 1.0, atol=1e-5)
    # Moving along the direction increases the signed distance by the step.
    np.testing.assert_allclose(box_distance(points + 0.001 * direction), expected + 0.001,
                               atol=2e-5)
    np.testing.assert_allclose(box_distance(closest), 0.0, atol=1e-6)
    np.testing.assert_array_equal(inside_by_parity(mesh, points), expected < 0)
    np.testing.assert_allclose(signed_distance(points, vertices, faces), expected, atol=1e-5)


def test_band_limits_the_search_and_known_inside_points_are_found_at_any_depth() -> None:
    vertices, faces = box()
    mesh = warp_mesh(vertices, faces)
    points = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.29], [0.0, 0.0, 0.5]])
    distance, closest, direction = surface_offsets(mesh, points, max_dist=0.02)
    assert np.isinf(distance[[0, 2]]).all() and distance[1] == pytest.approx(-0.01, abs=1e-6)
    np.testing.assert_array_equal(direction[[0, 2]], 0.0)
    np.testing.assert_array_equal(closest[[0, 2]], points[[0, 2]])
    depth, _, outward = surface_offsets(mesh, points[:1], max_dist=1.0,
                                        inside=np.array([True]))
    assert depth[0] == pytest.approx(-0.15, abs=1e-6)  # nearest faces: y = ±0.15
    assert abs(outward[0, 1]) == pytest.approx(1.0, abs=1e-6)


def test_refit_moves_the_mesh_and_checks_the_vertex_count() -> None:
    vertices, faces = box()
    mesh = warp_mesh(vertices, faces)
    shift = np.array([1.0, 0.0, 0.0])
    refit_mesh(mesh, vertices + shift)
    point = np.array([[1.0, 0.0, 0.0]])
    assert surface_offsets(mesh, point)[0][0] == pytest.approx(-0.15, abs=1e-6)
    assert not inside_by_parity(mesh, np.zeros((1, 3)))[0]
    with pytest.raises(ValueError, match=r"\(\d+, 3\)"):
        refit_mesh(mesh, vertices[:-1])
