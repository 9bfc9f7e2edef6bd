"""A panel's interior points: a jittered triangular lattice, clear of the boundary.

The points are kept out of every boundary segment's diametral circle, so a Delaunay
triangulation of boundary + interior points keeps the boundary segments as edges
(a conforming triangulation); the lattice gives valences around 6, varied by the
jitter. Coordinates are the pattern plane's (X, Z), metres.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree


def diametral_conflicts(points: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """``(P,)`` True where a point lies in (1.2×) the diametral circle of a boundary
    segment ``(S, 2, 2)``: such a point keeps the segment out of a Delaunay mesh."""
    mids = segments.mean(axis=1)
    radius = 0.6 * np.linalg.norm(segments[:, 1] - segments[:, 0], axis=1)
    tree = cKDTree(mids)
    k = min(8, len(mids))
    distance, idx = tree.query(points, k=k)
    distance = distance.reshape(len(points), k)
    idx = idx.reshape(len(points), k)
    return (distance < radius[idx]).any(axis=1)


def _inside_polygon(polygon: np.ndarray, points: np.ndarray) -> np.ndarray:
    """``(P,)`` True where ``points (P, 2)`` lie inside ``polygon (n, 2)``."""
    from matplotlib.path import Path

    return Path(polygon).contains_points(points)


def interior_points(polygon: np.ndarray, count: int, rng: np.random.Generator) -> np.ndarray:
    """About ``count`` jittered-grid points inside ``polygon`` and clear of its segments'
    diametral circles: the lattice spacing is set from the polygon's area, then corrected
    once for the points lost along the boundary."""
    area = 0.5 * abs(float(np.sum(polygon[:, 0] * np.roll(polygon[:, 1], -1)
                                  - np.roll(polygon[:, 0], -1) * polygon[:, 1])))
    segments = np.stack([polygon, np.roll(polygon, -1, axis=0)], axis=1)
    # A triangular lattice of spacing h holds 2 / (√3 h²) points per unit area.
    spacing = float(np.sqrt(2.0 * area / (np.sqrt(3.0) * max(count, 1))))
    state = rng.bit_generator.state
    kept = len(_clear(_jittered_points(polygon, spacing, rng), segments))
    rng.bit_generator.state = state  # same draws, finer grid: reproducible per seed
    spacing *= float(np.sqrt(max(kept, 1) / max(count, 1)))
    return _clear(_jittered_points(polygon, spacing, rng), segments)


def _clear(points: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """The ``points (P, 2)`` outside every diametral circle of ``segments (S, 2, 2)``."""
    return points[~diametral_conflicts(points, segments)] if len(points) else points


def _jittered_points(polygon: np.ndarray, spacing: float, rng: np.random.Generator) -> np.ndarray:
    """Jittered grid points (±35 % of a cell) inside ``polygon``, rows offset by half a
    cell (a triangular lattice, so Delaunay gives valences around 6, varied by the
    jitter)."""
    lo, hi = polygon.min(axis=0), polygon.max(axis=0)
    row_step = spacing * np.sqrt(3) / 2
    rows = np.arange(lo[1], hi[1] + row_step, row_step)
    cols = np.arange(lo[0] - spacing, hi[0] + spacing, spacing)
    xx, zz = np.meshgrid(cols, rows)
    xx = xx + 0.5 * spacing * (np.arange(len(rows)) % 2)[:, None]
    points = np.stack([xx.ravel(), zz.ravel()], axis=1)
    points += rng.uniform(-0.35, 0.35, points.shape) * np.array([spacing, row_step])
    return points[_inside_polygon(polygon, points)]
