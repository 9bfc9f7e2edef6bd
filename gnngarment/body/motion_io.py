"""Reading a motion by name or file: :func:`load_motion` picks the loader;
:func:`load_motion_for_body` retargets a file onto the body it will play on (and puts a
lead-in from the rest pose in front, :mod:`gnngarment.body.lead_in`).

One loader per format, each returning a canonical :class:`~gnngarment.body.motion.Motion`
(Z up, T-pose rest, world-aligned local axes; see :mod:`gnngarment.body.skeleton`):

* procedural names: :func:`gnngarment.body.procedural.make_motion`;
* ``.npz``, AMASS or NCS-style SMPL: :func:`gnngarment.body.smpl_motion.load_npz_motion`;
* ``.bvh``: :func:`gnngarment.body.bvh_motion.load_bvh_motion`;
* CLOTH3D ``info.mat``: :func:`gnngarment.body.cloth3d_motion.load_cloth3d_motion`.

Supported formats: ``docs/motions.md``.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from gnngarment.body.bvh_motion import load_bvh_motion
from gnngarment.body.cloth3d_motion import load_cloth3d_motion
from gnngarment.body.lead_in import (
    DEFAULT_LEAD_IN_SECONDS,
    check_lead_in_seconds,
    trim_reference_pose,
    with_lead_in,
)
from gnngarment.body.motion import Motion, MotionError
from gnngarment.body.smpl_motion import load_npz_motion

if TYPE_CHECKING:
    from gnngarment.body.body_model import BodyModel

__all__ = ["MOTION_FILE_TYPES", "default_lead_in", "load_motion", "load_motion_for_body"]

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


def default_lead_in(spec: str | Path) -> float:
    """The lead-in (seconds) a motion gets unless told otherwise:
    :data:`~gnngarment.body.lead_in.DEFAULT_LEAD_IN_SECONDS` for a file (a spec with a
    suffix), which starts wherever its clip does; ``0`` for a procedural name, which
    starts at rest and holds it (:mod:`gnngarment.body.procedural`)."""
    return DEFAULT_LEAD_IN_SECONDS if Path(spec).suffix else 0.0


def load_motion_for_body(
    spec: str | Path,
    body_model: BodyModel,
    shape: Any = None,
    fps: float | None = None,
    joint_map: Mapping[str, str | None] | str | Path | None = None,
    up_axis: str = "auto",
    lead_in: float = 0.0,
    **procedural,
) -> Motion:
    """:func:`load_motion` for a motion that will play on ``body_model`` in ``shape``: a
    file (a spec with a suffix) is retargeted onto that shape's rest skeleton
    (``rest_joints``: a BVH's rest pose and units); a procedural name gets the
    ``procedural`` keyword arguments (duration, ...), which a file does not take.

    Args:
        lead_in: seconds of a blend from the rest pose (the pose the garment template is
            draped in) into the motion, in front of it
            (:func:`~gnngarment.body.lead_in.with_lead_in`): the first
            ``lead_in_frames(lead_in, fps)`` frames (at the file's own rate when ``fps``
            is ``None``).
            With a lead-in, a file's T-pose reference frame and its blend into the clip
            are dropped first, at the file's own frame rate
            (:func:`~gnngarment.body.lead_in.trim_reference_pose`), since they are the
            jump the lead-in replaces. ``0`` (the default): the motion as loaded.

    Raises:
        MotionError: as :func:`load_motion`, or ``lead_in`` not a finite number of
            seconds in ``[0, MAX_LEAD_IN_SECONDS]``.
    """
    lead_in = check_lead_in_seconds(lead_in)
    if not Path(spec).suffix:
        motion = load_motion(spec, fps, joint_map, up_axis, **procedural)
        return with_lead_in(motion, lead_in)  # procedural motions start at rest: a hold
    rest_joints = body_model.rest(shape).joints.numpy()
    if not lead_in:
        return load_motion(spec, fps, joint_map, up_axis, rest_joints=rest_joints)
    if fps is not None and not (np.isfinite(fps) and fps > 0):  # as load_motion says it
        raise MotionError(f"fps must be a finite number > 0, got {fps}")
    # Trimmed before resampling: at the file's rate the reference frame's jump stands out
    # from the clip's own movement; resampled, it is merged into the clip's first frames.
    motion = trim_reference_pose(load_motion(spec, None, joint_map, up_axis,
                                             rest_joints=rest_joints))
    if fps is not None and abs(fps - motion.fps) > 1e-9:
        motion = motion.resample(fps)
    return with_lead_in(motion, lead_in)
