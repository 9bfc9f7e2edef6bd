"""Tiny cloth-and-body scenes shared by the tests of `data_prep/simulate/`."""

from __future__ import annotations

import numpy as np
import trimesh

from tests.meshes import grid

FPS = 30.0


def sphere(radius: float, centre: tuple[float, float, float] = (0.0, 0.0, 0.0),
            subdivisions: int = 3) -> tuple[np.ndarray, np.ndarray]:
    sphere = trimesh.creation.icosphere(subdivisions=subdivisions, radius=radius)
    return np.asarray(sphere.vertices) + np.asarray(centre), np.asarray(sphere.faces)


def square(cells: int, size: float, height: float) -> tuple[np.ndarray, np.ndarray]:
    """A ``size``-metre square cloth centred over the origin at z = ``height``."""
    pos, faces = grid(cells + 1, cells + 1, spacing=size / cells)
    return pos + np.array([-size / 2, -size / 2, height]), faces
