from pathlib import Path

import numpy as np
import pytest

from gnngarment.body.motion import MotionError
from gnngarment.body.motion_io import load_motion
from gnngarment.body.skeleton import JOINT_INDEX
from gnngarment.body.smpl_motion import (
    SMPL_TO_CANONICAL,
    load_amass_motion,
    load_npz_motion,
    motion_from_smpl,
)

UPRIGHT = np.array([np.pi / 2, 0.0, 0.0])  # SMPL root turning Y-up into Z-up


def _smpl_poses(frames):
    poses = np.zeros((frames, 24, 3))
    poses[:, 0] = UPRIGHT
    poses[:, JOINT_INDEX["L_knee"]] = [0.5, 0.0, 0.0]  # knee bend about SMPL's X
    poses[:, JOINT_INDEX["L_shoulder"]] = [0.0, 0.0, -0.8]  # lower the left arm about SMPL's Z
    return poses


def test_smpl_conversion():
    motion = motion_from_smpl(_smpl_poses(3), np.arange(9.0).reshape(3, 3), 30.0)
    assert np.allclose(motion.rotations[:, 0], 0, atol=1e-12)  # upright SMPL root → rest
    assert np.allclose(motion.rotations[:, JOINT_INDEX["L_knee"]], [0.5, 0, 0])
    # SMPL's Z (front) is canonical −Y: the arm lowering is about −Y... i.e. +0.8 about Y.
    assert np.allclose(motion.rotations[:, JOINT_INDEX["L_shoulder"]], [0, 0.8, 0])
    assert np.allclose(motion.translation[0], 0)  # relative to the first frame
    assert np.allclose(motion.translation[2], [6, 6, 6])
    assert np.allclose(SMPL_TO_CANONICAL @ [0, 1, 0], [0, 0, 1])


@pytest.mark.parametrize("width", [72, 156, 165])
def test_amass(tmp_path, width):
    poses = np.zeros((4, width))
    poses[:, :72] = _smpl_poses(4).reshape(4, 72)
    poses[:, 66:72] = 0.3  # hands (SMPL) or fingers/jaw (SMPL-H/X)
    path = tmp_path / "clip.npz"
    np.savez(path, poses=poses, trans=np.zeros((4, 3)), mocap_framerate=np.array(120.0))
    motion = load_amass_motion(path)
    assert motion.fps == 120 and motion.num_frames == 4
    assert np.allclose(motion.rotations[:, 0], 0, atol=1e-12)
    hands = motion.rotations[:, [22, 23]]
    assert np.allclose(hands, 0) == (width != 72)
    assert load_motion(path, fps=60).fps == 60


@pytest.mark.parametrize(
    ("arrays", "match"),
    [
        ({"trans": np.zeros((4, 3)), "mocap_framerate": 30.0}, "no 'poses'"),
        ({"poses": np.zeros((4, 70)), "trans": np.zeros((4, 3)), "mocap_framerate": 30.0}, "poses"),
        (
            {"poses": np.zeros((4, 72)), "trans": np.zeros((3, 3)), "mocap_framerate": 30.0},
            "translation",
        ),
        (
            {"poses": np.full((4, 72), np.nan), "trans": np.zeros((4, 3)), "mocap_framerate": 30.0},
            "NaN",
        ),
        ({"poses": np.zeros((4, 72)), "trans": np.zeros((4, 3)), "mocap_framerate": 0.0}, "> 0"),
        ({"poses": np.zeros((4, 72)), "trans": np.zeros((4, 3))}, "framerate"),
    ],
)
def test_amass_errors_name_the_file(tmp_path, arrays, match):
    path = tmp_path / "bad_clip.npz"
    np.savez(path, **arrays)
    with pytest.raises(MotionError, match=match) as info:
        load_amass_motion(path)
    assert "bad_clip.npz" in str(info.value)


# ---- NCS-style SMPL .npz and rigs that are not SMPL (issue 13 item 5) --------------------------

MIXAMO_NPZ = (
    Path(__file__).resolve().parents[2].parent / "shared" / "real-world" / "motions"
    / "ncs_mixamo_0000.npz"
)  # fmt: skip


def _ncs_poses(frames):
    """NCS-style poses (T, 24, 3): Y-up world, so an upright body has a zero root."""
    poses = np.zeros((frames, 24, 3))
    poses[:, JOINT_INDEX["L_knee"]] = [0.5, 0.0, 0.0]
    poses[:, JOINT_INDEX["L_shoulder"]] = [0.0, 0.0, -0.8]
    poses[1:, 0] = [0.0, 0.3, 0.0]  # turning about SMPL's Y: the vertical
    return poses


@pytest.mark.parametrize("width", [None, 72, 156])
def test_ncs_style_npz(tmp_path, width):
    frames = 4
    poses = _ncs_poses(frames)
    trans = np.zeros((frames, 3))
    trans[:, 1] = [0.9, 1.0, 1.1, 1.2]  # rising along SMPL's Y (up)
    trans[:, 2] = [0.0, 0.1, 0.2, 0.3]  # walking along SMPL's Z (front)
    path = tmp_path / "ncs_clip.npz"
    stored = poses if width is None else np.zeros((frames, width))
    if width is not None:
        stored[:, :72] = poses.reshape(frames, 72)
        stored[:, 66:] = 0.3  # SMPL's hands (72) or SMPL-H fingers (156): not the hands
    np.savez(path, poses=stored, trans=trans, fps=30.0)
    for motion in (load_npz_motion(path), load_motion(path)):
        assert motion.fps == 30 and motion.num_frames == frames
        assert np.allclose(motion.rotations[0, 0], 0, atol=1e-12)  # upright without a turn
        assert np.allclose(motion.rotations[1, 0], [0, 0, 0.3])  # SMPL Y is our Z
        assert np.allclose(motion.rotations[:, JOINT_INDEX["L_shoulder"]], [0, 0.8, 0])
        # Y up → Z up, front +Z → −Y.
        assert np.allclose(motion.translation[-1], [0, -0.3, 0.3])
        assert np.allclose(motion.rotations[:, JOINT_INDEX["L_hand"]], 0) == (width != 72)
    # up_axis="z" reads the same file as an AMASS-like Z-up world: the root turns.
    z_up = load_npz_motion(path, up_axis="z")
    assert np.allclose(z_up.translation[-1], [0, 0.3, 0.3])
    assert not np.allclose(z_up.rotations[0, 0], 0)
    assert np.allclose(load_motion(path, up_axis="z").translation, z_up.translation)


def test_amass_up_axis_is_z_unless_told(tmp_path):
    poses = np.zeros((2, 72))
    trans = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    path = tmp_path / "amass.npz"
    np.savez(path, poses=poses, trans=trans, mocap_framerate=np.array(60.0))
    assert np.allclose(load_npz_motion(path).translation[-1], [0, 1, 0])
    assert np.allclose(load_npz_motion(path, up_axis="y").translation[-1], [0, 0, 1])


def _assert_rig_message(message, path_name, joints):
    assert message.startswith(str(path_name)) and "\n" not in message
    assert f"quaternions on a {joints}-joint rig" in message and "not SMPL" in message
    assert "export it as BVH" in message and "--joint-map" in message
    assert "has no 'mocap_framerate'" not in message


def test_a_quaternion_rig_npz_is_named_not_blamed_on_its_frame_rate(tmp_path):
    path = tmp_path / "mixamo_like.npz"
    np.savez(path, poses=np.tile([1.0, 0, 0, 0], (5, 65, 1)), trans=np.zeros((5, 3)),
             fps=np.array(30.0), source=np.array("Run Forward (1).fbx"))  # fmt: skip
    with pytest.raises(MotionError) as info:
        load_motion(path)
    _assert_rig_message(str(info.value), path, 65)
    assert "'Run Forward (1).fbx'" in str(info.value)


@pytest.mark.skipif(
    not MIXAMO_NPZ.is_file(),
    reason=f"{MIXAMO_NPZ} is absent: third-party test data kept in ../shared/real-world "
    "beside the repository, not in a clone",
)
def test_the_real_mixamo_npz_gets_an_accurate_message():
    with pytest.raises(MotionError) as info:
        load_motion(MIXAMO_NPZ)
    _assert_rig_message(str(info.value), MIXAMO_NPZ, 65)


@pytest.mark.parametrize(
    ("arrays", "match"),
    [
        ({"trans": np.zeros((4, 3)), "fps": 30.0}, "no 'poses' array.*supported .npz motions"),
        ({"poses": np.zeros((4, 24, 3)), "trans": np.zeros((4, 3))}, "no frame rate"),
        ({"poses": np.zeros((4, 24, 3)), "fps": 30.0}, "no 'trans'"),
        ({"poses": np.zeros((4, 70)), "trans": np.zeros((4, 3)), "fps": 30.0}, r"\(T, 24, 3\)"),
        ({"poses": np.zeros((4, 52, 3)), "trans": np.zeros((4, 3)), "fps": 30.0},
         "3-vectors on a 52-joint rig"),
        ({"poses": np.zeros((4, 24, 3)), "trans": np.zeros((4, 3)), "fps": 0.0}, "'fps' must be"),
        ({"poses": np.zeros((4, 24, 3)), "trans": np.zeros((3, 3)), "fps": 30.0}, "translation"),
    ],
)  # fmt: skip
def test_npz_errors_name_the_file(tmp_path, arrays, match):
    path = tmp_path / "bad_motion.npz"
    np.savez(path, **arrays)
    with pytest.raises(MotionError, match=match) as info:
        load_motion(path)
    assert "bad_motion.npz" in str(info.value) and "\n" not in str(info.value)
