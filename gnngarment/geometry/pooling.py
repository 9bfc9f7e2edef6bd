"""Algorithm 1 of the blueprint: structure-preserving graph pooling.

Per connected component: start at the centre (lowest-index vertex of minimal hop
eccentricity), take the BFS hop distance ``d`` of every vertex from it, keep the
vertices at even ``d`` and drop those at odd ``d``. Every dropped vertex links each of
its neighbours at ``d - 1`` to each of its neighbours at ``d + 1`` (the second-order
connection through it survives), and the original edges between kept vertices stay.
The coarse graph is therefore connected whenever the fine one is (every kept vertex at
``d >= 2`` gets an edge to a kept vertex at ``d - 2``) and depends only on topology,
never on Euclidean proximity, so folds and contacts do not merge distant cloth.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gnngarment.geometry.eccentricity import graph_centres, hop_distance
from gnngarment.geometry.graph import adjacency_matrix, edge_index_from_pairs


@dataclass
class PooledGraph:
    """The coarse graph of one pooling step.

    Attributes:
        kept: ``(N_c,)`` int64 fine indices of the kept vertices, ascending (kept
            vertices keep their relative order; coarse vertex ``k`` is ``kept[k]``).
        edge_index: ``(2, E_c)`` int64 coarse edge index (coarse numbering, both
            directions).
        hop_distance: ``(N,)`` int64 BFS hop distance of each fine vertex from its
            component's centre.
        centres: ``(C,)`` int64 fine index of each component's centre.
    """

    kept: np.ndarray
    edge_index: np.ndarray
    hop_distance: np.ndarray
    centres: np.ndarray


def pool(edge_index: np.ndarray, num_vertices: int) -> PooledGraph:
    """Pool a graph once (Algorithm 1).

    Shapes:
        edge_index: ``(2, E)`` symmetric int edge index of the fine graph.
        returns: :class:`PooledGraph` with ``N_c`` = number of even-distance vertices.
    """
    edge_index = np.asarray(edge_index, dtype=np.int64)
    centres, _ = graph_centres(edge_index, num_vertices)
    adjacency = adjacency_matrix(edge_index, num_vertices)

    distance = np.full(num_vertices, -1, dtype=np.int64)
    for centre in centres:
        from_centre = hop_distance(adjacency, int(centre))
        reached = from_centre >= 0
        distance[reached] = from_centre[reached]

    is_kept = distance % 2 == 0
    kept = np.flatnonzero(is_kept)
    coarse_index = np.full(num_vertices, -1, dtype=np.int64)
    coarse_index[kept] = np.arange(len(kept))

    source, target = edge_index
    # Original edges between kept vertices.
    both_kept = is_kept[source] & is_kept[target]
    pairs = [np.stack([source[both_kept], target[both_kept]], axis=1)]

    # Through every dropped vertex i: each neighbour at d-1 to each neighbour at d+1.
    # Grouping the directed edges (i -> j) by i lets us form all (from, to) pairs of a
    # vertex with one sort, instead of a Python loop over dropped vertices.
    dropped_source = ~is_kept[source]
    step = distance[target] - distance[source]
    from_edges = dropped_source & (step == -1)
    to_edges = dropped_source & (step == 1)
    pairs.append(_pairs_through(source[from_edges], target[from_edges],
                                source[to_edges], target[to_edges]))

    fine_pairs = np.concatenate(pairs)
    coarse_edges = edge_index_from_pairs(coarse_index[fine_pairs], len(kept))
    return PooledGraph(kept=kept, edge_index=coarse_edges, hop_distance=distance,
                       centres=centres)


def _pairs_through(via_a: np.ndarray, end_a: np.ndarray, via_b: np.ndarray,
                   end_b: np.ndarray) -> np.ndarray:
    """All ``(end_a, end_b)`` pairs that share the same ``via`` vertex.

    Shapes: four ``(P_a,)``/``(P_b,)`` int arrays → ``(Q, 2)`` pairs.
    """
    if len(via_a) == 0 or len(via_b) == 0:
        return np.zeros((0, 2), dtype=np.int64)
    order_b = np.argsort(via_b, kind="stable")
    via_b, end_b = via_b[order_b], end_b[order_b]
    first = np.searchsorted(via_b, via_a, side="left")
    last = np.searchsorted(via_b, via_a, side="right")
    count = last - first
    # Repeat every a-entry once per matching b-entry, then index the matching b's.
    repeated_a = np.repeat(np.arange(len(via_a)), count)
    offsets = np.arange(len(repeated_a)) - np.repeat(np.cumsum(count) - count, count)
    b_index = np.repeat(first, count) + offsets
    return np.stack([end_a[repeated_a], end_b[b_index]], axis=1)
