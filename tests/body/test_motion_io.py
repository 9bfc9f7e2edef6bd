import numpy as np
import pytest

from gnngarment.body.motion import MotionError
from gnngarment.body.motion_io import load_motion


def test_unknown_file_type_and_missing_file(tmp_path):
    (tmp_path / "x.fbx").write_text("")
    with pytest.raises(MotionError, match="unknown motion"):
        load_motion(tmp_path / "x.fbx")
    with pytest.raises(MotionError, match="not found"):
        load_motion(tmp_path / "missing.bvh")
    (tmp_path / "junk.npz").write_text("not a zip")
    with pytest.raises(MotionError, match="junk.npz"):
        load_motion(tmp_path / "junk.npz")


@pytest.mark.parametrize("fps", [0.0, -30.0, float("nan")])
def test_a_frame_rate_that_is_not_positive_is_refused(fps):
    with pytest.raises(MotionError, match="fps must be a finite number > 0"):
        load_motion("walk", fps=fps, duration=1.0)  # was silently 30 fps for 0
    assert load_motion("walk", duration=1.0).fps == 30.0  # no fps: the library's default


def test_options_a_motion_cannot_use_are_refused(tmp_path):
    path = tmp_path / "clip.npz"
    np.savez(path, poses=np.zeros((2, 72)), trans=np.zeros((2, 3)), mocap_framerate=30.0)
    with pytest.raises(MotionError, match="joint map applies to .bvh motions only"):
        load_motion(path, joint_map={"L_hip": "Thigh"})
    with pytest.raises(MotionError, match="up axis applies to .npz and .bvh"):
        load_motion("walk", up_axis="y", duration=1.0)
    with pytest.raises(MotionError, match="up_axis must be"):
        load_motion(path, up_axis="x")
