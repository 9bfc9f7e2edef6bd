"""The attention graph: every node's incoming edges, indexed for the edge softmax and
the CSR aggregation of :class:`~gnngarment.model.graph_attention.GraphAttention`.

The index structures (self loops, edges sorted by target, row pointers, per-head column
indices) depend only on the topology, so :class:`AttentionGraph` builds them once and
every layer, frame and call on that graph reuses them.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import torch

from gnngarment.model.sparse_matrix import INT32_MAX, CsrPattern, structure_mode


@dataclass(eq=False)
class HeadLayout:
    """Index structures of an :class:`AttentionGraph` for a given number of heads.

    Attention values are stored target by target, then head by head, then edge by edge
    (``(i, h, k)`` order), so that the values of target ``i`` and head ``h`` are one
    contiguous softmax segment and those of target ``i`` (all heads) one CSR row.

    Attributes:
        source_slot: ``(E'·H,)`` index ``j·H + h`` of each value's source node and head
            into node-major ``(N·H)`` arrays; also the column indices of both matrices.
        target_slot: ``(E'·H,)`` index ``i·H + h`` of each value's softmax segment.
        segment_index: the same as int64 (``scatter_add`` takes no other index type).
        segment_ptr: ``(N·H + 1,)`` int64 offsets of the softmax segments.
        head_rows: ``(N·H, N·H)`` pattern, one row per target and head (concatenated heads).
        node_rows: ``(N, N·H)`` pattern, one row per target (averaged heads).
    """

    source_slot: torch.Tensor
    target_slot: torch.Tensor
    segment_index: torch.Tensor
    segment_ptr: torch.Tensor
    head_rows: CsrPattern
    node_rows: CsrPattern


class AttentionGraph:
    """Incoming edges of every node, ready for
    :class:`~gnngarment.model.graph_attention.GraphAttention`; build once.

    Self loops of the input are dropped and exactly one per node added (``GATConv``'s
    ``add_self_loops=True``), so every node attends at least to itself and no softmax
    segment is empty. Repeated edges are kept, as PyG keeps them.

    A graph made of identical copies of smaller graphs (the frames of a garment,
    :meth:`repeated`) remembers them as ``blocks``, so that the edge softmax can gather
    with one copy's indices (:meth:`block_layouts`).

    Shapes:
        ptr ``(N + 1,)`` int64: incoming edges of node ``i`` are ``ptr[i]:ptr[i+1]``.
        source ``(E',)`` int64: source node of every edge, edges sorted by target.
    """

    def __init__(self, ptr: torch.Tensor, source: torch.Tensor, num_nodes: int,
                 blocks: tuple[tuple[AttentionGraph, int], ...] | None = None):
        self.ptr = ptr
        self.source = source
        self.num_nodes = num_nodes
        #: ``((graph, copies), ...)``: this graph is, in node order, ``copies`` disjoint
        #: copies of each ``graph`` in turn; ``None`` when not known to repeat.
        self.blocks = blocks
        self._layouts: dict[int, HeadLayout] = {}

    @classmethod
    def repeated(cls, blocks: Sequence[tuple[AttentionGraph, int]]) -> AttentionGraph:
        """The disjoint union of ``copies`` copies of each graph, in order (nodes and
        edges numbered copy by copy): the same graph :meth:`from_edge_index` builds from
        the offset, concatenated edge lists, knowing its ``blocks``."""
        device = blocks[0][0].device if blocks else torch.device("cpu")
        with structure_mode():
            ptrs = [torch.zeros(1, dtype=torch.long, device=device)]
            sources = [torch.zeros(0, dtype=torch.long, device=device)]
            nodes = edges = 0
            for graph, copies in blocks:
                copy = torch.arange(copies, device=device)[:, None]
                ptrs.append((graph.ptr[None, 1:] + edges + copy * graph.num_edges).flatten())
                sources.append((graph.source[None] + nodes + copy * graph.num_nodes).flatten())
                nodes += copies * graph.num_nodes
                edges += copies * graph.num_edges
            return cls(torch.cat(ptrs), torch.cat(sources), nodes,
                       tuple((graph, copies) for graph, copies in blocks))

    def block_layouts(self, heads: int) -> list[tuple[HeadLayout, int]] | None:
        """``[(layout of one copy, copies), ...]`` for :attr:`blocks`, or ``None``."""
        if self.blocks is None:
            return None
        return [(graph.layout(heads), copies) for graph, copies in self.blocks]

    @classmethod
    def from_edge_index(cls, edge_index: torch.Tensor, num_nodes: int) -> AttentionGraph:
        """Build from a PyG ``edge_index`` (row 0 sources, row 1 targets).

        Shapes:
            edge_index ``(2, E)`` integer, values in ``[0, num_nodes)``.

        Raises:
            ValueError: bad shape or an index outside ``[0, num_nodes)``.
        """
        if edge_index.dim() != 2 or edge_index.shape[0] != 2:
            raise ValueError(f"edge_index must be (2, E), got {tuple(edge_index.shape)}")
        with structure_mode():
            return cls._from_edge_index(edge_index.long(), num_nodes)

    @classmethod
    def _from_edge_index(cls, edge_index: torch.Tensor, num_nodes: int) -> AttentionGraph:
        if edge_index.numel() and (int(edge_index.min()) < 0
                                   or int(edge_index.max()) >= num_nodes):
            raise ValueError(f"edge_index has node indices outside [0, {num_nodes})")
        source, target = edge_index
        keep = source != target
        loops = torch.arange(num_nodes, device=edge_index.device)
        source = torch.cat([source[keep], loops])
        target = torch.cat([target[keep], loops])
        # Sorting by (target, source) gives CSR rows; the order inside a row does not
        # change the result beyond float rounding.
        order = torch.argsort(target * max(num_nodes, 1) + source)
        counts = torch.bincount(target, minlength=num_nodes)
        ptr = torch.cat([counts.new_zeros(1), torch.cumsum(counts, 0)])
        return cls(ptr, source[order], num_nodes)

    @property
    def num_edges(self) -> int:
        """``E'``: edges including the self loops."""
        return int(self.source.shape[0])

    @property
    def device(self) -> torch.device:
        return self.source.device

    @property
    def edge_index(self) -> torch.Tensor:
        """``(2, E')`` the edges, self loops included (``GATConv`` accepts it as is: it
        drops and re-adds the self loops)."""
        degree = self.ptr[1:] - self.ptr[:-1]
        target = torch.repeat_interleave(torch.arange(self.num_nodes, device=self.device),
                                         degree)
        return torch.stack([self.source, target])

    def to(self, device: torch.device | str) -> AttentionGraph:
        """This graph on ``device`` (``self`` when already there)."""
        if torch.device(device) == self.device:
            return self
        blocks = (None if self.blocks is None else
                  tuple((graph.to(device), copies) for graph, copies in self.blocks))
        return AttentionGraph(self.ptr.to(device), self.source.to(device), self.num_nodes,
                              blocks)

    def layout(self, heads: int) -> HeadLayout:
        """Index structures for ``heads`` attention heads (built on first use, cached)."""
        if heads not in self._layouts:
            with structure_mode():
                self._layouts[heads] = self._build_layout(heads)
        return self._layouts[heads]

    def _build_layout(self, heads: int) -> HeadLayout:
        if self.blocks is not None:
            return self._assemble_layout(heads)
        n, h_count, device = self.num_nodes, heads, self.device
        degree = self.ptr[1:] - self.ptr[:-1]                                  # (N,)
        target = torch.repeat_interleave(torch.arange(n, device=device), degree)  # (E',)
        local = torch.arange(self.num_edges, device=device) - self.ptr[target]
        head = torch.arange(h_count, device=device)
        # Position of (edge e, head h) in (i, h, k) order.
        position = (self.ptr[target, None] * h_count + head * degree[target, None]
                    + local[:, None]).flatten()
        source_slot = torch.empty_like(position)
        source_slot[position] = (self.source[:, None] * h_count + head).flatten()
        target_slot = torch.empty_like(position)
        target_slot[position] = (target[:, None] * h_count + head).flatten()
        segment_ptr = torch.cat([degree.new_zeros(1),
                                 torch.cumsum(degree.repeat_interleave(h_count), 0)])
        node_ptr = self.ptr * h_count
        index_type = torch.int32 if position.numel() <= INT32_MAX else torch.int64
        col = source_slot.to(index_type)
        return HeadLayout(
            # int32 gathers are several times faster than int64 ones on this CPU.
            source_slot=col,
            target_slot=target_slot.to(index_type),
            segment_index=target_slot,
            segment_ptr=segment_ptr,
            head_rows=CsrPattern(segment_ptr.to(index_type), col, (n * h_count, n * h_count)),
            node_rows=CsrPattern(node_ptr.to(index_type), col, (n, n * h_count)),
        )

    def _assemble_layout(self, heads: int) -> HeadLayout:
        """The layout of a graph of repeated copies, from each block's own layout (built
        once per block graph) offset copy by copy: no sort, and the CSR patterns know
        their blocks, so that their transposes are assembled the same way."""
        device = self.device
        total = sum(copies * graph.num_edges for graph, copies in self.blocks or ()) * heads
        # Offsets added in the index type itself: one pass per array, no int64 detour.
        index_type = torch.int32 if total <= INT32_MAX else torch.int64
        zero = torch.zeros(1, dtype=index_type, device=device)
        sources, targets, segments, nodes_ptr = [], [], [zero], [zero]
        head_blocks, node_blocks = [], []
        node = value = 0
        for graph, copies in self.blocks or ():
            layout = graph.layout(heads)
            copy = torch.arange(copies, device=device, dtype=index_type)[:, None]
            slots = node * heads + copy * (graph.num_nodes * heads)
            values = value + copy * (graph.num_edges * heads)
            sources.append((layout.source_slot.to(index_type)[None] + slots).flatten())
            targets.append((layout.target_slot.to(index_type)[None] + slots).flatten())
            segments.append((layout.head_rows.crow.to(index_type)[None, 1:]
                             + values).flatten())
            nodes_ptr.append((layout.node_rows.crow.to(index_type)[None, 1:]
                              + values).flatten())
            head_blocks.append((layout.head_rows, copies))
            node_blocks.append((layout.node_rows, copies))
            node += copies * graph.num_nodes
            value += copies * graph.num_edges * heads
        n = self.num_nodes
        target_slot = torch.cat(targets)
        segment_ptr = torch.cat(segments)
        col = torch.cat(sources)
        return HeadLayout(
            source_slot=col,
            target_slot=target_slot,
            segment_index=target_slot.long(),
            segment_ptr=segment_ptr.long(),
            head_rows=CsrPattern(segment_ptr, col, (n * heads, n * heads), tuple(head_blocks)),
            node_rows=CsrPattern(torch.cat(nodes_ptr), col, (n, n * heads),
                                 tuple(node_blocks)),
        )
