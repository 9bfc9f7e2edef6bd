"""Validation of generated garments: topology, orientation, clearance, intersections.

:func:`garment_problems` lists everything wrong with a garment (empty = valid); the
generator runs it on every garment it returns and the tests run it on samples.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from scipy.spatial import cKDTree

from data_prep.garments.angles import corner_angles

if TYPE_CHECKING:
    from data_prep.garments.body_frame import BodyFrame
    from data_prep.garments.garment import Garment

MIN_ANGLE_DEG = 2.0  # smallest triangle angle accepted


def _segments_hit_triangles(p0: np.ndarray, p1: np.ndarray, a: np.ndarray, b: np.ndarray,
                            c: np.ndarray, eps: float = 1e-12) -> np.ndarray:
    """``(M,)`` True where segment ``p0 → p1`` crosses triangle ``(a, b, c)``, row by row
    (Möller–Trumbore with the parameter restricted to the segment; coplanar pairs count
    as missing, which only matters for degenerate meshes)."""
    direction = p1 - p0
    e1, e2 = b - a, c - a
    h = np.cross(direction, e2)
    det = np.einsum("ij,ij->i", e1, h)
    ok = np.abs(det) > eps * np.linalg.norm(e1, axis=1) * np.linalg.norm(e2, axis=1) * (
        np.linalg.norm(direction, axis=1) + 1e-300)
    inv = 1.0 / np.where(ok, det, 1.0)
    s = p0 - a
    u = np.einsum("ij,ij->i", s, h) * inv
    q = np.cross(s, e1)
    v = np.einsum("ij,ij->i", direction, q) * inv
    t = np.einsum("ij,ij->i", e2, q) * inv
    return ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t >= 0) & (t <= 1)


def self_intersections(pos: np.ndarray, faces: np.ndarray, chunk: int = 200_000) -> np.ndarray:
    """Pairs of triangles that share no vertex and intersect: ``(K, 2)`` face indices.

    Candidate pairs are triangles whose bounding spheres overlap (k-d tree on
    centroids); two triangles intersect iff an edge of one crosses the other.

    Shapes:
        pos: ``(N, 3)``, faces: ``(F, 3)``.
    """
    corners = pos[faces]
    centroid = corners.mean(axis=1)
    radius = np.linalg.norm(corners - centroid[:, None], axis=2).max(axis=1)
    pairs = cKDTree(centroid).query_pairs(2 * float(radius.max()), output_type="ndarray")
    if len(pairs) == 0:
        return np.zeros((0, 2), dtype=np.int64)
    gap = np.linalg.norm(centroid[pairs[:, 0]] - centroid[pairs[:, 1]], axis=1)
    pairs = pairs[gap <= radius[pairs[:, 0]] + radius[pairs[:, 1]]]
    shared = (faces[pairs[:, 0]][:, :, None] == faces[pairs[:, 1]][:, None, :]).any(axis=(1, 2))
    pairs = pairs[~shared]
    hits = []
    for start in range(0, len(pairs), chunk):
        block = pairs[start:start + chunk]
        hit = np.zeros(len(block), dtype=bool)
        for first, second in ((0, 1), (1, 0)):
            edge_tri, face_tri = corners[block[:, first]], corners[block[:, second]]
            for k in range(3):
                hit |= _segments_hit_triangles(edge_tri[:, k], edge_tri[:, (k + 1) % 3],
                                               face_tri[:, 0], face_tri[:, 1], face_tri[:, 2])
        hits.append(block[hit])
    return np.concatenate(hits) if hits else np.zeros((0, 2), dtype=np.int64)


def min_angles_deg(pos: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """``(F,)`` smallest interior angle of each triangle, degrees."""
    return np.degrees(corner_angles(pos, faces)).min(axis=1)


def garment_problems(garment: Garment, body: BodyFrame, expected_openings: int | None = None,
                     clearance: float = 0.005, intersections: bool = True) -> list[str]:
    """Everything wrong with a garment mesh (an empty list means valid).

    Checks: mesh errors and findings of :func:`gnngarment.geometry.check_mesh` (no
    degenerate or duplicate faces, no non-manifold edges, no unreferenced vertices, one
    component); consistent orientation; every vertex a manifold disk or half-disk; a
    sphere with one hole per opening (Euler characteristic); the expected number of
    boundary loops; smallest angle ≥ 2°; normals facing away from the body; no vertex
    inside the body or closer than ``clearance`` (metres), no face centre or edge middle
    inside it; no self-intersection.
    """
    from data_prep.garments.mesher import boundary_loops
    from gnngarment.geometry import check_mesh

    pos, faces = garment.pos, garment.faces
    problems: list[str] = []
    report = check_mesh(pos, faces, source=garment.name)
    problems += report.errors + report.findings
    if report.errors:
        return problems
    n = len(pos)
    directed = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    keys = directed[:, 0] * n + directed[:, 1]
    if len(np.unique(keys)) != len(keys):
        problems.append("inconsistent orientation (a directed edge is used twice)")
    undirected = np.unique(np.sort(directed, axis=1)[:, 0] * n + np.sort(directed, axis=1)[:, 1])
    edge_v = np.bincount(np.concatenate([undirected // n, undirected % n]), minlength=n)
    face_v = np.bincount(faces.ravel(), minlength=n)
    star = edge_v - face_v  # 0: closed fan, 1: open fan (boundary); anything else: pinched
    if ((star != 0) & (star != 1)).any():
        problems.append(f"{int(((star != 0) & (star != 1)).sum())} non-manifold vertices")
    try:
        loops = boundary_loops(faces)
    except ValueError as error:
        problems.append(str(error))
        loops = []
    euler = n - len(undirected) + len(faces)
    if loops and euler != 2 - len(loops):
        problems.append(f"Euler characteristic {euler} is not that of a sphere with "
                        f"{len(loops)} holes")
    if expected_openings is not None and len(loops) != expected_openings:
        problems.append(f"{len(loops)} boundary loops, expected {expected_openings}")
    if len(garment.openings) != len(loops):
        problems.append(f"{len(garment.openings)} named openings for {len(loops)} loops")
    smallest = float(min_angles_deg(pos, faces).min())
    if smallest < MIN_ANGLE_DEG:
        problems.append(f"a triangle has a {smallest:.2f}° angle")
    inside, distance = body.distance.clearance(pos, threshold=max(2 * clearance, 0.02))
    if inside.any():
        problems.append(f"{int(inside.sum())} vertices inside the body")
    if (distance < clearance).any():
        problems.append(f"{int((distance < clearance).sum())} vertices closer than "
                        f"{clearance * 1000:.0f} mm to the body")
    # Between the vertices too: no face centre or edge middle inside the body. The signed
    # distance is 1-Lipschitz, so only faces with a vertex closer than their longest
    # edge can have such a point inside.
    corners = pos[faces]
    longest = np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2).max(axis=1)
    near = corners[distance[faces].min(axis=1) < longest]
    between = np.concatenate([near.mean(axis=1),
                              0.5 * (near + np.roll(near, 1, axis=1)).reshape(-1, 3)])
    crossing, _ = body.distance.clearance(between, threshold=0.02)
    if crossing.any():
        problems.append(f"{int(crossing.sum())} face centres or edge middles inside the body")
    # Outward: vertex normals agree with the direction away from the closest body point.
    from gnngarment.geometry import vertex_normals

    _, _, away = body.distance.query(pos, exact_below=0.02)
    agree = float(np.mean(np.einsum("ij,ij->i", vertex_normals(pos, faces), away) > 0))
    if agree < 0.9:
        problems.append(f"only {agree:.0%} of vertex normals face away from the body")
    if intersections:
        crossing = self_intersections(pos, faces)
        if len(crossing):
            problems.append(f"{len(crossing)} pairs of self-intersecting triangles")
    return problems
