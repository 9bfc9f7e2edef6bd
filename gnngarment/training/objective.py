"""The loss of each stage on a batch: weighted terms listed in the config and summed."""

from __future__ import annotations

import torch

from gnngarment.data.dataset import TrainingBatch
from gnngarment.model.deformer import DeformerOutput
from gnngarment.training import losses
from gnngarment.training.config import LossWeights, StageConfig


def stage_weights(stage: str, weights: LossWeights, stages: StageConfig) -> dict[str, float]:
    """The weight of every term in ``stage`` (0 = off)."""
    extra = {"blend_shape": weights.blend_shape} if weights.blend_shape > 0 else {}
    if stage == "supervised":
        return {"vertex": weights.vertex, "edge": weights.edge, "normal": weights.normal,
                **extra}
    scaled = {"vertex": weights.vertex * stages.physics_scale,
              "edge": weights.edge * stages.physics_scale,
              "collision": weights.collision, "gravity": weights.gravity, **extra}
    if stage == "physics_strain":
        scaled |= {"stretch": weights.stretch, "shear": weights.shear}
    return scaled


def loss_terms(output: DeformerOutput, batch: TrainingBatch, names: list[str],
               collision_margin: float) -> dict[str, torch.Tensor]:
    """Unweighted loss terms ``names`` of a batch's prediction (each a scalar)."""
    pred = output.posed
    terms: dict[str, torch.Tensor] = {}
    for name in names:
        if name == "vertex":
            terms[name] = losses.vertex_loss(pred, batch.target)
        elif name == "edge":
            terms[name] = losses.edge_loss(pred, batch.target, batch.edges)
        elif name == "normal":
            terms[name] = losses.normal_loss(pred, batch.target, batch.faces)
        elif name == "collision":
            terms[name] = losses.collision_loss(pred, batch.body_points, batch.body_normals,
                                                output.item, batch.body_item, collision_margin)
        elif name == "gravity":
            # Energy relative to the ground-truth heights: the gradient (each vertex's
            # weight) is the same as for absolute heights, the value stays readable.
            terms[name] = losses.gravity_loss(pred, batch.target, batch.vertex_mass,
                                              int(batch.item.max()) + 1)
        elif name == "blend_shape":
            terms[name] = losses.blend_shape_loss(output.blend_shapes)
        elif name == "stretch":
            terms[name] = losses.stretch_loss(pred, batch.faces, batch.rest_inverse,
                                              batch.rest_area)
        elif name == "shear":
            terms[name] = losses.shear_loss(pred, batch.faces, batch.rest_inverse,
                                            batch.rest_area)
        else:
            raise ValueError(f"unknown loss term '{name}'")
    return terms


def stage_loss(output: DeformerOutput, batch: TrainingBatch, stage: str, weights: LossWeights,
               stages: StageConfig, collision_margin: float
               ) -> tuple[torch.Tensor, dict[str, float]]:
    """Weighted sum of the stage's terms, and every term's (unweighted) value."""
    active = stage_weights(stage, weights, stages)
    terms = loss_terms(output, batch, list(active), collision_margin)
    total = sum(active[name] * value for name, value in terms.items())
    return total, {name: float(value.detach()) for name, value in terms.items()}
