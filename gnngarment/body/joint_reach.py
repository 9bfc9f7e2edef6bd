"""Which joints may move a garment vertex: those whose body region lies within reach of it.

A joint's *region* is the set of body vertices it moves noticeably (skinning weight at
least :data:`REGION_WEIGHT`). How far a joint is from a garment vertex is measured on the
body, from the vertex's nearest body point (:func:`joint_region_distances`), so that a
hem hanging 25 cm off the legs is not "far" from the legs. The far-joint metric
(``evaluation.metrics.far_joint_weight``) counts the weight a garment puts on joints
farther than 20 cm; the model's weight head is forbidden such joints outright
(``ModelConfig.weight_reach``, :func:`reachable_joints`) with the *same* distances, so
the metric's bound holds by construction, not by training. (The reach was first
measured on the garment's own transferred weights; near an armpit the garment's torso
lies within 20 cm of a sleeve while the body's spine region does not, and a trained
model put 93 % of a sleeve vertex's weight on the spine with that reach on:
docs/results.md, "More training designs".)
"""

from __future__ import annotations

import numpy as np
import torch
from scipy.spatial import cKDTree

#: A point belongs to a joint's region when the joint moves it at least this much.
REGION_WEIGHT = 0.1


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


def reachable_joints(joint_distances: torch.Tensor, body_weights: torch.Tensor,
                     reach: float) -> torch.Tensor:
    """For every garment vertex, the joints whose body region lies within ``reach``
    (metres, measured as :func:`joint_region_distances` measures). Each vertex's
    strongest transferred body joint is always reachable, so every row allows at least
    one joint.

    Shapes:
        joint_distances ``(N, S)`` metres, body_weights ``(N, S)`` → ``(N, S)`` bool.
    """
    if reach <= 0:
        raise ValueError(f"reach must be positive (metres), got {reach}")
    if joint_distances.shape != body_weights.shape:
        raise ValueError(f"joint_distances {tuple(joint_distances.shape)} and body_weights "
                         f"{tuple(body_weights.shape)} must have the same shape")
    reachable = joint_distances <= reach
    vertices = torch.arange(len(body_weights), device=body_weights.device)
    reachable[vertices, body_weights.argmax(dim=1)] = True
    return reachable
