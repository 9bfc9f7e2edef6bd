"""Batched multilevel graph structure: many garments (and frames) in one block-diagonal
graph per level, as PyG's ``Batch`` does for one level."""

from __future__ import annotations

import weakref
from collections import OrderedDict
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
        runs: ``(hierarchy, copies)`` runs of consecutive graphs that are one garment's
            copies (its frames), in order; their attention structures are built as
            repeated copies (:meth:`AttentionGraph.repeated`).

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
    runs: list[tuple[PoolHierarchy, int]] = field(default_factory=list)
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
            num_nodes = int(self.batch[level].shape[0])
            if self.runs:
                graph = repeated_level_graph(self.runs, level, edge_index.device)
                edges = sum(copies * _level_edges(hierarchy, level).shape[1]
                            for hierarchy, copies in self.runs)
                if graph.num_nodes != num_nodes or edges != edge_index.shape[1]:
                    raise ValueError(f"level {level}: runs do not describe edge_index")
            else:
                graph = AttentionGraph.from_edge_index(edge_index, num_nodes)
            cached = (edge_index, graph)
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


#: Garment hierarchies whose attention graphs (with their layouts and transposes, built
#: on first use) are kept between calls: a training run sees the same garments batch
#: after batch, and rebuilding them was ~20 % of a supervised step (docs/experiments/
#: 2026-12-03-speed-issue14.md, item 11). Least recently used first out; a 10,000-vertex
#: skirt's structures (3 levels, 4 and 24 heads, with the transposes training builds)
#: measured 90 MB, hence the bound.
CACHED_HIERARCHIES = 32
_level_graphs: OrderedDict[int, tuple[weakref.ref, dict]] = OrderedDict()


def level_graph(hierarchy: PoolHierarchy, level: int, device: torch.device) -> AttentionGraph:
    """One copy's attention graph at ``level`` (0: the garment, ``l``: its ``l``-th
    pooled graph), the same object for the same hierarchy while it stays among the
    :data:`CACHED_HIERARCHIES` most recently used."""
    key = id(hierarchy)
    entry = _level_graphs.get(key)
    if entry is None or entry[0]() is not hierarchy:
        entry = (weakref.ref(hierarchy), {})
        _level_graphs[key] = entry
        while len(_level_graphs) > CACHED_HIERARCHIES:
            _level_graphs.popitem(last=False)
    _level_graphs.move_to_end(key)
    graphs = entry[1]
    if (level, str(device)) not in graphs:
        nodes = (hierarchy.num_vertices if level == 0
                 else hierarchy.levels[level - 1].num_vertices)
        graphs[(level, str(device))] = AttentionGraph.from_edge_index(
            torch.as_tensor(_level_edges(hierarchy, level), device=device), nodes)
    return graphs[(level, str(device))]


def repeated_level_graph(runs: Sequence[tuple[PoolHierarchy, int]], level: int,
                         device: torch.device) -> AttentionGraph:
    """The attention graph at ``level`` of ``copies`` copies of each hierarchy in turn,
    assembled from the cached :func:`level_graph` of each (no sort)."""
    return AttentionGraph.repeated([(level_graph(hierarchy, level, device), copies)
                                    for hierarchy, copies in runs])


def _level_edges(hierarchy: PoolHierarchy, level: int) -> np.ndarray:
    """``(2, E)`` the hierarchy's edges at ``level``."""
    return hierarchy.edge_index if level == 0 else hierarchy.levels[level - 1].edge_index


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
            pieces.append(_level_edges(hierarchy, level) + offsets[g, level])
        edge_index.append(torch.from_numpy(np.concatenate(pieces, axis=1)))
        batch.append(torch.from_numpy(np.repeat(np.arange(len(hierarchies)), counts[:, level])))
    for step in range(depth):
        kept.append(torch.from_numpy(np.concatenate(
            [h.levels[step].kept + offsets[g, step] for g, h in enumerate(hierarchies)])))
        unpool.append(_to_torch_sparse(sp.block_diag([h.levels[step].unpool for h in hierarchies],
                                                  format="csr")))
    runs: list[tuple[PoolHierarchy, int]] = []
    for hierarchy in hierarchies:
        if runs and runs[-1][0] is hierarchy:
            runs[-1] = (hierarchy, runs[-1][1] + 1)
        else:
            runs.append((hierarchy, 1))
    return GraphLevels(edge_index=edge_index, batch=batch, kept=kept, unpool=unpool,
                       num_graphs=len(hierarchies), runs=runs)
