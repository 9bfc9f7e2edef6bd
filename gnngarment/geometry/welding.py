"""Welding coincident vertices: an STL export or a UV-split OBJ stores one vertex per
triangle corner (or per seam side), and a graph network then sees triangle soup — every
triangle its own connected component, no message ever crossing an edge."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Vertices closer than this share a position (metres): far below any garment edge
#: (millimetres), far above float32 rounding of one position written twice (~1e-7 m).
WELD_TOLERANCE = 1e-6


@dataclass(frozen=True)
class WeldedMesh:
    """A mesh with coincident vertices merged.

    Attributes:
        pos: ``(M, 3)`` welded vertices (each the first of its group, in input order).
        faces: ``(F', 3)`` triangles on them; triangles that collapse (two corners in one
            group) are dropped.
        index: ``(N,)`` the welded vertex of every input vertex: ``pos[index]`` gives the
            input vertex order back (what exports write).
        merged: input vertices that were merged into another (``N − M``).
    """

    pos: np.ndarray
    faces: np.ndarray
    index: np.ndarray
    merged: int


def weld_vertices(pos: np.ndarray, faces: np.ndarray,
                  tolerance: float = WELD_TOLERANCE) -> WeldedMesh:
    """Merge vertices within ``tolerance`` of each other (transitively).

    Shapes:
        pos ``(N, 3)`` metres, faces ``(F, 3)`` → :class:`WeldedMesh`.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    pos = np.asarray(pos)
    faces = np.asarray(faces, dtype=np.int64)
    count = len(pos)
    pairs = cKDTree(pos).query_pairs(tolerance, output_type="ndarray")
    if len(pairs) == 0:
        return WeldedMesh(pos=pos, faces=faces, index=np.arange(count), merged=0)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(count, count))
    _, labels = connected_components(graph, directed=False)
    # Number the groups in order of their first vertex, so an already welded mesh keeps
    # its order and the result does not depend on scipy's traversal.
    _, first = np.unique(labels, return_index=True)
    order = np.argsort(first)
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    index = rank[labels]
    welded_faces = index[faces]
    kept = ((welded_faces[:, 0] != welded_faces[:, 1]) & (welded_faces[:, 1] != welded_faces[:, 2])
            & (welded_faces[:, 2] != welded_faces[:, 0]))
    return WeldedMesh(pos=pos[np.sort(first)], faces=welded_faces[kept], index=index,
                      merged=int(count - len(first)))
