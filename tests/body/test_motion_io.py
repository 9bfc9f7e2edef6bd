import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from gnngarment.body.motion import MotionError
from gnngarment.body.motion_io import (
    SMPL_TO_CANONICAL,
    UnmappedJointsWarning,
    load_amass_motion,
    load_bvh_motion,
    load_cloth3d_motion,
    load_motion,
    motion_from_smpl,
    read_cloth3d_info,
)
from gnngarment.body.skeleton import JOINT_INDEX

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


def test_cloth3d(tmp_path):
    from scipy.io import savemat

    frames = 5
    info = {
        "poses": _smpl_poses(frames).reshape(frames, 72).T,
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


# A CMU-style hierarchy (cgspeed BVH conversion), Y up, T-pose rest.
_CMU = [
    ("Hips", None, (0, 0, 0)),
    ("LHipJoint", "Hips", (0, 0, 0)), ("LeftUpLeg", "LHipJoint", (1.6, -2, 0.8)),
    ("LeftLeg", "LeftUpLeg", (0, -7, 0)), ("LeftFoot", "LeftLeg", (0, -7, 0)),
    ("LeftToeBase", "LeftFoot", (0, -0.5, 2)),
    ("RHipJoint", "Hips", (0, 0, 0)), ("RightUpLeg", "RHipJoint", (-1.6, -2, 0.8)),
    ("RightLeg", "RightUpLeg", (0, -7, 0)), ("RightFoot", "RightLeg", (0, -7, 0)),
    ("RightToeBase", "RightFoot", (0, -0.5, 2)),
    ("LowerBack", "Hips", (0, 0, 0)), ("Spine", "LowerBack", (0, 2, 0)),
    ("Spine1", "Spine", (0, 2, 0)), ("Neck", "Spine1", (0, 2, 0)), ("Neck1", "Neck", (0, 1, 0)),
    ("Head", "Neck1", (0, 1, 0)),
    ("LeftShoulder", "Spine1", (0, 2, 0)), ("LeftArm", "LeftShoulder", (3, 0, 0)),
    ("LeftForeArm", "LeftArm", (5, 0, 0)), ("LeftHand", "LeftForeArm", (4, 0, 0)),
    ("LeftFingerBase", "LeftHand", (1, 0, 0)), ("LThumb", "LeftHand", (0.5, 0, 0.5)),
    ("RightShoulder", "Spine1", (0, 2, 0)), ("RightArm", "RightShoulder", (-3, 0, 0)),
    ("RightForeArm", "RightArm", (-5, 0, 0)), ("RightHand", "RightForeArm", (-4, 0, 0)),
    ("RightFingerBase", "RightHand", (-1, 0, 0)),
]  # fmt: skip


def _write_bvh(path, joints=_CMU, frames=None):
    children = {}
    for name, parent, _ in joints:
        children.setdefault(parent, []).append(name)
    offsets = {name: offset for name, _, offset in joints}
    order = []
    lines = []

    def emit(name, depth):
        pad = "  " * depth
        keyword = "ROOT" if depth == 0 else "JOINT"
        lines.append(f"{pad}{keyword} {name}")
        lines.append(f"{pad}{{")
        lines.append(f"{pad}  OFFSET {' '.join(map(str, offsets[name]))}")
        if depth == 0:
            lines.append(
                f"{pad}  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation"
            )
        else:
            lines.append(f"{pad}  CHANNELS 3 Zrotation Yrotation Xrotation")
        order.append(name)
        kids = children.get(name, [])
        for child in kids:
            emit(child, depth + 1)
        if not kids:
            lines.append(f"{pad}  End Site")
            lines.append(f"{pad}  {{")
            lines.append(f"{pad}    OFFSET 0 0 0")
            lines.append(f"{pad}  }}")
        lines.append(f"{pad}}}")

    emit(children[None][0], 0)
    channels = 3 + 3 * len(order)
    if frames is None:
        frames = np.zeros((3, channels))
        frames[:, 1] = 17.0
        frames[1:, 0] = [5.0, 10.0]
        column = 3 + 3 * order.index("LeftForeArm")  # its Zrotation channel
        frames[1:, column] = 30.0
        column = 3 + 3 * order.index("Neck1") + 2  # Neck1 Xrotation: folds into head
        frames[1:, column] = 20.0
    text = (
        "HIERARCHY\n"
        + "\n".join(lines)
        + f"\nMOTION\nFrames: {len(frames)}\nFrame Time: 0.0083333\n"
    )
    text += "\n".join(" ".join(f"{v:.6f}" for v in row) for row in frames) + "\n"
    path.write_text(text)
    return order


def test_bvh_cmu(tmp_path):
    path = tmp_path / "01_01.bvh"
    _write_bvh(path)
    with pytest.warns(UnmappedJointsWarning, match="LHipJoint.*Neck1|Neck1.*LHipJoint") as record:
        motion = load_bvh_motion(path)
    assert "LThumb" in str(record[0].message)
    assert motion.fps == pytest.approx(120.0, rel=1e-3) and motion.num_frames == 3
    assert np.allclose(motion.rotations[0], 0, atol=1e-12)
    # BVH Z (front) is canonical −Y: 30° about BVH Z on the left forearm → −30° about Y... .
    expected = Rotation.from_matrix(
        SMPL_TO_CANONICAL
        @ Rotation.from_euler("z", 30, degrees=True).as_matrix()
        @ SMPL_TO_CANONICAL.T
    ).as_rotvec()
    assert np.allclose(motion.rotations[1, JOINT_INDEX["L_elbow"]], expected, atol=1e-9)
    assert np.allclose(motion.rotations[2, JOINT_INDEX["head"]], np.radians([20, 0, 0]), atol=1e-9)
    # Root translation: relative to frame 0, scaled to metres (leg 14 units → 0.79 m), Y up → Z up.
    assert np.allclose(motion.translation[2], [10 * 0.79 / 14, 0, 0])


def test_bvh_missing_joint_is_an_error(tmp_path):
    path = tmp_path / "broken.bvh"
    joints = [j for j in _CMU if j[0] not in ("LeftLeg",)]
    joints = [(n, "LeftUpLeg" if p == "LeftLeg" else p, o) for n, p, o in joints]
    _write_bvh(path, joints, frames=np.zeros((2, 3 + 3 * len(joints))))
    with pytest.raises(MotionError, match="broken.bvh.*L_knee"):
        load_bvh_motion(path)
    (tmp_path / "garbage.bvh").write_text("HIERARCHY\nnonsense {")
    with pytest.raises(MotionError, match="garbage.bvh"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        load_bvh_motion(tmp_path / "garbage.bvh")
