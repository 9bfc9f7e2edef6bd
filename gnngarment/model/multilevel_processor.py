"""M^mp: the multilevel graph U-Net (generic: it knows nothing about garments)."""

from __future__ import annotations

import torch
from torch import nn
from torch_geometric.nn import ASAPooling, GATConv, SAGPooling, TopKPooling

from gnngarment.model.graph_levels import GraphLevels


class MultilevelProcessor(nn.Module):
    """Embedding GAT → ``levels`` × (pool, GAT) → ``levels`` × (unpool, + skip, GAT) →
    output GAT, all GATs with averaged heads; tanh after every GAT but the output one.

    ``pooling="structure"`` uses the precomputed hierarchy (Algorithm 1: keep the
    ``kept`` vertices and the coarse edges; Algorithm 2: multiply by the unpooling
    matrix). The learned PyG poolers (``topk``, ``sag``, ``asap``) pool by score at run
    time and unpool by scattering back to the kept indices, as the blueprint's
    baselines do.

    Shapes:
        x ``(N, in_channels)`` with ``graph`` describing ``N`` vertices at level 0
        → ``(N, out_channels)``.
    """

    def __init__(self, in_channels: int, channels: int, heads: int, out_channels: int,
                 out_heads: int, levels: int, pooling: str = "structure",
                 pooling_ratio: float = 0.5, dropout: float = 0.0):
        super().__init__()
        self.levels = levels
        self.pooling = pooling

        def gat(width_in: int, width_out: int, n_heads: int) -> GATConv:
            return GATConv(width_in, width_out, heads=n_heads, concat=False, dropout=dropout)

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

    def forward(self, x: torch.Tensor, graph: GraphLevels) -> torch.Tensor:
        edge_index, batch = graph.edge_index[0], graph.batch[0]
        x = torch.tanh(self.embedding(x, edge_index))
        skips: list[tuple[torch.Tensor, torch.Tensor, torch.Tensor | None]] = []
        for level in range(self.levels):
            if self.pooling == "structure":
                skips.append((x, edge_index, None))
                x = x[graph.kept[level]]
                edge_index = graph.edge_index[level + 1]
            else:
                skips.append((x, edge_index, None))
                pooled = self.poolers[level](x, edge_index, batch=batch)
                x, edge_index, batch, perm = pooled[0], pooled[1], pooled[3], pooled[4]
                skips[-1] = (skips[-1][0], skips[-1][1], perm)
            x = torch.tanh(self.encoders[level](x, edge_index))
        for level in reversed(range(self.levels)):
            skip, edge_index, perm = skips[level]
            if self.pooling == "structure":
                up = torch.sparse.mm(graph.unpool[level], x)
            else:
                up = x.new_zeros(skip.shape[0], x.shape[1]).index_copy(0, perm, x)
            x = torch.tanh(self.decoders[level](up + skip, edge_index))
        return self.output(x, edge_index)
