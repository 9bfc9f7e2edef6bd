"""The supervised vertex term ``L_v``: squared distance to the simulated garment."""

from __future__ import annotations

import torch

from gnngarment.data.dataset import TrainingBatch
from gnngarment.model.deformer import DeformerOutput


def vertex_loss(pred: torch.Tensor, target: torch.Tensor) -> torch.Tensor:
    """Mean squared vertex distance (m²). Shapes: ``(V, 3)``, ``(V, 3)`` → scalar."""
    return ((pred - target) ** 2).sum(-1).mean()


def term(output: DeformerOutput, batch: TrainingBatch, collision_margin: float) -> torch.Tensor:
    return vertex_loss(output.posed, batch.target)
