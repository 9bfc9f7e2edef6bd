"""E^t1 / E^t2: LSTM encoders of a window of per-frame motion features."""

from __future__ import annotations

import torch
from torch import nn


class MotionEncoder(nn.Module):
    """Multi-layer LSTM over the last ``m`` frames; the last hidden state is the code.

    E^t1 reads joint rotations + root displacement (75 values per frame), E^t2 reads
    flattened body-vertex velocities (``3 N_b'`` per frame). ``state`` lets streaming
    inference carry the LSTM state from frame to frame instead of re-reading a window.

    Shapes:
        windows ``(B, m, in_channels)`` → ``(B, hidden)`` (and the new state).
    """

    def __init__(self, in_channels: int, hidden: int, layers: int):
        super().__init__()
        self.lstm = nn.LSTM(in_channels, hidden, num_layers=layers, batch_first=True)
        self.reset_parameters()

    def reset_parameters(self) -> None:
        for name, parameter in self.lstm.named_parameters():
            if name.startswith("weight"):
                nn.init.kaiming_uniform_(parameter, nonlinearity="linear")
            else:
                nn.init.zeros_(parameter)

    def forward(self, windows: torch.Tensor,
                state: tuple[torch.Tensor, torch.Tensor] | None = None
                ) -> tuple[torch.Tensor, tuple[torch.Tensor, torch.Tensor]]:
        output, new_state = self.lstm(windows, state)
        return output[:, -1], new_state
