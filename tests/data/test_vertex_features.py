"""The garment graph's 30 input channels (:func:`garment_vertex_features`)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from gnngarment.data.vertex_features import VERTEX_FEATURE_CHANNELS, garment_vertex_features
from tests.meshes import grid, interleave, random_disk


def joints(seed: int = 0) -> np.ndarray:
    return np.random.default_rng(seed).normal(scale=0.3, size=(24, 3))


def test_channels_are_position_unit_normal_and_joint_distances_in_metres() -> None:
    pos, faces = grid(3, 4, spacing=0.1)  # z = 0 plane, counter-clockwise seen from +z
    body = np.zeros((24, 3))
    body[5] = [0.0, 0.0, 0.3]   # 0.3 m above the first vertex
    body[7] = [0.3, 0.2, 0.0]   # the last vertex
    features = garment_vertex_features(pos, faces, body)
    assert features.shape == (12, VERTEX_FEATURE_CHANNELS) == (12, 30)
    assert features.dtype == np.float32
    np.testing.assert_allclose(features[:, :3], pos, atol=1e-7)
    np.testing.assert_allclose(features[:, 3:6], np.tile([0.0, 0.0, 1.0], (12, 1)), atol=1e-7)
    distances = features[:, 6:]
    assert distances.shape == (12, 24)
    np.testing.assert_allclose(distances[0, 5], 0.3, rtol=1e-6)
    np.testing.assert_allclose(distances[-1, 7], 0.0, atol=1e-7)
    np.testing.assert_allclose(distances[:, 0], np.linalg.norm(pos, axis=1), rtol=1e-6)


def test_reversed_winding_flips_the_normals_only() -> None:
    pos, faces = random_disk(40, 1)
    body = joints()
    features = garment_vertex_features(pos, faces, body)
    flipped = garment_vertex_features(pos, faces[:, ::-1], body)
    np.testing.assert_allclose(flipped[:, 3:6], -features[:, 3:6], atol=1e-6)
    np.testing.assert_array_equal(np.delete(flipped, [3, 4, 5], 1),
                                  np.delete(features, [3, 4, 5], 1))


def test_moving_garment_and_body_together_keeps_normals_and_distances() -> None:
    # Rest positions are in the body frame: a rigid motion of both changes the position
    # channels (and rotates the normals) but not the garment-to-body relation.
    pos, faces = random_disk(40, 2)
    body = joints()
    rotation = Rotation.from_rotvec([0.3, -0.5, 0.8]).as_matrix()
    shift = np.array([0.4, -1.2, 0.7])
    before = garment_vertex_features(pos, faces, body)
    after = garment_vertex_features(pos @ rotation.T + shift, faces, body @ rotation.T + shift)
    np.testing.assert_allclose(after[:, 6:], before[:, 6:], atol=1e-5)
    np.testing.assert_allclose(after[:, 3:6], before[:, 3:6] @ rotation.T, atol=1e-5)
    np.testing.assert_allclose(after[:, :3], pos @ rotation.T + shift, atol=1e-6)
    # Moving the garment alone changes its distances to the body.
    alone = garment_vertex_features(pos + shift, faces, body)
    assert np.abs(alone[:, 6:] - before[:, 6:]).max() > 0.1


def test_distances_scale_with_the_garment_and_body() -> None:
    pos, faces = random_disk(30, 3)
    body = joints()
    before = garment_vertex_features(pos, faces, body)
    scaled = garment_vertex_features(2.5 * pos, faces, 2.5 * body)
    np.testing.assert_allclose(scaled[:, 6:], 2.5 * before[:, 6:], rtol=1e-5)
    np.testing.assert_allclose(scaled[:, 3:6], before[:, 3:6], atol=1e-6)  # still unit


def test_relabelling_vertices_permutes_the_rows() -> None:
    pos, faces = random_disk(50, 4)
    body = joints()
    permutation = np.random.default_rng(9).permutation(len(pos))
    relabelled = interleave(pos, faces, seed=9)
    np.testing.assert_allclose(garment_vertex_features(*relabelled, body),
                               garment_vertex_features(pos, faces, body)[permutation],
                               atol=1e-6)


def test_a_vertex_in_no_face_gets_a_zero_normal() -> None:
    pos, faces = grid(2, 2)
    pos = np.vstack([pos, [5.0, 5.0, 5.0]])
    features = garment_vertex_features(pos, faces, joints())
    np.testing.assert_array_equal(features[-1, 3:6], 0.0)
    np.testing.assert_allclose(np.linalg.norm(features[:-1, 3:6], axis=1), 1.0, rtol=1e-6)


@pytest.mark.parametrize("shape", [(23, 3), (24, 2), (24,)])
def test_joints_of_another_shape_are_rejected_naming_them(shape: tuple[int, ...]) -> None:
    pos, faces = grid(2, 2)
    with pytest.raises(ValueError, match=r"joints must have shape \(24, 3\), got " +
                       str(shape).replace("(", r"\(").replace(")", r"\)")):
        garment_vertex_features(pos, faces, np.zeros(shape))


def test_positions_of_another_shape_are_rejected_naming_them() -> None:
    pos, faces = random_disk(30, 5)
    with pytest.raises(ValueError, match=r"pos must have shape \(N, 3\)"):
        garment_vertex_features(pos[:, :2], faces, joints())
