"""A length scale of a mesh, for features that must not depend on units or resolution."""

from __future__ import annotations

import numpy as np

from gnngarment.geometry.normals import face_normals


def surface_area(pos: np.ndarray, faces: np.ndarray) -> float:
    """Total triangle area, in squared input units."""
    cross = face_normals(np.asarray(pos, dtype=np.float64), faces, normalize=False)
    return float(0.5 * np.linalg.norm(cross, axis=1).sum())


def mesh_scale(pos: np.ndarray, faces: np.ndarray) -> float:
    """``sqrt(total surface area)``: a length (input units) that scales with the mesh,
    is unchanged by remeshing, and does not depend on how the mesh is posed or folded
    (unlike a bounding box)."""
    return float(np.sqrt(surface_area(pos, faces)))


def vertex_areas(pos: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """``(N,)`` lumped (barycentric) vertex areas: a third of each incident triangle."""
    area = 0.5 * np.linalg.norm(
        face_normals(np.asarray(pos, dtype=np.float64), faces, normalize=False), axis=1)
    areas = np.zeros(len(pos))
    for corner in range(3):
        np.add.at(areas, np.asarray(faces)[:, corner], area / 3.0)
    return areas
