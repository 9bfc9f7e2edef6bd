import numpy as np
import pytest

from gnngarment.body.cloth3d_motion import load_cloth3d_motion, read_cloth3d_info
from gnngarment.body.motion import MotionError
from gnngarment.body.skeleton import JOINT_INDEX


def _cloth3d_poses(frames):
    """``(72, T)`` as CLOTH3D stores them: an upright SMPL root, the left knee bent."""
    poses = np.zeros((frames, 24, 3))
    poses[:, 0] = [np.pi / 2, 0.0, 0.0]  # SMPL root turning Y-up into Z-up
    poses[:, JOINT_INDEX["L_knee"]] = [0.5, 0.0, 0.0]  # knee bend about SMPL's X
    return poses.reshape(frames, 72).T


def test_cloth3d(tmp_path):
    from scipy.io import savemat

    frames = 5
    info = {
        "poses": _cloth3d_poses(frames),
        "shape": np.zeros(10),
        "trans": np.stack([np.linspace(0, 1, frames), np.zeros(frames), np.zeros(frames)]),
        "gender": 1,
        "zrot": np.pi / 2,
        "outfit": {"Top": {"fabric": "cotton"}},
    }
    path = tmp_path / "info.mat"
    savemat(path, {"info": info})
    assert read_cloth3d_info(path)["outfit"]["Top"]["fabric"] == "cotton"
    motion = load_cloth3d_motion(path)
    assert motion.num_frames == frames and motion.fps == 30
    assert np.allclose(motion.rotations[:, 0], 0, atol=1e-9)
    assert np.allclose(motion.rotations[:, JOINT_INDEX["L_knee"]], [0.5, 0, 0])
    assert np.allclose(motion.translation[-1], [1, 0, 0])
    turned = load_cloth3d_motion(path, apply_zrot=True)
    assert np.allclose(turned.translation[-1], [0, 1, 0], atol=1e-9)
    assert np.allclose(turned.rotations[:, 0], [0, 0, np.pi / 2])
    # Single frame: (72,) and (3,).
    savemat(
        tmp_path / "one.mat", {"info": {**info, "poses": info["poses"][:, 0], "trans": np.zeros(3)}}
    )
    assert load_cloth3d_motion(tmp_path / "one.mat").num_frames == 1
    savemat(tmp_path / "bad.mat", {"info": {"trans": np.zeros(3)}})
    with pytest.raises(MotionError, match="bad.mat.*poses"):
        load_cloth3d_motion(tmp_path / "bad.mat")


def test_cloth3d_top_level_layout(tmp_path):
    from scipy.io import savemat

    # CLOTH3D's own layout: one top-level variable per field, no 'info' struct.
    savemat(tmp_path / "info.mat", {"poses": np.zeros((72, 2)), "trans": np.zeros((3, 2)),
                                    "outfit": {"Top": {"fabric": "silk"}}})  # fmt: skip
    info = read_cloth3d_info(tmp_path / "info.mat")
    assert info["poses"].shape == (72, 2) and info["outfit"] == {"Top": {"fabric": "silk"}}
    assert load_cloth3d_motion(tmp_path / "info.mat").num_frames == 2


def test_read_cloth3d_info_errors_name_the_file(tmp_path):
    from scipy.io import savemat

    path = tmp_path / "info.mat"
    with pytest.raises(MotionError, match=f"{path}: file not found"):
        read_cloth3d_info(path)
    path.write_bytes(b"MATLAB 5.0 MAT-file" + bytes(100))
    with pytest.raises(MotionError, match=f"{path}: cannot read MAT file"):
        read_cloth3d_info(path)
    savemat(path, {"info": np.zeros(3)})
    with pytest.raises(MotionError, match="expected a struct of sequence information"):
        read_cloth3d_info(path)
