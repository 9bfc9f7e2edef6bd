"""Reading motions from files: AMASS ``.npz``, BVH (CMU naming), CLOTH3D ``info.mat``.

All loaders return a canonical :class:`~gnngarment.body.motion.Motion` (Z up, T-pose
rest, world-aligned local axes; see :mod:`gnngarment.body.skeleton`). SMPL-convention
data (AMASS, CLOTH3D) has Y-up joint axes but a Z-up world (its root rotation includes
the +90° turn about X); it is converted by ``R'_j = C R_j Cᵀ`` for ``j ≥ 1`` and
``R'_0 = R_0 Cᵀ`` with ``C = Rx(+90°)``, which leaves world positions unchanged. BVH
(Y-up world and axes) is converted by ``C R_j Cᵀ`` for every joint and ``C t`` for the
translation.

Translation: by default the first frame's root translation is subtracted, so every
loaded motion starts with the pelvis at its rest position (``relative_translation``).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from gnngarment.body.motion import Motion, MotionError
from gnngarment.body.skeleton import JOINT_NAMES, JOINT_PARENTS, NUM_JOINTS

# SMPL (Y-up) body axes → canonical (Z-up) axes: a +90° rotation about X.
SMPL_TO_CANONICAL = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


class UnmappedJointsWarning(UserWarning):
    """Joints of a motion file that are not mapped onto the canonical skeleton."""


def motion_from_smpl(
    poses: np.ndarray,
    translation: np.ndarray,
    fps: float,
    name: str = "",
    world_y_up: bool = False,
    relative_translation: bool = True,
) -> Motion:
    """A canonical motion from SMPL-convention axis-angles.

    Args:
        poses: ``(T, 24, 3)`` or ``(T, 72)`` SMPL local axis-angles (Y-up joint axes).
        translation: ``(T, 3)`` SMPL ``transl``.
        fps: frame rate.
        name: label used in error messages.
        world_y_up: the world frame is Y-up too (BVH-like); else Z-up (AMASS, CLOTH3D).
        relative_translation: subtract the first frame's translation.
    """
    from scipy.spatial.transform import Rotation

    poses = np.asarray(poses, dtype=np.float64)
    translation = np.asarray(translation, dtype=np.float64)
    where = f"{name}: " if name else ""
    if poses.ndim == 2 and poses.shape[1] == NUM_JOINTS * 3:
        poses = poses.reshape(-1, NUM_JOINTS, 3)
    if poses.ndim != 3 or poses.shape[1:] != (NUM_JOINTS, 3):
        raise MotionError(f"{where}SMPL poses must be (T, 72) or (T, 24, 3), got {poses.shape}")
    if translation.shape != (poses.shape[0], 3):
        raise MotionError(
            f"{where}translation must be ({poses.shape[0]}, 3), got {translation.shape}"
        )
    if not np.all(np.isfinite(poses)) or not np.all(np.isfinite(translation)):
        raise MotionError(f"{where}poses/translation contain NaN or infinite values")
    C = SMPL_TO_CANONICAL
    mats = Rotation.from_rotvec(poses.reshape(-1, 3)).as_matrix().reshape(-1, NUM_JOINTS, 3, 3)
    converted = C @ mats @ C.T
    if not world_y_up:
        converted[:, 0] = mats[:, 0] @ C.T
    else:
        translation = translation @ C.T
    if relative_translation:
        translation = translation - translation[:1]
    rotations = Rotation.from_matrix(converted.reshape(-1, 3, 3)).as_rotvec()
    return Motion(rotations.reshape(-1, NUM_JOINTS, 3), translation, fps, name)


def load_amass_motion(path: str | Path, relative_translation: bool = True) -> Motion:
    """An AMASS ``.npz``: ``poses`` (T, 72 | 156 | 165), ``trans`` (T, 3), frame rate in
    ``mocap_framerate`` (or ``mocap_frame_rate``).

    The 22 body joints are the first 66 values. SMPL's two hand joints are the next 6
    values only for 72-wide (SMPL) poses; for SMPL-H (156) and SMPL-X (165) those values
    are finger/jaw/eye rotations, so the hands are left at rest.
    """
    path = Path(path)
    if not path.is_file():
        raise MotionError(f"{path}: file not found")
    try:
        data = np.load(path, allow_pickle=False)
    except Exception as error:
        raise MotionError(f"{path}: not a readable .npz file ({error})") from error
    for key in ("poses", "trans"):
        if key not in data:
            raise MotionError(f"{path}: AMASS file has no '{key}' array (keys: {list(data)})")
    fps_key = next((k for k in ("mocap_framerate", "mocap_frame_rate") if k in data), None)
    if fps_key is None:
        raise MotionError(f"{path}: AMASS file has no 'mocap_framerate'")
    poses = np.asarray(data["poses"], dtype=np.float64)
    if poses.ndim != 2 or poses.shape[1] not in (72, 156, 165):
        raise MotionError(f"{path}: 'poses' must be (T, 72|156|165), got {poses.shape}")
    body = np.zeros((poses.shape[0], 72))
    body[:, : 72 if poses.shape[1] == 72 else 66] = poses[:, : 72 if poses.shape[1] == 72 else 66]
    fps = float(np.asarray(data[fps_key]))
    if not np.isfinite(fps) or fps <= 0:
        raise MotionError(f"{path}: mocap frame rate must be > 0, got {fps}")
    return motion_from_smpl(
        body, data["trans"], fps, str(path), relative_translation=relative_translation
    )


def _mat_to_dict(value):
    from scipy.io.matlab import mat_struct

    if isinstance(value, mat_struct):
        return {name: _mat_to_dict(getattr(value, name)) for name in value._fieldnames}
    if isinstance(value, dict):
        return {key: _mat_to_dict(item) for key, item in value.items()}
    return value


def read_cloth3d_info(path: str | Path) -> dict:
    """A CLOTH3D ``info.mat`` as a plain dict (``mat_struct`` → dict, recursively)."""
    from scipy.io import loadmat

    path = Path(path)
    if not path.is_file():
        raise MotionError(f"{path}: file not found")
    try:
        mat = loadmat(path, struct_as_record=False, squeeze_me=True)
    except Exception as error:
        raise MotionError(f"{path}: not a readable MATLAB file ({error})") from error
    info = mat.get("info", None)
    info = (
        _mat_to_dict(info)
        if info is not None
        else {k: _mat_to_dict(v) for k, v in mat.items() if not k.startswith("__")}
    )
    if not isinstance(info, dict):
        raise MotionError(f"{path}: expected a struct of sequence information")
    return info


def load_cloth3d_motion(
    path: str | Path, fps: float = 30.0, apply_zrot: bool = False, relative_translation: bool = True
) -> Motion:
    """A CLOTH3D sequence's motion from its ``info.mat``: ``poses`` (72, T) or (72,),
    ``trans`` (3, T) or (3,), ``zrot`` (radians).

    Args:
        fps: CLOTH3D stores no frame rate; 30 fps is the usual assumption.
        apply_zrot: rotate the motion about world Z by ``zrot`` (root orientation and
            translation; exact when the rest pelvis lies on the Z axis).
    """
    from scipy.spatial.transform import Rotation

    info = read_cloth3d_info(path)
    for key in ("poses", "trans"):
        if key not in info:
            raise MotionError(f"{path}: info.mat has no '{key}' field")
    poses = np.asarray(info["poses"], dtype=np.float64)
    trans = np.asarray(info["trans"], dtype=np.float64)
    if poses.shape == (72,):
        poses = poses[:, None]
    if trans.shape == (3,):
        trans = trans[:, None]
    if poses.ndim != 2 or poses.shape[0] != 72:
        raise MotionError(f"{path}: 'poses' must be (72, T), got {poses.shape}")
    if trans.shape != (3, poses.shape[1]):
        raise MotionError(f"{path}: 'trans' must be (3, {poses.shape[1]}), got {trans.shape}")
    motion = motion_from_smpl(
        poses.T, trans.T, fps, str(path), relative_translation=relative_translation
    )
    if apply_zrot:
        zrot = float(np.asarray(info.get("zrot", 0.0)))
        rz = Rotation.from_rotvec([0.0, 0.0, zrot])
        rotations = motion.rotations.copy()
        rotations[:, 0] = (rz * Rotation.from_rotvec(rotations[:, 0])).as_rotvec()
        motion = Motion(rotations, rz.apply(motion.translation), fps, motion.name)
    return motion


# Canonical joint → candidate BVH joint names (CMU first, then Mixamo-like), first unused wins.
BVH_JOINT_CANDIDATES: dict[str, tuple[str, ...]] = {
    "pelvis": ("Hips", "Pelvis", "Root"),
    "L_hip": ("LeftUpLeg", "LeftThigh", "LThigh"),
    "R_hip": ("RightUpLeg", "RightThigh", "RThigh"),
    "spine1": ("LowerBack", "Spine"),
    "L_knee": ("LeftLeg", "LeftShin", "LShin"),
    "R_knee": ("RightLeg", "RightShin", "RShin"),
    "spine2": ("Spine", "Spine1"),
    "L_ankle": ("LeftFoot", "LFoot"),
    "R_ankle": ("RightFoot", "RFoot"),
    "spine3": ("Spine1", "Spine2", "Chest"),
    "L_foot": ("LeftToeBase", "LeftToe", "LToe"),
    "R_foot": ("RightToeBase", "RightToe", "RToe"),
    "neck": ("Neck",),
    "L_collar": ("LeftShoulder", "LeftCollar", "LCollar"),
    "R_collar": ("RightShoulder", "RightCollar", "RCollar"),
    "head": ("Head",),
    "L_shoulder": ("LeftArm", "LeftUpArm", "LShldr"),
    "R_shoulder": ("RightArm", "RightUpArm", "RShldr"),
    "L_elbow": ("LeftForeArm", "LeftLowArm", "LForeArm"),
    "R_elbow": ("RightForeArm", "RightLowArm", "RForeArm"),
    "L_wrist": ("LeftHand", "LHand"),
    "R_wrist": ("RightHand", "RHand"),
    "L_hand": ("LeftFingerBase", "LeftHandIndex1", "LeftHandMiddle1"),
    "R_hand": ("RightFingerBase", "RightHandIndex1", "RightHandMiddle1"),
}
# Joints a BVH may lack (left at rest, with a warning); any other missing joint is an error.
BVH_OPTIONAL_JOINTS = frozenset(
    {"spine2", "spine3", "neck", "L_collar", "R_collar", "L_foot", "R_foot", "L_hand", "R_hand"}
)
_LEG_LENGTH = 0.79  # metres (Anny's default thigh + shin), target of scale="auto"


def _bare(name: str) -> str:
    return name.split(":")[-1]


def load_bvh_motion(
    path: str | Path, scale: float | str = "auto", relative_translation: bool = True
) -> Motion:
    """A BVH file (parsed by the PyPI ``bvh`` package) mapped onto the 24 joints.

    Assumes the BVH rest pose (all channels zero) is a T-pose with a Y-up world, as in
    the CMU conversions. Rotations of unmapped intermediate joints fold into their
    nearest mapped descendant; unmapped leaves (fingers, end sites) are dropped. Both
    are listed in an :class:`UnmappedJointsWarning`.

    Args:
        scale: metres per BVH unit, or ``"auto"`` to make the left leg
            (knee + ankle offsets) 0.79 m long.
    """
    from bvh import Bvh
    from scipy.spatial.transform import Rotation

    path = Path(path)
    if not path.is_file():
        raise MotionError(f"{path}: file not found")
    try:
        mocap = Bvh(path.read_text(errors="replace"))
        names = mocap.get_joints_names()
        frames = np.asarray(mocap.frames, dtype=np.float64)
        frame_time = float(mocap.frame_time)
    except Exception as error:
        raise MotionError(f"{path}: not a readable BVH file ({error})") from error
    if not names or frames.ndim != 2 or frames.shape[0] < 1:
        raise MotionError(f"{path}: BVH file has no joints or no frames")
    if frame_time <= 0 or not np.isfinite(frame_time):
        raise MotionError(f"{path}: BVH frame time must be > 0, got {frame_time}")
    if not np.all(np.isfinite(frames)):
        raise MotionError(f"{path}: BVH frames contain NaN or infinite values")

    bare = {_bare(n): n for n in names}
    mapping: dict[str, str] = {}
    used: set[str] = set()
    for joint in JOINT_NAMES:
        for candidate in BVH_JOINT_CANDIDATES[joint]:
            if candidate in bare and candidate not in used:
                mapping[joint] = bare[candidate]
                used.add(candidate)
                break
    missing = [j for j in JOINT_NAMES if j not in mapping]
    required_missing = [j for j in missing if j not in BVH_OPTIONAL_JOINTS]
    if required_missing:
        raise MotionError(
            f"{path}: BVH lacks joints for {', '.join(required_missing)} "
            f"(looked for {', '.join(BVH_JOINT_CANDIDATES[required_missing[0]])} …)"
        )
    unmapped = [n for n in names if _bare(n) not in used]
    if unmapped or missing:
        warnings.warn(
            f"{path}: BVH joints not mapped onto the canonical skeleton: "
            f"{', '.join(unmapped) or 'none'}; canonical joints left at rest: "
            f"{', '.join(missing) or 'none'}",
            UnmappedJointsWarning,
            stacklevel=2,
        )

    # Global rotation of every BVH joint per frame, parents first (get_joints_names order).
    count = frames.shape[0]
    global_rot: dict[str, np.ndarray] = {}
    root_position = None
    try:
        for name in names:
            channels = mocap.joint_channels(name)
            start = mocap.get_joint_channels_index(name)
            rot_channels = [(i, c[0].upper()) for i, c in enumerate(channels) if "rotation" in c]
            if rot_channels:
                order = "".join(axis for _, axis in rot_channels)
                angles = frames[:, [start + i for i, _ in rot_channels]]
                local = Rotation.from_euler(order, angles, degrees=True).as_matrix()
            else:
                local = np.broadcast_to(np.eye(3), (count, 3, 3))
            parent = mocap.joint_parent(name)
            parent_rot = global_rot.get(parent.name) if parent is not None else None
            global_rot[name] = local if parent_rot is None else parent_rot @ local
            if name == mapping["pelvis"]:
                pos = [(i, c[0].upper()) for i, c in enumerate(channels) if "position" in c]
                if len(pos) != 3:
                    raise MotionError(f"{path}: BVH root '{name}' has no 3 position channels")
                xyz = {axis: frames[:, start + i] for i, axis in pos}
                root_position = np.stack([xyz["X"], xyz["Y"], xyz["Z"]], axis=1)
    except MotionError:
        raise
    except Exception as error:
        raise MotionError(f"{path}: malformed BVH hierarchy or channels ({error})") from error

    if scale == "auto":
        leg = sum(np.linalg.norm(mocap.joint_offset(mapping[j])) for j in ("L_knee", "L_ankle"))
        if leg <= 0:
            raise MotionError(f"{path}: cannot infer the BVH scale (zero leg length)")
        scale = _LEG_LENGTH / leg
    scale = float(scale)

    # Canonical local rotations: R_j = G_parent(j)ᵀ G_j with G of missing joints = parent's.
    canonical_global = np.empty((count, NUM_JOINTS, 3, 3))
    local = np.empty((count, NUM_JOINTS, 3, 3))
    for j, joint in enumerate(JOINT_NAMES):
        parent = JOINT_PARENTS[j]
        if joint in mapping:
            canonical_global[:, j] = global_rot[mapping[joint]]
        else:
            canonical_global[:, j] = canonical_global[:, parent]
        if parent < 0:
            local[:, j] = canonical_global[:, j]
        else:
            local[:, j] = np.swapaxes(canonical_global[:, parent], -1, -2) @ canonical_global[:, j]
    poses = Rotation.from_matrix(local.reshape(-1, 3, 3)).as_rotvec().reshape(count, NUM_JOINTS, 3)
    return motion_from_smpl(
        poses,
        root_position * scale,
        1.0 / frame_time,
        str(path),
        world_y_up=True,
        relative_translation=relative_translation,
    )


MOTION_FILE_TYPES = (".npz", ".bvh", ".mat")


def load_motion(spec: str | Path, fps: float | None = None, **procedural) -> Motion:
    """A motion from a procedural-library name or a file (``.npz`` AMASS, ``.bvh``,
    CLOTH3D ``info.mat``), resampled to ``fps`` when given.

    ``procedural`` keyword arguments (duration, speed, amplitude, seed) go to
    :func:`~gnngarment.body.procedural.make_motion`.

    Raises:
        MotionError: unknown name, unreadable file, or ``fps`` not a finite number > 0.
    """
    from gnngarment.body.procedural import MOTION_LIBRARY, make_motion

    if fps is not None and not (np.isfinite(fps) and fps > 0):
        raise MotionError(f"fps must be a finite number > 0, got {fps}")
    name = str(spec)
    if name in MOTION_LIBRARY:
        return make_motion(name, **({} if fps is None else {"fps": fps}), **procedural)
    path = Path(spec)
    suffix = path.suffix.lower()
    if suffix not in MOTION_FILE_TYPES:
        raise MotionError(
            f"{path}: unknown motion '{name}': not a procedural motion "
            f"({', '.join(MOTION_LIBRARY)}) nor a file of type {', '.join(MOTION_FILE_TYPES)}"
        )
    if not path.is_file():
        raise MotionError(f"{path}: file not found")
    if suffix == ".npz":
        motion = load_amass_motion(path)
    elif suffix == ".bvh":
        motion = load_bvh_motion(path)
    else:
        motion = load_cloth3d_motion(path)
    return motion.resample(fps) if fps is not None and abs(fps - motion.fps) > 1e-9 else motion
