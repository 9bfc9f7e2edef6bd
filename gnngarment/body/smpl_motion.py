"""SMPL-convention motions: the axis conversion and the ``.npz`` files that hold them.

SMPL-convention data (AMASS, CLOTH3D) has Y-up joint axes but a Z-up world (its root
rotation includes the +90° turn about X); :func:`motion_from_smpl` converts it by
``R'_j = C R_j Cᵀ`` for ``j ≥ 1`` and ``R'_0 = R_0 Cᵀ`` with ``C = Rx(+90°)``
(:data:`SMPL_TO_CANONICAL`), which leaves world positions unchanged. SMPL data in a
Y-up world (NCS-style ``.npz``) is converted by ``C R_j Cᵀ`` for every joint and
``C t`` for the translation. The result is a canonical
:class:`~gnngarment.body.motion.Motion` (Z up, T-pose rest, world-aligned local axes;
see :mod:`gnngarment.body.skeleton`).

Files: AMASS ``.npz`` (:func:`load_amass_motion`) and AMASS or NCS-style SMPL ``.npz``
told apart by their keys (:func:`load_npz_motion`); formats in ``docs/motions.md``.

Translation: by default the first frame's root translation is subtracted, so every
loaded motion starts with the pelvis at its rest position (``relative_translation``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gnngarment.body.motion import Motion, MotionError
from gnngarment.body.skeleton import NUM_JOINTS

__all__ = ["SMPL_TO_CANONICAL", "load_amass_motion", "load_npz_motion", "motion_from_smpl"]

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
    try:
        fps = float(np.asarray(data[fps_key], dtype=np.float64).reshape(-1)[0])
    except (TypeError, ValueError, IndexError):
        raise MotionError(f"{path}: '{fps_key}' must be a number, got {data[fps_key]!r}"
                          ) from None
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
