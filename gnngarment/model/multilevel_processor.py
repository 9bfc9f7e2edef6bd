"""M^mp: the multilevel graph U-Net (generic: it knows nothing about garments)."""

from __future__ import annotations

import torch
from torch import nn
from torch_geometric.nn import ASAPooling, SAGPooling, TopKPooling

from gnngarment.model.attention_graph import AttentionGraph
from gnngarment.model.graph_attention import apply_attention, graph_attention
from gnngarment.model.graph_levels import GraphLevels


class MultilevelProcessor(nn.Module):
    """Embedding GAT → ``levels`` × (pool, GAT) → ``levels`` × (unpool, + skip, GAT) →
    output GAT, all GATs with averaged heads; tanh after every GAT but the output one.

    ``pooling="structure"`` uses the precomputed hierarchy (Algorithm 1: keep the
    ``kept`` vertices and the coarse edges; Algorithm 2: multiply by the unpooling
    matrix). The learned PyG poolers (``topk``, ``sag``, ``asap``) pool by score at run
    time and unpool by scattering back to the kept indices, as the blueprint's
    baselines do.

    ``attention`` picks the GAT implementation (``"csr"``: :class:`GraphAttention`,
    ``"pyg"``: ``GATConv``; same parameters, same function). With ``"csr"`` the attention
    structure of each level is built once per :class:`GraphLevels` and shared by all the
    layers of that level (embedding, decoder and output at level 0).

    ``input_columns`` (``(k,)`` long, optional) says that ``x`` holds only these input
    columns and all others are zero: the embedding GAT then reads only them (the same
    result; the deformer's input is mostly zero columns, see
    :attr:`~gnngarment.model.deformer.DeformerContext.active_channels`).

    Shapes:
        x ``(N, in_channels)`` (``(N, k)`` with ``input_columns``) with ``graph``
        describing ``N`` vertices at level 0 → ``(N, out_channels)``.
    """

    def __init__(self, in_channels: int, channels: int, heads: int, out_channels: int,
                 out_heads: int, levels: int, pooling: str = "structure",
                 pooling_ratio: float = 0.5, dropout: float = 0.0, attention: str = "csr"):
        super().__init__()
        self.levels = levels
        self.pooling = pooling

        def gat(width_in: int, width_out: int, n_heads: int) -> nn.Module:
            return graph_attention(width_in, width_out, n_heads, concat=False, dropout=dropout,
                                   attention=attention)

        self.embedding = gat(in_channels, channels, heads)
        self.encoders = nn.ModuleList(gat(channels, channels, heads) for _ in range(levels))
        self.decoders = nn.ModuleList(gat(channels, channels, heads) for _ in range(levels))
        self.output = gat(channels, out_channels, out_heads)
        self.poolers = nn.ModuleList()
        if pooling != "structure":
            for _ in range(levels):
                if pooling == "topk":
                    self.poolers.append(TopKPooling(channels, ratio=pooling_ratio))
                elif pooling == "sag":
                    self.poolers.append(SAGPooling(channels, ratio=pooling_ratio))
                elif pooling == "asap":
                    self.poolers.append(ASAPooling(channels, ratio=pooling_ratio))
                else:
                    raise ValueError(f"unknown pooling '{pooling}'")

    def forward(self, x: torch.Tensor, graph: GraphLevels,
                input_columns: torch.Tensor | None = None) -> torch.Tensor:
        if self.pooling == "structure":
            return self._forward_structure(x, graph, input_columns)
        return self._forward_learned(x, graph, input_columns)

    def _forward_structure(self, x: torch.Tensor, graph: GraphLevels,
                           input_columns: torch.Tensor | None) -> torch.Tensor:
        def gat(layer: nn.Module, features: torch.Tensor, level: int,
                columns: torch.Tensor | None = None) -> torch.Tensor:
            return apply_attention(layer, features, graph.edge_index[level],
                                   lambda: graph.attention_graph(level), columns)

        # tanh_ and add_ in place: the GAT and unpooling outputs are fresh tensors that
        # nothing else reads, and each saved a (N, channels) allocation per layer.
        x = gat(self.embedding, x, 0, input_columns).tanh_()
        skips: list[torch.Tensor] = []
        for level in range(self.levels):
            skips.append(x)
            x = gat(self.encoders[level], x[graph.kept[level]], level + 1).tanh_()
        for level in reversed(range(self.levels)):
            up = (graph.unpool_operator(level) @ x).add_(skips[level])
            x = gat(self.decoders[level], up, level).tanh_()
        return gat(self.output, x, 0)

    def _forward_learned(self, x: torch.Tensor, graph: GraphLevels,
                         input_columns: torch.Tensor | None) -> torch.Tensor:
        # Pooling by score changes the coarse graphs on every call: their attention
        # structures are built per call, once per level, shared by its encoder and decoder.
        edge_index, batch = graph.edge_index[0], graph.batch[0]
        structures: dict[int, AttentionGraph] = {}

        def gat(layer: nn.Module, features: torch.Tensor, edges: torch.Tensor,
                level: int, columns: torch.Tensor | None = None) -> torch.Tensor:
            def build() -> AttentionGraph:
                if level not in structures:
                    structures[level] = (graph.attention_graph(0) if level == 0 else
                                         AttentionGraph.from_edge_index(edges, features.shape[0]))
                return structures[level]
            return apply_attention(layer, features, edges, build, columns)

        x = torch.tanh(gat(self.embedding, x, edge_index, 0, input_columns))
        skips: list[tuple[torch.Tensor, torch.Tensor, torch.Tensor]] = []
        for level in range(self.levels):
            pooled = self.poolers[level](x, edge_index, batch=batch)
            skips.append((x, edge_index, pooled[4]))
            x, edge_index, batch = pooled[0], pooled[1], pooled[3]
            x = torch.tanh(gat(self.encoders[level], x, edge_index, level + 1))
        for level in reversed(range(self.levels)):
            skip, edge_index, perm = skips[level]
            up = x.new_zeros(skip.shape[0], x.shape[1]).index_copy(0, perm, x)
            x = torch.tanh(gat(self.decoders[level], up + skip, edge_index, level))
        return gat(self.output, x, edge_index, 0)
