"""Points spread uniformly over a mesh surface (by area), reproducibly."""

from __future__ import annotations

import numpy as np

from gnngarment.geometry.normals import face_normals


def surface_samples(vertices: np.ndarray, faces: np.ndarray, count: int,
                    seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """``count`` points uniform over the surface area, and the face each lies on.

    A fixed ``seed`` makes one mesh always give one answer (placement checks and body
    fitting must not change their verdict between runs).

    Shapes:
        vertices ``(N, 3)``, faces ``(F, 3)`` → points ``(count, 3)`` float64, face
        index ``(count,)`` int64.

    Raises:
        ValueError: the mesh has no area.
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    area = 0.5 * np.linalg.norm(face_normals(vertices, faces, normalize=False), axis=1)
    if not area.sum() > 0:
        raise ValueError("the mesh has no area")
    rng = np.random.default_rng(seed)
    chosen = rng.choice(len(faces), size=count, p=area / area.sum())
    u, v = rng.random((2, count))
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    corners = vertices[faces[chosen]]
    points = (corners[:, 0] + u[:, None] * (corners[:, 1] - corners[:, 0])
              + v[:, None] * (corners[:, 2] - corners[:, 0]))
    return points, chosen
