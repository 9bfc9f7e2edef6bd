"""Per-vertex normals."""

from __future__ import annotations

import numpy as np


def face_normals(pos: np.ndarray, faces: np.ndarray, normalize: bool = True) -> np.ndarray:
    """Face normals (right-handed winding); unnormalised ones have length twice the
    triangle area.

    Shapes:
        pos: ``(..., N, 3)`` (leading axes, e.g. frames, are kept), faces: ``(F, 3)`` →
        ``(..., F, 3)``.
    """
    corners = np.asarray(pos)[..., np.asarray(faces), :]  # (..., F, 3 corners, 3)
    normals = np.cross(corners[..., 1, :] - corners[..., 0, :],
                       corners[..., 2, :] - corners[..., 0, :])
    if normalize:
        normals = normals / np.maximum(np.linalg.norm(normals, axis=-1, keepdims=True), 1e-300)
    return normals


def vertex_normals(pos: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Area-weighted vertex normals.

    Each face adds its area-scaled normal to its three corners, so large faces dominate
    and the result does not depend on how finely a flat region is triangulated.

    Shapes:
        pos: ``(..., N, 3)`` (any leading axes, e.g. frames), faces: ``(F, 3)`` →
        ``(..., N, 3)`` float64 unit normals; vertices used by no face (or whose faces
        cancel) get the zero vector.
    """
    pos = np.asarray(pos, dtype=np.float64)
    faces = np.asarray(faces)
    weighted = face_normals(pos, faces, normalize=False)
    normals = np.zeros_like(pos)
    for corner in range(3):
        np.add.at(normals, (Ellipsis, faces[:, corner], slice(None)), weighted)
    length = np.linalg.norm(normals, axis=-1, keepdims=True)
    return np.where(length > 0, normals / np.where(length > 0, length, 1.0), 0.0)
