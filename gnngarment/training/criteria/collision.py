"""The physics collision term ``L_c``: penetration of the posed body, as HOOD and SNUG
measure it (offset from the nearest body point along its outward normal)."""

from __future__ import annotations

import numpy as np
import torch

from gnngarment.data.dataset import TrainingBatch
from gnngarment.model.deformer import DeformerOutput


def nearest_body_points(pos: torch.Tensor, body: torch.Tensor, item: torch.Tensor,
                        body_item: torch.Tensor) -> torch.Tensor:
    """Index of the nearest body point of the same item for every garment vertex.

    A KD-tree per item (scipy): no gradient is needed through the *choice* of nearest
    point, only through the distance to it.

    Shapes:
        pos ``(V, 3)``, body ``(M, 3)``, item ``(V,)``, body_item ``(M,)`` → ``(V,)`` long.
    """
    from scipy.spatial import cKDTree

    positions = pos.detach().cpu().numpy()
    body_points = body.detach().cpu().numpy()
    items, body_items = item.cpu().numpy(), body_item.cpu().numpy()
    nearest = np.empty(len(positions), dtype=np.int64)
    body_order = np.argsort(body_items, kind="stable")
    body_bounds = np.searchsorted(body_items[body_order], np.arange(items.max() + 2))
    for k in np.unique(items):
        members = np.flatnonzero(items == k)
        candidates = body_order[body_bounds[k]:body_bounds[k + 1]]
        _, local = cKDTree(body_points[candidates]).query(positions[members])
        nearest[members] = candidates[local]
    return torch.from_numpy(nearest).to(pos.device)


def signed_distance(pos: torch.Tensor, body: torch.Tensor, body_normals: torch.Tensor,
                    item: torch.Tensor, body_item: torch.Tensor) -> torch.Tensor:
    """Approximate signed distance to the posed body (m): the offset from the nearest
    body point along that point's outward normal (negative inside), as HOOD and SNUG
    use for collisions.

    Shapes:
        pos ``(V, 3)``; body, body_normals ``(M, 3)``; item ``(V,)``; body_item ``(M,)``
        → ``(V,)``.
    """
    nearest = nearest_body_points(pos, body, item, body_item)
    return ((pos - body[nearest]) * body_normals[nearest]).sum(-1)


def collision_loss(pos: torch.Tensor, body: torch.Tensor, body_normals: torch.Tensor,
                   item: torch.Tensor, body_item: torch.Tensor,
                   margin: float = 0.004) -> torch.Tensor:
    """Mean ``|min(h(x) − ε, 0)|``: penetration depth below the margin ``ε`` (m)."""
    depth = signed_distance(pos, body, body_normals, item, body_item) - margin
    return torch.clamp(depth, max=0).abs().mean()



def term(output: DeformerOutput, batch: TrainingBatch, collision_margin: float) -> torch.Tensor:
    return collision_loss(output.posed, batch.body_points, batch.body_normals, output.item,
                          batch.body_item, collision_margin)
