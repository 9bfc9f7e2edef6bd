"""Distances from mesh vertices to skeleton joints (the per-vertex body features)."""

from __future__ import annotations

import numpy as np


def joint_distances(pos: np.ndarray, joints: np.ndarray) -> np.ndarray:
    """Euclidean distance from every vertex to every joint.

    Shapes:
        pos: ``(N, 3)`` vertices, joints: ``(S, 3)`` joint positions, same frame and
        unit (metres for the canonical body) → ``(N, S)``.
    """
    pos = np.asarray(pos, dtype=np.float64)
    joints = np.asarray(joints, dtype=np.float64)
    if pos.ndim != 2 or pos.shape[1] != 3:
        raise ValueError(f"pos must have shape (N, 3), got {pos.shape}")
    if joints.ndim != 2 or joints.shape[1] != 3:
        raise ValueError(f"joints must have shape (S, 3), got {joints.shape}")
    return np.linalg.norm(pos[:, None, :] - joints[None, :, :], axis=-1)
