"""Stitching the front and back panels along their seams into one mesh."""

from __future__ import annotations

import dataclasses

import numpy as np

from data_prep.garments.errors import PatternError
from data_prep.garments.pattern import Pattern


@dataclasses.dataclass
class PanelMesh:
    """Stitched front + back panels.

    Attributes:
        xz: ``(N, 2)`` pattern position of every vertex.
        side: ``(N,)`` −1 front, +1 back, 0 seam (shared).
        faces: ``(F, 3)`` outward-facing (front triangles counter-clockwise seen from −Y).
        opening: ``(N,)`` the cut index + 1 of a vertex on an opening, 0 elsewhere
            (seam corners carry their opening's label).
    """

    xz: np.ndarray
    side: np.ndarray
    faces: np.ndarray
    opening: np.ndarray


def stitch(pattern: Pattern, panels: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]]
           ) -> PanelMesh:
    """Join the triangulated panels into one mesh: seam points become shared vertices,
    each panel keeps its own opening and interior points, and the triangles are
    oriented outward.

    Args:
        pattern: the panels' runs (those the triangulation was made with).
        panels: side → ``(boundary (B, 2), interior (I, 2), triangles (T, 3))``, the
            boundary in :meth:`Pattern.boundary` order, triangles indexing boundary
            then interior points.

    Raises:
        PatternError: if a panel's boundary does not match the pattern's runs.
    """
    xz, side_of, opening = [], [], []
    seam_index = []
    # Shared vertices: every point of every seam run, corners included (a corner joins
    # the front and back halves of its opening's loop).
    corner_label: dict[tuple[int, int], int] = {}
    for position, (kind, _) in enumerate(pattern.order):
        if kind != 0:
            prev_i = pattern.order[position - 1][1]
            next_i = pattern.order[(position + 1) % len(pattern.order)][1]
            corner_label[(prev_i, -1)] = kind  # end of the seam before this opening
            corner_label[(next_i, 0)] = kind  # start of the seam after it
    for i, run in enumerate(pattern.seams):
        first = len(xz)
        for j, point in enumerate(run):
            xz.append(point)
            side_of.append(0)
            label = corner_label.get((i, 0), 0) if j == 0 else (
                corner_label.get((i, -1), 0) if j == len(run) - 1 else 0)
            opening.append(label)
        seam_index.append(first + np.arange(len(run)))
    faces = []
    for side in (-1, 1):
        boundary, interior, tri = panels[side]
        runs = pattern.boundary(side)
        index = []
        for (kind, i), run in zip(pattern.order, runs, strict=True):
            if kind == 0:
                index.append(seam_index[i][:-1])
            else:
                # An opening run's ends are the neighbouring seams' corners.
                own = len(xz) + np.arange(len(run) - 2)
                xz.extend(run[1:-1])
                side_of.extend([side] * (len(run) - 2))
                opening.extend([kind] * (len(run) - 2))
                previous_seam = pattern.order[(pattern.order.index((kind, i)) - 1)][1]
                index.append(np.concatenate([[seam_index[previous_seam][-1]], own]))
        index = np.concatenate(index)
        if len(index) != len(boundary):
            raise PatternError("internal error: boundary bookkeeping mismatch")
        interior_index = len(xz) + np.arange(len(interior))
        xz.extend(interior)
        side_of.extend([side] * len(interior))
        opening.extend([0] * len(interior))
        local_to_global = np.concatenate([index, interior_index])
        points = np.concatenate([boundary, interior])
        corners = points[tri]
        cross = ((corners[:, 1, 0] - corners[:, 0, 0]) * (corners[:, 2, 1] - corners[:, 0, 1])
                 - (corners[:, 1, 1] - corners[:, 0, 1]) * (corners[:, 2, 0] - corners[:, 0, 0]))
        # Counter-clockwise in (x, z) faces −Y (x × z = −y): outward on the front panel.
        ccw = np.where((cross > 0)[:, None], tri, tri[:, [0, 2, 1]])
        oriented = ccw if side < 0 else ccw[:, [0, 2, 1]]
        faces.append(local_to_global[oriented])
    return PanelMesh(xz=np.asarray(xz, dtype=np.float64), side=np.asarray(side_of, dtype=np.int64),
                     faces=np.concatenate(faces).astype(np.int64),
                     opening=np.asarray(opening, dtype=np.int64))
