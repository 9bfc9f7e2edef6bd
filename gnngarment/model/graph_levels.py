"""Batched multilevel graph structure: many garments (and frames) in one block-diagonal
graph per level, as PyG's ``Batch`` does for one level."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
import torch

from gnngarment.geometry.hierarchy import PoolHierarchy
from gnngarment.model.attention_graph import AttentionGraph
from gnngarment.model.sparse_matrix import SparseOperator


@dataclass
class GraphLevels:
    """Block-diagonal graphs of a batch of garments at every pooling level.

    Attributes:
        edge_index: per level ``l``, ``(2, E_l)`` long, graphs offset and stacked.
        batch: per level, ``(N_l,)`` long graph index of every vertex.
        kept: per pooling step ``l -> l + 1``, ``(N_{l+1},)`` long indices into level ``l``.
        unpool: per pooling step, ``(N_l, N_{l+1})`` sparse (COO) unpooling operator.
        num_graphs: graphs in the batch.

    The attention structure of every level (:meth:`attention_graph`) and the CSR form
    of every unpooling operator (:meth:`unpool_operator`) are built on first use and
    cached here, so all GAT layers of a level, both processors and every call with this
    object share them.
    """

    edge_index: list[torch.Tensor]
    batch: list[torch.Tensor]
    kept: list[torch.Tensor]
    unpool: list[torch.Tensor]
    num_graphs: int
    _attention: dict[int, tuple[torch.Tensor, AttentionGraph]] = field(
        default_factory=dict, init=False, repr=False)
    _unpool: dict[int, tuple[torch.Tensor, SparseOperator]] = field(
        default_factory=dict, init=False, repr=False)

    @property
    def depth(self) -> int:
        return len(self.kept)

    def attention_graph(self, level: int) -> AttentionGraph:
        """The :class:`AttentionGraph` of ``edge_index[level]``: built once and cached
        (rebuilt only if ``edge_index[level]`` was replaced, e.g. moved to a device)."""
        edge_index = self.edge_index[level]
        cached = self._attention.get(level)
        if cached is None or cached[0] is not edge_index:
            cached = (edge_index, AttentionGraph.from_edge_index(
                edge_index, int(self.batch[level].shape[0])))
            self._attention[level] = cached
        return cached[1]

    def unpool_operator(self, step: int) -> SparseOperator:
        """``unpool[step]`` as a :class:`SparseOperator` (built once, cached like
        :meth:`attention_graph`)."""
        matrix = self.unpool[step]
        cached = self._unpool.get(step)
        if cached is None or cached[0] is not matrix:
            cached = (matrix, SparseOperator(matrix))
            self._unpool[step] = cached
        return cached[1]


def _to_torch_sparse(matrix: sp.spmatrix) -> torch.Tensor:
    """Coalesced COO tensor (COO: stable autograd through ``torch.sparse.mm``)."""
    matrix = sp.coo_matrix(matrix)
    indices = torch.from_numpy(np.vstack([matrix.row, matrix.col]).astype(np.int64))
    values = torch.from_numpy(matrix.data.astype(np.float32))
    # Built from scipy, so the invariants hold; checking them would cost a pass.
    return torch.sparse_coo_tensor(indices, values, size=matrix.shape,
                                   check_invariants=False).coalesce()


def stack_hierarchies(hierarchies: Sequence[PoolHierarchy], depth: int) -> GraphLevels:
    """Stack garments' hierarchies into block-diagonal levels.

    The same hierarchy object may appear several times (one copy per frame of a
    garment): each occurrence becomes its own graph.

    Args:
        hierarchies: one per graph of the batch.
        depth: levels to use (``<=`` every hierarchy's depth).

    Raises:
        ValueError: a hierarchy is shallower than ``depth``.
    """
    for index, hierarchy in enumerate(hierarchies):
        if hierarchy.depth < depth:
            raise ValueError(f"garment {index} has a {hierarchy.depth}-level hierarchy; the "
                             f"model needs {depth} levels (re-prepare it)")
    counts = np.array([[h.num_vertices] + [lv.num_vertices for lv in h.levels[:depth]]
                       for h in hierarchies], dtype=np.int64).reshape(len(hierarchies), depth + 1)
    offsets = np.vstack([np.zeros((1, depth + 1), dtype=np.int64), np.cumsum(counts, axis=0)])

    edge_index, batch, kept, unpool = [], [], [], []
    for level in range(depth + 1):
        pieces = []
        for g, hierarchy in enumerate(hierarchies):
            edges = hierarchy.edge_index if level == 0 else hierarchy.levels[level - 1].edge_index
            pieces.append(edges + offsets[g, level])
        edge_index.append(torch.from_numpy(np.concatenate(pieces, axis=1)))
        batch.append(torch.from_numpy(np.repeat(np.arange(len(hierarchies)), counts[:, level])))
    for step in range(depth):
        kept.append(torch.from_numpy(np.concatenate(
            [h.levels[step].kept + offsets[g, step] for g, h in enumerate(hierarchies)])))
        unpool.append(_to_torch_sparse(sp.block_diag([h.levels[step].unpool for h in hierarchies],
                                                  format="csr")))
    return GraphLevels(edge_index=edge_index, batch=batch, kept=kept, unpool=unpool,
                       num_graphs=len(hierarchies))
