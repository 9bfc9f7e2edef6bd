"""The supervised normal term ``L_n``: face orientations of the simulated garment."""

from __future__ import annotations

import torch

from gnngarment.data.dataset import TrainingBatch
from gnngarment.model.deformer import DeformerOutput


def face_normals(pos: torch.Tensor, faces: torch.Tensor) -> torch.Tensor:
    """``(F, 3)`` unit face normals of ``pos (V, 3)``, differentiable (the numpy twin for
    geometry is :func:`gnngarment.geometry.normals.face_normals`)."""
    a, b, c = pos[faces[:, 0]], pos[faces[:, 1]], pos[faces[:, 2]]
    return torch.nn.functional.normalize(torch.cross(b - a, c - a, dim=-1), dim=-1, eps=1e-12)


def normal_loss(pred: torch.Tensor, target: torch.Tensor, faces: torch.Tensor) -> torch.Tensor:
    """Mean ``1 − n·n̂`` over faces (0 when every face keeps its orientation)."""
    return (1 - (face_normals(pred, faces) * face_normals(target, faces)).sum(-1)).mean()


def term(output: DeformerOutput, batch: TrainingBatch, collision_margin: float) -> torch.Tensor:
    return normal_loss(output.posed, batch.target, batch.faces)
