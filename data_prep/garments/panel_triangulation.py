"""Triangulating the pattern's panels: a conforming Delaunay mesh of each, stitched.

Each panel is its boundary points plus jittered interior points
(:mod:`.interior_points`); a Delaunay triangulation keeps the triangles inside the
boundary polygon, which must be a disk. Boundary segments the triangulation misses
are split and both panels meshed again; chords both panels would share are resolved
(:mod:`.seam_chords`) before the panels are stitched (:mod:`.stitching`).
Coordinates are the pattern plane's (X, Z), metres.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import Delaunay

from data_prep.garments.errors import PatternError
from data_prep.garments.interior_points import diametral_conflicts, interior_points
from data_prep.garments.pattern import Pattern
from data_prep.garments.seam_chords import resolve_shared_chords
from data_prep.garments.stitching import PanelMesh, stitch


def triangulate(pattern: Pattern, interior_count: dict[int, int],
                rng: np.random.Generator) -> PanelMesh:
    """Mesh both panels (conforming Delaunay) and stitch them along the seams.

    Both panels share the seam points, so an edge between two seam points that is not
    a seam segment (a chord cutting off a corner, or across a narrow strap) must not be
    in both panels: it would carry four triangles (see
    :func:`~.seam_chords.resolve_shared_chords`). Boundary segments a panel's Delaunay
    mesh misses are split and both panels meshed again.

    Args:
        pattern: the panels, boundaries already resampled (consecutive points = edges).
        interior_count: per side, how many interior points to place (a jittered grid).
        rng: random generator for the interior points (different per panel).

    Raises:
        PatternError: if a clean triangulation cannot be found.
    """
    seams = [run.copy() for run in pattern.seams]
    openings = {side: [run.copy() for run in runs] for side, runs in pattern.openings.items()}
    interiors: dict[int, np.ndarray] = {}
    forced: dict[int, np.ndarray] = {-1: np.zeros((0, 2)), 1: np.zeros((0, 2))}
    for _attempt in range(20):
        current = Pattern(seams=seams, openings=openings, order=pattern.order)
        panels, clean = {}, True
        seam_missing = [np.zeros(len(run) - 1, dtype=bool) for run in seams]
        for side in (-1, 1):
            runs = current.boundary(side)
            boundary = np.concatenate([run[:-1] for run in runs])
            if side not in interiors:
                interiors[side] = interior_points(boundary, interior_count[side], rng)
            points, tri, missing = _triangulate_panel(boundary, interiors[side], forced[side])
            panels[side] = (boundary, points[len(boundary):], tri)
            if missing.any():
                clean = False
                offset = 0
                for (kind, i), run in zip(current.order, runs, strict=True):
                    flags = missing[offset: offset + len(run) - 1]
                    if kind == 0:
                        seam_missing[i] |= flags
                    elif flags.any():
                        openings[side][i] = _split(run, flags)
                    offset += len(run) - 1
        if clean:
            extra = resolve_shared_chords(current, panels)
            if not any(len(points) for points in extra.values()):
                return stitch(current, panels)
            for side, points in extra.items():
                forced[side] = np.concatenate([forced[side], points])
        seams = [_split(run, flags) if flags.any() else run
                 for run, flags in zip(seams, seam_missing, strict=True)]
    raise PatternError("could not build a conforming triangulation of the pattern")


def _split(run: np.ndarray, missing: np.ndarray) -> np.ndarray:
    """Insert the midpoint of each segment of ``run`` flagged in ``missing (n − 1,)``."""
    pieces = []
    for i in range(len(run) - 1):
        pieces.append(run[i])
        if missing[i]:
            pieces.append((run[i] + run[i + 1]) / 2)
    pieces.append(run[-1])
    return np.array(pieces)


def _triangulate_panel(boundary: np.ndarray, interior: np.ndarray, forced: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Delaunay triangulation of one panel.

    Returns:
        points ``(B + I, 2)`` (boundary first), triangles inside the polygon ``(T, 3)``
        (empty if not conforming) and ``missing (B,)``: boundary segments (i → i + 1)
        that are not edges, or touch a point no triangle uses.
    """
    segments = np.stack([boundary, np.roll(boundary, -1, axis=0)], axis=1)
    interior = interior[~diametral_conflicts(interior, segments)] if len(interior) else interior
    points = np.concatenate([boundary, interior, forced])
    # Guard points far outside: the polygon is then strictly inside the convex hull, so
    # Qhull never makes flat slivers out of collinear boundary points on the hull.
    centre, span = boundary.mean(axis=0), float(np.ptp(boundary, axis=0).max())
    angles = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    guards = centre + 2 * span * np.stack([np.cos(angles), np.sin(angles)], axis=1)
    tri = Delaunay(np.concatenate([points, guards])).simplices
    tri = tri[(tri < len(points)).all(axis=1)]
    b = np.arange(len(boundary))
    nxt = (b + 1) % len(b)
    keys = np.minimum(b, nxt) * len(points) + np.maximum(b, nxt)
    missing = ~np.isin(keys, _edge_set(tri, len(points)))
    if missing.any():
        return points, np.zeros((0, 3), dtype=np.int64), missing
    tri = _inside_triangles(points, tri, len(boundary))
    _check_panel(tri, len(boundary), len(points))
    used = np.zeros(len(points), dtype=bool)
    used[tri.ravel()] = True
    orphan = ~used[: len(boundary)]
    missing = orphan | np.roll(orphan, -1)  # split the segments around an orphan point
    # Interior points no triangle uses (Qhull drops exact duplicates) are removed.
    keep = used.copy()
    keep[: len(boundary)] = True
    remap = np.cumsum(keep) - 1
    return points[keep], remap[tri], missing


def _inside_triangles(points: np.ndarray, tri: np.ndarray, count: int) -> np.ndarray:
    """The triangles inside the polygon ``points[:count]`` (counter-clockwise), given a
    triangulation that contains every polygon edge: the triangles connected to the left
    side of a polygon edge without crossing one. Robust where a centroid test is not
    (slivers along the boundary)."""
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components

    n = len(points)
    edges = np.stack([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]], axis=1)  # (T, 3, 2)
    third = tri[:, [2, 0, 1]]
    key = np.sort(edges, axis=2)
    key = key[..., 0] * n + key[..., 1]
    b = np.arange(count)
    polygon_key = np.minimum(b, (b + 1) % count) * n + np.maximum(b, (b + 1) % count)
    on_polygon = np.isin(key, polygon_key)
    # Triangles sharing an edge that is not a polygon edge are on the same side.
    flat_key = key.ravel()
    owner = np.repeat(np.arange(len(tri)), 3)
    order = np.argsort(flat_key, kind="stable")
    sorted_key = flat_key[order]
    pair = np.flatnonzero((sorted_key[1:] == sorted_key[:-1]) & ~on_polygon.ravel()[order[1:]])
    first, second = owner[order[pair]], owner[order[pair + 1]]
    graph = sp.coo_matrix((np.ones(len(pair)), (first, second)), shape=(len(tri), len(tri)))
    _, component = connected_components(graph, directed=False)
    # A triangle on a polygon edge is inside if its third vertex is left of the edge
    # as the polygon runs (i -> i + 1).
    t, e = np.nonzero(on_polygon)
    start, end = edges[t, e, 0], edges[t, e, 1]
    forward = (end - start) % count == 1
    tail, head = np.where(forward, start, end), np.where(forward, end, start)
    d, v = points[head] - points[tail], points[third[t, e]] - points[tail]
    left = d[:, 0] * v[:, 1] - d[:, 1] * v[:, 0] > 0
    inside_components = np.zeros(component.max() + 1, dtype=bool)
    inside_components[component[t[left]]] = True
    return tri[inside_components[component]]


def _check_panel(tri: np.ndarray, count: int, n: int) -> None:
    """A panel must be a disk bounded by the polygon: each polygon edge in one triangle,
    every other edge in two (a sliver outside the polygon would break this)."""
    edges = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    keys, counts = np.unique(edges[:, 0] * n + edges[:, 1], return_counts=True)
    b = np.arange(count)
    polygon = np.minimum(b, (b + 1) % count) * n + np.maximum(b, (b + 1) % count)
    on_polygon = np.isin(keys, polygon)
    if (counts[on_polygon] != 1).any() or (counts[~on_polygon] != 2).any() or (
            on_polygon.sum() != count):
        raise PatternError("a pattern panel did not triangulate as a disk")


def _edge_set(tri: np.ndarray, n: int) -> np.ndarray:
    """Sorted unique keys ``lo · n + hi`` of the edges of triangles ``tri (T, 3)``."""
    edges = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    edges = np.sort(edges, axis=1)
    return np.unique(edges[:, 0] * n + edges[:, 1])
