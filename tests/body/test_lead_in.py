"""The lead-in from the rest pose (:mod:`gnngarment.body.lead_in`): tiny hand-made motions
with analytic answers, and CMU 09_01 (whose file jumps out of a T-pose) when present."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from gnngarment.body.lead_in import (
    FAST_START_SPEED,
    MAX_LEAD_IN_SECONDS,
    MAX_TRIMMED_SECONDS,
    check_lead_in_seconds,
    lead_in_frames,
    reference_pose_frames,
    trim_reference_pose,
    with_lead_in,
)
from gnngarment.body.motion import Motion, MotionError
from gnngarment.body.motion_io import default_lead_in, load_motion_for_body
from gnngarment.body.procedural import smoothstep

CMU_09_01 = Path("/work/shared/real-world/motions/cmu/09_01.bvh")


def _posed_motion(frames: int = 5, fps: float = 30.0, seed: int = 0) -> Motion:
    """A motion whose every joint is rotated up to ~1 rad and slowly turning, the root
    off the origin."""
    generator = np.random.default_rng(seed)
    start = generator.uniform(-0.6, 0.6, (1, 24, 3))
    drift = generator.uniform(-0.01, 0.01, (frames, 1, 1)).cumsum(axis=0)
    translation = np.array([0.1, -0.2, 0.05]) + np.linspace(0, 0.03, frames)[:, None]
    return Motion(start + drift, translation, fps, "clip")


def _angles(rotations: np.ndarray) -> np.ndarray:
    """``(T, 24)`` radians: each joint's rotation angle from rest."""
    return np.linalg.norm(rotations, axis=-1)


def _steps(rotations: np.ndarray) -> np.ndarray:
    """``(T−1, 24)`` radians: each joint's rotation from one frame to the next."""
    before = Rotation.from_rotvec(rotations[:-1].reshape(-1, 3))
    after = Rotation.from_rotvec(rotations[1:].reshape(-1, 3))
    return (before.inv() * after).magnitude().reshape(len(rotations) - 1, -1)


def test_it_starts_at_rest_and_ends_with_the_motion_unchanged() -> None:
    motion = _posed_motion()
    led = with_lead_in(motion, 0.5)
    count = lead_in_frames(0.5, motion.fps)
    assert count == 15 and len(led) == count + len(motion)
    assert led.fps == motion.fps and led.name == motion.name
    np.testing.assert_array_equal(led.rotations[0], 0.0)  # the rest pose ...
    np.testing.assert_array_equal(led.translation[0], 0.0)  # ... at the origin
    np.testing.assert_array_equal(led.rotations[count:], motion.rotations)
    np.testing.assert_array_equal(led.translation[count:], motion.translation)


def test_the_blend_follows_the_ease_on_the_shortest_path() -> None:
    """Frame ``i`` is the first pose's rotation scaled by ``smoothstep(i / n)`` (a slerp
    from the identity is a scaled axis-angle), the translation likewise."""
    motion = _posed_motion()
    led = with_lead_in(motion, 0.4)
    count = lead_in_frames(0.4, motion.fps)
    ease = smoothstep(np.arange(count) / count)
    np.testing.assert_allclose(led.rotations[:count], ease[:, None, None] * motion.rotations[0],
                               atol=1e-9)
    np.testing.assert_allclose(led.translation[:count], ease[:, None] * motion.translation[0],
                               atol=1e-12)


def test_per_frame_rotation_steps_are_bounded_and_vanish_at_both_ends() -> None:
    """The ease's largest slope is 15/8, so no joint turns more than 15/8 · θ / n a frame
    (θ its first-pose angle), and the first and last steps are far smaller."""
    motion = _posed_motion()
    count = lead_in_frames(0.5, motion.fps)
    led = with_lead_in(motion, 0.5)
    steps = _steps(led.rotations[:count + 1])
    bound = 15 / 8 * _angles(motion.rotations[:1]) / count
    assert np.all(steps <= bound + 1e-9)
    # Leaves rest and arrives at the first pose at rest: the end steps are 10/n³ · θ
    # (2.4% of the bound at n = 15), where a linear blend would step θ / n.
    assert np.all(steps[0] <= 0.05 * bound[0] + 1e-12)
    assert np.all(steps[-1] <= 0.05 * bound[0] + 1e-12)


def test_zero_or_under_half_a_frame_returns_the_motion_itself() -> None:
    motion = _posed_motion()
    assert with_lead_in(motion, 0.0) is motion
    assert with_lead_in(motion, 0.4 / motion.fps) is motion
    assert lead_in_frames(0.0, 30.0) == 0 and lead_in_frames(1.0, 120.0) == 120


def test_a_motion_at_rest_gets_a_hold_of_the_rest_pose() -> None:
    """The count never depends on the motion: a motion starting at rest is held there."""
    led = with_lead_in(Motion.rest(3), 0.2)
    assert len(led) == 3 + 6
    np.testing.assert_array_equal(led.rotations, 0.0)
    np.testing.assert_array_equal(led.translation, 0.0)


@pytest.mark.parametrize("seconds", [-0.1, math.nan, math.inf, MAX_LEAD_IN_SECONDS + 0.1])
def test_lead_in_lengths_out_of_range_are_refused(seconds: float) -> None:
    with pytest.raises(MotionError, match="finite number of seconds"):
        check_lead_in_seconds(seconds)
    with pytest.raises(MotionError, match="finite number of seconds"):
        with_lead_in(_posed_motion(), seconds)
    with pytest.raises(MotionError, match="finite number of seconds"):
        lead_in_frames(seconds, 30.0)


def test_lead_in_limits_and_frame_rates_are_checked() -> None:
    assert check_lead_in_seconds(0) == 0.0
    assert check_lead_in_seconds(MAX_LEAD_IN_SECONDS) == MAX_LEAD_IN_SECONDS
    with pytest.raises(MotionError, match="fps must be"):
        lead_in_frames(0.5, 0.0)


def _reference_start(blend: int, fps: float = 120.0, frames: int = 40) -> Motion:
    """A clip moving slowly, opened by a rest (T-pose) frame that jumps into it over
    ``blend`` frames (a CMU BVH conversion's first 1/30 s)."""
    clip = _posed_motion(frames, fps)
    rotations, translation = clip.rotations.copy(), clip.translation.copy()
    for frame in range(blend + 1):
        rotations[frame] = frame / (blend + 1) * clip.rotations[blend + 1]
    translation -= translation[0]  # as the loaders' relative translation
    return Motion(rotations, translation, fps, "reference")


def test_a_t_pose_reference_frame_and_its_blend_are_found_and_dropped() -> None:
    motion = _reference_start(blend=3)
    assert reference_pose_frames(motion) == 4
    trimmed = trim_reference_pose(motion)
    np.testing.assert_array_equal(trimmed.rotations, motion.rotations[4:])
    np.testing.assert_allclose(trimmed.translation[0], 0.0, atol=1e-15)  # still at the origin
    np.testing.assert_allclose(np.diff(trimmed.translation, axis=0),
                               np.diff(motion.translation[4:], axis=0), atol=1e-15)


def test_a_start_that_is_not_a_reference_pose_is_kept() -> None:
    posed = _posed_motion(40, 120.0)  # far from rest: not a reference frame
    assert reference_pose_frames(posed) == 0 and trim_reference_pose(posed) is posed
    # At rest but leaving it slowly (a procedural motion's ramp): movement, not a jump.
    slow = Motion(np.linspace(0, 1, 40)[:, None, None] * np.full((1, 24, 3), 0.05),
                  np.zeros((40, 3)), 120.0)
    assert _steps(slow.rotations).max() * slow.fps < FAST_START_SPEED
    assert reference_pose_frames(slow) == 0
    assert reference_pose_frames(Motion.rest(1)) == 0


def test_a_clip_that_keeps_jumping_loses_no_more_than_the_limit() -> None:
    """A rest frame followed by frames flipping between two poses at 120 fps (a broken
    clip, not a blend): only the first :data:`MAX_TRIMMED_SECONDS` are dropped."""
    clip = _posed_motion(40, 120.0)
    flips = (np.arange(40) % 2)[:, None, None] * clip.rotations
    motion = Motion(flips, np.zeros((40, 3)), 120.0)
    assert reference_pose_frames(motion) == round(MAX_TRIMMED_SECONDS * motion.fps) == 12


def test_load_motion_for_body_puts_the_lead_in_in_front(anny_body) -> None:
    walk = load_motion_for_body("walk", anny_body, fps=30.0, duration=0.5)
    led = load_motion_for_body("walk", anny_body, fps=30.0, lead_in=0.2, duration=0.5)
    assert len(led) == len(walk) + 6  # procedural motions start at rest: a hold
    np.testing.assert_array_equal(led.rotations[6:], walk.rotations)
    with pytest.raises(MotionError, match="finite number of seconds"):
        load_motion_for_body("walk", anny_body, lead_in=-1.0, duration=0.5)
    assert default_lead_in("walk") == 0.0 and default_lead_in("clip.bvh") == 0.5


@pytest.mark.skipif(not CMU_09_01.is_file(), reason=f"{CMU_09_01} not on this machine")
def test_cmu_09_01_leaves_the_rest_pose_without_a_pop(anny_body) -> None:
    """Without a lead-in, 09_01 jumps from a T-pose into a run: body vertices move up to
    ~870 mm in its first 1/30 s. With the default 0.5 s lead-in the body starts at the
    rest body exactly, moves < 200 mm a frame in the lead-in (measured 147 mm; the run
    itself reaches 270 mm) and the lead-in arrives in the clip without a jump."""
    import torch

    shape = anny_body.parse_shape("average")
    led = load_motion_for_body(CMU_09_01, anny_body, shape, fps=30.0, lead_in=0.5)
    count = lead_in_frames(0.5, 30.0)
    with torch.no_grad():
        vertices = anny_body.pose(led, shape).vertices.numpy()
    rest = anny_body.rest(shape).vertices.numpy()
    np.testing.assert_allclose(vertices[0], rest, atol=1e-5)
    steps = np.linalg.norm(np.diff(vertices, axis=0), axis=2).max(axis=1)
    assert steps[:count].max() < 0.2
    assert steps.max() < 0.4  # the clip's own running, not a pop
