"""A plain multilayer perceptron with Kaiming-initialised layers."""

from __future__ import annotations

import torch
from torch import nn


class MLP(nn.Module):
    """Linear layers with ReLU between (and after the last, as the blueprint's encoders).

    Shapes:
        ``(..., in_channels)`` → ``(..., channels[-1])``.
    """

    def __init__(self, in_channels: int, channels: list[int], final_activation: bool = True):
        super().__init__()
        layers: list[nn.Module] = []
        width = in_channels
        for k, out in enumerate(channels):
            layers.append(nn.Linear(width, out))
            if k < len(channels) - 1 or final_activation:
                layers.append(nn.ReLU())
            width = out
        self.layers = nn.Sequential(*layers)
        self.reset_parameters()

    def reset_parameters(self) -> None:
        for layer in self.layers:
            if isinstance(layer, nn.Linear):
                nn.init.kaiming_uniform_(layer.weight, nonlinearity="relu")
                nn.init.zeros_(layer.bias)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.layers(x)
