"""Reading motions from files: AMASS and NCS-style SMPL ``.npz``, BVH, CLOTH3D ``info.mat``.

All loaders return a canonical :class:`~gnngarment.body.motion.Motion` (Z up, T-pose
rest, world-aligned local axes; see :mod:`gnngarment.body.skeleton`). SMPL-convention
data (AMASS, CLOTH3D) has Y-up joint axes but a Z-up world (its root rotation includes
the +90° turn about X); it is converted by ``R'_j = C R_j Cᵀ`` for ``j ≥ 1`` and
``R'_0 = R_0 Cᵀ`` with ``C = Rx(+90°)``, which leaves world positions unchanged.
SMPL data in a Y-up world (NCS-style ``.npz``) is converted by ``C R_j Cᵀ`` for every
joint and ``C t`` for the translation. BVH files (name table, rest-pose retargeting,
units) are read by :mod:`gnngarment.body.bvh_motion`; its public names are re-exported
here. Supported formats: ``docs/motions.md``.

Translation: by default the first frame's root translation is subtracted, so every
loaded motion starts with the pelvis at its rest position (``relative_translation``).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np

from gnngarment.body.bvh_motion import (
    BVH_JOINT_CANDIDATES,
    BVH_OPTIONAL_JOINTS,
    DEFAULT_REST_JOINTS,
    UnmappedJointsWarning,
    load_bvh_motion,
    map_bvh_joints,
    normalize_joint_name,
    read_joint_map,
)
from gnngarment.body.motion import Motion, MotionError
from gnngarment.body.skeleton import NUM_JOINTS

__all__ = [
    "BVH_JOINT_CANDIDATES",
    "BVH_OPTIONAL_JOINTS",
    "DEFAULT_REST_JOINTS",
    "MOTION_FILE_TYPES",
    "SMPL_TO_CANONICAL",
    "UnmappedJointsWarning",
    "load_amass_motion",
    "load_bvh_motion",
    "load_cloth3d_motion",
    "load_motion",
    "load_npz_motion",
    "map_bvh_joints",
    "motion_from_smpl",
    "normalize_joint_name",
    "read_cloth3d_info",
    "read_joint_map",
]

# SMPL (Y-up) body axes → canonical (Z-up) axes: a +90° rotation about X.
SMPL_TO_CANONICAL = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


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


def load_amass_motion(
    path: str | Path, relative_translation: bool = True, up_axis: str = "z"
) -> Motion:
    """An AMASS ``.npz``: ``poses`` (T, 72 | 156 | 165), ``trans`` (T, 3), frame rate in
    ``mocap_framerate`` (or ``mocap_frame_rate``).

    The 22 body joints are the first 66 values. SMPL's two hand joints are the next 6
    values only for 72-wide (SMPL) poses; for SMPL-H (156) and SMPL-X (165) those values
    are finger/jaw/eye rotations, so the hands are left at rest.

    Args:
        up_axis: the world's up axis, ``"z"`` (AMASS) or ``"y"``.
    """
    path = Path(path)
    if not path.is_file():
        raise MotionError(f"{path}: file not found")
    try:
        data = np.load(path, allow_pickle=False)
    except Exception as error:
        message = " ".join(str(error).split())
        raise MotionError(f"{path}: not a readable .npz file ({message})") from error
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
        body,
        data["trans"],
        fps,
        str(path),
        world_y_up=_world_y_up(up_axis, path),
        relative_translation=relative_translation,
    )


def _world_y_up(up_axis: str, path: Path) -> bool:
    if up_axis not in ("y", "z"):
        raise MotionError(f"{path}: up_axis must be 'auto', 'y' or 'z', got {up_axis!r}")
    return up_axis == "y"


_SUPPORTED_NPZ = (
    "AMASS (poses (T, 72|156|165), trans (T, 3), mocap_framerate; Z-up world) or NCS-style "
    "SMPL (poses (T, 24, 3) or (T, 72), trans (T, 3), fps; Y-up world)"
)


def load_npz_motion(
    path: str | Path, up_axis: str = "auto", relative_translation: bool = True
) -> Motion:
    """An SMPL motion ``.npz``: AMASS or NCS-style, told apart by the keys.

    * AMASS: ``poses`` (T, 72 | 156 | 165), ``trans`` (T, 3), ``mocap_framerate``; Z-up
      world (:func:`load_amass_motion`).
    * NCS-style: ``poses`` (T, 24, 3) or (T, 72) SMPL axis-angles (SMPL-H/X widths 156/165
      give their 22 body joints), ``trans`` (T, 3), ``fps``; Y-up world (the SMPL body
      stands upright with a zero root rotation).

    Args:
        up_axis: ``"auto"`` (Z for AMASS, Y for NCS-style), ``"y"`` or ``"z"``.

    Raises:
        MotionError: a rig that is not SMPL (e.g. Mixamo quaternions on 65 joints), a
            missing key, bad shapes or values; one line naming the file.
    """
    path = Path(path)
    if not path.is_file():
        raise MotionError(f"{path}: file not found")
    if up_axis not in ("auto", "y", "z"):
        raise MotionError(f"{path}: up_axis must be 'auto', 'y' or 'z', got {up_axis!r}")
    try:
        data = np.load(path, allow_pickle=False)
        keys = list(data.files)
        arrays = {key: data[key] for key in keys}
    except Exception as error:
        message = " ".join(str(error).split())
        raise MotionError(f"{path}: not a readable .npz file ({message})") from error
    if "poses" not in arrays:
        raise MotionError(
            f"{path}: no 'poses' array (keys: {', '.join(keys) or 'none'}); supported .npz "
            f"motions: {_SUPPORTED_NPZ}"
        )
    poses = arrays["poses"]
    if poses.ndim == 3 and (poses.shape[2] == 4 or poses.shape[1] != 24):
        kind = "quaternions" if poses.shape[2] == 4 else f"{poses.shape[2]}-vectors"
        origin = arrays.get("source")
        origin = f" (source {str(origin)!r})" if origin is not None and origin.ndim == 0 else ""
        raise MotionError(
            f"{path}: 'poses' {poses.shape} holds {kind} on a {poses.shape[1]}-joint rig"
            f"{origin}, not SMPL's 24 axis-angle joints; supported .npz motions: "
            f"{_SUPPORTED_NPZ}; for another rig export it as BVH and load that "
            "(--joint-map FILE for unusual joint names)"
        )
    fps_key = next((k for k in ("mocap_framerate", "mocap_frame_rate") if k in arrays), None)
    if fps_key is not None:
        return load_amass_motion(
            path, relative_translation, up_axis="z" if up_axis == "auto" else up_axis
        )
    if "fps" not in arrays:
        raise MotionError(
            f"{path}: no frame rate: expected 'mocap_framerate' (AMASS) or 'fps' (NCS-style)"
            f" (keys: {', '.join(keys)})"
        )
    if "trans" not in arrays:
        raise MotionError(f"{path}: NCS-style file has no 'trans' array (keys: {', '.join(keys)})")
    if poses.ndim == 2 and poses.shape[1] in (156, 165):  # SMPL-H/X: body joints only
        body = np.zeros((poses.shape[0], 72))
        body[:, :66] = poses[:, :66]
        poses = body
    if not (poses.ndim == 3 and poses.shape[1:] == (24, 3)) and not (
        poses.ndim == 2 and poses.shape[1] == 72
    ):
        raise MotionError(f"{path}: NCS-style 'poses' must be (T, 24, 3) or (T, 72), got "
                          f"{poses.shape}")  # fmt: skip
    try:
        fps = float(np.asarray(arrays["fps"], dtype=np.float64).reshape(-1)[0])
    except (TypeError, ValueError, IndexError) as error:
        raise MotionError(f"{path}: 'fps' must be a number, got {arrays['fps']!r}") from error
    if not np.isfinite(fps) or fps <= 0:
        raise MotionError(f"{path}: 'fps' must be > 0, got {fps}")
    return motion_from_smpl(
        np.asarray(poses, dtype=np.float64),
        np.asarray(arrays["trans"], dtype=np.float64),
        fps,
        str(path),
        world_y_up=_world_y_up("y" if up_axis == "auto" else up_axis, path),
        relative_translation=relative_translation,
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


MOTION_FILE_TYPES = (".npz", ".bvh", ".mat")


def load_motion(
    spec: str | Path,
    fps: float | None = None,
    joint_map: Mapping[str, str | None] | str | Path | None = None,
    up_axis: str = "auto",
    rest_joints: np.ndarray | None = None,
    **procedural,
) -> Motion:
    """A motion from a procedural-library name or a file, resampled to ``fps`` when given.

    Files: ``.npz`` AMASS or NCS-style SMPL (:func:`load_npz_motion`), ``.bvh``
    (:func:`~gnngarment.body.bvh_motion.load_bvh_motion`), CLOTH3D ``info.mat``
    (:func:`load_cloth3d_motion`). ``procedural`` keyword arguments (duration, speed,
    amplitude, seed) go to :func:`~gnngarment.body.procedural.make_motion`.

    Args:
        joint_map: BVH only: canonical joint → BVH joint names (a mapping or a
            ``.json``/``.yaml`` file, see ``docs/motions.md``).
        up_axis: ``.npz``/``.bvh`` only: the file's up axis, ``"auto"``, ``"y"`` or ``"z"``.
        rest_joints: ``(24, 3)`` T-pose rest joints (metres) of the body the motion will
            play on, for BVH rest-pose retargeting and units (default: Anny's default
            shape); other formats are already in the canonical T-pose and ignore it.

    Raises:
        MotionError: unknown name, unreadable file, an option the file type does not
            take, or ``fps`` not a finite number > 0.
    """
    from gnngarment.body.procedural import MOTION_LIBRARY, make_motion

    if fps is not None and not (np.isfinite(fps) and fps > 0):
        raise MotionError(f"fps must be a finite number > 0, got {fps}")
    if up_axis not in ("auto", "y", "z"):
        raise MotionError(f"{spec}: up_axis must be 'auto', 'y' or 'z', got {up_axis!r}")
    name = str(spec)
    path = Path(spec)
    suffix = path.suffix.lower()
    if name in MOTION_LIBRARY or suffix not in (".npz", ".bvh"):
        # Options a motion of this kind cannot use are errors, not silently ignored.
        if joint_map is not None:
            raise MotionError(f"{name}: a joint map applies to .bvh motions only")
        if up_axis != "auto":
            raise MotionError(f"{name}: an up axis applies to .npz and .bvh motions only")
    elif suffix == ".npz" and joint_map is not None:
        raise MotionError(f"{name}: a joint map applies to .bvh motions only")
    if name in MOTION_LIBRARY:
        return make_motion(name, **({} if fps is None else {"fps": fps}), **procedural)
    if suffix not in MOTION_FILE_TYPES:
        raise MotionError(
            f"{path}: unknown motion '{name}': not a procedural motion "
            f"({', '.join(MOTION_LIBRARY)}) nor a file of type {', '.join(MOTION_FILE_TYPES)}"
        )
    if not path.is_file():
        raise MotionError(f"{path}: file not found")
    if suffix == ".npz":
        motion = load_npz_motion(path, up_axis=up_axis)
    elif suffix == ".bvh":
        motion = load_bvh_motion(
            path, joint_map=joint_map, up_axis=up_axis, rest_joints=rest_joints
        )
    else:
        motion = load_cloth3d_motion(path)
    return motion.resample(fps) if fps is not None and abs(fps - motion.fps) > 1e-9 else motion
