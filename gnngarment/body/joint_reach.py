"""Which joints may move a garment vertex: those near it on the body *and* on the garment.

A joint's *region* is the set of points it moves noticeably (skinning weight at least
:data:`REGION_WEIGHT`). The far-joint metric (``evaluation.metrics.far_joint_weight``)
counts the weight a garment puts on joints whose **body** region lies more than 20 cm
beyond the vertex's nearest body point (:func:`joint_region_distances`: so a hem hanging
25 cm off the legs is not "far" from the legs). The model's weight head is forbidden
(``ModelConfig.weight_reach``, :func:`reachable_joints`) every joint that is out of
reach by that same distance — so the metric's bound holds by construction — and also
every joint whose **garment** region (garment vertices its transferred body weight moves
by at least :data:`REGION_WEIGHT`) is out of reach: a joint that moves no part of the
garment near a vertex has no business moving it.

Why both (measured, docs/results.md "The weight reach on the body's regions"): the
garment's regions alone let a trained model put 93 % of a sleeve vertex's weight on the
spine, whose garment region (the torso) lies within 20 cm of the armpit while its body
region does not; the body's regions alone admit joints the shipped model was never
trained on for some vertices (on the demo test trousers: the pelvis, hips, knees and
lower spine at vertices the garment rule forbade them) and cost it 0.35 mm on the
benchmark test split (skirt 8.1 → 9.7 mm). Together they bound the far weight at 0 and
leave the shipped model's test figures unchanged to every printed digit.
"""

from __future__ import annotations

import numpy as np
import torch
from scipy.spatial import cKDTree

#: A point belongs to a joint's region when the joint moves it at least this much.
REGION_WEIGHT = 0.1

#: Garment vertices compared with one garment region at a time: bounds the distance block
#: at ``ROW_CHUNK × region size`` floats (a 20,000-vertex garment stays under ~0.3 GB).
ROW_CHUNK = 4096


def joint_region_distances(points: np.ndarray, body_rest_vertices: np.ndarray,
                           body_skinning_weights: np.ndarray) -> np.ndarray:
    """How far each joint's body region lies from each point, beyond the body itself:
    the distance from the point to the region's nearest body vertex minus the distance
    to the nearest body vertex of all (so 0 where the nearest body vertex belongs to the
    region). A joint that moves no body vertex by :data:`REGION_WEIGHT` is infinitely far.

    Shapes:
        points ``(N, 3)`` (metres, the body's rest frame), body_rest_vertices
        ``(N_b, 3)``, body_skinning_weights ``(N_b, S)`` → ``(N, S)`` metres, ≥ 0.
    """
    points = np.asarray(points, dtype=np.float64)
    body = np.asarray(body_rest_vertices, dtype=np.float64)
    weights = np.asarray(body_skinning_weights)
    if weights.ndim != 2 or len(weights) != len(body):
        raise ValueError(f"body_skinning_weights must be ({len(body)}, S), got {weights.shape}")
    distances = np.full((len(points), weights.shape[1]), np.inf)
    for joint in range(weights.shape[1]):
        region = body[weights[:, joint] >= REGION_WEIGHT]
        if len(region):
            distances[:, joint] = cKDTree(region).query(points)[0]
    nearest = cKDTree(body).query(points)[0]
    # Rounding can leave the nearest region a hair below the nearest vertex of all.
    return np.maximum(distances - nearest[:, None], 0.0)


def reachable_joints(rest_pos: torch.Tensor, body_weights: torch.Tensor,
                     joint_distances: torch.Tensor, reach: float) -> torch.Tensor:
    """For every garment vertex, the joints within ``reach`` (metres) of it both on the
    body (``joint_distances``, measured as :func:`joint_region_distances` measures) and
    on the garment (the nearest garment vertex the joint's transferred body weight moves
    by at least :data:`REGION_WEIGHT`; Euclidean, rest pose). Each vertex's strongest
    transferred body joint is always reachable, so every row allows at least one joint.

    Shapes:
        rest_pos ``(N, 3)`` metres, body_weights ``(N, S)`` (the garment's transferred
        body weights), joint_distances ``(N, S)`` metres → ``(N, S)`` bool.
    """
    if reach <= 0:
        raise ValueError(f"reach must be positive (metres), got {reach}")
    if joint_distances.shape != body_weights.shape:
        raise ValueError(f"joint_distances {tuple(joint_distances.shape)} and body_weights "
                         f"{tuple(body_weights.shape)} must have the same shape")
    reachable = joint_distances <= reach
    points = rest_pos.detach()
    for joint in range(body_weights.shape[1]):
        region = points[body_weights[:, joint] >= REGION_WEIGHT]
        if not len(region):
            reachable[:, joint] = False
            continue
        for start in range(0, len(points), ROW_CHUNK):
            near = torch.cdist(points[start:start + ROW_CHUNK], region).min(dim=1).values
            reachable[start:start + ROW_CHUNK, joint] &= near <= reach
    vertices = torch.arange(len(body_weights), device=body_weights.device)
    reachable[vertices, body_weights.argmax(dim=1)] = True
    return reachable
