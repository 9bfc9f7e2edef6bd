"""E^gg: the garment graph encoder (joint-specific attention heads)."""

from __future__ import annotations

import torch
from torch import nn
from torch_geometric.nn import GATConv


class GarmentGraphEncoder(nn.Module):
    """GAT blocks with one attention head per joint (``heads = S = 24``), ReLU.

    The blocks' per-head widths are ``channels`` (the blueprint's [32, 64, 128, 128]);
    heads are concatenated, so block ``k`` maps ``S·c_{k-1}`` to ``S·c_k`` channels and
    the features stay split by joint. The style cues ``C^gs`` multiply the features of
    every head before the last block (blueprint Sec. 3.2), giving ``X̂^gg``.

    Shapes:
        x ``(N, in_channels)``, edge_index ``(2, E)``, style ``(N, F)`` (each vertex's
        garment style cues, gathered by the caller) → ``(N, S, F)``.
    """

    def __init__(self, in_channels: int, channels: list[int], heads: int, dropout: float = 0.0):
        super().__init__()
        self.heads = heads
        self.blocks = nn.ModuleList()
        width = in_channels
        for out in channels:
            self.blocks.append(GATConv(width, out, heads=heads, concat=True, dropout=dropout))
            width = heads * out

    def forward(self, x: torch.Tensor, edge_index: torch.Tensor,
                style: torch.Tensor) -> torch.Tensor:
        for block in self.blocks[:-1]:
            x = torch.relu(block(x, edge_index))
        x = x.view(x.shape[0], self.heads, -1) * style[:, None, :]
        x = torch.relu(self.blocks[-1](x.flatten(1), edge_index))
        return x.view(x.shape[0], self.heads, -1)
