"""E^gg: the garment graph encoder (joint-specific attention heads)."""

from __future__ import annotations

import torch
from torch import nn

from gnngarment.model.attention_graph import AttentionGraph
from gnngarment.model.graph_attention import apply_attention, graph_attention


class GarmentGraphEncoder(nn.Module):
    """GAT blocks with one attention head per joint (``heads = S = 24``), ReLU.

    The blocks' per-head widths are ``channels`` (the blueprint's [32, 64, 128, 128]);
    heads are concatenated, so block ``k`` maps ``S·c_{k-1}`` to ``S·c_k`` channels and
    the features stay split by joint. The style cues ``C^gs`` multiply the features of
    every head before the last block (blueprint Sec. 3.2), giving ``X̂^gg``.

    ``attention`` picks the GAT implementation (``"csr"`` or ``"pyg"``, see
    :func:`~gnngarment.model.graph_attention.graph_attention`); with ``"csr"`` the
    attention structure is built once per call and shared by all blocks.

    Shapes:
        x ``(N, in_channels)``, edge_index ``(2, E)``, style ``(N, F)`` (each vertex's
        garment style cues, gathered by the caller) → ``(N, S, F)``.
    """

    def __init__(self, in_channels: int, channels: list[int], heads: int, dropout: float = 0.0,
                 attention: str = "csr"):
        super().__init__()
        self.heads = heads
        self.blocks = nn.ModuleList()
        width = in_channels
        for out in channels:
            self.blocks.append(graph_attention(width, out, heads, concat=True, dropout=dropout,
                                               attention=attention))
            width = heads * out

    def forward(self, x: torch.Tensor, edge_index: torch.Tensor,
                style: torch.Tensor, attention_graph: AttentionGraph | None = None
                ) -> torch.Tensor:
        """``attention_graph``: ``edge_index``'s structure when the caller has it (built
        from ``edge_index`` otherwise)."""
        structure: list[AttentionGraph] = [] if attention_graph is None else [attention_graph]

        def graph() -> AttentionGraph:
            if not structure:
                structure.append(AttentionGraph.from_edge_index(edge_index, x.shape[0]))
            return structure[0]

        for block in self.blocks[:-1]:
            x = torch.relu(apply_attention(block, x, edge_index, graph))
        x = x.view(x.shape[0], self.heads, -1) * style[:, None, :]
        x = torch.relu(apply_attention(self.blocks[-1], x.flatten(1), edge_index, graph))
        return x.view(x.shape[0], self.heads, -1)
