"""Edge graph, normals, scale and joint distances on shapes with known answers."""

from __future__ import annotations

import numpy as np
import trimesh

from gnngarment.geometry.graph import connected_components, edge_index_from_faces
from gnngarment.geometry.joint_distances import joint_distances
from gnngarment.geometry.normals import vertex_normals
from gnngarment.geometry.scale import mesh_scale, surface_area, vertex_areas
from tests.meshes import grid, tube, union


def test_edge_index_is_symmetric_and_counts_mesh_edges() -> None:
    pos, faces = grid(3, 4)  # 2*3*... edges: horizontal 9 + vertical 8 + diagonals 6
    edge_index = edge_index_from_faces(faces, len(pos))
    pairs = set(map(tuple, edge_index.T.tolist()))
    assert all((b, a) in pairs for a, b in pairs)
    assert edge_index.shape[1] == 2 * (9 + 8 + 6)
    assert not (edge_index[0] == edge_index[1]).any()


def test_components_numbered_by_lowest_vertex() -> None:
    pos, faces = union(grid(3, 3), tube(3, 5))
    faces = np.vstack([faces[len(faces) // 2:], faces[: len(faces) // 2]])
    labels = connected_components(edge_index_from_faces(faces, len(pos)), len(pos))
    assert labels[0] == 0 and labels[-1] == 1


def test_sphere_normals_point_outward_and_flat_grid_points_up() -> None:
    sphere = trimesh.creation.icosphere(3)
    normals = vertex_normals(sphere.vertices, sphere.faces)
    radial = sphere.vertices / np.linalg.norm(sphere.vertices, axis=1, keepdims=True)
    assert (np.einsum("ij,ij->i", normals, radial) > 0.999).all()
    pos, faces = grid(4, 4)
    np.testing.assert_allclose(vertex_normals(pos, faces), [[0, 0, 1]] * len(pos), atol=1e-12)


def test_vertex_normals_of_frames_are_each_frames_normals() -> None:
    """Leading axes (frames, as E_norm passes them) give each frame's own normals, and a
    vertex no face uses gets the zero vector."""
    sphere = trimesh.creation.icosphere(subdivisions=2)
    faces = np.asarray(sphere.faces)
    rng = np.random.default_rng(0)
    frames = sphere.vertices[None] * rng.uniform(0.5, 2.0, (3, 1, 3))  # stretched spheres
    frames = np.concatenate([frames, np.zeros((3, 1, 3))], axis=1)     # one unused vertex
    together = vertex_normals(frames.astype(np.float32), faces)
    assert together.shape == frames.shape and together.dtype == np.float64
    for t in range(3):
        np.testing.assert_array_equal(together[t], vertex_normals(frames[t].astype(np.float32),
                                                                   faces))
    np.testing.assert_array_equal(together[:, -1], 0.0)


def test_scale_is_unit_and_resolution_independent() -> None:
    pos, faces = grid(5, 5, spacing=0.25)  # a 1 m × 1 m sheet
    assert np.isclose(surface_area(pos, faces), 1.0)
    assert np.isclose(mesh_scale(pos, faces), 1.0)
    fine_pos, fine_faces = grid(9, 9, spacing=0.125)
    assert np.isclose(mesh_scale(fine_pos, fine_faces), 1.0)
    assert np.isclose(mesh_scale(pos * 100, faces), 100.0)  # centimetres
    assert np.isclose(vertex_areas(pos, faces).sum(), 1.0)


def test_joint_distances() -> None:
    pos = np.array([[0.0, 0, 0], [3, 4, 0]])
    joints = np.array([[0.0, 0, 0], [0, 0, 2], [3, 4, 0]])
    np.testing.assert_allclose(joint_distances(pos, joints), [[0, 2, 5], [5, np.sqrt(29), 0]])


def test_largest_component_keeps_the_biggest_piece_reindexed() -> None:
    """Anny's mesh is the body plus tongue and eyes: the body is what is kept."""
    from gnngarment.geometry.graph import largest_component
    from tests.meshes import random_disk, tube, union

    pos, faces = union(random_disk(40, 1), tube(10, 12))  # disk first: 40 + 120 vertices
    keep, kept = largest_component(faces, len(pos))
    assert len(keep) == 120 and keep.min() == 40
    assert kept.min() == 0 and kept.max() == 119 and len(kept) == 2 * 9 * 12
    assert np.allclose(pos[keep][kept], pos[faces[faces.min(axis=1) >= 40]])
