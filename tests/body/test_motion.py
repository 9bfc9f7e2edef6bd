import numpy as np
import pytest

from gnngarment.body.motion import Motion, MotionError


def _motion(frames=10, fps=30.0):
    rng = np.random.default_rng(0)
    return Motion(
        0.3 * rng.standard_normal((frames, 24, 3)), rng.standard_normal((frames, 3)), fps, "m"
    )


@pytest.mark.parametrize(
    ("rotations", "translation", "fps", "match"),
    [
        (np.zeros((5, 23, 3)), np.zeros((5, 3)), 30, "rotations must have shape"),
        (np.zeros((5, 24, 3)), np.zeros((4, 3)), 30, "translation must have shape"),
        (np.full((5, 24, 3), np.nan), np.zeros((5, 3)), 30, "NaN"),
        (np.zeros((5, 24, 3)), np.zeros((5, 3)), 0, "fps must be > 0"),
        (np.zeros((5, 24, 3)), np.zeros((5, 3)), -1, "fps must be > 0"),
        (np.zeros((0, 24, 3)), np.zeros((0, 3)), 30, "at least one frame"),
    ],
)
def test_validation(rotations, translation, fps, match):
    with pytest.raises(MotionError, match=match):
        Motion(rotations, translation, fps, "clip.npz")


def test_error_names_source():
    with pytest.raises(MotionError, match="clip.npz"):
        Motion(np.zeros((5, 23, 3)), np.zeros((5, 3)), 30, "clip.npz")


def test_slicing_and_concatenation():
    m = _motion(10)
    assert m[2:5].num_frames == 3 and np.array_equal(m[2:5].rotations, m.rotations[2:5])
    assert m[3].num_frames == 1 and m[-1].num_frames == 1
    both = Motion.concatenate([m, m[:4]])
    assert both.num_frames == 14 and np.array_equal(both.rotations[10:], m.rotations[:4])
    with pytest.raises(MotionError, match="resample"):
        Motion.concatenate([m, _motion(3, fps=60)])
    with pytest.raises(MotionError):
        m[20:30]


def test_resample_slerp():
    rotations = np.zeros((2, 24, 3))
    rotations[1, 5] = [0.0, 0.0, 1.0]
    m = Motion(rotations, np.array([[0, 0, 0], [1.0, 0, 0]]), fps=1.0)
    up = m.resample(4.0)
    assert up.num_frames == 5 and up.fps == 4.0
    assert np.allclose(up.rotations[2, 5], [0, 0, 0.5])  # halfway by slerp
    assert np.allclose(up.translation[:, 0], [0, 0.25, 0.5, 0.75, 1.0])
    m = _motion(31)
    back = m.resample(60).resample(30)
    assert back.num_frames == m.num_frames
    from scipy.spatial.transform import Rotation

    a = Rotation.from_rotvec(back.rotations.reshape(-1, 3))
    b = Rotation.from_rotvec(m.rotations.reshape(-1, 3))
    assert np.max((a.inv() * b).magnitude()) < 1e-9
    with pytest.raises(MotionError):
        m.resample(0)


def test_rest_and_duration():
    rest = Motion.rest(31, fps=30)
    assert rest.duration == pytest.approx(1.0)
    assert not rest.rotations.any() and len(rest) == 31
