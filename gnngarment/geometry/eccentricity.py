"""Exact graph centres (minimal hop eccentricity) without all-pairs BFS.

Algorithm 1 of the blueprint starts each component's BFS at "the first vertex with the
minimal eccentricity". Computing every eccentricity exactly costs one BFS per vertex
(O(N·E)), far too slow for 20k-vertex garments. We use the bounding scheme of Takes &
Kosters (2013) restricted to what the centre needs: every BFS from a vertex ``v`` with
eccentricity ``e(v)`` bounds every other vertex ``w`` by

    max(d(v, w), e(v) - d(v, w)) <= e(w) <= e(v) + d(v, w),

and vertices whose lower bound exceeds the best known eccentricity can never be the
centre. Phase 1 pins the radius down (alternating BFS from the vertex with the smallest
lower bound and the one with the largest upper bound); phase 2 walks the remaining
candidates in index order to find the *lowest-index* vertex whose eccentricity equals
the radius, so ties are broken exactly as the brute-force definition does.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import breadth_first_order

from gnngarment.geometry.graph import adjacency_matrix, connected_components


def hop_distance(adjacency: sp.csr_matrix, source: int) -> np.ndarray:
    """``(N,)`` int64 hop (edge-count) distances from ``source``; -1 where unreachable.

    scipy's compiled BFS gives the BFS tree; depths follow by pointer doubling on the
    predecessor array (log2(depth) vectorised passes), which measured ~1.7x faster
    than ``dijkstra(unweighted=True)`` on a 20k-vertex mesh.
    """
    n = adjacency.shape[0]
    _, predecessor = breadth_first_order(adjacency, source, directed=True,
                                         return_predecessors=True)
    ancestor = predecessor.astype(np.int64)
    unreached = ancestor < 0
    ancestor[unreached] = source  # the source itself and vertices of other components
    depth = np.ones(n, dtype=np.int64)
    depth[unreached] = 0
    while True:
        grand = ancestor[ancestor]
        if np.array_equal(grand, ancestor):
            break
        depth += depth[ancestor]
        ancestor = grand
    depth[unreached] = -1
    depth[source] = 0
    return depth


def connected_centre(adjacency: sp.csr_matrix) -> tuple[int, int, int]:
    """Centre of a *connected* graph: the lowest-index vertex of minimal eccentricity.

    Args:
        adjacency: ``(n, n)`` symmetric CSR adjacency of one connected component.

    Returns:
        centre: vertex index (local to ``adjacency``).
        radius: its eccentricity (hops).
        bfs_runs: number of BFS runs used (for benchmarks and tests of the pruning).
    """
    n = adjacency.shape[0]
    if n == 1:
        return 0, 0, 0
    lower = np.zeros(n, dtype=np.int64)
    upper = np.full(n, np.iinfo(np.int64).max // 4, dtype=np.int64)
    exact = np.zeros(n, dtype=bool)
    bfs_runs = 0

    def visit(vertex: int) -> int:
        nonlocal bfs_runs
        distance = hop_distance(adjacency, vertex)
        bfs_runs += 1
        eccentricity = int(distance.max())
        np.maximum(lower, np.maximum(distance, eccentricity - distance), out=lower)
        np.minimum(upper, eccentricity + distance, out=upper)
        lower[vertex] = upper[vertex] = eccentricity
        exact[vertex] = True
        return eccentricity

    # Phase 1: radius = min(upper) once no vertex can still go below it.
    take_smallest_lower = True
    while True:
        best = int(upper.min())
        open_ = (~exact) & (lower < best)
        if not open_.any():
            break
        candidates = np.flatnonzero(open_)
        if take_smallest_lower:
            # smallest lower bound; among those, the largest upper bound (most to learn)
            key = np.lexsort((-upper[candidates], lower[candidates]))
        else:
            key = np.lexsort((lower[candidates], -upper[candidates]))
        visit(int(candidates[key[0]]))
        take_smallest_lower = not take_smallest_lower
    radius = int(upper.min())

    # Phase 2: lowest index with eccentricity == radius. Since e(v) >= radius for all v,
    # upper[v] == radius proves e(v) == radius; lower[v] > radius rules v out.
    for vertex in np.flatnonzero(lower <= radius):
        vertex = int(vertex)
        if lower[vertex] > radius:  # ruled out by a BFS run during this loop
            continue
        if upper[vertex] == radius or visit(vertex) == radius:
            return vertex, radius, bfs_runs
    raise AssertionError("no vertex attains the radius; bounds are inconsistent")


def graph_centres(edge_index: np.ndarray, num_vertices: int) -> tuple[np.ndarray, np.ndarray]:
    """Per-component centres of a graph (Algorithm 1's ``x_center``).

    Shapes:
        edge_index: ``(2, E)`` symmetric edge index.
        returns: ``centres (C,)`` global vertex index of each component's centre, and
        ``labels (N,)`` the component of every vertex (component ``c`` is the one
        whose lowest vertex index is the ``c``-th smallest).
    """
    labels = connected_components(edge_index, num_vertices)
    adjacency = adjacency_matrix(edge_index, num_vertices)
    num_components = int(labels.max()) + 1 if num_vertices else 0
    centres = np.empty(num_components, dtype=np.int64)
    order = np.argsort(labels, kind="stable")  # vertices grouped by component, in index order
    bounds = np.searchsorted(labels[order], np.arange(num_components + 1))
    for component in range(num_components):
        members = order[bounds[component]:bounds[component + 1]]
        local = adjacency[members][:, members]
        centre, _, _ = connected_centre(local.tocsr())
        centres[component] = members[centre]
    return centres, labels
