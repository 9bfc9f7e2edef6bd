"""Body-side model inputs (:func:`body_shape_inputs`, :func:`body_motion_inputs`), on the
small synthetic SMPL-format model (the real loading path, no licensed files)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch

from gnngarment.body.body_model import BodyModel
from gnngarment.body.motion import Motion
from gnngarment.body.smpl_model import SMPLBodyModel
from gnngarment.data.body_inputs import body_motion_inputs, body_shape_inputs
from tests.smpl_files import synthetic_smpl, write_synthetic_smpl

COUNT = 16


class NoWeightsSMPL(SMPLBodyModel):
    """A body model that does not expose its skinning weights (the interface default)."""

    skinning_weights = BodyModel.skinning_weights


@pytest.fixture(scope="module")
def smpl_path(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_synthetic_smpl(tmp_path_factory.mktemp("smpl") / "SMPL_NEUTRAL.npz")


@pytest.fixture(scope="module")
def body(smpl_path: Path) -> SMPLBodyModel:
    return SMPLBodyModel(smpl_path)


def test_shape_inputs_have_the_documented_shapes_and_units(body: SMPLBodyModel) -> None:
    inputs = body_shape_inputs(body, None, COUNT)
    rest = body.rest()
    n = rest.vertices.shape[0]
    assert inputs.joints.shape == (24, 3) and inputs.joints.dtype == np.float32
    assert inputs.distances.shape == (COUNT, 24) and inputs.distances.dtype == np.float32
    assert inputs.subset.shape == (COUNT,) and inputs.subset.dtype == np.int64
    assert len(set(inputs.subset.tolist())) == COUNT
    assert inputs.subset.min() >= 0 and inputs.subset.max() < n
    assert inputs.rest_vertices.shape == (n, 3)
    assert inputs.faces.shape[1] == 3 and inputs.faces.dtype == np.int64
    np.testing.assert_allclose(inputs.joints, rest.joints.numpy(), atol=1e-6)
    np.testing.assert_allclose(inputs.rest_vertices, rest.vertices.numpy(), atol=1e-6)
    # D: metres from every subset vertex to every rest joint.
    expected = np.linalg.norm(inputs.rest_vertices[inputs.subset][:, None]
                              - inputs.joints[None], axis=-1)
    np.testing.assert_allclose(inputs.distances, expected, rtol=1e-5, atol=1e-6)
    weights = inputs.skinning_weights
    assert weights.shape == (n, 24) and weights.dtype == np.float32
    np.testing.assert_allclose(weights.sum(1), 1.0, rtol=1e-6)
    np.testing.assert_array_equal(weights, synthetic_smpl()["weights"].astype(np.float32))


def test_another_shape_changes_the_features_but_not_the_subset(body: SMPLBodyModel) -> None:
    mean = body_shape_inputs(body, None, COUNT)
    other = body_shape_inputs(body, body.parse_shape([2.0, -1.0, 1.0]), COUNT)
    np.testing.assert_array_equal(other.subset, mean.subset)  # same topology, same vertices
    np.testing.assert_array_equal(other.faces, mean.faces)
    assert np.abs(other.distances - mean.distances).max() > 1e-3
    assert np.abs(other.rest_vertices - mean.rest_vertices).max() > 1e-3


def test_a_body_model_without_skinning_weights_gives_none(smpl_path: Path) -> None:
    bare = NoWeightsSMPL(smpl_path)
    with pytest.raises(NotImplementedError):
        bare.skinning_weights()
    inputs = body_shape_inputs(bare, None, COUNT)
    assert inputs.skinning_weights is None
    assert inputs.distances.shape == (COUNT, 24)


def test_the_rest_motion_leaves_the_body_at_rest(body: SMPLBodyModel) -> None:
    shape = body_shape_inputs(body, None, COUNT)
    inputs = body_motion_inputs(body, None, Motion.rest(3, fps=25.0), COUNT)
    assert inputs.fps == 25.0 and isinstance(inputs.fps, float)
    assert inputs.motion_features.shape == (3, 75)
    assert inputs.velocities.shape == (3, COUNT, 3)
    assert inputs.joint_transforms.shape == (3, 24, 4, 4)
    assert inputs.vertices.shape == (3, *shape.rest_vertices.shape)
    for array in (inputs.motion_features, inputs.velocities, inputs.joint_transforms,
                  inputs.vertices):
        assert array.dtype == np.float32
    np.testing.assert_array_equal(inputs.motion_features, 0.0)
    np.testing.assert_allclose(inputs.velocities, 0.0, atol=1e-5)
    np.testing.assert_allclose(inputs.joint_transforms, np.broadcast_to(np.eye(4), (3, 24, 4, 4)),
                               atol=1e-6)
    np.testing.assert_allclose(inputs.vertices, np.broadcast_to(shape.rest_vertices,
                                                                inputs.vertices.shape), atol=1e-5)


def test_a_steady_translation_gives_metres_per_second(body: SMPLBodyModel) -> None:
    frames, fps, step = 4, 30.0, np.array([0.01, -0.02, 0.005])  # metres per frame
    motion = Motion(np.zeros((frames, 24, 3)), np.arange(frames)[:, None] * step, fps)
    inputs = body_motion_inputs(body, None, motion, COUNT)
    shape = body_shape_inputs(body, None, COUNT)
    # Root displacement since the previous frame (zero at frame 0), after 72 axis-angles.
    np.testing.assert_array_equal(inputs.motion_features[:, :72], 0.0)
    np.testing.assert_allclose(inputs.motion_features[0, 72:], 0.0)
    np.testing.assert_allclose(inputs.motion_features[1:, 72:],
                               np.broadcast_to(step, (frames - 1, 3)), atol=1e-6)
    # Every subset vertex moves rigidly at step · fps m/s (zero at frame 0).
    np.testing.assert_allclose(inputs.velocities[0], 0.0, atol=1e-5)
    np.testing.assert_allclose(inputs.velocities[1:],
                               np.broadcast_to(step * fps, (frames - 1, COUNT, 3)), atol=1e-3)
    np.testing.assert_allclose(inputs.vertices[2], shape.rest_vertices + 2 * step, atol=1e-5)
    # Same frames at twice the frame rate: twice the velocity, same displacement.
    fast = body_motion_inputs(body, None, Motion(motion.rotations, motion.translation, 2 * fps),
                              COUNT)
    np.testing.assert_allclose(fast.velocities, 2 * inputs.velocities, rtol=1e-5, atol=1e-5)
    np.testing.assert_array_equal(fast.motion_features, inputs.motion_features)


def test_velocities_are_those_of_the_subset_vertices(body: SMPLBodyModel) -> None:
    rng = np.random.default_rng(1)
    motion = Motion(0.3 * rng.standard_normal((3, 24, 3)), 0.1 * rng.standard_normal((3, 3)),
                    20.0)
    inputs = body_motion_inputs(body, None, motion, COUNT)
    subset = body_shape_inputs(body, None, COUNT).subset
    np.testing.assert_allclose(inputs.motion_features[:, :72],
                               motion.rotations.reshape(3, 72), atol=1e-6)
    expected = np.diff(inputs.vertices[:, subset], axis=0) * 20.0
    np.testing.assert_allclose(inputs.velocities[1:], expected, rtol=1e-4, atol=1e-4)
    assert np.abs(inputs.velocities[1:]).max() > 0.1  # the pose does move the subset
    # The posed vertices follow the joint transforms (one-hot weights in this model).
    rest = torch.from_numpy(body_shape_inputs(body, None, COUNT).rest_vertices).double()
    owner = synthetic_smpl()["weights"].argmax(1)
    transforms = torch.from_numpy(inputs.joint_transforms).double()[:, owner]  # (T, N, 4, 4)
    posed = (transforms[..., :3, :3] @ rest[None, :, :, None])[..., 0] + transforms[..., :3, 3]
    np.testing.assert_allclose(posed.numpy(), inputs.vertices, atol=1e-4)
