"""The garment graph's input features ``x_i`` (blueprint Sec. 3.2): 30 channels."""

from __future__ import annotations

import numpy as np

from gnngarment.geometry.joint_distances import joint_distances
from gnngarment.geometry.normals import vertex_normals

#: position (3) + normal (3) + distances to the 24 joints.
VERTEX_FEATURE_CHANNELS = 30


def garment_vertex_features(pos: np.ndarray, faces: np.ndarray,
                            joints: np.ndarray) -> np.ndarray:
    """Per-vertex features of a garment on its rest body.

    Shapes:
        pos ``(N, 3)`` garment rest positions and joints ``(24, 3)`` the rest body's
        joints, both in the body frame (metres, Z up); faces ``(F, 3)``
        → ``(N, 30)`` float32: position, unit normal, distance to every joint (metres).
    """
    pos = np.asarray(pos, dtype=np.float64)
    joints = np.asarray(joints, dtype=np.float64)
    if pos.ndim != 2 or pos.shape[1] != 3:
        raise ValueError(f"pos must have shape (N, 3), got {pos.shape}")
    if joints.shape != (24, 3):
        raise ValueError(f"joints must have shape (24, 3), got {joints.shape}")
    features = np.concatenate(
        [pos, vertex_normals(pos, faces), joint_distances(pos, joints)], axis=1)
    return features.astype(np.float32)
