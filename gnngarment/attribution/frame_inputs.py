"""The per-frame model inputs of the one frame an attribution is computed at."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from gnngarment.attribution.errors import AttributionArgumentError
from gnngarment.body.skeleton import NUM_JOINTS
from gnngarment.data.body_inputs import BodyMotionInputs
from gnngarment.model.config import ModelConfig
from gnngarment.model.deformer import MOTION_CHANNELS, DeformerContext, GarmentDeformer


@dataclass
class FrameInputs:
    """One frame's inputs, batched as :meth:`GarmentDeformer.forward` takes them
    (one pair, one frame).

    Attributes:
        motion_window: ``(1, 1, m, 75)`` joint axis-angles + root displacement.
        velocity_window: ``(1, 1, m, 3 N_b')`` body-subset velocities (m/s).
        joint_transforms: ``(1, 1, 24, 4, 4)`` skinning transforms of the frame.
        history_transforms: ``(T, 24, 4, 4)`` the transforms of every frame up to and
            including this one (a model with dynamics carries its oscillators over
            them), or ``None``: the frame as if the body had held it (no history).
        fps: frames per second of that history.
    """

    motion_window: torch.Tensor
    velocity_window: torch.Tensor
    joint_transforms: torch.Tensor
    history_transforms: torch.Tensor | None = None
    fps: float = 30.0

    def dynamic_offsets(self, model: GarmentDeformer, context: DeformerContext
                        ) -> torch.Tensor | None:
        """The oscillators' blend shapes ``(ΣN, 3)`` at this frame for every pair of
        ``context`` (they depend on its features, so an attribution recomputes them per
        interpolation step), or ``None`` for a model without dynamics."""
        if not model.has_dynamics:
            return None
        history = (self.joint_transforms[0] if self.history_transforms is None
                   else self.history_transforms)
        pairs = context.num_pairs
        frames = torch.full((pairs, 1), history.shape[0] - 1, dtype=torch.long)
        return model.dynamic_blend_shapes(context, [history] * pairs, frames, self.fps)

    @classmethod
    def rest(cls, config: ModelConfig) -> FrameInputs:
        """The body standing still in its rest pose: zero motion and velocity, identity
        transforms (so ``posed = rest + blend shapes``).

        An untrained deformer predicts exactly zero blend shapes here (its LSTMs start
        with zero biases, so zero input gives a zero code): attribute at a real frame.
        """
        window = config.window
        return cls(motion_window=torch.zeros(1, 1, window, MOTION_CHANNELS),
                   velocity_window=torch.zeros(1, 1, window, 3 * config.body_vertices),
                   joint_transforms=torch.eye(4).repeat(1, 1, NUM_JOINTS, 1, 1))

    @classmethod
    def from_motion(cls, frames: BodyMotionInputs, index: int, window: int) -> FrameInputs:
        """Frame ``index`` of a posed motion with its ``window`` frames of history
        (frames before 0 repeat frame 0, as in training and :func:`animate`).

        Raises:
            ValueError: ``index`` outside ``0..T-1`` or ``window < 1``.
        """
        from gnngarment.data.dataset import window_indices

        total = frames.motion_features.shape[0]
        if not 0 <= index < total:
            raise AttributionArgumentError(
                "frame_index", f"frame index {index} is out of range for a motion of "
                f"{total} frames (expected 0..{total - 1})")
        if window < 1:
            raise ValueError(f"window must be >= 1, got {window}")
        rows = window_indices(np.array([index]), window)[0]                     # (m,)
        velocity = frames.velocities.reshape(total, -1)                          # (T, 3 N_b')
        return cls(
            motion_window=torch.from_numpy(np.ascontiguousarray(
                frames.motion_features[rows], dtype=np.float32))[None, None],
            velocity_window=torch.from_numpy(np.ascontiguousarray(
                velocity[rows], dtype=np.float32))[None, None],
            joint_transforms=torch.from_numpy(np.ascontiguousarray(
                frames.joint_transforms[index], dtype=np.float32))[None, None],
            history_transforms=torch.from_numpy(np.ascontiguousarray(
                frames.joint_transforms[:index + 1], dtype=np.float32)),
            fps=float(frames.fps))

    @classmethod
    def coerce(cls, value: FrameInputs | tuple[torch.Tensor, torch.Tensor, torch.Tensor],
               config: ModelConfig) -> FrameInputs:
        """Accept a :class:`FrameInputs` or a ``(motion, velocity, transforms)`` tuple
        with or without the two leading singleton axes (``(m, 75)`` or
        ``(1, 1, m, 75)``, ...), and validate it.

        Raises:
            ValueError: wrong shape or non-finite values (names the tensor).
        """
        if isinstance(value, FrameInputs):
            frame = value
        else:
            if len(value) != 3:
                raise ValueError("frame inputs must be (motion_window, velocity_window, "
                                 f"joint_transforms), got {len(value)} tensors")
            motion, velocity, transforms = (torch.as_tensor(v, dtype=torch.float32)
                                            for v in value)
            frame = cls(motion_window=_batched(motion, 2), velocity_window=_batched(velocity, 2),
                        joint_transforms=_batched(transforms, 3))
        frame.validate(config)
        return frame

    def validate(self, config: ModelConfig) -> None:
        """Raise ``ValueError`` naming the tensor whose shape or values are wrong."""
        motion = self.motion_window
        if motion.dim() != 4 or motion.shape[:2] != (1, 1) or motion.shape[3] != MOTION_CHANNELS:
            raise ValueError(f"motion_window must have shape (1, 1, m, {MOTION_CHANNELS}), "
                             f"got {tuple(motion.shape)}")
        window = motion.shape[2]
        expected = {
            "velocity_window": (1, 1, window, 3 * config.body_vertices),
            "joint_transforms": (1, 1, NUM_JOINTS, 4, 4),
        }
        for name, shape in expected.items():
            actual = tuple(getattr(self, name).shape)
            if actual != shape:
                raise ValueError(f"{name} must have shape {shape}, got {actual}")
        for name in ("motion_window", "velocity_window", "joint_transforms"):
            if not torch.isfinite(getattr(self, name)).all():
                raise ValueError(f"{name} contains NaN or inf")

    def to(self, device: torch.device | str) -> FrameInputs:
        """A float32 copy on ``device`` (a copy, so tensors made in inference mode can
        enter autograd)."""
        def copy(tensor: torch.Tensor) -> torch.Tensor:
            return tensor.detach().to(device=device, dtype=torch.float32).clone()

        history = None if self.history_transforms is None else copy(self.history_transforms)
        return FrameInputs(copy(self.motion_window), copy(self.velocity_window),
                           copy(self.joint_transforms), history, self.fps)


def _batched(tensor: torch.Tensor, item_dims: int) -> torch.Tensor:
    """Add the (pair, frame) axes to an unbatched tensor of ``item_dims`` dimensions."""
    return tensor[None, None] if tensor.dim() == item_dims else tensor
