"""A penalty on the size of the blend shapes (ours, not in the blueprint: the
``losses.blend_shape`` weight, 0 = off; docs/training.md)."""

from __future__ import annotations

import torch

from gnngarment.data.dataset import TrainingBatch
from gnngarment.model.deformer import DeformerOutput


def blend_shape_loss(blend_shapes: torch.Tensor) -> torch.Tensor:
    """Mean squared blend shape (m²): zero for plain skinning of the template.
    Shapes: ``(V, 3)`` → scalar."""
    return (blend_shapes ** 2).sum(-1).mean()


def term(output: DeformerOutput, batch: TrainingBatch, collision_margin: float) -> torch.Tensor:
    # The submodules' corrections only: the oscillators' displacement is motion the data
    # asks for, bounded by their own gain limit.
    return blend_shape_loss(output.static_blend_shapes)
