"""E^gs: the garment style encoder."""

from __future__ import annotations

import torch
from torch import nn

from gnngarment.model.mlp import MLP


class StyleEncoder(nn.Module):
    """MLP on the Nyström descriptor (eigenvalues of the geodesic affinity).

    Shapes:
        descriptor ``(G, N*)`` → style cues ``C^gs (G, F)``.
    """

    def __init__(self, landmarks: int, channels: list[int]):
        super().__init__()
        self.mlp = MLP(landmarks, channels)

    def forward(self, descriptor: torch.Tensor) -> torch.Tensor:
        return self.mlp(descriptor)
