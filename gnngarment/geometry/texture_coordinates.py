"""Per-face-corner texture coordinates (OBJ's ``vt`` + ``f v/vt``), and the per-vertex
layout glTF needs.

A garment's UVs are stored as OBJ stores them: a table ``uv (K, 2)`` and, for every
triangle corner, an index into it, ``uv_faces (F, 3)`` (same triangle order as
``faces``). A vertex on a UV seam has several UVs, one per side, while its position is
one; the vertex order and count stay the mesh's. ``uv`` follows the OBJ/Blender
convention: origin at the bottom-left of the image, ``v`` up (glTF's ``v`` points down:
``v_gltf = 1 − v``). The layout's check,
:func:`~gnngarment.io.obj.check_texture_coordinates`, lives with the OBJ format.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gnngarment.io.obj import check_texture_coordinates


@dataclass(frozen=True)
class SeamSplit:
    """A mesh with one UV per vertex: seam vertices duplicated, nothing else changed.

    Attributes:
        source: ``(M,)`` int64, the mesh vertex each split vertex copies; ``source[:N]``
            is ``arange(N)`` (split vertex ``i < N`` *is* vertex ``i``), the ``M − N``
            seam duplicates follow in order of first use.
        faces: ``(F, 3)`` int64 triangles over the split vertices, same order as the
            input's.
        uv: ``(M, 2)`` float64 per split vertex (OBJ convention); ``(0, 0)`` for a vertex
            no triangle uses.
    """

    source: np.ndarray
    faces: np.ndarray
    uv: np.ndarray

    @property
    def seam_vertices(self) -> int:
        """How many vertices the split added (``M − N``)."""
        return int(len(self.source) - np.count_nonzero(
            self.source == np.arange(len(self.source))))


def split_uv_seams(faces: np.ndarray, uv: np.ndarray, uv_faces: np.ndarray,
                   num_vertices: int) -> SeamSplit:
    """Duplicate every vertex once per distinct UV it has at its corners.

    Corners of a vertex that use equal UV *values* (even through different ``uv``
    indices) share one split vertex, so only real seams are split. The first
    (vertex, UV) pair of each vertex, in corner order, keeps the vertex's index.

    Shapes:
        faces ``(F, 3)``, uv ``(K, 2)``, uv_faces ``(F, 3)`` → :class:`SeamSplit` with
        ``M ≥ num_vertices`` vertices.

    Raises:
        ValueError: inconsistent shapes or indices out of range.
    """
    faces = np.asarray(faces, dtype=np.int64)
    check_texture_coordinates(uv, uv_faces, len(faces))
    if faces.ndim != 2 or faces.shape[1] != 3:
        raise ValueError(f"faces must be (F, 3), got {faces.shape}")
    if len(faces) and (faces.min() < 0 or faces.max() >= num_vertices):
        raise ValueError(f"faces index [{faces.min()}, {faces.max()}] outside "
                         f"[0, {num_vertices - 1}]")
    uv = np.asarray(uv, dtype=np.float64)
    # Canonical UV ids by value: duplicate vt lines must not create seams.
    values, canonical = np.unique(uv, axis=0, return_inverse=True)
    corner_vertex = faces.ravel()
    corner_uv = canonical.reshape(-1)[np.asarray(uv_faces, dtype=np.int64).ravel()]
    keys = corner_vertex * len(values) + corner_uv
    _, first_corner, corner_pair = np.unique(keys, return_index=True, return_inverse=True)
    # Pairs in order of first use; a vertex's first pair keeps the vertex's own index.
    order = np.argsort(first_corner, kind="stable")
    pair_vertex = corner_vertex[first_corner[order]]
    pair_uv = corner_uv[first_corner[order]]
    _, primary = np.unique(pair_vertex, return_index=True)
    is_primary = np.zeros(len(order), dtype=bool)
    is_primary[primary] = True
    new_index = np.empty(len(order), dtype=np.int64)
    new_index[is_primary] = pair_vertex[is_primary]
    extra = np.flatnonzero(~is_primary)
    new_index[extra] = num_vertices + np.arange(len(extra))
    rank = np.empty(len(order), dtype=np.int64)
    rank[order] = np.arange(len(order))  # unique-key position → first-use position
    split_faces = new_index[rank[corner_pair.reshape(-1)]].reshape(-1, 3)
    source = np.concatenate([np.arange(num_vertices), pair_vertex[extra]]).astype(np.int64)
    vertex_uv = np.zeros((len(source), 2))
    vertex_uv[new_index] = values[pair_uv]
    return SeamSplit(source=source, faces=split_faces, uv=vertex_uv)
