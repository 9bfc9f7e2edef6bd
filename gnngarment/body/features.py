"""Body and motion features of the blueprint (Li et al. 2024, Sec. 3).

* ``D`` — joint–vertex distances over the fixed body-vertex subset, the input of E^bs.
* per-frame motion state — the 24 joint rotations and the root translation relative to
  the previous frame, ``3 (S + 1) = 75`` values, the input of E^t1;
* body-vertex velocities over the subset, ``3 N_b′`` values per frame, the input of E^t2;
* windows of the last ``m`` frames of either.

Padding rule: the window of frame ``t`` holds frames ``t − m + 1 … t``; frame indices
before 0 are replaced by frame 0 (the first frame is repeated), so a sequence shorter
than ``m`` is padded at its start by copies of its first frame.
"""

from __future__ import annotations

import torch

from gnngarment.body.motion import Motion
from gnngarment.body.skeleton import NUM_JOINTS


def joint_vertex_distances(vertices: torch.Tensor, joints: torch.Tensor) -> torch.Tensor:
    """Euclidean distances between body vertices and joints (the body-shape feature D).

    Shapes:
        vertices ``(..., N, 3)``, joints ``(..., 24, 3)`` → ``(..., N, 24)`` metres.
    """
    if vertices.shape[-1] != 3 or joints.shape[-2:] != (NUM_JOINTS, 3):
        raise ValueError(
            f"expected vertices (..., N, 3) and joints (..., {NUM_JOINTS}, 3), got "
            f"{tuple(vertices.shape)} and {tuple(joints.shape)}"
        )
    return torch.linalg.norm(vertices[..., :, None, :] - joints[..., None, :, :], dim=-1)


def motion_features(motion: Motion, dtype: torch.dtype = torch.float32) -> torch.Tensor:
    """Per-frame motion state: 24 axis-angles then the root displacement since the
    previous frame (zero for the first frame).

    Shapes:
        → ``(T, 75)`` = ``(T, 24·3 + 3)``.
    """
    rotations, translation = motion.to_torch(dtype)
    displacement = torch.zeros_like(translation)
    displacement[1:] = translation[1:] - translation[:-1]
    return torch.cat([rotations.reshape(motion.num_frames, -1), displacement], dim=1)


def vertex_velocities(vertices: torch.Tensor, fps: float) -> torch.Tensor:
    """Backward-difference velocities ``(x_t − x_{t−1}) · fps`` (m/s), zero at frame 0.

    Shapes:
        vertices ``(T, N, 3)`` → ``(T, N, 3)``.
    """
    if vertices.dim() != 3 or vertices.shape[-1] != 3:
        raise ValueError(f"vertices must be (T, N, 3), got {tuple(vertices.shape)}")
    if fps <= 0:
        raise ValueError(f"fps must be > 0, got {fps}")
    velocities = torch.zeros_like(vertices)
    velocities[1:] = (vertices[1:] - vertices[:-1]) * fps
    return velocities


def sliding_windows(frames: torch.Tensor, window: int) -> torch.Tensor:
    """Windows of the last ``window`` frames for every frame, oldest first.

    Frame indices before 0 repeat frame 0 (module docstring).

    Shapes:
        frames ``(T, ...)`` → ``(T, window, ...)``; ``[t, -1]`` is frame ``t``.
    """
    if window < 1:
        raise ValueError(f"window must be >= 1, got {window}")
    count = frames.shape[0]
    if count < 1:
        raise ValueError("need at least one frame")
    offsets = torch.arange(-window + 1, 1)
    index = (torch.arange(count)[:, None] + offsets[None, :]).clamp(min=0)
    return frames[index]


def motion_windows(motion: Motion, window: int, dtype: torch.dtype = torch.float32) -> torch.Tensor:
    """Inputs of E^t1: :func:`motion_features` in windows of the last ``window`` frames.

    Shapes:
        → ``(T, window, 75)``.
    """
    return sliding_windows(motion_features(motion, dtype), window)


def velocity_windows(velocities: torch.Tensor, window: int) -> torch.Tensor:
    """Inputs of E^t2: flattened body-vertex velocities in windows of ``window`` frames.

    Shapes:
        velocities ``(T, N′, 3)`` → ``(T, window, 3 N′)``.
    """
    if velocities.dim() != 3 or velocities.shape[-1] != 3:
        raise ValueError(f"velocities must be (T, N', 3), got {tuple(velocities.shape)}")
    return sliding_windows(velocities.reshape(velocities.shape[0], -1), window)
