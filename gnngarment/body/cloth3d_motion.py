"""CLOTH3D sequence motions: SMPL poses and translation from a sequence's ``info.mat``.

``info.mat`` (MATLAB v5) holds ``poses (72, T)`` (or ``(72,)`` for one frame) SMPL
axis-angles, ``trans (3, T)`` (or ``(3,)``), ``zrot`` and the rest of the sequence's
information; CLOTH3D stores no frame rate. The poses are converted by
:func:`~gnngarment.body.smpl_motion.motion_from_smpl` (SMPL convention, Z-up world) into
a canonical :class:`~gnngarment.body.motion.Motion`. Formats: ``docs/motions.md``.
"""

from __future__ import annotations

from pathlib import Path

from gnngarment.body.motion import Motion, MotionError
from gnngarment.body.smpl_motion import motion_from_smpl
from gnngarment.io.mat import MatFileError, finite_array, finite_number, read_mat

__all__ = ["load_cloth3d_motion", "read_cloth3d_info"]


def read_cloth3d_info(path: str | Path) -> dict:
    """A CLOTH3D ``info.mat`` as a plain dict (:func:`gnngarment.io.mat.read_mat`'s
    values), from its top-level variables or from one ``info`` struct.

    Raises:
        MotionError: the file is missing or unreadable, or ``info`` is not a struct.
    """
    try:
        variables = read_mat(path)
    except MatFileError as error:
        raise MotionError(str(error)) from None
    info = variables.get("info", variables)
    if not isinstance(info, dict):
        raise MotionError(f"{path}: expected a struct of sequence information")
    return info


def load_cloth3d_motion(
    path: str | Path, fps: float = 30.0, apply_zrot: bool = False, relative_translation: bool = True
) -> Motion:
    """A CLOTH3D sequence's motion from its ``info.mat``: ``poses`` (72, T) or (72,),
    ``trans`` (3, T) or (3,), ``zrot`` (radians).

    Raises:
        MotionError: naming the file and the field: a field missing, not numeric (a
            string, struct or cell array), holding NaN/inf, or of the wrong shape.

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
    try:
        poses = finite_array(info["poses"], "poses")
        trans = finite_array(info["trans"], "trans")
        zrot = finite_number(info.get("zrot", 0.0), "zrot") if apply_zrot else 0.0
    except ValueError as error:
        raise MotionError(f"{path}: {error}") from None
    if poses.shape == (72,):
        poses = poses[:, None]
    if trans.shape == (3,):
        trans = trans[:, None]
    if poses.ndim != 2 or poses.shape[0] != 72 or poses.shape[1] < 1:
        raise MotionError(f"{path}: 'poses' must be (72, T), got {poses.shape}")
    if trans.shape != (3, poses.shape[1]):
        raise MotionError(f"{path}: 'trans' must be (3, {poses.shape[1]}), got {trans.shape}")
    motion = motion_from_smpl(
        poses.T, trans.T, fps, str(path), relative_translation=relative_translation
    )
    if apply_zrot:
        rz = Rotation.from_rotvec([0.0, 0.0, zrot])
        rotations = motion.rotations.copy()
        rotations[:, 0] = (rz * Rotation.from_rotvec(rotations[:, 0])).as_rotvec()
        motion = Motion(rotations, rz.apply(motion.translation), fps, motion.name)
    return motion
