"""Angles between vectors and at triangle corners, in radians: one formula for the
body's angle-weighted pseudo-normals, the mesher's Delaunay flips and the mesh checks."""

from __future__ import annotations

import numpy as np


def vector_angles(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``(P,)`` angle between the rows of ``u (P, 3)`` and ``v (P, 3)``, radians, in
    ``[0, π]`` (π/2 where a row is zero: no division by zero)."""
    cos = np.einsum("ij,ij->i", u, v) / np.maximum(
        np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1), 1e-300)
    return np.arccos(np.clip(cos, -1.0, 1.0))


def corner_angles(pos: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """``(F, 3)`` interior angle of each triangle of ``faces (F, 3)`` at its corner ``k``
    (``pos (N, 3)``), radians."""
    corners = pos[faces]
    return np.stack([vector_angles(corners[:, (k + 1) % 3] - corners[:, k],
                                   corners[:, (k + 2) % 3] - corners[:, k])
                     for k in range(3)], axis=1)
