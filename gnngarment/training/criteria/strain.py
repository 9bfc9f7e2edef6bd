"""The physics strain terms ``L_st`` (stretch) and ``L_sh`` (shear): Green–Lagrange
strain of every triangle against its rest shape."""

from __future__ import annotations

import torch

from gnngarment.data.dataset import TrainingBatch
from gnngarment.model.deformer import DeformerOutput


def green_strain(pos: torch.Tensor, faces: torch.Tensor, rest_inverse: torch.Tensor
                 ) -> torch.Tensor:
    """Green–Lagrange strain ``E = ½ (FᵀF − I)`` per triangle, ``(F, 2, 2)``.

    ``rest_inverse (F, 2, 2)`` comes from
    :func:`gnngarment.geometry.triangle_frames.rest_triangle_frames`.
    """
    a, b, c = pos[faces[:, 0]], pos[faces[:, 1]], pos[faces[:, 2]]
    deformed = torch.stack([b - a, c - a], dim=-1)            # (F, 3, 2)
    gradient = deformed @ rest_inverse.to(pos.dtype)            # (F, 3, 2)
    identity = torch.eye(2, dtype=pos.dtype, device=pos.device)
    return 0.5 * (gradient.transpose(-1, -2) @ gradient - identity)


def stretch_loss(pos: torch.Tensor, faces: torch.Tensor, rest_inverse: torch.Tensor,
                 rest_area: torch.Tensor) -> torch.Tensor:
    """Area-weighted mean of ``E_uu² + E_vv²`` (stretch along the rest frame axes)."""
    strain = green_strain(pos, faces, rest_inverse)
    energy = strain[:, 0, 0] ** 2 + strain[:, 1, 1] ** 2
    return (energy * rest_area).sum() / rest_area.sum()


def shear_loss(pos: torch.Tensor, faces: torch.Tensor, rest_inverse: torch.Tensor,
               rest_area: torch.Tensor) -> torch.Tensor:
    """Area-weighted mean of ``E_uv²`` (in-plane shear)."""
    strain = green_strain(pos, faces, rest_inverse)
    return ((strain[:, 0, 1] ** 2) * rest_area).sum() / rest_area.sum()


def stretch_term(output: DeformerOutput, batch: TrainingBatch,
                 collision_margin: float) -> torch.Tensor:
    return stretch_loss(output.posed, batch.faces, batch.rest_inverse, batch.rest_area)


def shear_term(output: DeformerOutput, batch: TrainingBatch,
               collision_margin: float) -> torch.Tensor:
    return shear_loss(output.posed, batch.faces, batch.rest_inverse, batch.rest_area)
