"""The loss of each stage on a batch: weighted terms listed in the config and summed."""

from __future__ import annotations

import torch

from gnngarment.data.dataset import TrainingBatch
from gnngarment.model.deformer import DeformerOutput
from gnngarment.training.config import LossWeights, StageConfig
from gnngarment.training.criteria import CRITERIA


def stage_weights(stage: str, weights: LossWeights, stages: StageConfig) -> dict[str, float]:
    """The weight of every term in ``stage`` (0 = off)."""
    extra = {"blend_shape": weights.blend_shape} if weights.blend_shape > 0 else {}
    if stage == "supervised":
        collision = ({"collision": stages.supervised_collision}
                     if stages.supervised_collision > 0 else {})
        return {"vertex": weights.vertex, "edge": weights.edge, "normal": weights.normal,
                **collision, **extra}
    scaled = {"vertex": weights.vertex * stages.physics_scale,
              "edge": weights.edge * stages.physics_scale,
              "collision": weights.collision, "gravity": weights.gravity, **extra}
    if stage == "physics_strain":
        scaled |= {"stretch": weights.stretch, "shear": weights.shear}
    return scaled


def loss_terms(output: DeformerOutput, batch: TrainingBatch, names: list[str],
               collision_margin: float) -> dict[str, torch.Tensor]:
    """Unweighted loss terms ``names`` of a batch's prediction (each a scalar), each
    computed by its criterion (:data:`~gnngarment.training.criteria.CRITERIA`)."""
    unknown = [name for name in names if name not in CRITERIA]
    if unknown:
        raise ValueError(f"unknown loss term '{unknown[0]}' (known: {', '.join(CRITERIA)})")
    return {name: CRITERIA[name](output, batch, collision_margin) for name in names}


def stage_loss(output: DeformerOutput, batch: TrainingBatch, stage: str, weights: LossWeights,
               stages: StageConfig, collision_margin: float
               ) -> tuple[torch.Tensor, dict[str, float]]:
    """Weighted sum of the stage's terms, and every term's (unweighted) value."""
    active = stage_weights(stage, weights, stages)
    terms = loss_terms(output, batch, list(active), collision_margin)
    total = sum(active[name] * value for name, value in terms.items())
    return total, {name: float(value.detach()) for name, value in terms.items()}
