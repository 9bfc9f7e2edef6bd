from __future__ import annotations

import numpy as np
import pytest
import trimesh

from gnngarment.geometry.body_collisions import (
    CollisionSettings,
    resolve_collisions,
    spread_pushes,
)
from gnngarment.geometry.graph import adjacency_matrix, edge_index_from_faces
from gnngarment.geometry.signed_distance import signed_distance, warp_mesh, winding_numbers
from tests.meshes import box_signed_distance, closed_box, grid

HALF = np.array([0.2, 0.15, 0.3])
EPSILON = CollisionSettings().epsilon
#: The resolution accepts ε within float32 query rounding.
TOLERANCE = 1e-5


def sheet(x0: float, width: int, z: float, spacing: float = 0.01
          ) -> tuple[np.ndarray, np.ndarray]:
    """A flat ``21 × width`` garment patch at height ``z`` from ``x = x0``, y ∈ ±0.1."""
    pos, faces = grid(21, width, spacing)
    pos[:, 0] += x0
    pos[:, 1] -= 0.1
    pos[:, 2] = z
    return pos, faces


def spike(pos: np.ndarray, resolved: np.ndarray, faces: np.ndarray) -> float:
    """Largest difference between a vertex's displacement and its neighbours' mean,
    relative to the largest displacement."""
    adjacency = adjacency_matrix(edge_index_from_faces(faces, len(pos)), len(pos))
    degree = np.asarray(adjacency.sum(axis=1)).ravel()
    shift = resolved - pos
    laplacian = shift - (adjacency @ shift) / degree[:, None]
    return float(np.linalg.norm(laplacian, axis=1).max() / np.linalg.norm(shift, axis=1).max())


def test_vertices_inside_a_box_end_epsilon_outside() -> None:
    body, body_faces = closed_box(HALF)
    # 1 cm under the top face, running out over the side: pushed up, or out sideways.
    pos, faces = sheet(-0.4049, 41, HALF[2] - 0.01)
    before = box_signed_distance(pos, HALF)
    assert (before < 0).sum() > 100
    resolved, stats = resolve_collisions(pos, faces, body, body_faces)
    assert box_signed_distance(resolved, HALF).min() >= EPSILON - TOLERANCE
    assert stats.inside[0] == (before < 0).sum() and stats.close[0] == (before < EPSILON).sum()
    assert stats.remaining[0] == 0 and stats.moved[0] > stats.close[0]
    assert stats.max_push[0] == pytest.approx(np.linalg.norm(resolved - pos, axis=1).max())


def test_vertices_deep_inside_a_sphere_end_epsilon_outside() -> None:
    sphere = trimesh.creation.icosphere(subdivisions=3, radius=0.3)
    body, body_faces = np.asarray(sphere.vertices), np.asarray(sphere.faces)
    # A cap 20 cm deep: the middle lies far beyond the search band inside.
    pos, faces = sheet(-0.3, 61, 0.1, spacing=0.01)
    resolved, stats = resolve_collisions(pos, faces, body, body_faces)
    assert signed_distance(pos, body, body_faces).min() < -0.15
    assert signed_distance(resolved, body, body_faces).min() >= EPSILON - TOLERANCE
    assert stats.remaining[0] == 0


def test_vertices_farther_than_epsilon_do_not_move() -> None:
    body, body_faces = closed_box(HALF)
    pos, faces = sheet(-0.3, 61, HALF[2] + 0.05)
    resolved, stats = resolve_collisions(pos, faces, body, body_faces)
    np.testing.assert_array_equal(resolved, pos)
    assert stats.moved[0] == 0 and stats.close[0] == 0
    # Next to a collision only the neighbourhood moves: pushes fall off within the
    # smoothing radius plus one ring per Jacobi pass.
    pos, faces = sheet(-0.6049, 121, HALF[2] - 0.01)
    settings = CollisionSettings()
    resolved, _ = resolve_collisions(pos, faces, body, body_faces, settings)
    reach = HALF[0] + EPSILON + settings.smoothing_radius + 0.01 * (
        settings.smoothing_iterations + 1)
    far = np.abs(pos[:, 0]) > reach
    assert far.sum() > 100
    np.testing.assert_array_equal(resolved[far], pos[far])


@pytest.mark.parametrize("case", ["poke", "edge"])
def test_correction_is_spread_without_spikes(case: str) -> None:
    body, body_faces = closed_box(HALF)
    if case == "poke":  # one vertex 5 mm into the top, its neighbours 1 cm above it
        pos, faces = sheet(-0.1, 21, HALF[2] + 0.01)
        pos[np.argmin(np.linalg.norm(pos[:, :2], axis=1)), 2] = HALF[2] - 0.005
    else:  # a sheet through the top edge: pushed up on one side, sideways at the edge
        pos, faces = sheet(-0.4049, 41, HALF[2] - 0.01)
    smooth, _ = resolve_collisions(pos, faces, body, body_faces)
    raw, _ = resolve_collisions(pos, faces, body, body_faces, CollisionSettings(
        smoothing_radius=0.0, smoothing_iterations=0))
    assert box_signed_distance(raw, HALF).min() >= EPSILON - TOLERANCE
    # Moving only the colliding vertices leaves a spike; the spread halves it at least.
    assert spike(pos, raw, faces) > 0.6
    assert spike(pos, smooth, faces) < 0.5


def test_frames_resolve_against_their_own_body_pose() -> None:
    body, body_faces = closed_box(HALF)
    pos, faces = sheet(-0.4049, 41, HALF[2] - 0.01)
    offsets = np.array([[0.0, 0.0, 0.0], [0.5, -0.2, 0.1], [-1.0, 0.3, 0.0]])
    frames = pos[None] + offsets[:, None]
    bodies = body[None] + offsets[:, None]
    resolved, stats = resolve_collisions(frames.astype(np.float32), faces, bodies, body_faces)
    assert resolved.shape == frames.shape and resolved.dtype == np.float32
    single, _ = resolve_collisions(pos, faces, body, body_faces)
    for t, offset in enumerate(offsets):
        np.testing.assert_allclose(resolved[t], single + offset, atol=2e-5)
    assert (stats.close == stats.close[0]).all() and (stats.remaining == 0).all()


def test_spread_is_a_linear_falloff_along_edges() -> None:
    count, spacing, radius = 12, 0.01, 0.05
    pos = np.column_stack([spacing * np.arange(count), np.zeros(count), np.zeros(count)])
    source, target = edge_index_from_faces(
        np.stack([np.arange(count - 2), np.arange(1, count - 1), np.arange(2, count)], 1),
        count)
    indptr = np.searchsorted(source, np.arange(count + 1))
    push = np.zeros(count)
    push[3] = 0.01
    up = np.tile([0.0, 0.0, 1.0], (count, 1))
    shift = spread_pushes(push, up, pos, indptr, target, radius)
    # Through the triangle strip the path to vertex k is |k − 3| edges of 1 cm (or one
    # 2 cm edge): the tent s (1 − ℓ / r), zero beyond r.
    expected = 0.01 * np.maximum(1 - spacing * np.abs(np.arange(count) - 3) / radius, 0)
    np.testing.assert_allclose(shift[:, 2], expected, atol=1e-8)  # float32 lengths
    np.testing.assert_array_equal(shift[:, :2], 0.0)


def test_bad_inputs_are_refused_with_the_expected_shape() -> None:
    body, body_faces = closed_box(HALF)
    pos, faces = sheet(-0.1, 21, 0.0)
    with pytest.raises(ValueError, match=r"garment must be \(N, 3\) or \(T, N, 3\)"):
        resolve_collisions(pos[:, :2], faces, body, body_faces)
    with pytest.raises(ValueError, match="one pose per garment frame"):
        resolve_collisions(np.stack([pos, pos]), faces, np.stack([body] * 3), body_faces)
    with pytest.raises(ValueError, match="one pose per garment frame"):
        resolve_collisions(pos, faces, body[None], body_faces)
    with pytest.raises(ValueError, match="faces must be"):
        resolve_collisions(pos, faces + len(pos), body, body_faces)
    with pytest.raises(ValueError, match="body_faces must be"):
        resolve_collisions(pos, faces, body, body_faces.astype(float))
    with pytest.raises(ValueError, match="must not be negative"):
        resolve_collisions(pos, faces, body, body_faces, CollisionSettings(epsilon=-1.0))


def test_vertices_by_a_buried_surface_are_moved_out_of_every_part() -> None:
    """Where the body intersects itself (a small sphere sunk into a big one, like an
    upper arm in the chest), a vertex inside the big part but just outside the small one
    has a buried closest surface: seen from it the vertex is outside. It must still end
    ε outside the union."""
    from tests.geometry.test_signed_distance import sunk_spheres

    body, body_faces = sunk_spheres()
    # A patch 5 mm off the small sphere's far side (x = 0.255), inside the big sphere.
    pos, faces = sheet(-0.1, 21, 0.0)
    pos = pos[:, [2, 0, 1]] + [0.255, 0.0, 0.0]   # the plane x = 0.255, 0.2 × 0.2 m
    mesh = warp_mesh(body, body_faces)
    inside = winding_numbers(mesh, pos) >= 1
    assert inside.all()
    resolved, stats = resolve_collisions(pos, faces, body, body_faces)
    assert (winding_numbers(warp_mesh(body, body_faces), resolved) == 0).all()
    assert stats.inside[0] == len(pos) and stats.remaining[0] == 0
    # out through the big sphere, not deeper in: every vertex ends outside its radius
    assert (np.linalg.norm(resolved, axis=1) >= 0.3 - 1e-3).all()
