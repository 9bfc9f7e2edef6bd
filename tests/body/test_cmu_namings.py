"""The two namings of the CMU clips in ``../shared/real-world/motions/cmu``, and the spine
spread: a file with fewer spine joints than ours shares a joint's rotation among ours.

1. Poser-style names (most clips): ``hip/abdomen/chest/neck/head``, ``lCollar/lShldr/
   lForeArm/lHand``, ``lButtock/lThigh/lShin/lFoot``: two spine joints, so ``chest``
   stands for spine2 and spine3.
2. The original CMU (ASF) names (``16_*``): ``lhipjoint/lfemur/ltibia/lfoot/ltoes``,
   ``lowerback/upperback/thorax/lowerneck/upperneck/head``, ``lclavicle/lhumerus/
   lradius/lwrist/lhand/lfingers``: the skeleton of ``cmu_131_*`` under other names.

Tiny hand-written hierarchies (offsets rounded from ``02_01.bvh`` and ``16_01.bvh``) check
the names and the rotations exactly; the real clips are third-party data beside the
repository, and their test skips when the folder is absent.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from gnngarment.body.bvh_motion import (
    Y_UP_TO_CANONICAL,
    UnmappedJointsWarning,
    load_bvh_motion,
    map_bvh_joints,
)
from gnngarment.body.skeleton import JOINT_INDEX, JOINT_NAMES
from tests.body.test_bvh_motion import (
    CGSPEED,
    CMU131,
    FOOT_AND_HAND,
    LIMB_BONES,
    MOTIONS,
    _bone_errors,
    _frames_from_rotations,
    _global_rotation,
    _names_parents,
    _parse_bvh,
    _quiet_load,
    _random_motion,
    _write_bvh,
)

C = Y_UP_TO_CANONICAL
CMU_CLIPS = MOTIONS / "cmu"
# Joints a garment cannot feel, excused where the file has no joint for them.
TOES_AND_HANDS = frozenset({"L_foot", "R_foot", "L_hand", "R_hand"})


def _depth_first(joints):
    """The joints in the order ``_write_bvh`` writes them: the frame columns follow it."""
    children: dict = {}
    for joint in joints:
        children.setdefault(joint[1], []).append(joint)
    ordered = []

    def visit(joint):
        ordered.append(joint)
        for child in children.get(joint[0], []):
            visit(child)

    visit(children[None][0])
    return ordered


def _both_sides(torso, left):
    """A hierarchy from its torso and left-side joints: each ``l…`` joint mirrored to
    ``r…`` (BVH +X is the body's left)."""
    sided = {name for name, _, _ in left}

    def right(name):
        return "r" + name[1:] if name in sided else name

    mirrored = [(right(n), right(p), (-o[0], o[1], o[2])) for n, p, o in left]
    return _depth_first(torso + left + mirrored)


POSER = _both_sides(
    [("hip", None, (0, 0, 0)), ("abdomen", "hip", (0, 20.69, -0.73)),
     ("chest", "abdomen", (0, 11.70, -0.49)), ("neck", "chest", (0, 22.19, -2.19)),
     ("head", "neck", (-0.24, 7.07, 1.22)), ("leftEye", "head", (4.15, 8.05, 8.05))],
    [("lCollar", "chest", (2.68, 19.26, -4.88)), ("lShldr", "lCollar", (8.78, -1.95, 1.46)),
     ("lForeArm", "lShldr", (28.17, -1.71, 0.49)), ("lHand", "lForeArm", (22.59, 0.77, 7.07)),
     ("lMid1", "lHand", (8.25, 1.18, 3.41)), ("lThumb1", "lHand", (1.22, -0.49, 3.41)),
     ("lButtock", "hip", (8.78, 4.35, 1.22)), ("lThigh", "lButtock", (0, -1.71, -2.19)),
     ("lShin", "lThigh", (0, -36.82, 0.73)), ("lFoot", "lShin", (-0.73, -45.11, -5.12))],
)  # fmt: skip

CMU_ASF = _both_sides(
    [("hip", None, (0, 0, 0)), ("lowerback", "hip", (0, 0, 0)),
     ("upperback", "lowerback", (0, 2.12, -0.25)), ("thorax", "upperback", (0.06, 2.14, -0.03)),
     ("lowerneck", "thorax", (0, 0, 0)), ("upperneck", "lowerneck", (-0.10, 1.63, 0.24)),
     ("head", "upperneck", (0.11, 1.66, -0.23))],
    [("lhipjoint", "hip", (0, 0, 0)), ("lfemur", "lhipjoint", (1.57, -1.77, 0.73)),
     ("ltibia", "lfemur", (2.41, -6.61, 0)), ("lfoot", "ltibia", (2.66, -7.31, 0)),
     ("ltoes", "lfoot", (0.21, -0.57, 2.13)), ("lclavicle", "thorax", (0, 0, 0)),
     ("lhumerus", "lclavicle", (3.29, 0.79, -0.68)), ("lradius", "lhumerus", (5.15, 0, 0)),
     ("lwrist", "lradius", (3.75, 0, 0)), ("lhand", "lwrist", (0, 0, 0)),
     ("lfingers", "lhand", (0.53, 0, 0)), ("lthumb", "lhand", (0, 0, 0))],
)  # fmt: skip


def _sided_names(left: dict[str, str]) -> dict[str, str]:
    right = {k.replace("L_", "R_"): "r" + v[1:] for k, v in left.items() if k.startswith("L_")}
    return {**left, **right}


POSER_NAMES = _sided_names({
    "pelvis": "hip", "spine1": "abdomen", "spine2": "chest", "neck": "neck", "head": "head",
    "L_hip": "lThigh", "L_knee": "lShin", "L_ankle": "lFoot", "L_collar": "lCollar",
    "L_shoulder": "lShldr", "L_elbow": "lForeArm", "L_wrist": "lHand",
})  # fmt: skip
CMU_ASF_NAMES = _sided_names({
    "pelvis": "hip", "spine1": "lowerback", "spine2": "upperback", "spine3": "thorax",
    "neck": "upperneck", "head": "head", "L_hip": "lfemur", "L_knee": "ltibia",
    "L_ankle": "lfoot", "L_foot": "ltoes", "L_collar": "lclavicle", "L_shoulder": "lhumerus",
    "L_elbow": "lradius", "L_wrist": "lwrist", "L_hand": "lfingers",
})  # fmt: skip


def _local(motion, joint):
    """``(T, 3, 3)`` local rotation of a canonical joint."""
    return Rotation.from_rotvec(motion.rotations[:, JOINT_INDEX[joint]]).as_matrix()


def _angle(rotation):
    return float(np.degrees(np.linalg.norm(Rotation.from_matrix(rotation).as_rotvec())))


def _bend(joints, bends, frames=2):
    """Frames: all zero at 0; from frame 1 on, joint ``name`` turns by ``bends[name]``
    (``"ZYX"`` degrees, the channel order ``_write_bvh`` writes)."""
    rows = np.zeros((frames, 3 + 3 * len(joints)))
    names = [name for name, _, _ in joints]
    for name, angles in bends.items():
        column = 3 + 3 * names.index(name)
        rows[1:, column : column + 3] = angles
    return rows


def _zyx(angles):
    return Rotation.from_euler("ZYX", angles, degrees=True).as_matrix()


def _relative(rotations):
    """``(T, 3, 3)`` rotations relative to frame 0: ``Q(t) Q(0)ᵀ``."""
    return rotations @ np.swapaxes(rotations[:1], -1, -2)


# ---- names ------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("joints", "expected"),
    [(POSER, POSER_NAMES), (CMU_ASF, CMU_ASF_NAMES)],
    ids=["poser", "cmu-asf"],
)
def test_cmu_namings_map_every_joint_they_have(joints, expected):
    """Poser names lack spine3 (chest stands for it), toes and a hand joint (lHand is
    the wrist, the fingers are left out); the original CMU names have all 24."""
    mapping = map_bvh_joints(*_names_parents(joints))
    assert mapping == expected
    assert len(set(mapping.values())) == len(mapping)


# ---- Poser names: chest stands for spine2 and spine3 ------------------------------------------


def test_a_chest_bend_is_split_between_spine2_and_spine3(tmp_path):
    """A bend of chest alone: spine2 and spine3 each turn by half of it about the same
    axis, spine3 ends where the chest is, and nothing above turns twice."""
    chest = (20.0, -10.0, 30.0)
    path = _write_bvh(tmp_path / "chest.bvh", POSER, _bend(POSER, {"chest": chest}))
    with pytest.warns(UnmappedJointsWarning, match="'chest' spread over spine2, spine3"):
        motion = load_bvh_motion(path)
    whole = C @ _zyx(chest) @ C.T  # the chest's turn in our world
    half = Rotation.from_rotvec(Rotation.from_matrix(whole).as_rotvec() / 2).as_matrix()
    assert np.allclose(_relative(_global_rotation(motion, "spine3"))[1], whole, atol=1e-9)
    assert np.allclose(_relative(_global_rotation(motion, "spine2"))[1], half, atol=1e-9)
    spine2, spine3 = _local(motion, "spine2")[1], _local(motion, "spine3")[1]
    assert np.allclose(spine2, spine3, atol=1e-9)
    assert _angle(spine2) == pytest.approx(_angle(whole) / 2, abs=1e-6)
    assert _angle(spine2 @ spine3) == pytest.approx(_angle(whole), abs=1e-6)
    for joint in ("spine1", "neck", "head", "L_collar", "R_collar", "L_shoulder"):
        assert np.allclose(_local(motion, joint)[1], _local(motion, joint)[0], atol=1e-9), joint


def test_the_split_reproduces_the_chest_in_every_frame(tmp_path):
    """Random rotations on every joint (eyes, buttocks and fingers too): spine2 and spine3
    share the chest's rotation equally, spine3 turns exactly as the chest does, and every
    limb bone points where the file's does."""
    root, local = _random_motion(POSER, frames=9, seed=5)
    local[0] = np.eye(3)  # frame 0 at rest: our spine3 there is the rest alignment
    path = _write_bvh(tmp_path / "poser.bvh", POSER, _frames_from_rotations(POSER, root, local))
    motion = _quiet_load(path)
    names = [name for name, _, _ in POSER]
    chest = local[:, names.index("hip")] @ local[:, names.index("abdomen")]
    chest = chest @ local[:, names.index("chest")]  # (T, 3, 3) the file's global chest
    spine3 = _global_rotation(motion, "spine3")
    assert np.allclose(spine3, C @ chest @ C.T @ spine3[:1], atol=1e-9)
    assert np.allclose(_local(motion, "spine2"), _local(motion, "spine3"), atol=1e-9)
    errors = _bone_errors(motion, path, POSER_NAMES, LIMB_BONES)
    assert max(float(v.max()) for v in errors.values()) < 1e-4


def test_a_joint_map_null_holds_spine3_at_rest(tmp_path):
    """``spine3: null`` in a joint map keeps spine3 out of the spread: spine2 takes the
    whole chest."""
    path = _write_bvh(tmp_path / "held.bvh", POSER, _bend(POSER, {"chest": (0, 0, 30)}))
    motion = _quiet_load(path, joint_map={"spine3": None})
    assert np.allclose(_local(motion, "spine3"), np.eye(3), atol=1e-12)
    assert _angle(_local(motion, "spine2")[1]) == pytest.approx(30.0, abs=1e-6)


def test_a_lone_spine_joint_bends_all_three(tmp_path):
    """Hips → Spine → Neck: Spine's rotation is shared in thirds by spine1..spine3."""
    drop = {"LowerBack", "Spine1"}
    joints = [
        (name, {"LowerBack": "Hips", "Spine1": "Spine"}.get(parent, parent), offset)
        for name, parent, offset in CGSPEED
        if name not in drop
    ]
    joints = [(n, p, (0, 4, 0) if p == "Spine" else o) for n, p, o in joints]
    mapping = map_bvh_joints(*_names_parents(joints))
    assert mapping["spine1"] == "Spine" and "spine2" not in mapping and "spine3" not in mapping
    spine = (10.0, 25.0, -40.0)
    motion = _quiet_load(_write_bvh(tmp_path / "one.bvh", joints, _bend(joints, {"Spine": spine})))
    whole = C @ _zyx(spine) @ C.T
    thirds = [_local(motion, joint)[1] for joint in ("spine1", "spine2", "spine3")]
    assert np.allclose(thirds[0], thirds[1], atol=1e-9)
    assert np.allclose(thirds[1], thirds[2], atol=1e-9)
    assert _angle(thirds[0]) == pytest.approx(_angle(whole) / 3, abs=1e-6)
    assert np.allclose(_relative(_global_rotation(motion, "spine3"))[1], whole, atol=1e-9)


# ---- original CMU names -------------------------------------------------------------------------

# cmu_131_* names → the original CMU names of the same joints (16_*).
ASF_OF_131 = {
    "Hips": "hip", "Chest": "upperback", "Chest2": "thorax", "Neck": "upperneck",
    "Head": "head",
    **{f"{side}{a}": f"{s}{b}" for side, s in (("Left", "l"), ("Right", "r")) for a, b in (
        ("Hip", "femur"), ("Knee", "tibia"), ("Ankle", "foot"), ("Toe", "toes"),
        ("Collar", "clavicle"), ("Shoulder", "humerus"), ("Elbow", "radius"),
        ("Wrist", "wrist"))},
    "LHipJoint": "lhipjoint", "RHipJoint": "rhipjoint", "LFingers": "lfingers",
    "RFingers": "rfingers", "LThumb": "lthumb",
}  # fmt: skip


def test_original_cmu_names_play_like_the_cmu_131_names(tmp_path):
    """``16_*`` is the skeleton of ``cmu_131_*`` (hip joints, clavicles and lowerneck at
    offset 0, a zero-offset lhand) under the original names: one recording written both
    ways loads to the same motion, and its limb bones point where the file's do."""
    renamed = [(ASF_OF_131.get(n, n), ASF_OF_131.get(p, p), o) for n, p, o in CMU131]
    root, local = _random_motion(CMU131, frames=8, seed=6)
    frames = _frames_from_rotations(CMU131, root, local)
    ours = _quiet_load(_write_bvh(tmp_path / "131.bvh", CMU131, frames))
    path = _write_bvh(tmp_path / "asf.bvh", renamed, frames)
    theirs = _quiet_load(path)
    assert np.allclose(theirs.rotations, ours.rotations, atol=1e-12)
    assert np.allclose(theirs.translation, ours.translation, atol=1e-12)
    names_of = map_bvh_joints(*_names_parents(renamed))
    errors = _bone_errors(theirs, path, names_of, LIMB_BONES + FOOT_AND_HAND)
    assert max(float(v.max()) for v in errors.values()) < 1e-4


def test_upperback_and_thorax_bends_show_in_spine2_and_spine3(tmp_path):
    upperback, thorax = (0.0, 0.0, 20.0), (30.0, 0.0, 0.0)
    rows = _bend(CMU_ASF, {"upperback": upperback, "thorax": thorax})
    motion = _quiet_load(_write_bvh(tmp_path / "asf.bvh", CMU_ASF, rows))
    assert np.allclose(
        _relative(_global_rotation(motion, "spine2"))[1], C @ _zyx(upperback) @ C.T, atol=1e-9
    )
    assert np.allclose(
        _relative(_global_rotation(motion, "spine3"))[1],
        C @ _zyx(upperback) @ _zyx(thorax) @ C.T,
        atol=1e-9,
    )
    assert _angle(_local(motion, "spine3")[1]) == pytest.approx(30.0, abs=1e-6)
    for joint in ("spine1", "neck", "L_collar", "R_collar"):
        assert np.allclose(_local(motion, joint)[1], _local(motion, joint)[0], atol=1e-9), joint


# ---- the real CMU clips -------------------------------------------------------------------------

needs_cmu_clips = pytest.mark.skipif(
    not CMU_CLIPS.is_dir(),
    reason=f"{CMU_CLIPS} is absent: the CMU BVH clips are third-party test data kept in "
    "../shared/real-world beside the repository, not in a clone",
)


def _still_file_joints(path):
    """(names, parents) of the file's joints, and the names of those whose rotation
    channels never change over the clip (by less than 1e-6°)."""
    names, parents, _, channels, frames = _parse_bvh(path)
    still, column = set(), 0
    for name, joint_channels in zip(names, channels, strict=True):
        rotation = [column + k for k, c in enumerate(joint_channels) if c.endswith("rotation")]
        column += len(joint_channels)
        # (Poser copies keep ~1e-12° of export noise in channels CMU never recorded.)
        if np.ptp(frames[:, rotation], axis=0).max(initial=0.0) < 1e-6:
            still.add(name)
    return names, parents, still


@pytest.fixture(scope="module")
def cmu_clips():
    """Every clip of the folder, loaded once: ``{stem: (motion, mapping, still names)}``
    (measured: 54 clips in ~6 s on 2 cores)."""
    clips = {}
    for path in sorted(CMU_CLIPS.glob("*.bvh")):
        names, parents, still = _still_file_joints(path)
        mapping = map_bvh_joints(names, parents)
        clips[path.stem] = (_quiet_load(path), mapping, still)
    return clips


@needs_cmu_clips
def test_every_cmu_clip_drives_every_joint_a_garment_feels(cmu_clips):
    """Each canonical joint turns over the clip (by > 0.5°; the least-moving measured
    turns 1.9°), except toes and hands the file has no joint for, and joints whose own
    channels the file never changes: CMU records no clavicle or finger motion, so our
    collars (and, in 16_*, hands) keep their rest relation to the spine (wrist)."""
    assert len(cmu_clips) >= 54
    for stem, (motion, mapping, still) in cmu_clips.items():
        shape = (motion.num_frames, len(JOINT_NAMES))
        local = Rotation.from_rotvec(motion.rotations.reshape(-1, 3)).as_matrix()
        relative = _relative(local.reshape(*shape, 3, 3)).reshape(-1, 3, 3)
        turned = np.degrees(np.linalg.norm(Rotation.from_matrix(relative).as_rotvec(), axis=-1))
        turned = turned.reshape(shape).max(axis=0)  # (24,) degrees
        held = {j for j, name in mapping.items() if name in still}
        assert held <= {"L_collar", "R_collar", "L_hand", "R_hand"}, (stem, held)
        expected = [
            j for j in JOINT_NAMES
            if j not in held and (j in mapping or j not in TOES_AND_HANDS)
        ]  # fmt: skip
        idle = [j for j in expected if turned[JOINT_INDEX[j]] <= 0.5]
        assert not idle, (stem, idle)
        if "spine3" not in mapping:  # Poser names: chest shared in halves
            assert np.allclose(_local(motion, "spine2"), _local(motion, "spine3"), atol=1e-9)


@needs_cmu_clips
@pytest.mark.parametrize("clip", ["16_01", "16_02"])
def test_original_names_clips_follow_the_recording(cmu_clips, clip):
    """The ``16_*`` clips (original CMU names, refused before): every limb bone points
    where the file's does."""
    motion, mapping, _ = cmu_clips[clip]
    errors = _bone_errors(motion, CMU_CLIPS / f"{clip}.bvh", mapping, LIMB_BONES)
    assert max(float(v.max()) for v in errors.values()) < 0.1
