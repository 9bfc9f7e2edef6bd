"""A flared skirt with an irregular triangulation, like garments exported from DCC tools."""

from __future__ import annotations

import numpy as np
from scipy.spatial import Delaunay


def flared_skirt(num_vertices: int = 2000, waist_radius: float = 0.15,
                 hem_radius: float = 0.45, length: float = 0.6, waist_height: float = 0.0,
                 seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """An open cone (waist ring on top, hem ring below), Z-up, metres.

    The surface is the Delaunay triangulation of random, area-uniform points in a flat
    annulus with evenly spaced rim points, lifted onto the cone, so valences vary as in
    real garments (no eccentricity ties from symmetry) while both openings stay clean
    boundary loops.

    Args:
        num_vertices: approximate vertex count (exact up to the rim rounding).
        waist_radius, hem_radius, length, waist_height: metres.
        seed: random seed of the interior points.

    Returns:
        pos ``(N, 3)`` float64, faces ``(F, 3)`` int64 (outward-facing).
    """
    if num_vertices < 50:
        raise ValueError(f"num_vertices must be >= 50, got {num_vertices}")
    rng = np.random.default_rng(seed)
    inner, outer = 1.0, 3.0
    rim_count = int(np.sqrt(num_vertices) * 2.2)
    angles = 2 * np.pi * np.arange(rim_count) / rim_count
    rims = [np.column_stack([r * np.cos(angles), r * np.sin(angles)]) for r in (inner, outer)]
    interior = num_vertices - 2 * rim_count
    # Area-uniform samples in the annulus, kept off the rims so no sliver hugs them.
    radius = np.sqrt(rng.uniform((inner + 0.02) ** 2, (outer - 0.02) ** 2, interior))
    theta = rng.uniform(0, 2 * np.pi, interior)
    points = np.vstack([*rims, np.column_stack([radius * np.cos(theta),
                                                radius * np.sin(theta)])])
    faces = Delaunay(points).simplices
    faces = faces[np.linalg.norm(points[faces].mean(axis=1), axis=1) > inner]  # the hole
    r = np.linalg.norm(points, axis=1)
    t = (r - inner) / (outer - inner)  # 0 at the waist, 1 at the hem
    scale = (waist_radius + (hem_radius - waist_radius) * t) / r
    pos = np.column_stack([points * scale[:, None], waist_height - length * t])
    used = np.unique(faces)
    remap = np.full(len(pos), -1)
    remap[used] = np.arange(len(used))
    # Delaunay triangles are counter-clockwise seen from +z; lifted onto the downward
    # cone they face outward, away from the body (checked in the tests).
    return pos[used], remap[faces].astype(np.int64)
