import numpy as np
import pytest
import torch

from gnngarment.body.features import (
    joint_vertex_distances,
    motion_features,
    motion_windows,
    sliding_windows,
    velocity_windows,
    vertex_velocities,
)
from gnngarment.body.motion import Motion


def test_sliding_windows_pad_with_first_frame():
    frames = torch.arange(4.0)[:, None]
    windows = sliding_windows(frames, 3)
    assert windows.shape == (4, 3, 1)
    assert windows[0, :, 0].tolist() == [0, 0, 0]
    assert windows[1, :, 0].tolist() == [0, 0, 1]
    assert windows[3, :, 0].tolist() == [1, 2, 3]
    # Shorter than the window: padded by repeating the first frame.
    assert sliding_windows(frames[:2], 5)[1, :, 0].tolist() == [0, 0, 0, 0, 1]
    with pytest.raises(ValueError):
        sliding_windows(frames, 0)


def test_motion_features_relative_translation():
    rotations = np.zeros((3, 24, 3))
    rotations[:, 4, 0] = [0.1, 0.2, 0.3]
    translation = np.array([[0, 0, 0], [0, -0.1, 0], [0, -0.3, 0.05]])
    features = motion_features(Motion(rotations, translation, 30))
    assert features.shape == (3, 75)
    assert torch.allclose(features[:, 12], torch.tensor([0.1, 0.2, 0.3]))
    assert torch.allclose(
        features[:, 72:], torch.tensor([[0, 0, 0], [0, -0.1, 0], [0, -0.2, 0.05]]), atol=1e-7
    )
    assert motion_windows(Motion(rotations, translation, 30), 4).shape == (3, 4, 75)


def test_velocities_and_distances():
    vertices = torch.zeros(3, 2, 3)
    vertices[1, 0, 0] = 0.1
    vertices[2, 0, 0] = 0.3
    v = vertex_velocities(vertices, fps=10)
    assert torch.allclose(v[:, 0, 0], torch.tensor([0.0, 1.0, 2.0]))
    assert velocity_windows(v, 2).shape == (3, 2, 6)
    joints = torch.zeros(24, 3)
    joints[1] = torch.tensor([3.0, 4.0, 0.0])
    d = joint_vertex_distances(torch.zeros(5, 3), joints)
    assert d.shape == (5, 24) and torch.allclose(d[:, 1], torch.full((5,), 5.0))
    with pytest.raises(ValueError):
        vertex_velocities(vertices, fps=0)
