"""Algorithm 2 of the blueprint: neighbour-weighted unpooling, as one sparse matrix.

Kept vertices copy their coarse features. A dropped vertex ``i`` takes a weighted mean
of its kept neighbours ``j`` with

    ŵ_ij = A_ij / Σ_{i' dropped neighbour of j} A_i'j,    w_ij = ŵ_ij / Σ_j ŵ_ij,

so a kept vertex that feeds many dropped vertices counts less for each of them. (A BFS
parity argument guarantees every dropped vertex has a kept neighbour: its parent at
``d - 1``.) Filling from neighbours instead of copying pre-pooling features removes the
wave-like artefacts shown in the blueprint's Fig. 2. The result is an ``(N, N_c)``
matrix ``U``; unpooling features is ``x_fine = U @ x_coarse``.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp


def unpooling_matrix(edge_index: np.ndarray, num_vertices: int, kept: np.ndarray) -> sp.csr_matrix:
    """Build the unpooling operator of one pooling step.

    Shapes:
        edge_index: ``(2, E)`` symmetric edge index of the *fine* graph.
        kept: ``(N_c,)`` ascending fine indices of the kept vertices.
        returns: ``(N, N_c)`` float64 CSR matrix; kept rows are one-hot, every row sums
        to 1.

    Raises:
        ValueError: a dropped vertex has no kept neighbour (``kept`` is not a pooling
            of this graph).
    """
    edge_index = np.asarray(edge_index, dtype=np.int64)
    kept = np.asarray(kept, dtype=np.int64)
    is_kept = np.zeros(num_vertices, dtype=bool)
    is_kept[kept] = True
    coarse_index = np.full(num_vertices, -1, dtype=np.int64)
    coarse_index[kept] = np.arange(len(kept))

    source, target = edge_index  # i = dropped vertex, j = kept neighbour
    mask = ~is_kept[source] & is_kept[target]
    dropped, neighbour = source[mask], target[mask]

    # Σ_{i' dropped nbr of j} A_i'j: how many dropped vertices each kept vertex feeds.
    feeds = np.bincount(neighbour, minlength=num_vertices).astype(np.float64)
    raw = 1.0 / feeds[neighbour]  # ŵ_ij with A_ij = 1 on every listed edge
    row_sum = np.bincount(dropped, weights=raw, minlength=num_vertices)
    orphans = np.flatnonzero(~is_kept & (row_sum == 0))
    if len(orphans):
        raise ValueError(f"{len(orphans)} dropped vertices have no kept neighbour "
                         f"(e.g. vertex {orphans[0]}); 'kept' is not a pooling of this graph")
    weight = raw / row_sum[dropped]

    rows = np.concatenate([kept, dropped])
    cols = np.concatenate([np.arange(len(kept)), coarse_index[neighbour]])
    values = np.concatenate([np.ones(len(kept)), weight])
    matrix = sp.csr_matrix((values, (rows, cols)), shape=(num_vertices, len(kept)))
    matrix.sum_duplicates()
    return matrix
