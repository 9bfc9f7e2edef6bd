"""A motion's documented limits: rates and lengths that are typos or attacks are refused
by name before any frame is built (issue 38)."""

from __future__ import annotations

import numpy as np
import pytest

from gnngarment.body.motion import Motion, MotionError
from gnngarment.body.motion_limits import MAX_FPS, MAX_MOTION_SECONDS, motion_option_problem
from gnngarment.body.smpl_motion import load_npz_motion


@pytest.mark.parametrize("fps", ["thirty", 1e12, float("nan"), 0.0])
def test_a_motion_file_whose_fps_lies_is_refused_naming_it(tmp_path, fps) -> None:
    path = tmp_path / "motion.npz"
    np.savez(path, poses=np.zeros((4, 72)), trans=np.zeros((4, 3)), fps=np.asarray(fps))
    with pytest.raises(MotionError, match=f"{path}.*fps"):
        load_npz_motion(path)


def test_a_motion_of_any_plausible_rate_is_accepted() -> None:
    for fps in (24.0, 120.0, 250.0, 1000.0):
        assert Motion(np.zeros((3, 24, 3)), np.zeros((3, 3)), fps).fps == fps
    with pytest.raises(MotionError, match="at most"):
        Motion(np.zeros((3, 24, 3)), np.zeros((3, 3)), 1e12)


def test_option_limits_hold_at_their_edges() -> None:
    assert motion_option_problem(MAX_FPS, MAX_MOTION_SECONDS) is None
    assert motion_option_problem(30.0, 2 / 30) is None            # two frames
    assert "fewer than 2" in motion_option_problem(30.0, 1 / 30)
    assert "--fps" in motion_option_problem(MAX_FPS * 1.01, 1.0)
    assert "--duration" in motion_option_problem(30.0, MAX_MOTION_SECONDS * 1.01)
