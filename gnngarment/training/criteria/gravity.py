"""The physics gravity term ``L_g``: gravitational potential energy of the garment."""

from __future__ import annotations

import torch

from gnngarment.data.dataset import TrainingBatch
from gnngarment.model.deformer import DeformerOutput

#: Standard gravity (m/s²), along −Z (the library's up axis is +Z).
GRAVITY = 9.81


def gravity_loss(pos: torch.Tensor, reference: torch.Tensor, vertex_mass: torch.Tensor,
                 num_garments: int = 1) -> torch.Tensor:
    """Gravitational potential energy relative to ``reference`` heights, per garment
    (joules): ``Σ_i m_i g (z_i − z_ref,i) / num_garments``. Mass-weighted so the pull
    on a vertex is its weight, independent of the mesh resolution.

    Shapes:
        pos, reference ``(V, 3)`` metres; vertex_mass ``(V,)`` kg.
    """
    return GRAVITY * (vertex_mass * (pos[:, 2] - reference[:, 2])).sum() / num_garments



def term(output: DeformerOutput, batch: TrainingBatch, collision_margin: float) -> torch.Tensor:
    # Energy relative to the ground-truth heights: the gradient (each vertex's weight) is
    # the same as for absolute heights, the value stays readable.
    return gravity_loss(output.posed, batch.target, batch.vertex_mass,
                        int(batch.item.max()) + 1)
