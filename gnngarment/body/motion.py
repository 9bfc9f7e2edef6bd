"""The :class:`Motion` type: local joint rotations + root translation over time.

Shapes:
    rotations ``(T, 24, 3)`` axis-angle (radians) in the canonical convention of
    :mod:`gnngarment.body.skeleton` (world-aligned rest axes, Z up, T-pose rest);
    translation ``(T, 3)`` metres, added to the pelvis; ``fps`` frames per second.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from gnngarment.body.skeleton import NUM_JOINTS


class MotionError(ValueError):
    """A motion (array or file) is malformed; the message names its source."""


def _where(source: str) -> str:
    return f"{source}: " if source else ""


@dataclasses.dataclass(frozen=True)
class Motion:
    """A motion of the canonical skeleton.

    Attributes:
        rotations: ``(T, 24, 3)`` float64 local axis-angle rotations.
        translation: ``(T, 3)`` float64 root translation (metres), added to the pelvis.
        fps: frame rate, > 0.
        name: free-form label (file name or procedural motion name).
    """

    rotations: np.ndarray
    translation: np.ndarray
    fps: float
    name: str = ""

    def __post_init__(self) -> None:
        rotations = np.asarray(self.rotations, dtype=np.float64)
        translation = np.asarray(self.translation, dtype=np.float64)
        where = _where(self.name)
        if rotations.ndim != 3 or rotations.shape[1:] != (NUM_JOINTS, 3):
            raise MotionError(
                f"{where}rotations must have shape (T, {NUM_JOINTS}, 3), got {rotations.shape}"
            )
        if rotations.shape[0] < 1:
            raise MotionError(f"{where}a motion needs at least one frame")
        if translation.shape != (rotations.shape[0], 3):
            raise MotionError(
                f"{where}translation must have shape ({rotations.shape[0]}, 3), "
                f"got {translation.shape}"
            )
        if not np.all(np.isfinite(rotations)) or not np.all(np.isfinite(translation)):
            raise MotionError(f"{where}rotations/translation contain NaN or infinite values")
        from gnngarment.body.motion_limits import MAX_SOURCE_FPS

        try:
            fps = float(self.fps)
        except (TypeError, ValueError):
            raise MotionError(f"{where}fps must be a number, got {self.fps!r}") from None
        if not np.isfinite(fps) or not 0 < fps <= MAX_SOURCE_FPS:
            raise MotionError(f"{where}fps must be > 0 and at most {MAX_SOURCE_FPS:g}, "
                              f"got {self.fps}")
        object.__setattr__(self, "rotations", rotations)
        object.__setattr__(self, "translation", translation)
        object.__setattr__(self, "fps", fps)

    @property
    def num_frames(self) -> int:
        return int(self.rotations.shape[0])

    def __len__(self) -> int:
        return self.num_frames

    @property
    def duration(self) -> float:
        """Seconds between the first and the last frame."""
        return (self.num_frames - 1) / self.fps

    @classmethod
    def rest(cls, num_frames: int = 1, fps: float = 30.0, name: str = "rest") -> Motion:
        """``num_frames`` frames of the rest pose at the origin."""
        return cls(np.zeros((num_frames, NUM_JOINTS, 3)), np.zeros((num_frames, 3)), fps, name)

    def __getitem__(self, index: slice | int) -> Motion:
        """Frames ``index`` (a slice, or one frame kept as a 1-frame motion)."""
        if isinstance(index, (int, np.integer)):
            index = slice(int(index), int(index) + 1 if int(index) != -1 else None)
        if not isinstance(index, slice):
            raise TypeError(f"Motion indices must be int or slice, got {type(index).__name__}")
        rotations = self.rotations[index]
        if rotations.shape[0] == 0:
            raise MotionError(f"{_where(self.name)}slice {index} selects no frames")
        return dataclasses.replace(self, rotations=rotations, translation=self.translation[index])

    def resample(self, fps: float) -> Motion:
        """The same motion at another frame rate: rotations by slerp, translation linearly.

        The new frames lie at ``k / fps`` for ``k = 0 … ⌊duration · fps⌋``.
        """
        from scipy.spatial.transform import Rotation, Slerp

        fps = float(fps)
        if not np.isfinite(fps) or fps <= 0:
            raise MotionError(f"{_where(self.name)}target fps must be > 0, got {fps}")
        if self.num_frames == 1:
            return dataclasses.replace(self, fps=fps)
        old_times = np.arange(self.num_frames) / self.fps
        count = int(np.floor(self.duration * fps + 1e-9)) + 1
        new_times = np.minimum(np.arange(count) / fps, old_times[-1])
        rotations = np.empty((count, NUM_JOINTS, 3))
        for j in range(NUM_JOINTS):
            slerp = Slerp(old_times, Rotation.from_rotvec(self.rotations[:, j]))
            rotations[:, j] = slerp(new_times).as_rotvec()
        translation = np.stack(
            [np.interp(new_times, old_times, self.translation[:, k]) for k in range(3)], axis=1
        )
        return Motion(rotations, translation, fps, self.name)

    @staticmethod
    def concatenate(motions: Sequence[Motion], name: str | None = None) -> Motion:
        """Frames of ``motions`` one after another (all must share one fps)."""
        if not motions:
            raise MotionError("cannot concatenate an empty list of motions")
        fps = motions[0].fps
        for motion in motions[1:]:
            if abs(motion.fps - fps) > 1e-9:
                raise MotionError(
                    f"cannot concatenate motions at {fps} and {motion.fps} fps; resample first"
                )
        return Motion(
            np.concatenate([m.rotations for m in motions]),
            np.concatenate([m.translation for m in motions]),
            fps,
            name if name is not None else "+".join(m.name for m in motions),
        )

    def to_torch(self, dtype=None):
        """``(rotations (T, 24, 3), translation (T, 3))`` as torch tensors (float32 default)."""
        import torch

        dtype = dtype or torch.float32
        return (
            torch.as_tensor(self.rotations, dtype=dtype),
            torch.as_tensor(self.translation, dtype=dtype),
        )
