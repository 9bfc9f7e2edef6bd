import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from gnngarment.body.motion import MotionError
from gnngarment.body.procedural import (
    JOINT_LIMITS_DEG,
    MOTION_LIBRARY,
    list_motions,
    make_motion,
)
from gnngarment.body.skeleton import JOINT_INDEX, JOINT_NAMES

NAMES = [name for name, _ in list_motions()]


def _angular_velocity(motion):
    """(T−1, 24) angular speed between consecutive frames, rad/s."""
    mats = Rotation.from_rotvec(motion.rotations.reshape(-1, 3)).as_matrix()
    mats = mats.reshape(motion.num_frames, 24, 3, 3)
    rel = np.einsum("tjba,tjbc->tjac", mats[:-1], mats[1:])
    rotvec = Rotation.from_matrix(rel.reshape(-1, 3, 3)).as_rotvec()
    return rotvec.reshape(motion.num_frames - 1, 24, 3) * motion.fps


def test_library_has_the_required_motions():
    required = {
        "walk",
        "run",
        "jump",
        "squat",
        "arm_raise",
        "wave",
        "twist",
        "kick",
        "sit_down",
        "dance",
    }
    assert required <= set(MOTION_LIBRARY) and len(NAMES) >= 10


@pytest.mark.parametrize("name", NAMES)
def test_starts_at_rest_and_moves(name):
    motion = make_motion(name, duration=3.0, fps=30)
    assert motion.num_frames == 91 and motion.name == name
    assert np.abs(motion.rotations[0]).max() == 0 and np.abs(motion.translation[0]).max() == 0
    # Rest is held for a few frames, then the body moves.
    assert np.abs(motion.rotations[:5]).max() < 1e-9
    assert np.abs(motion.rotations[-30:]).max() > 0.2


@pytest.mark.parametrize("name", NAMES)
def test_joint_limits(name):
    for seed in (None, 3):
        motion = make_motion(name, duration=5.0, amplitude=1.2, speed=1.5, seed=seed)
        angles = np.degrees(Rotation.from_rotvec(motion.rotations.reshape(-1, 3)).magnitude())
        largest = angles.reshape(motion.num_frames, 24).max(0)
        for j, joint in enumerate(JOINT_NAMES[1:], start=1):
            assert largest[j] <= JOINT_LIMITS_DEG[joint], (name, joint, largest[j])
        # Knees only flex (positive X rotation), elbows don't hyperextend much.
        knees = motion.rotations[:, [JOINT_INDEX["L_knee"], JOINT_INDEX["R_knee"]], 0]
        assert knees.min() > -1e-9


@pytest.mark.parametrize("name", NAMES)
def test_smooth_no_velocity_spikes(name):
    """Smooth motions: doubling the frame rate halves the frame-to-frame change of angular
    velocity (a kink in the velocity would not shrink); accelerations stay human-sized."""
    coarse = _angular_velocity(make_motion(name, fps=30))
    fine = _angular_velocity(make_motion(name, fps=60))
    jump_coarse = np.abs(np.diff(coarse, axis=0)).max()
    jump_fine = np.abs(np.diff(fine, axis=0)).max()
    assert jump_fine <= 0.6 * jump_coarse + 1e-6
    assert jump_coarse * 30 < 300.0  # rad/s²
    assert np.abs(coarse).max() < 15.0  # rad/s


def test_translation_is_smooth_and_walk_moves_forward():
    walk = make_motion("walk", duration=4.0)
    speed = np.linalg.norm(np.diff(walk.translation, axis=0), axis=1) * walk.fps
    assert walk.translation[-1, 1] < -2.5  # forward is −Y
    assert np.abs(np.diff(speed)).max() * walk.fps < 20.0  # m/s², no jumps
    assert make_motion("walk", speed=2.0).translation[-1, 1] < walk.translation[-1, 1]


def test_seeds_are_reproducible_and_vary():
    a = make_motion("wave", seed=1)
    assert np.array_equal(a.rotations, make_motion("wave", seed=1).rotations)
    assert not np.allclose(a.rotations, make_motion("wave", seed=2).rotations)
    assert (
        np.abs(make_motion("squat", amplitude=0.5).rotations).max()
        < np.abs(make_motion("squat").rotations).max()
    )


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"name": "moonwalk"}, "unknown motion"),
        ({"name": "walk", "fps": 0}, "fps"),
        ({"name": "walk", "duration": -1}, "duration"),
        ({"name": "walk", "speed": 10}, "speed"),
        ({"name": "walk", "amplitude": 3}, "amplitude"),
    ],
)
def test_validation(kwargs, match):
    with pytest.raises(MotionError, match=match):
        make_motion(**kwargs)
