"""The frame an attribution is taken at."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from gnngarment.attribution import FrameInputs
from gnngarment.data.body_inputs import BodyMotionInputs
from tests.model.pairs import tiny_config


def motion_inputs(frames: int, body_vertices: int) -> BodyMotionInputs:
    """Frame t's motion features and velocities all equal t (to read windows back)."""
    t = np.arange(frames, dtype=np.float32)
    transforms = np.tile(np.eye(4, dtype=np.float32), (frames, 24, 1, 1))
    transforms[:, :, 0, 3] = t[:, None]
    return BodyMotionInputs(
        motion_features=np.repeat(t[:, None], 75, axis=1),
        velocities=np.broadcast_to(t[:, None, None], (frames, body_vertices, 3)).copy(),
        joint_transforms=transforms, vertices=np.zeros((frames, 5, 3), np.float32), fps=30.0)


def test_rest_frame() -> None:
    config = tiny_config()
    frame = FrameInputs.rest(config)
    assert frame.motion_window.shape == (1, 1, config.window, 75)
    assert frame.velocity_window.shape == (1, 1, config.window, 3 * config.body_vertices)
    torch.testing.assert_close(frame.joint_transforms[0, 0, 7], torch.eye(4))
    frame.validate(config)


def test_from_motion_pads_with_the_first_frame() -> None:
    config = tiny_config()                                       # window 3, 32 body vertices
    frames = motion_inputs(6, config.body_vertices)
    first = FrameInputs.from_motion(frames, 1, config.window)
    assert first.motion_window[0, 0, :, 0].tolist() == [0.0, 0.0, 1.0]
    assert first.velocity_window.shape == (1, 1, 3, 96)
    assert first.velocity_window[0, 0, :, -1].tolist() == [0.0, 0.0, 1.0]
    assert first.joint_transforms[0, 0, 0, 0, 3].item() == 1.0
    last = FrameInputs.from_motion(frames, 5, config.window)
    assert last.motion_window[0, 0, :, 0].tolist() == [3.0, 4.0, 5.0]
    with pytest.raises(ValueError, match="frame index 6 is out of range for a motion of 6"):
        FrameInputs.from_motion(frames, 6, config.window)


def test_coerce_accepts_unbatched_tuples() -> None:
    config = tiny_config()
    frame = FrameInputs.coerce((np.zeros((3, 75)), np.zeros((3, 96)), np.eye(4)[None].repeat(
        24, axis=0)), config)
    assert frame.motion_window.shape == (1, 1, 3, 75)
    assert frame.joint_transforms.shape == (1, 1, 24, 4, 4)
    rest = FrameInputs.rest(config)
    assert FrameInputs.coerce(rest, config) is rest


@pytest.mark.parametrize(("shapes", "message"), [
    (((3, 74), (3, 96), (24, 4, 4)), r"motion_window must have shape \(1, 1, m, 75\)"),
    (((3, 75), (2, 96), (24, 4, 4)), r"velocity_window must have shape \(1, 1, 3, 96\)"),
    (((3, 75), (3, 96), (23, 4, 4)), r"joint_transforms must have shape"),
    (((2, 3, 75), (3, 96), (24, 4, 4)), "motion_window must have shape"),
    (((3, 75), (3, 96)), "frame inputs must be"),
])
def test_coerce_rejects_bad_shapes(shapes, message) -> None:
    tensors = tuple(torch.zeros(shape) for shape in shapes)
    with pytest.raises(ValueError, match=message):
        FrameInputs.coerce(tensors, tiny_config())
