"""The supervised edge term ``L_e``: edge lengths of the simulated garment."""

from __future__ import annotations

import torch

from gnngarment.data.dataset import TrainingBatch
from gnngarment.model.deformer import DeformerOutput


def edge_lengths(pos: torch.Tensor, edges: torch.Tensor) -> torch.Tensor:
    """``(E,)`` lengths (m) of the edges ``(2, E)`` of ``pos (V, 3)``."""
    return (pos[edges[0]] - pos[edges[1]]).norm(dim=-1)


def edge_loss(pred: torch.Tensor, target: torch.Tensor, edges: torch.Tensor) -> torch.Tensor:
    """Mean squared edge-length difference (m²)."""
    return ((edge_lengths(pred, edges) - edge_lengths(target, edges)) ** 2).mean()


def term(output: DeformerOutput, batch: TrainingBatch, collision_margin: float) -> torch.Tensor:
    return edge_loss(output.posed, batch.target, batch.edges)
