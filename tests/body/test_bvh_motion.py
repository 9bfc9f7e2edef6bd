"""BVH motions: the joint-name table, user joint maps, rest-pose retargeting and units
(issue 13 item 3).

The retargeting tests compare our skeleton's forward kinematics with the BVH file's own,
computed here by a separate tokenizer and FK (not the library's ``bvh``-package path),
on tiny hand-made hierarchies and on the real CMU clips in ``../shared/real-world``
(third-party data beside the repository, never in it; those tests skip when it is
absent, as in a user's clone).
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest
import torch
from scipy.spatial.transform import Rotation

from gnngarment.body.bvh_motion import (
    BVH_JOINT_CANDIDATES,
    DEFAULT_REST_JOINTS,
    Y_UP_TO_CANONICAL,
    UnmappedJointsWarning,
    load_bvh_motion,
    map_bvh_joints,
    normalize_joint_name,
    read_joint_map,
)
from gnngarment.body.motion import MotionError
from gnngarment.body.motion_io import load_motion
from gnngarment.body.skeleton import JOINT_INDEX, JOINT_NAMES, forward_kinematics

REAL_WORLD = Path(__file__).resolve().parents[2].parent / "shared" / "real-world"
MOTIONS = REAL_WORLD / "motions"
needs_real_world = pytest.mark.skipif(
    not (MOTIONS / "cmu_131_01.bvh").is_file(),
    reason=f"{MOTIONS} is absent: the CMU BVH clips are third-party test data kept in "
    "../shared/real-world beside the repository, not in a clone",
)

# ---- hand-made hierarchies --------------------------------------------------------------

# cgspeed conversion of CMU (LeftShoulder = collar, LeftArm = upper arm), Y up, T-pose rest.
CGSPEED = [
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

# The CMU skeleton of the real clips (131_*): LeftHip/LeftKnee/LeftAnkle, LeftCollar with
# LeftShoulder as the UPPER ARM, lowerback/Chest/Chest2/lowerneck, zero-offset lhand;
# rest pose with arms down and legs splayed (offsets rounded from cmu_131_01.bvh).
CMU131 = [
    ("Hips", None, (0, 0, 0)),
    ("LHipJoint", "Hips", (0, 0, 0)), ("LeftHip", "LHipJoint", (1.25, -1.64, 0.72)),
    ("LeftKnee", "LeftHip", (2.49, -6.85, 0)), ("LeftAnkle", "LeftKnee", (2.37, -6.51, 0)),
    ("LeftToe", "LeftAnkle", (0.15, -0.41, 2.21)),
    ("RHipJoint", "Hips", (0, 0, 0)), ("RightHip", "RHipJoint", (-1.18, -1.64, 0.72)),
    ("RightKnee", "RightHip", (-2.47, -6.77, 0)), ("RightAnkle", "RightKnee", (-2.38, -6.55, 0)),
    ("RightToe", "RightAnkle", (-0.17, -0.48, 2.03)),
    ("lowerback", "Hips", (0, 0, 0)), ("Chest", "lowerback", (-0.02, 1.99, 0)),
    ("Chest2", "Chest", (-0.01, 1.99, -0.01)), ("lowerneck", "Chest2", (0, 0, 0)),
    ("Neck", "lowerneck", (0, 1.61, 0.11)), ("Head", "Neck", (-0.01, 1.6, 0.01)),
    ("LeftCollar", "Chest2", (0, 0, 0)), ("LeftShoulder", "LeftCollar", (3.05, 1.47, -0.02)),
    ("LeftElbow", "LeftShoulder", (0, -4.25, 0)), ("LeftWrist", "LeftElbow", (0, -3.28, 0)),
    ("lhand", "LeftWrist", (0, 0, 0)), ("LFingers", "lhand", (0, -0.66, 0)),
    ("LThumb", "LeftWrist", (0, 0, 0)),
    ("RightCollar", "Chest2", (0, 0, 0)), ("RightShoulder", "RightCollar", (-2.84, 1.32, -0.23)),
    ("RightElbow", "RightShoulder", (0, -4.46, 0)), ("RightWrist", "RightElbow", (0, -3.44, 0)),
    ("rhand", "RightWrist", (0, 0, 0)), ("RFingers", "rhand", (0, -0.62, 0)),
]  # fmt: skip

LIMB_BONES = [
    (f"{s}_{a}", f"{s}_{b}")
    for s in "LR"
    for a, b in (("hip", "knee"), ("knee", "ankle"), ("shoulder", "elbow"), ("elbow", "wrist"))
]
CMU_NAMES = {
    "pelvis": "Hips", "L_hip": "LeftHip", "R_hip": "RightHip", "L_knee": "LeftKnee",
    "R_knee": "RightKnee", "L_ankle": "LeftAnkle", "R_ankle": "RightAnkle",
    "L_shoulder": "LeftShoulder", "R_shoulder": "RightShoulder", "L_elbow": "LeftElbow",
    "R_elbow": "RightElbow", "L_wrist": "LeftWrist", "R_wrist": "RightWrist",
}  # fmt: skip


def _names_parents(joints):
    names = [n for n, _, _ in joints]
    return names, [-1 if p is None else names.index(p) for _, p, _ in joints]


def _write_bvh(path, joints, frames, orders=None, frame_time=1 / 120):
    """A BVH file; ``frames`` ``(T, 3 + 3B)``: root position, then each joint's three
    rotation channels (degrees) in its order (``orders[name]``, default ``"ZYX"``)."""
    orders = orders or {}
    children: dict = {}
    for name, parent, _ in joints:
        children.setdefault(parent, []).append(name)
    offsets = {name: offset for name, _, offset in joints}
    lines = []

    def emit(name, depth):
        pad = "  " * depth
        lines.append(f"{pad}{'ROOT' if depth == 0 else 'JOINT'} {name}\n{pad}{{")
        lines.append(f"{pad}  OFFSET {' '.join(f'{v:.6f}' for v in offsets[name])}")
        rotations = " ".join(f"{axis}rotation" for axis in orders.get(name, "ZYX"))
        position = "Xposition Yposition Zposition " if depth == 0 else ""
        lines.append(f"{pad}  CHANNELS {6 if depth == 0 else 3} {position}{rotations}")
        for child in children.get(name, []):
            emit(child, depth + 1)
        if not children.get(name):
            lines.append(f"{pad}  End Site\n{pad}  {{\n{pad}    OFFSET 0 0 0\n{pad}  }}")
        lines.append(f"{pad}}}")

    emit(children[None][0], 0)
    rows = "\n".join(" ".join(f"{v:.9f}" for v in row) for row in np.atleast_2d(frames))
    path.write_text(
        "HIERARCHY\n" + "\n".join(lines)
        + f"\nMOTION\nFrames: {len(np.atleast_2d(frames))}\nFrame Time: {frame_time:.7f}\n"
        + rows + "\n"
    )  # fmt: skip
    return path


def _frames_from_rotations(joints, root_position, local, orders=None):
    """BVH frame rows from root positions ``(T, 3)`` and local rotation matrices
    ``(T, B, 3, 3)`` (in the file's joint order)."""
    orders = orders or {}
    columns = [root_position]
    for b, (name, _, _) in enumerate(joints):
        order = orders.get(name, "ZYX")
        columns.append(Rotation.from_matrix(local[:, b]).as_euler(order, degrees=True))
    return np.concatenate(columns, axis=1)


def _random_motion(joints, frames=12, seed=0, spread=0.6):
    rng = np.random.default_rng(seed)
    local = (
        Rotation.from_rotvec(spread * rng.standard_normal((frames * len(joints), 3)))
        .as_matrix()
        .reshape(frames, len(joints), 3, 3)
    )
    root = np.cumsum(rng.standard_normal((frames, 3)), axis=0)
    return root, local


def _reparameterize_rest(joints, local, turns):
    """The same recorded motion on a skeleton whose rest pose differs: the segment of
    each joint in ``turns`` is rotated by ``turns[name]`` (BVH world frame) in the rest
    pose. Child offsets turn with it and the channels compensate (``G' = G Dᵀ``), so
    every frame puts every joint at the same world position."""
    names, parents = _names_parents(joints)
    eye = np.eye(3)
    turn = [np.asarray(turns.get(n, eye)) for n in names]
    new_joints = [
        (name, parent, tuple(turn[parents[b]] @ np.asarray(offset, float)) if parent else offset)
        for b, (name, parent, offset) in enumerate(joints)
    ]
    new_local = np.empty_like(local)
    for b in range(len(names)):
        before = turn[parents[b]] if parents[b] >= 0 else eye
        new_local[:, b] = before @ local[:, b] @ turn[b].T
    return new_joints, new_local


# ---- an independent BVH reader and forward kinematics ----------------------------------------


def _parse_bvh(path):
    """(names, parents, offsets (B, 3), channels, frames (T, C)) by plain tokenizing."""
    tokens = Path(path).read_text().split()
    names, parents, offsets, channels = [], [], [], []
    stack, i, current = [], 0, None
    while tokens[i] != "MOTION":
        token = tokens[i]
        if token in ("ROOT", "JOINT"):
            names.append(tokens[i + 1])
            parents.append(stack[-1] if stack else -1)
            current, i = len(names) - 1, i + 2
        elif token == "End":
            current, i = None, i + 2
        elif token == "{":
            stack.append(current)
            i += 1
        elif token == "}":
            stack.pop()
            i += 1
        elif token == "OFFSET":
            if current is not None:
                offsets.append([float(v) for v in tokens[i + 1 : i + 4]])
            i += 4
        elif token == "CHANNELS":
            count = int(tokens[i + 1])
            channels.append(tokens[i + 2 : i + 2 + count])
            i += 2 + count
        else:
            i += 1
    count = int(tokens[i + 2])
    frames = np.array(tokens[i + 6 :], dtype=float).reshape(count, -1)
    return names, parents, np.array(offsets), channels, frames


def _bvh_positions(path):
    """World joint positions ``(T, B, 3)`` of a BVH file in its own frame and units."""
    names, parents, offsets, channels, frames = _parse_bvh(path)
    rotations = np.zeros((len(frames), len(names), 3, 3))
    positions = np.zeros((len(frames), len(names), 3))
    column = 0
    for b, joint_channels in enumerate(channels):
        values = frames[:, column : column + len(joint_channels)]
        column += len(joint_channels)
        rot = [(k, c[0]) for k, c in enumerate(joint_channels) if c.endswith("rotation")]
        local = Rotation.from_euler(
            "".join(a for _, a in rot), values[:, [k for k, _ in rot]], degrees=True
        ).as_matrix()
        if parents[b] < 0:
            rotations[:, b] = local
            positions[:, b] = offsets[b]
            for k, c in enumerate(joint_channels):
                if c.endswith("position"):
                    positions[:, b, "XYZ".index(c[0])] += values[:, k]
        else:
            p = parents[b]
            rotations[:, b] = rotations[:, p] @ local
            positions[:, b] = positions[:, p] + rotations[:, p] @ offsets[b]
    return names, positions


def _our_joints(motion, rest_joints=DEFAULT_REST_JOINTS):
    rotations, translation = motion.to_torch(torch.float64)
    _, joints = forward_kinematics(rotations, torch.as_tensor(rest_joints), translation)
    return joints.numpy()


def _angles(ours, theirs):
    cos = np.sum(ours * theirs, -1) / (
        np.linalg.norm(ours, axis=-1) * np.linalg.norm(theirs, axis=-1)
    )
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


def _bone_errors(motion, path, names_of, bones, rest_joints=DEFAULT_REST_JOINTS, up="y"):
    """Per-frame angles (degrees) between our bones and the BVH's, ``{bone: (T,)}``."""
    ours = _our_joints(motion, rest_joints)
    names, positions = _bvh_positions(path)
    positions = positions @ (Y_UP_TO_CANONICAL if up == "y" else np.eye(3)).T
    index = {n: i for i, n in enumerate(names)}
    return {
        (a, b): _angles(
            ours[:, JOINT_INDEX[b]] - ours[:, JOINT_INDEX[a]],
            positions[:, index[names_of[b]]] - positions[:, index[names_of[a]]],
        )
        for a, b in bones
    }


def _quiet_load(*args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UnmappedJointsWarning)
        return load_bvh_motion(*args, **kwargs)


# ---- names ----------------------------------------------------------------------------------


def test_normalize_joint_name():
    assert normalize_joint_name("mixamorig:LeftUpLeg") == "leftupleg"
    assert normalize_joint_name("mixamorig_Hips") == "hips"
    assert normalize_joint_name("Bip01 L Thigh") == "lthigh"
    assert normalize_joint_name("thigh_l") == "thighl"
    assert normalize_joint_name("Character1|L_Knee") == "lknee"


def _chain(*spec):
    """(names, parents) of a hierarchy written as ``"name<parent"`` strings."""
    names = [s.split("<")[0] for s in spec]
    parents = [names.index(s.split("<")[1]) if "<" in s else -1 for s in spec]
    return names, parents


def _limbs(
    prefix, hip, knee, ankle, toe, collar, arm, elbow, wrist, hand, spine_top, pelvis="Hips"
):
    out = []
    for side, short in (("Left", "L"), ("Right", "R")):

        def n(template, side=side, short=short):
            return prefix + template.format(side=side, s=short)

        legs = [f"{n(hip)}<{prefix}{pelvis}", f"{n(knee)}<{n(hip)}", f"{n(ankle)}<{n(knee)}"]
        legs += [f"{n(toe)}<{n(ankle)}"] if toe else []
        top = f"{n(collar)}<{spine_top}" if collar else None
        arms = ([top] if top else []) + [
            f"{n(arm)}<{n(collar) if collar else spine_top}", f"{n(elbow)}<{n(arm)}",
            f"{n(wrist)}<{n(elbow)}",
        ] + ([f"{n(hand)}<{n(wrist)}"] if hand else [])  # fmt: skip
        out += legs + arms
    return out


@pytest.mark.parametrize(
    ("spec", "expected"),
    [
        pytest.param(  # cgspeed: LeftShoulder is the collar (LeftArm follows)
            _chain(
                "Hips",
                "LowerBack<Hips",
                "Spine<LowerBack",
                "Spine1<Spine",
                "Neck<Spine1",
                "Neck1<Neck",
                "Head<Neck1",
                *_limbs(
                    "",
                    "{side}UpLeg",
                    "{side}Leg",
                    "{side}Foot",
                    "{side}ToeBase",
                    "{side}Shoulder",
                    "{side}Arm",
                    "{side}ForeArm",
                    "{side}Hand",
                    "{side}FingerBase",
                    "Spine1",
                ),
            ),
            {
                "spine1": "LowerBack",
                "spine2": "Spine",
                "spine3": "Spine1",
                "neck": "Neck",
                "L_collar": "LeftShoulder",
                "L_shoulder": "LeftArm",
                "L_ankle": "LeftFoot",
                "L_foot": "LeftToeBase",
                "L_wrist": "LeftHand",
                "L_hand": "LeftFingerBase",
            },
            id="cgspeed",
        ),
        pytest.param(  # CMU's own names: LeftShoulder is the upper arm (LeftElbow follows)
            _names_parents(CMU131),
            {
                "L_hip": "LeftHip",
                "L_knee": "LeftKnee",
                "L_ankle": "LeftAnkle",
                "L_foot": "LeftToe",
                "spine1": "lowerback",
                "spine2": "Chest",
                "spine3": "Chest2",
                "neck": "Neck",
                "L_collar": "LeftCollar",
                "L_shoulder": "LeftShoulder",
                "L_elbow": "LeftElbow",
                "L_wrist": "LeftWrist",
                "L_hand": "LFingers",
                "R_shoulder": "RightShoulder",
            },
            id="cmu-131",
        ),
        pytest.param(  # Mixamo, namespaced
            _chain(
                "mixamorig:Hips",
                "mixamorig:Spine<mixamorig:Hips",
                "mixamorig:Spine1<mixamorig:Spine",
                "mixamorig:Spine2<mixamorig:Spine1",
                "mixamorig:Neck<mixamorig:Spine2",
                "mixamorig:Head<mixamorig:Neck",
                *_limbs(
                    "mixamorig:",
                    "{side}UpLeg",
                    "{side}Leg",
                    "{side}Foot",
                    "{side}ToeBase",
                    "{side}Shoulder",
                    "{side}Arm",
                    "{side}ForeArm",
                    "{side}Hand",
                    "{side}HandMiddle1",
                    "mixamorig:Spine2",
                ),
            ),
            {
                "pelvis": "mixamorig:Hips",
                "spine1": "mixamorig:Spine",
                "spine2": "mixamorig:Spine1",
                "spine3": "mixamorig:Spine2",
                "L_collar": "mixamorig:LeftShoulder",
                "L_shoulder": "mixamorig:LeftArm",
                "L_wrist": "mixamorig:LeftHand",
                "L_hand": "mixamorig:LeftHandMiddle1",
                "R_foot": "mixamorig:RightToeBase",
            },
            id="mixamo",
        ),
        pytest.param(  # MotionBuilder/HumanIK: a reference root, four spine joints, no toes
            _chain(
                "reference",
                "Hips<reference",
                "Spine<Hips",
                "Spine1<Spine",
                "Spine2<Spine1",
                "Spine3<Spine2",
                "Neck<Spine3",
                "Head<Neck",
                *_limbs(
                    "",
                    "{side}UpLeg",
                    "{side}Leg",
                    "{side}Foot",
                    None,
                    "{side}Shoulder",
                    "{side}Arm",
                    "{side}ForeArm",
                    "{side}Hand",
                    None,
                    "Spine3",
                ),
            ),
            {
                "pelvis": "Hips",
                "spine1": "Spine",
                "spine2": "Spine1",
                "spine3": "Spine2",
                "L_ankle": "LeftFoot",
                "L_wrist": "LeftHand",
                "L_collar": "LeftShoulder",
            },
            id="motionbuilder",
        ),
        pytest.param(  # SMPL names: L_Foot is the toes, L_Shoulder the upper arm
            _chain(
                "Pelvis",
                "Spine1<Pelvis",
                "Spine2<Spine1",
                "Spine3<Spine2",
                "Neck<Spine3",
                "Head<Neck",
                *_limbs(
                    "",
                    "{s}_Hip",
                    "{s}_Knee",
                    "{s}_Ankle",
                    "{s}_Foot",
                    "{s}_Collar",
                    "{s}_Shoulder",
                    "{s}_Elbow",
                    "{s}_Wrist",
                    "{s}_Hand",
                    "Spine3",
                    pelvis="Pelvis",
                ),
            ),
            {
                "L_hip": "L_Hip",
                "L_ankle": "L_Ankle",
                "L_foot": "L_Foot",
                "L_collar": "L_Collar",
                "L_shoulder": "L_Shoulder",
                "L_wrist": "L_Wrist",
                "L_hand": "L_Hand",
                "spine3": "Spine3",
            },
            id="smpl",
        ),
        pytest.param(  # Unreal Engine mannequin names
            _chain("pelvis", "spine_01<pelvis", "spine_02<spine_01", "spine_03<spine_02",
                   "neck_01<spine_03", "head<neck_01",
                   *_limbs("", "thigh_{s}", "calf_{s}", "foot_{s}", "ball_{s}", "clavicle_{s}",
                           "upperarm_{s}", "lowerarm_{s}", "hand_{s}", "middle_01_{s}",
                           "spine_03", pelvis="pelvis")),
            {"pelvis": "pelvis", "spine1": "spine_01", "spine3": "spine_03", "neck": "neck_01",
             "L_hip": "thigh_L", "L_knee": "calf_L", "L_ankle": "foot_L", "L_foot": "ball_L",
             "L_collar": "clavicle_L", "L_shoulder": "upperarm_L", "L_elbow": "lowerarm_L",
             "L_wrist": "hand_L", "L_hand": "middle_01_L"},
            id="unreal",
        ),
        pytest.param(  # 3ds Max Biped: thighs under the first spine joint, collars under the neck
            _chain("Bip01", "Bip01 Pelvis<Bip01", "Bip01 Spine<Bip01 Pelvis",
                   "Bip01 Spine1<Bip01 Spine", "Bip01 Spine2<Bip01 Spine1",
                   "Bip01 Neck<Bip01 Spine2", "Bip01 Head<Bip01 Neck",
                   *_limbs("Bip01 ", "{s} Thigh", "{s} Calf", "{s} Foot", "{s} Toe0",
                           "{s} Clavicle", "{s} UpperArm", "{s} Forearm", "{s} Hand",
                           "{s} Finger2", "Bip01 Neck", pelvis="Spine")),
            {"pelvis": "Bip01 Pelvis", "spine1": "Bip01 Spine", "spine3": "Bip01 Spine2",
             "L_hip": "Bip01 L Thigh", "L_ankle": "Bip01 L Foot", "L_foot": "Bip01 L Toe0",
             "L_collar": "Bip01 L Clavicle", "L_shoulder": "Bip01 L UpperArm",
             "L_wrist": "Bip01 L Hand", "L_hand": "Bip01 L Finger2"},
            id="biped",
        ),
    ],
)  # fmt: skip
def test_name_table_covers_the_common_conventions(spec, expected):
    names, parents = spec
    mapping = map_bvh_joints(names, parents)
    assert {k: mapping.get(k) for k in expected} == expected
    assert len(set(mapping.values())) == len(mapping)  # no BVH joint plays two joints


def test_left_shoulder_is_decided_by_the_hierarchy():
    """LeftShoulder with LeftElbow/LeftForeArm right below is the upper arm; with LeftArm
    below it is the collar."""
    base = ["Hips", "Spine<Hips", "Neck<Spine", "Head<Neck", "LeftUpLeg<Hips",
            "LeftLeg<LeftUpLeg", "LeftFoot<LeftLeg", "RightUpLeg<Hips", "RightLeg<RightUpLeg",
            "RightFoot<RightLeg"]  # fmt: skip
    arms = []
    for side in ("Left", "Right"):
        arms += [f"{side}Shoulder<Spine", f"{side}ForeArm<{side}Shoulder",
                 f"{side}Hand<{side}ForeArm"]  # fmt: skip
    mapping = map_bvh_joints(*_chain(*base, *arms))
    assert mapping["L_shoulder"] == "LeftShoulder" and "L_collar" not in mapping
    assert mapping["L_elbow"] == "LeftForeArm"
    arms = []
    for side in ("Left", "Right"):
        arms += [f"{side}Shoulder<Spine", f"{side}Arm<{side}Shoulder",
                 f"{side}ForeArm<{side}Arm", f"{side}Hand<{side}ForeArm"]  # fmt: skip
    mapping = map_bvh_joints(*_chain(*base, *arms))
    assert mapping["L_collar"] == "LeftShoulder" and mapping["L_shoulder"] == "LeftArm"


def test_every_canonical_joint_has_candidates():
    assert set(BVH_JOINT_CANDIDATES) == set(JOINT_NAMES)
    assert all(BVH_JOINT_CANDIDATES[j] for j in JOINT_NAMES)


# ---- joint maps -------------------------------------------------------------------------------

# Unreal-like names the table does not know for the legs.
ODD_LEGS = [(n.replace("LeftUpLeg", "Oberschenkel_L").replace("LeftLeg", "Knie_L"), p and
             p.replace("LeftUpLeg", "Oberschenkel_L").replace("LeftLeg", "Knie_L"), o)
            for n, p, o in CGSPEED]  # fmt: skip


@pytest.mark.parametrize("suffix", [".json", ".yaml"])
def test_joint_map_file_names_unknown_joints(tmp_path, suffix):
    names, parents = _names_parents(ODD_LEGS)
    with pytest.raises(MotionError, match="L_hip") as info:
        map_bvh_joints(names, parents, source="odd.bvh")
    assert "--joint-map" in str(info.value)
    entries = {"L_hip": "Oberschenkel_L", "L_knee": "Knie_L", "L_hand": None}
    path = tmp_path / f"map{suffix}"
    if suffix == ".json":
        path.write_text(json.dumps(entries))
    else:
        path.write_text("L_hip: Oberschenkel_L\nL_knee: Knie_L\nL_hand: null\n")
    assert read_joint_map(path) == entries
    mapping = map_bvh_joints(names, parents, path, source="odd.bvh")
    assert mapping["L_hip"] == "Oberschenkel_L" and mapping["L_knee"] == "Knie_L"
    assert "L_hand" not in mapping and mapping["R_hand"] == "RightFingerBase"


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ('{"L_hipp": "LeftUpLeg"}', "key 'L_hipp' is not a canonical joint"),
        ('{"L_hip": 3}', "value of 'L_hip' must be a joint name or null"),
        ('{"L_knee": null}', "'L_knee' to null, but that joint is required"),
        ('["L_hip", "LeftUpLeg"]', "must be a mapping"),
        ('{"L_hip": "LeftUpLeg",', "not a readable joint map"),
        ('{"L_hip": "Thigh_L"}', "'L_hip' → 'Thigh_L': no joint 'Thigh_L'"),
        ('{"L_hip": "LeftUpLeg", "R_hip": "LeftUpLeg"}', "uses 'LeftUpLeg' for two joints"),
        ('{"L_knee": "RightLeg"}', "does not hang under"),
    ],
)
def test_bad_joint_map_names_the_file_and_key(tmp_path, text, match):
    path = tmp_path / "my_map.json"
    path.write_text(text)
    bvh = _write_bvh(tmp_path / "clip.bvh", CGSPEED, np.zeros((2, 3 + 3 * len(CGSPEED))))
    with pytest.raises(MotionError, match=match) as info:
        _quiet_load(bvh, joint_map=path)
    message = str(info.value)
    assert "\n" not in message and message.startswith(str(path))


def test_joint_map_file_type_and_absence(tmp_path):
    (tmp_path / "map.txt").write_text("{}")
    with pytest.raises(MotionError, match=r"map\.txt.*\.json, \.yaml or \.yml"):
        read_joint_map(tmp_path / "map.txt")
    with pytest.raises(MotionError, match="nope.json: joint map file not found"):
        read_joint_map(tmp_path / "nope.json")


def test_swapped_legs_in_a_joint_map_are_caught_by_the_bone_check(tmp_path):
    """A consistent but wrong map (left and right legs swapped) loads, but our legs then
    disagree with the recording — what the real-clip tests below would catch."""
    root, local = _random_motion(CGSPEED, frames=8, seed=3, spread=0.4)
    path = _write_bvh(tmp_path / "clip.bvh", CGSPEED, _frames_from_rotations(CGSPEED, root, local))
    names = {
        "L_hip": "LeftUpLeg",
        "L_knee": "LeftLeg",
        "L_ankle": "LeftFoot",
        "R_hip": "RightUpLeg",
        "R_knee": "RightLeg",
        "R_ankle": "RightFoot",
    }
    swapped = {k.replace("L_", "@").replace("R_", "L_").replace("@", "R_"): v
               for k, v in names.items()}  # fmt: skip
    bones = [("L_hip", "L_knee"), ("R_knee", "R_ankle")]
    good = _bone_errors(_quiet_load(path), path, names, bones)
    bad = _bone_errors(_quiet_load(path, joint_map=swapped), path, names, bones)
    assert max(float(v.max()) for v in good.values()) < 1e-4
    assert min(float(np.median(v)) for v in bad.values()) > 20.0


# ---- retargeting on hand-made hierarchies ----------------------------------------------------


def test_bvh_cgspeed_tpose(tmp_path):
    frames = np.zeros((3, 3 + 3 * len(CGSPEED)))
    frames[:, 1] = 17.0
    frames[1:, 0] = [5.0, 10.0]
    names, _ = _names_parents(CGSPEED)
    frames[1:, 3 + 3 * names.index("LeftForeArm")] = 30.0  # its Zrotation
    frames[1:, 3 + 3 * names.index("Neck1") + 2] = 20.0  # Neck1 Xrotation: folds into head
    path = _write_bvh(tmp_path / "01_01.bvh", CGSPEED, frames)
    with pytest.warns(UnmappedJointsWarning, match="LHipJoint.*Neck1|Neck1.*LHipJoint") as record:
        motion = load_bvh_motion(path)
    assert "LThumb" in str(record[0].message)
    assert motion.fps == pytest.approx(120.0, rel=1e-3) and motion.num_frames == 3
    # A T-pose rest stays a T-pose: arms along ±X; the body frame is upright to < 1°.
    rest = _our_joints(motion[0])[0]
    for side, sign in (("L", 1), ("R", -1)):
        arm = rest[JOINT_INDEX[f"{side}_wrist"]] - rest[JOINT_INDEX[f"{side}_shoulder"]]
        assert np.allclose(arm / np.linalg.norm(arm), [sign, 0, 0], atol=1e-9)
    assert np.linalg.norm(motion.rotations[0, 0]) < np.radians(1)
    # BVH Z (front) is canonical −Y: 30° about BVH Z on the left forearm.
    expected = Rotation.from_matrix(
        Y_UP_TO_CANONICAL @ Rotation.from_euler("z", 30, degrees=True).as_matrix()
        @ Y_UP_TO_CANONICAL.T
    ).as_rotvec()  # fmt: skip
    assert np.allclose(motion.rotations[1, JOINT_INDEX["L_elbow"]], expected, atol=1e-9)
    assert np.allclose(motion.rotations[2, JOINT_INDEX["head"]], np.radians([20, 0, 0]), atol=1e-6)
    # Root translation: relative to frame 0, scaled so the legs (7 + 7 units) match ours.
    ours = np.mean([
        np.linalg.norm(DEFAULT_REST_JOINTS[JOINT_INDEX[f"{s}_knee"]]
                       - DEFAULT_REST_JOINTS[JOINT_INDEX[f"{s}_hip"]])
        + np.linalg.norm(DEFAULT_REST_JOINTS[JOINT_INDEX[f"{s}_ankle"]]
                         - DEFAULT_REST_JOINTS[JOINT_INDEX[f"{s}_knee"]])
        for s in "LR"
    ])  # fmt: skip
    assert np.allclose(motion.translation[2], [10 * ours / 14, 0, 0])


# cgspeed with twist joints that carry an offset (forearm and shin split in two), listed
# depth-first like every hierarchy here (the order of the frame columns).
TWIST = []
for _name, _parent, _offset in CGSPEED:
    if _name == "LeftHand":
        TWIST.append(("LeftForeArmTwist", "LeftForeArm", (2, 0, 0)))
        _parent, _offset = "LeftForeArmTwist", (2, 0, 0)
    if _name == "RightFoot":
        TWIST.append(("RightLegTwist", "RightLeg", (0, -3.5, 0)))
        _parent, _offset = "RightLegTwist", (0, -3.5, 0)
    TWIST.append((_name, _parent, _offset))
FOOT_AND_HAND = [("L_ankle", "L_foot"), ("R_ankle", "R_foot"), ("L_wrist", "L_hand")]


@pytest.mark.parametrize(
    "hierarchy", [CGSPEED, CMU131, TWIST], ids=["cgspeed", "cmu-131", "twist-joints"]
)
def test_limb_bones_point_where_the_bvh_bones_do(tmp_path, hierarchy):
    """Random rotations on every joint, intermediate ones included (CMU's zero-offset
    lhand/lowerneck, cgspeed's Neck1, twist joints with an offset): every limb bone of
    ours is parallel to the BVH's."""
    root, local = _random_motion(hierarchy, frames=10, seed=1)
    path = _write_bvh(tmp_path / "clip.bvh", hierarchy,
                      _frames_from_rotations(hierarchy, root, local))  # fmt: skip
    names_of = dict(map_bvh_joints(*_names_parents(hierarchy)))
    errors = _bone_errors(_quiet_load(path), path, names_of, LIMB_BONES + FOOT_AND_HAND)
    assert max(float(v.max()) for v in errors.values()) < 1e-4


def _global_rotation(motion, joint):
    """``(T, 3, 3)`` world rotation of a canonical joint: its chain of local rotations."""
    from gnngarment.body.skeleton import JOINT_PARENTS

    chain, j = [], JOINT_INDEX[joint]
    while j >= 0:
        chain.append(j)
        j = JOINT_PARENTS[j]
    out = np.broadcast_to(np.eye(3), (motion.num_frames, 3, 3))
    for j in reversed(chain):
        out = out @ Rotation.from_rotvec(motion.rotations[:, j]).as_matrix()
    return out


def test_a_zero_offset_joint_passes_its_twist_on(tmp_path):
    """CMU's lhand sits on the wrist (offset 0): its rotation, a twist about the hand's
    own axis, turns our wrist although no bone direction changes."""
    names, _ = _names_parents(CMU131)
    frames = np.zeros((2, 3 + 3 * len(CMU131)))
    frames[1, 3 + 3 * names.index("lhand") + 1] = 40.0  # its Yrotation: along the hand
    motion = _quiet_load(_write_bvh(tmp_path / "twist.bvh", CMU131, frames))
    wrist = _global_rotation(motion, "L_wrist")
    twist = Y_UP_TO_CANONICAL @ _turn("y", 40) @ Y_UP_TO_CANONICAL.T
    assert np.allclose(wrist[1] @ wrist[0].T, twist, atol=1e-9)


def _turn(axis, degrees):
    return Rotation.from_euler(axis, degrees, degrees=True).as_matrix()


# Rest-pose changes (BVH frame: Y up, +X = the body's left): arms hanging down, legs
# splayed 20°, feet pointing down, elbows bent — CMU-like rests instead of the T-pose.
REST_CHANGES = {
    "LeftArm": _turn("z", -90), "LeftForeArm": _turn("z", -90), "LeftHand": _turn("z", -90),
    "RightArm": _turn("z", 90), "RightForeArm": _turn("zx", [90, 30]),
    "RightHand": _turn("z", 90),
    "LeftUpLeg": _turn("z", 20), "LeftLeg": _turn("z", 20), "LeftFoot": _turn("x", 40),
    "RightUpLeg": _turn("z", -20), "RightLeg": _turn("zx", [-20, -15]),
}  # fmt: skip


def test_an_arms_down_rest_plays_like_the_tpose_rest(tmp_path):
    """The same recording on a T-pose rest and on an arms-down, legs-splayed rest gives
    the same joint positions; without retargeting it does not (arms out, legs crossed)."""
    root, local = _random_motion(CGSPEED, frames=10, seed=2, spread=0.5)
    tpose = _write_bvh(tmp_path / "tpose.bvh", CGSPEED,
                       _frames_from_rotations(CGSPEED, root, local))  # fmt: skip
    joints, turned_local = _reparameterize_rest(CGSPEED, local, REST_CHANGES)
    turned = _write_bvh(tmp_path / "down.bvh", joints,
                        _frames_from_rotations(joints, root, turned_local))  # fmt: skip
    a, b = _bvh_positions(tpose)[1], _bvh_positions(turned)[1]
    assert np.allclose(a, b, atol=1e-6)  # the construction: one recording, two rests
    reference = _our_joints(_quiet_load(tpose))
    assert np.allclose(_our_joints(_quiet_load(turned)), reference, atol=1e-6)
    raw = _our_joints(_quiet_load(turned, retarget=False))
    wrist = JOINT_INDEX["L_wrist"]
    assert np.linalg.norm(raw[:, wrist] - reference[:, wrist], axis=-1).min() > 0.2


def test_the_rest_frame_of_an_arms_down_bvh_hangs_our_arms_down(tmp_path):
    joints, _ = _reparameterize_rest(CGSPEED, np.zeros((1, len(CGSPEED), 3, 3)), REST_CHANGES)
    path = _write_bvh(tmp_path / "rest.bvh", joints, np.zeros((1, 3 + 3 * len(joints))))
    ours = _our_joints(_quiet_load(path))[0]
    arm = ours[JOINT_INDEX["L_wrist"]] - ours[JOINT_INDEX["L_shoulder"]]
    assert np.degrees(np.arccos(-arm[2] / np.linalg.norm(arm))) < 1.0  # straight down


def test_up_axis_and_units(tmp_path):
    """A Z-up copy (auto-detected) and a centimetre copy (auto scale) load the same."""
    root, local = _random_motion(CGSPEED, frames=6, seed=4, spread=0.3)
    path = _write_bvh(tmp_path / "y.bvh", CGSPEED, _frames_from_rotations(CGSPEED, root, local))
    reference = _quiet_load(path)
    C = Y_UP_TO_CANONICAL
    z_joints = [(n, p, tuple(C @ np.asarray(o, float))) for n, p, o in CGSPEED]
    z_local = C @ local @ C.T
    z_path = _write_bvh(tmp_path / "z.bvh", z_joints,
                        _frames_from_rotations(z_joints, root @ C.T, z_local))  # fmt: skip
    for motion in (_quiet_load(z_path), _quiet_load(z_path, up_axis="z")):
        assert np.allclose(_our_joints(motion), _our_joints(reference), atol=1e-6)
    cm_joints = [(n, p, tuple(100 * np.asarray(o, float))) for n, p, o in CGSPEED]
    cm_path = _write_bvh(tmp_path / "cm.bvh", cm_joints,
                         _frames_from_rotations(cm_joints, 100 * root, local))  # fmt: skip
    cm = _quiet_load(cm_path)
    assert np.allclose(cm.translation, reference.translation, atol=1e-6)
    assert np.allclose(_quiet_load(path, scale=0.5).translation[-1], 0.5 * (root[-1] - root[0])
                       @ C.T)  # fmt: skip
    upside_down = [(n, p, tuple(-np.asarray(o, float))) for n, p, o in CGSPEED]
    flipped = _write_bvh(tmp_path / "flip.bvh", upside_down, np.zeros((1, 3 + 3 * len(CGSPEED))))
    with pytest.raises(MotionError, match="flip.bvh: cannot tell the BVH up axis"):
        _quiet_load(flipped)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"scale": 0.0}, "scale must be a finite number > 0"),
        ({"scale": "metres"}, "scale must be a number or 'auto'"),
        ({"up_axis": "x"}, "up_axis must be 'auto', 'y' or 'z'"),
        ({"rest_joints": np.zeros((23, 3))}, "rest_joints must be finite"),
    ],
)
def test_bad_options_name_the_file(tmp_path, kwargs, match):
    path = _write_bvh(tmp_path / "opts.bvh", CGSPEED, np.zeros((1, 3 + 3 * len(CGSPEED))))
    with pytest.raises(MotionError, match=match) as info:
        _quiet_load(path, **kwargs)
    assert str(info.value).startswith(str(path))


def test_missing_joint_and_unreadable_files(tmp_path):
    joints = [(n, "LeftUpLeg" if p == "LeftLeg" else p, o) for n, p, o in CGSPEED
              if n != "LeftLeg"]  # fmt: skip
    path = _write_bvh(tmp_path / "broken.bvh", joints, np.zeros((2, 3 + 3 * len(joints))))
    with pytest.raises(MotionError, match="broken.bvh.*L_knee"):
        _quiet_load(path)
    (tmp_path / "garbage.bvh").write_text("HIERARCHY\nnonsense {")
    with pytest.raises(MotionError, match="garbage.bvh") as info:
        _quiet_load(tmp_path / "garbage.bvh")
    assert "\n" not in str(info.value)
    with pytest.raises(MotionError, match="missing.bvh: file not found"):
        load_bvh_motion(tmp_path / "missing.bvh")
    path = _write_bvh(tmp_path / "twice.bvh", CGSPEED, np.zeros((1, 3 + 3 * len(CGSPEED))))
    path.write_text(path.read_text().replace("JOINT RightFingerBase", "JOINT RightHand"))
    with pytest.raises(MotionError, match="twice.bvh: BVH joint names must be unique: RightHand"):
        _quiet_load(path)
    # Cut short: the motion section declares more frames than it holds.
    path = _write_bvh(tmp_path / "cut.bvh", CGSPEED, np.zeros((3, 3 + 3 * len(CGSPEED))))
    lines = path.read_text().splitlines()
    path.write_text("\n".join(lines[:-1]) + "\n")
    with pytest.raises(MotionError, match="cut.bvh: BVH declares 3 frames.*holds 2"):
        _quiet_load(path)


def test_load_motion_passes_the_joint_map(tmp_path):
    frames = np.zeros((2, 3 + 3 * len(ODD_LEGS)))
    path = _write_bvh(tmp_path / "odd.bvh", ODD_LEGS, frames)
    with pytest.raises(MotionError, match="L_hip"):
        load_motion(path)
    entries = {"L_hip": "Oberschenkel_L", "L_knee": "Knie_L"}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UnmappedJointsWarning)
        assert load_motion(path, joint_map=entries, fps=30).fps == 30
        # Another body's rest joints reach the retargeting: twice as large, twice the steps.
        frames[1, 0] = 4.0
        _write_bvh(path, ODD_LEGS, frames)
        small = load_motion(path, joint_map=entries)
        large = load_motion(path, joint_map=entries, rest_joints=2 * DEFAULT_REST_JOINTS)
    assert np.allclose(large.translation, 2 * small.translation) and small.translation[1, 0] > 0


def test_default_rest_joints_are_annys(anny_rest):
    assert np.abs(DEFAULT_REST_JOINTS - anny_rest.joints.numpy()).max() < 1e-3


# ---- the real CMU clips -------------------------------------------------------------------------

POSE_BONES = [("pelvis", "L_ankle"), ("pelvis", "R_ankle"), ("L_shoulder", "L_wrist"),
              ("R_shoulder", "R_wrist")]  # fmt: skip


@pytest.fixture(scope="module")
def cmu_clips():
    return {name: _quiet_load(MOTIONS / f"{name}.bvh")
            for name in ("cmu_131_01", "cmu_131_03", "cmu_scaled_131_01")}  # fmt: skip


@needs_real_world
def test_cmu_clips_map_onto_the_skeleton():
    names, parents, *_ = _parse_bvh(MOTIONS / "cmu_131_01.bvh")
    mapping = map_bvh_joints(names, parents)
    assert {k: mapping[k] for k in CMU_NAMES} == CMU_NAMES
    assert mapping["L_collar"] == "LeftCollar" and mapping["spine3"] == "Chest2"


@needs_real_world
@pytest.mark.parametrize("clip", ["cmu_131_01", "cmu_131_03"], ids=["walk", "hop"])
def test_cmu_clip_plays_the_recorded_motion(cmu_clips, anny_rest, clip):
    """Feet and hands follow the BVH's own forward kinematics on Anny's skeleton
    (measured: pelvis→ankle median 5°, shoulder→wrist 2–4°; limb bones exact); without
    the rest-pose retargeting the arms are 90° off and the legs 12–13° (crossed)."""
    path = MOTIONS / f"{clip}.bvh"
    rest = anny_rest.joints.numpy()
    errors = _bone_errors(cmu_clips[clip], path, CMU_NAMES, POSE_BONES, rest)
    for bone, angles in errors.items():
        assert np.median(angles) < 8.0, (bone, np.median(angles))
        assert np.percentile(angles, 95) < 15.0, (bone, np.percentile(angles, 95))
    limbs = _bone_errors(cmu_clips[clip], path, CMU_NAMES, LIMB_BONES, rest)
    assert max(float(v.max()) for v in limbs.values()) < 0.1
    raw = _bone_errors(_quiet_load(path, retarget=False), path, CMU_NAMES, POSE_BONES, rest)
    assert min(np.median(raw[b]) for b in POSE_BONES[2:]) > 60.0  # arms out
    assert min(np.median(raw[b]) for b in POSE_BONES[:2]) > 10.0  # legs pulled in
    # The root follows the recorded one, in metres, Z up.
    names, positions = _bvh_positions(path)
    root = positions[:, names.index("Hips")] @ Y_UP_TO_CANONICAL.T
    recorded = root - root[0]
    ratio = float(np.sum(cmu_clips[clip].translation * recorded) / np.sum(recorded**2))
    assert 0.050 < ratio < 0.060  # CMU unit ≈ 0.0564 m; our leg is 0.99 of the subject's
    assert np.allclose(cmu_clips[clip].translation, ratio * recorded, atol=1e-9)


@needs_real_world
def test_cmu_walk_speed_is_plausible(cmu_clips):
    walk = cmu_clips["cmu_131_01"]
    second = round(walk.fps)
    horizontal = walk.translation[:, :2]
    speed = np.linalg.norm(horizontal[second:] - horizontal[:-second], axis=1)  # m per 1 s
    assert 1.0 < speed.max() < 1.6  # measured 1.27 m/s
    assert np.all(np.abs(walk.translation[:, 2]) < 0.6)  # no flying off


@needs_real_world
def test_cmu_scaled_copy_loads_the_same(cmu_clips):
    """``cmu_scaled_131_01`` is the walk in metres: the auto scale is unit-independent."""
    walk, scaled = cmu_clips["cmu_131_01"], cmu_clips["cmu_scaled_131_01"]
    frames = min(walk.num_frames, scaled.num_frames)
    assert np.abs(walk.translation[:frames] - scaled.translation[:frames]).max() < 1e-5
    ours, theirs = _our_joints(walk[:frames]), _our_joints(scaled[:frames])
    assert np.abs(ours - theirs).max() < 1e-5  # measured 2 µm (the copy's rounding)
