"""Chords both panels would share: the one way stitching two panels can fail.

Both panels are triangulated with the same seam points, so an edge between two seam
points that is not a seam segment (a chord cutting off a corner, or across a narrow
strap) could be in both panels, and the stitched mesh would give it four triangles.
:func:`resolve_shared_chords` flips every such chord in the back panel, or, where its
quad is not convex, asks for a point that breaks it.

``panels`` maps a side (−1 front, +1 back) to that panel's ``(boundary (B, 2),
interior (I, 2), triangles (T, 3))``, triangles indexing boundary then interior points.
"""

from __future__ import annotations

import numpy as np

from data_prep.garments.pattern import Pattern


def _shared_ids(pattern: Pattern, side: int) -> np.ndarray:
    """Per boundary point of one panel (in :meth:`Pattern.boundary` order): the index of
    the shared (seam) vertex it is, numbering seam points run by run, or −1 for a point
    of that panel's own opening."""
    first = np.cumsum([0] + [len(run) for run in pattern.seams])
    ids = []
    for position, ((kind, i), run) in enumerate(zip(pattern.order, pattern.boundary(side),
                                                    strict=True)):
        if kind == 0:
            ids.append(first[i] + np.arange(len(run) - 1))
        else:
            previous = pattern.order[position - 1][1]
            ids.append(np.concatenate([[first[previous] + len(pattern.seams[previous]) - 1],
                                       np.full(len(run) - 2, -1)]))
    return np.concatenate(ids).astype(np.int64)


def _segments_cross(p: np.ndarray, q: np.ndarray, r: np.ndarray, s: np.ndarray) -> bool:
    """True if segments ``p–q`` and ``r–s`` (2D) cross at a point inside both."""
    def orient(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> float:
        return float((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))

    return (orient(p, q, r) * orient(p, q, s) < 0) and (orient(r, s, p) * orient(r, s, q) < 0)


def resolve_shared_chords(pattern: Pattern,
                          panels: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]]
                          ) -> dict[int, np.ndarray]:
    """Resolve what would break the stitched mesh; return points to add (per panel) if
    the panels must be meshed again (nothing to add: ``panels`` is ready to stitch).

    A chord between two seam points in both panels is flipped in the back panel (the
    other diagonal of its quad) when that quad is convex, else a point is added on the
    back panel's side of it.
    """
    chords, extra = {}, {-1: [], 1: []}
    for side in (-1, 1):
        boundary, _, tri = panels[side]
        count = len(boundary)
        ids = _shared_ids(pattern, side)
        edges = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
        edges = np.unique(edges, axis=0)
        on_boundary = (edges < count).all(axis=1)
        consecutive = ((edges[:, 1] - edges[:, 0]) % count == 1) | (
            (edges[:, 0] - edges[:, 1]) % count == 1)
        chord = edges[on_boundary & ~consecutive]
        shared = (ids[chord] >= 0).all(axis=1)
        chords[side] = {(int(min(ids[a], ids[b])), int(max(ids[a], ids[b]))): (int(a), int(b))
                        for a, b in chord[shared]}
    boundary, interior, tri = panels[1]
    points = np.concatenate([boundary, interior])
    tri = tri.copy()
    for key in chords[-1].keys() & chords[1].keys():
        a, b = chords[1][key]
        holding = np.flatnonzero(((tri == a) | (tri == b)).sum(axis=1) == 2)
        if len(holding) != 2:
            continue
        c = int(np.setdiff1d(tri[holding[0]], [a, b])[0])
        d = int(np.setdiff1d(tri[holding[1]], [a, b])[0])
        if _segments_cross(points[a], points[b], points[c], points[d]):
            tri[holding[0]] = [a, c, d]
            tri[holding[1]] = [b, d, c]
        else:
            inner = d if d >= len(boundary) else c
            extra[1].append((points[a] + points[b]) / 2 * 0.7 + 0.3 * points[inner])
    panels[1] = (boundary, interior, tri)
    return {side: np.array(found).reshape(-1, 2) for side, found in extra.items()}
