"""Intrinsic-Delaunay edge flips on a 3D triangle mesh (topology only; no vertex moves).

A Delaunay triangulation of the flat pattern is not Delaunay once lifted onto the
body-shaped surface: near the side folds and the corners of openings it leaves slivers
(an extreme case: three consecutive vertices of a boundary loop forming a triangle,
which becomes flat when the loop straightens in 3D). Lawson's flips with the 3D angles
fix that: an interior edge whose two opposite angles sum to more than π is replaced by
the other diagonal of its quad. Flips are applied in batches of edges that share no
triangle, skipping any that would duplicate an edge or fold the surface.
"""

from __future__ import annotations

import numpy as np

from data_prep.garments.angles import vector_angles


def _angle(pos: np.ndarray, apex: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``(E,)`` angle at ``pos[apex]`` between ``pos[a]`` and ``pos[b]``, radians."""
    return vector_angles(pos[a] - pos[apex], pos[b] - pos[apex])


def _normal(pos: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    n = np.cross(pos[b] - pos[a], pos[c] - pos[a])
    return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)


def _exists(sorted_key: np.ndarray, query: np.ndarray) -> np.ndarray:
    """``(Q,)`` True where ``query`` is in the sorted ``sorted_key``."""
    at = np.minimum(np.searchsorted(sorted_key, query), len(sorted_key) - 1)
    return sorted_key[at] == query


def delaunay_flips(pos: np.ndarray, faces: np.ndarray, rounds: int = 20,
                   tolerance: float = 1e-3) -> np.ndarray:
    """Flip edges until the mesh is (intrinsically) Delaunay or ``rounds`` pass.

    Shapes:
        pos: ``(N, 3)``; faces: ``(F, 3)`` consistently oriented manifold triangles.
        returns: ``(F, 3)`` faces, same count and orientation convention.
    """
    faces = np.array(faces, dtype=np.int64, copy=True)
    n = len(pos)
    for _ in range(rounds):
        # Directed half-edges (a -> b) with their triangle and opposite vertex.
        a = faces.ravel()
        b = faces[:, [1, 2, 0]].ravel()
        opposite = faces[:, [2, 0, 1]].ravel()
        triangle = np.repeat(np.arange(len(faces)), 3)
        key = a * n + b
        twin_key = b * n + a
        order = np.argsort(key)
        position = np.minimum(np.searchsorted(key[order], twin_key), len(key) - 1)
        has_twin = key[order][position] == twin_key
        # Each interior edge once: the half-edge with a < b.
        pick = np.flatnonzero(has_twin & (a < b))
        twin = order[position[pick]]
        c, d = opposite[pick], opposite[twin]
        ea, eb = a[pick], b[pick]
        violation = _angle(pos, c, ea, eb) + _angle(pos, d, ea, eb) - np.pi
        candidate = violation > tolerance
        if not candidate.any():
            break
        pick, twin, c, d, ea, eb, violation = (x[candidate] for x in
                                              (pick, twin, c, d, ea, eb, violation))
        # The new diagonal must not exist already (that would make a non-manifold edge).
        sorted_key = key[order]

        new_key = np.minimum(c, d) * n + np.maximum(c, d)
        fresh = ~_exists(sorted_key, c * n + d) & ~_exists(sorted_key, d * n + c) & (c != d)
        # The two new triangles must face the same way as the old pair (no fold).
        old = _normal(pos, ea, eb, c) + _normal(pos, eb, ea, d)
        first, second = _normal(pos, c, d, eb), _normal(pos, d, c, ea)
        unfolded = ((first * old).sum(1) > 0) & ((second * old).sum(1) > 0)
        ok = np.flatnonzero(fresh & unfolded)
        if len(ok) == 0:
            break
        # A batch of flips that share no triangle: each candidate that is the worst at
        # both of its triangles (ties to the lower index), and one flip per new diagonal.
        t1_all, t2_all = triangle[pick[ok]], triangle[twin[ok]]
        score = violation[ok] + 1e-12 * (len(ok) - np.arange(len(ok)))
        best = np.full(len(faces), -np.inf)
        np.maximum.at(best, t1_all, score)
        np.maximum.at(best, t2_all, score)
        winner = (score >= best[t1_all]) & (score >= best[t2_all])
        chosen = ok[winner]
        by_key = np.argsort(new_key[chosen], kind="stable")
        repeated = np.zeros(len(chosen), dtype=bool)
        repeated[by_key[1:]] = new_key[chosen][by_key[1:]] == new_key[chosen][by_key[:-1]]
        chosen = chosen[~repeated]
        t1, t2 = triangle[pick[chosen]], triangle[twin[chosen]]
        # (a, b, c) + (b, a, d)  ->  (c, d, b) + (d, c, a): orientation preserved.
        faces[t1] = np.stack([c[chosen], d[chosen], eb[chosen]], axis=1)
        faces[t2] = np.stack([d[chosen], c[chosen], ea[chosen]], axis=1)
    return faces
