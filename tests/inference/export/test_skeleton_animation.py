"""Joint tracks from skinning transforms: quaternions, orthonormalisation, recomposition."""

from __future__ import annotations

import numpy as np
import pytest
import torch
from scipy.spatial.transform import Rotation

from gnngarment.body.skeleton import forward_kinematics
from gnngarment.inference.export.skeleton_animation import (
    continuous_quaternions,
    matrix_to_quaternion,
    nearest_rotation,
    quaternion_to_matrix,
    skeleton_animation,
)
from tests.inference.animations import REST_JOINTS, joint_transforms


def test_quaternion_order_is_xyzw_and_right_handed() -> None:
    quarter_turn_z = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    np.testing.assert_allclose(matrix_to_quaternion(quarter_turn_z),
                               [0.0, 0.0, np.sqrt(0.5), np.sqrt(0.5)], atol=1e-12)
    np.testing.assert_allclose(quaternion_to_matrix([0.0, 0.0, np.sqrt(0.5), np.sqrt(0.5)]),
                               quarter_turn_z, atol=1e-12)


def test_quaternions_match_scipy_for_every_angle_including_half_turns() -> None:
    rotations = Rotation.random(500, random_state=0)
    half_turns = Rotation.from_rotvec(np.pi * np.eye(3))
    matrices = np.concatenate([rotations.as_matrix(), half_turns.as_matrix()])
    q = matrix_to_quaternion(matrices)
    expected = np.concatenate([rotations.as_quat(), half_turns.as_quat()])
    same = np.abs(np.sum(q * expected, axis=1))  # q and −q are the same rotation
    np.testing.assert_allclose(same, 1.0, atol=1e-12)
    np.testing.assert_allclose(quaternion_to_matrix(q), matrices, atol=1e-12)


def test_nearest_rotation_repairs_drift_and_never_reflects() -> None:
    rng = np.random.default_rng(0)
    exact = Rotation.random(50, random_state=1).as_matrix()
    noisy = exact + 1e-4 * rng.normal(size=exact.shape)
    fixed = nearest_rotation(noisy)
    np.testing.assert_allclose(fixed @ np.swapaxes(fixed, 1, 2), np.broadcast_to(np.eye(3),
                               fixed.shape), atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(fixed), 1.0, atol=1e-12)
    assert np.abs(fixed - exact).max() < 1e-3
    assert np.linalg.det(nearest_rotation(np.diag([1.0, 1.0, -1.0]))) == pytest.approx(1.0)


def test_continuous_quaternions_flip_sign_along_time() -> None:
    q = np.array([[0.0, 0.0, 0.0, 1.0], [0.0, 0.0, -0.1, -0.99], [0.0, 0.0, 0.2, 0.98]])
    out = continuous_quaternions(q)
    assert (np.sum(out[1:] * out[:-1], axis=1) > 0).all()
    np.testing.assert_allclose(np.abs(out), np.abs(q))


def test_tracks_recompose_the_skinning_transforms() -> None:
    transforms = joint_transforms(5).astype(np.float64)
    tracks = skeleton_animation(transforms, REST_JOINTS)
    np.testing.assert_allclose(tracks.skinning_transforms(), transforms, atol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(tracks.rotations, axis=-1), 1.0, atol=1e-12)
    # Rest pose: identity rotations, rest offsets between joints.
    rest, _ = forward_kinematics(torch.zeros(1, 24, 3, dtype=torch.float64),
                                 torch.tensor(REST_JOINTS))
    still = skeleton_animation(rest.numpy(), REST_JOINTS)
    np.testing.assert_allclose(still.translations[0], still.rest_translations, atol=1e-12)
    np.testing.assert_allclose(np.abs(still.rotations[0, :, 3]), 1.0, atol=1e-12)


def test_tracks_validate_their_input() -> None:
    with pytest.raises(ValueError, match=r"joint_transforms must be \(T, 24, 4, 4\)"):
        skeleton_animation(np.zeros((2, 23, 4, 4)), REST_JOINTS)
    with pytest.raises(ValueError, match="NaN"):
        skeleton_animation(np.full((1, 24, 4, 4), np.nan), REST_JOINTS)
    with pytest.raises(ValueError, match="parents"):
        skeleton_animation(np.tile(np.eye(4), (1, 2, 1, 1)), np.zeros((2, 3)), parents=(1, -1))
