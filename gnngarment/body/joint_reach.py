"""Which joints may move a garment vertex: those whose region lies within reach of it.

A joint's *region* is the set of points it moves noticeably (skinning weight at least
:data:`REGION_WEIGHT`). The far-joint metric (``evaluation.metrics.far_joint_weight``)
measures weight on joints whose body region is far from a vertex; the model's weight
head can instead be forbidden such joints outright (``ModelConfig.weight_reach``), using
the garment's own transferred body weights to find the regions, so it needs nothing the
model does not already receive.
"""

from __future__ import annotations

import torch

#: A point belongs to a joint's region when the joint moves it at least this much.
REGION_WEIGHT = 0.1

#: Garment vertices compared with one region at a time: bounds the distance block at
#: ``ROW_CHUNK × region size`` floats (a 20,000-vertex garment stays under ~0.3 GB).
ROW_CHUNK = 4096


def reachable_joints(rest_pos: torch.Tensor, body_weights: torch.Tensor,
                     reach: float) -> torch.Tensor:
    """For every garment vertex, the joints whose garment region lies within ``reach``.

    A joint's region here is the garment vertices its transferred body weight moves by
    at least :data:`REGION_WEIGHT`; its distance from a vertex is that of the region's
    nearest vertex (Euclidean, rest pose). A joint that moves no garment vertex that much
    is out of reach everywhere. Each vertex's strongest body joint is always reachable,
    so every row allows at least one joint.

    Shapes:
        rest_pos ``(N, 3)`` (metres), body_weights ``(N, S)`` → ``(N, S)`` bool.
    """
    if reach <= 0:
        raise ValueError(f"reach must be positive (metres), got {reach}")
    vertices, joints = body_weights.shape
    reachable = torch.zeros(vertices, joints, dtype=torch.bool, device=rest_pos.device)
    points = rest_pos.detach()
    for joint in range(joints):
        region = points[body_weights[:, joint] >= REGION_WEIGHT]
        if not len(region):
            continue
        for start in range(0, vertices, ROW_CHUNK):
            block = torch.cdist(points[start:start + ROW_CHUNK], region)
            reachable[start:start + ROW_CHUNK, joint] = block.min(dim=1).values <= reach
    strongest = body_weights.argmax(dim=1)
    reachable[torch.arange(vertices, device=rest_pos.device), strongest] = True
    return reachable
