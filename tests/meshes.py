"""Tiny procedural meshes for tests (no files, no golden data)."""

from __future__ import annotations

import numpy as np
from scipy.spatial import Delaunay


def grid(rows: int, cols: int, spacing: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Flat ``rows × cols`` vertex grid in the z = 0 plane, two triangles per cell."""
    y, x = np.meshgrid(np.arange(rows), np.arange(cols), indexing="ij")
    pos = np.stack([x.ravel() * spacing, y.ravel() * spacing, np.zeros(rows * cols)], axis=1)
    faces = []
    for r in range(rows - 1):
        for c in range(cols - 1):
            a = r * cols + c
            faces += [[a, a + 1, a + cols + 1], [a, a + cols + 1, a + cols]]
    return pos.astype(np.float64), np.array(faces, dtype=np.int64)


def tube(rings: int, sections: int, radius: float = 0.3, height: float = 0.6,
         twist: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Open cylinder (a skirt-like tube): ``rings × sections`` vertices, z-axis."""
    pos = []
    for r in range(rings):
        z = height * r / max(rings - 1, 1)
        for s in range(sections):
            angle = 2 * np.pi * s / sections + twist * r
            pos.append([radius * np.cos(angle), radius * np.sin(angle), z])
    faces = []
    for r in range(rings - 1):
        for s in range(sections):
            a, b = r * sections + s, r * sections + (s + 1) % sections
            faces += [[a, b, b + sections], [a, b + sections, a + sections]]
    return np.array(pos, dtype=np.float64), np.array(faces, dtype=np.int64)


def random_disk(num_points: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Delaunay triangulation of random points in the unit square (irregular valences,
    few eccentricity ties), lifted onto a gentle bump so it is not planar."""
    rng = np.random.default_rng(seed)
    xy = rng.random((num_points, 2))
    faces = Delaunay(xy).simplices.astype(np.int64)
    z = 0.2 * np.sin(3 * xy[:, 0]) * np.cos(2 * xy[:, 1])
    pos = np.column_stack([xy, z])
    # Drop slivers on the hull that have (near) zero area.
    corners = pos[faces]
    area = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0],
                                         corners[:, 2] - corners[:, 0]), axis=1)
    faces = faces[area > 1e-9]
    used = np.unique(faces)
    remap = np.full(len(pos), -1)
    remap[used] = np.arange(len(used))
    return pos[used], remap[faces]


def union(*meshes: tuple[np.ndarray, np.ndarray],
          offset: float = 3.0) -> tuple[np.ndarray, np.ndarray]:
    """Concatenate meshes into one multi-component mesh, shifted apart along x."""
    positions, faces, count = [], [], 0
    for k, (pos, tri) in enumerate(meshes):
        positions.append(pos + np.array([offset * k, 0.0, 0.0]))
        faces.append(tri + count)
        count += len(pos)
    return np.concatenate(positions), np.concatenate(faces)


def interleave(pos: np.ndarray, faces: np.ndarray, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Randomly relabel the vertices (a permutation of the vertex order)."""
    permutation = np.random.default_rng(seed).permutation(len(pos))
    inverse = np.empty_like(permutation)
    inverse[permutation] = np.arange(len(pos))
    return pos[permutation], inverse[faces]


def closed_box(half: np.ndarray, subdivisions: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """A closed axis-aligned box centred at the origin (outward winding), its faces
    subdivided so triangles are small (like a body mesh); half extents ``(3,)``."""
    import trimesh

    mesh = trimesh.creation.box(extents=2 * np.asarray(half, dtype=np.float64))
    for _ in range(subdivisions):
        mesh = mesh.subdivide()
    return np.asarray(mesh.vertices), np.asarray(mesh.faces)


def box_signed_distance(points: np.ndarray, half: np.ndarray) -> np.ndarray:
    """Exact signed distance ``(N,)`` of ``points (N, 3)`` to the box of
    :func:`closed_box` (negative inside)."""
    q = np.abs(points) - np.asarray(half)
    return np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0)
