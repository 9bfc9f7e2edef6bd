"""The edge graph of a mesh in PyG's vocabulary: ``edge_index (2, E)``, both directions."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp


def edge_index_from_faces(faces: np.ndarray, num_vertices: int) -> np.ndarray:
    """Undirected edge graph of a triangle mesh.

    Shapes:
        faces: ``(F, 3)`` int triangle indices.
        returns: ``(2, E)`` int64, every edge in both directions, sorted by
            (source, target), no self loops, no duplicates. ``num_vertices`` fixes the
            vertex count (isolated vertices simply have no edges).
    """
    faces = np.asarray(faces, dtype=np.int64)
    pairs = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    return edge_index_from_pairs(pairs, num_vertices)


def edge_index_from_pairs(pairs: np.ndarray, num_vertices: int) -> np.ndarray:
    """Symmetric, deduplicated ``(2, E)`` edge index from ``(P, 2)`` vertex pairs."""
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    both = np.concatenate([pairs, pairs[:, ::-1]])
    both = both[both[:, 0] != both[:, 1]]
    keys = np.unique(both[:, 0] * num_vertices + both[:, 1])
    return np.stack([keys // num_vertices, keys % num_vertices])


def adjacency_matrix(edge_index: np.ndarray, num_vertices: int) -> sp.csr_matrix:
    """``(N, N)`` CSR 0/1 adjacency matrix (int8) of an edge index."""
    edge_index = np.asarray(edge_index)
    data = np.ones(edge_index.shape[1], dtype=np.int8)
    matrix = sp.csr_matrix((data, (edge_index[0], edge_index[1])),
                           shape=(num_vertices, num_vertices))
    matrix.sum_duplicates()
    matrix.data[:] = 1
    return matrix


def connected_components(edge_index: np.ndarray, num_vertices: int) -> np.ndarray:
    """``(N,)`` int64 component label per vertex; labels are numbered in order of each
    component's lowest vertex index (component 0 holds vertex 0)."""
    from scipy.sparse.csgraph import connected_components as scipy_components

    _, labels = scipy_components(adjacency_matrix(edge_index, num_vertices), directed=False)
    # Relabel so the numbering follows vertex order, independent of scipy's traversal.
    _, first = np.unique(labels, return_index=True)
    order = np.argsort(first)
    relabel = np.empty_like(order)
    relabel[order] = np.arange(len(order))
    return relabel[labels].astype(np.int64)


def largest_component(faces: np.ndarray, num_vertices: int) -> tuple[np.ndarray, np.ndarray]:
    """The largest connected component of a triangle mesh (most vertices): e.g. Anny's
    body without its tongue and eyes.

    Shapes:
        faces ``(F, 3)`` → kept vertex indices ``(N', )`` (ascending) and the faces of the
        component ``(F', 3)`` re-indexed into them.
    """
    faces = np.asarray(faces, dtype=np.int64)
    labels = connected_components(edge_index_from_faces(faces, num_vertices), num_vertices)
    largest = np.argmax(np.bincount(labels))
    keep = np.flatnonzero(labels == largest)
    remap = np.full(num_vertices, -1, dtype=np.int64)
    remap[keep] = np.arange(len(keep))
    return keep, remap[faces[labels[faces[:, 0]] == largest]]
