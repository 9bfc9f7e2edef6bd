"""E^bs: the body shape encoder."""

from __future__ import annotations

import torch
from torch import nn

from gnngarment.model.mlp import MLP


class BodyShapeEncoder(nn.Module):
    """MLP over the body-vertex dimension of the joint–vertex distances ``D``.

    Every joint's column of ``D`` (its distances to the ``N_b'`` subset vertices) is
    mapped to ``F`` features by the same MLP, giving one cue vector per joint.

    Shapes:
        distances ``(G, N_b', S)`` → body cues ``C^bs (G, S, F)``.
    """

    def __init__(self, body_vertices: int, channels: list[int]):
        super().__init__()
        self.mlp = MLP(body_vertices, channels)

    def forward(self, distances: torch.Tensor) -> torch.Tensor:
        return self.mlp(distances.transpose(-1, -2))
