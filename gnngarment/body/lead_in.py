"""How an animation starts: a lead-in from the rest pose into a motion's first pose.

The garment template is draped on the rest body in the rest pose (T-pose: zero local
rotations, zero root translation — :meth:`Motion.rest`), so every animation starts
there. A motion file starts somewhere else: a clip that begins mid-stride makes the body
jump from the rest pose to its first pose in one frame (a pop in the export, and an
impulse no dynamics model should be fed). :func:`with_lead_in` puts frames in front
that blend from the rest pose into the first pose with a smooth ease.

Many mocap files (the CMU BVH conversions among them) open with a T-pose reference frame
that their filtering smears into the first pose over a few frames: the body leaves it at
50–160 rad/s, then moves at 5–20 rad/s (measured on 52 CMU clips at 120 fps). A lead-in
into that reference frame would leave the jump in place, so :func:`trim_reference_pose`
drops such a start first; :func:`~gnngarment.body.motion_io.load_motion_for_body` does
both when it is given a lead-in.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from gnngarment.body.motion import Motion, MotionError
from gnngarment.body.skeleton import NUM_JOINTS

__all__ = [
    "DEFAULT_LEAD_IN_SECONDS",
    "MAX_LEAD_IN_SECONDS",
    "check_lead_in_seconds",
    "lead_in_frames",
    "reference_pose_frames",
    "trim_reference_pose",
    "with_lead_in",
]

#: The lead-in the CLI gives a motion file (seconds): at 30 fps, 09_01's run starts with
#: body vertices moving at most 147 mm a frame in it, less than the run's own 270 mm.
DEFAULT_LEAD_IN_SECONDS = 0.5
#: The longest lead-in accepted (seconds): a longer one would be a motion of its own.
MAX_LEAD_IN_SECONDS = 10.0
#: A first frame counts as a T-pose reference frame only if no joint is rotated further
#: than this from the rest pose (radians): the CMU reference frames, retargeted onto our
#: skeleton, are within 0.30 rad; a natural standing pose has the arms ~1.2 rad down.
REFERENCE_POSE_RADIANS = 0.5
#: Leaving the first frame faster than this (rad/s, the fastest joint) is a jump, not
#: movement: the CMU clips move at up to ~20 rad/s once past their reference frame.
FAST_START_SPEED = 20.0
#: At most this much of a clip's start (seconds) is dropped as a reference pose and its
#: blend (the CMU blends last 1/30 s), so a clip that keeps moving fast loses no more.
MAX_TRIMMED_SECONDS = 0.1


def check_lead_in_seconds(seconds: float) -> float:
    """``seconds`` as a float, if it is a lead-in length :func:`with_lead_in` takes.

    Raises:
        MotionError: not a finite number in ``[0, MAX_LEAD_IN_SECONDS]``.
    """
    value = float(seconds)
    if not (math.isfinite(value) and 0.0 <= value <= MAX_LEAD_IN_SECONDS):
        raise MotionError(f"a lead-in must be a finite number of seconds in "
                          f"[0, {MAX_LEAD_IN_SECONDS:g}], got {seconds}")
    return value


def lead_in_frames(seconds: float, fps: float) -> int:
    """Frames :func:`with_lead_in` puts in front of a motion at ``fps``:
    ``round(seconds · fps)``; the motion's own frames start at this index.

    Raises:
        MotionError: ``seconds`` out of range (:func:`check_lead_in_seconds`) or ``fps``
            not a finite number > 0.
    """
    seconds = check_lead_in_seconds(seconds)
    if not (math.isfinite(fps) and fps > 0):
        raise MotionError(f"fps must be a finite number > 0, got {fps}")
    return round(seconds * fps)


def _ease(x: np.ndarray) -> np.ndarray:
    # The procedural library's C² ramp: zero velocity and acceleration at both ends, so
    # the body leaves the rest pose and arrives at the first pose without a kick.
    from gnngarment.body.procedural import smoothstep

    return smoothstep(x)


def with_lead_in(motion: Motion, seconds: float) -> Motion:
    """``motion`` preceded by a blend from the rest pose into its first frame.

    The ``n = round(seconds · fps)`` new frames ``i = 0 … n−1`` take the ease
    ``e = smoothstep(i / n)``: every joint's rotation is slerped from the identity to the
    first frame's by ``e``, the root translation goes from zero to the first frame's by
    ``e``. Frame 0 is the rest pose, frame ``n`` is ``motion``'s first frame, and
    ``motion`` follows unchanged. A motion that already starts at rest gets ``n`` frames
    of the rest pose (a hold), so the count never depends on the motion's content.

    Args:
        motion: rotations ``(T, 24, 3)`` axis-angle (radians), translation ``(T, 3)``
            metres.
        seconds: lead-in length, in ``[0, MAX_LEAD_IN_SECONDS]``; ``0`` (or less than
            half a frame) returns ``motion`` itself.

    Returns:
        A motion of ``n + T`` frames at ``motion.fps``, named as ``motion``.

    Raises:
        MotionError: ``seconds`` out of range.
    """
    from scipy.spatial.transform import Rotation, Slerp

    count = lead_in_frames(seconds, motion.fps)
    if count == 0:
        return motion
    ease = _ease(np.arange(count) / count)
    rotations = np.empty((count, NUM_JOINTS, 3))
    for joint in range(NUM_JOINTS):
        ends = Rotation.from_rotvec(np.stack([np.zeros(3), motion.rotations[0, joint]]))
        rotations[:, joint] = Slerp([0.0, 1.0], ends)(ease).as_rotvec()
    translation = ease[:, None] * motion.translation[:1]
    return Motion(np.concatenate([rotations, motion.rotations]),
                  np.concatenate([translation, motion.translation]), motion.fps, motion.name)


def _fastest_joint_speeds(motion: Motion) -> np.ndarray:
    """``(T−1,)`` rad/s: per frame step, the largest rotation angle of a joint's local
    rotation from one frame to the next, times fps."""
    from scipy.spatial.transform import Rotation

    before = Rotation.from_rotvec(motion.rotations[:-1].reshape(-1, 3))
    after = Rotation.from_rotvec(motion.rotations[1:].reshape(-1, 3))
    angles = (before.inv() * after).magnitude().reshape(-1, NUM_JOINTS)
    return angles.max(axis=1) * motion.fps


def reference_pose_frames(motion: Motion) -> int:
    """How many leading frames of ``motion`` are a T-pose reference frame and its blend
    into the clip (what :func:`trim_reference_pose` drops), ``0`` when it has none.

    The first frame is a reference pose when every joint is within
    :data:`REFERENCE_POSE_RADIANS` of rest and the fastest joint leaves it faster than
    :data:`FAST_START_SPEED`; the frames that follow belong to its blend while that
    speed stays above it, for at most :data:`MAX_TRIMMED_SECONDS` (and at least one
    frame of the clip is always kept).
    """
    if motion.num_frames < 2:
        return 0
    if np.linalg.norm(motion.rotations[0], axis=1).max() > REFERENCE_POSE_RADIANS:
        return 0
    limit = min(motion.num_frames - 1, max(1, round(MAX_TRIMMED_SECONDS * motion.fps)))
    fast = _fastest_joint_speeds(motion[:limit + 1]) > FAST_START_SPEED
    # The leading run of fast steps: frames before the first slow step are dropped.
    return int(np.argmin(fast)) if not fast.all() else limit


def trim_reference_pose(motion: Motion) -> Motion:
    """``motion`` without a leading T-pose reference frame and its blend
    (:func:`reference_pose_frames`), translated so that the first kept frame's root is
    where the first frame's was (a loaded motion keeps starting at the origin).

    Returns ``motion`` itself when it has no such start.
    """
    count = reference_pose_frames(motion)
    if count == 0:
        return motion
    kept = motion[count:]
    translation = kept.translation - kept.translation[:1] + motion.translation[:1]
    return dataclasses.replace(kept, translation=translation)
