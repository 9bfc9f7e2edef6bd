"""Rest-state quantities of triangles used by the strain energies and masses."""

from __future__ import annotations

import numpy as np


def rest_triangle_frames(pos: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Inverse 2D rest edge matrices ``D_m⁻¹`` and rest areas of every triangle.

    Each rest triangle is expressed in its own orthonormal 2D frame (first axis along
    its first edge), so the deformation gradient of a deformed triangle with edge
    matrix ``D_s (3, 2)`` is ``F = D_s D_m⁻¹ (3, 2)``.

    Shapes:
        pos ``(N, 3)`` metres, faces ``(F, 3)`` → ``(F, 2, 2)`` per metre, ``(F,)`` m².
    """
    pos = np.asarray(pos, dtype=np.float64)
    faces = np.asarray(faces)
    e1 = pos[faces[:, 1]] - pos[faces[:, 0]]
    e2 = pos[faces[:, 2]] - pos[faces[:, 0]]
    normal = np.cross(e1, e2)
    area = 0.5 * np.linalg.norm(normal, axis=1)
    u = e1 / np.linalg.norm(e1, axis=1, keepdims=True)
    v = np.cross(normal, e1)
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    rest_2d = np.stack([np.stack([(e1 * u).sum(1), (e2 * u).sum(1)], -1),
                        np.stack([(e1 * v).sum(1), (e2 * v).sum(1)], -1)], -2)
    return np.linalg.inv(rest_2d), area


def vertex_masses(pos: np.ndarray, faces: np.ndarray, density: float) -> np.ndarray:
    """Lumped vertex masses (kg): a third of each incident triangle's area times the
    fabric's areal density (kg/m²). Shapes: ``(N, 3)``, ``(F, 3)`` → ``(N,)``."""
    from gnngarment.geometry.scale import vertex_areas

    return vertex_areas(pos, faces) * density
