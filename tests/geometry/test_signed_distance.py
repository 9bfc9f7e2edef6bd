from __future__ import annotations

import numpy as np
import pytest
import trimesh

from gnngarment.geometry.signed_distance import (
    inside_by_parity,
    refit_mesh,
    signed_distance,
    sphere_directions,
    surface_offsets,
    union_exits,
    warp_mesh,
    winding_numbers,
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


def sunk_spheres() -> tuple[np.ndarray, np.ndarray]:
    """A body that intersects itself: a sphere of radius 0.1 m sunk into one of 0.3 m,
    its centre 0.15 m off the big one's (like an upper arm pressed into the chest)."""
    big = trimesh.creation.icosphere(subdivisions=4, radius=0.3)
    small = trimesh.creation.icosphere(subdivisions=4, radius=0.1)
    small.apply_translation([0.15, 0.0, 0.0])
    return (np.vstack([big.vertices, small.vertices]),
            np.vstack([big.faces, small.faces + len(big.vertices)]))


def test_winding_numbers_count_overlapping_parts_where_parity_cannot() -> None:
    vertices, faces = sunk_spheres()
    mesh = warp_mesh(vertices, faces)
    points = np.random.default_rng(1).uniform(-0.35, 0.35, (4000, 3))
    in_big = np.linalg.norm(points, axis=1) < 0.3
    in_small = np.linalg.norm(points - [0.15, 0.0, 0.0], axis=1) < 0.1
    # the facets lie up to ~0.4 mm inside the true spheres: leave those points out
    clear = (np.abs(np.linalg.norm(points, axis=1) - 0.3) > 1e-3) & (
        np.abs(np.linalg.norm(points - [0.15, 0.0, 0.0], axis=1) - 0.1) > 1e-3)
    expected = in_big.astype(int) + in_small
    np.testing.assert_array_equal(winding_numbers(mesh, points)[clear], expected[clear])
    assert (expected[clear] == 2).sum() > 30
    # parity calls the overlap outside: the reason the body tests use the winding number
    assert not inside_by_parity(mesh, points[clear & (expected == 2)]).any()


def test_union_exits_find_the_way_out_of_every_part_nearly_shortest() -> None:
    vertices, faces = sunk_spheres()
    mesh = warp_mesh(vertices, faces)
    points = np.random.default_rng(2).uniform(-0.28, 0.28, (3000, 3))
    points = points[np.linalg.norm(points, axis=1) < 0.29]
    winding = winding_numbers(mesh, points)
    assert set(np.unique(winding)) == {1, 2}
    length, ray = union_exits(mesh, points, winding, sphere_directions(64))
    shortest = 0.3 - np.linalg.norm(points, axis=1)   # the union's outside is the big sphere's
    assert (length >= shortest - 5e-4).all()          # never short of the outside
    assert (length <= shortest * 1.06 + 1e-3).all()   # 64 rays: within a few per cent
    exits = points + ray * (length + 1e-4)[:, None]
    assert (winding_numbers(mesh, exits) == 0).all()
    np.testing.assert_allclose(np.linalg.norm(sphere_directions(64), axis=1), 1.0, atol=1e-6)
