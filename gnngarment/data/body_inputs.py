"""Body-side model inputs of a (body shape, motion) pair, shared by the dataset
builder and inference so both feed the model the same numbers."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import torch

from gnngarment.body.body_model import BodyModel
from gnngarment.body.features import motion_features
from gnngarment.body.motion import Motion


@dataclass
class BodyShapeInputs:
    """Per body shape.

    Attributes:
        joints: ``(24, 3)`` rest joints (metres).
        distances: ``(N_b', 24)`` the body-shape feature ``D``.
        subset: ``(N_b',)`` indices of the feature vertices in the body template.
        rest_vertices: ``(N_b, 3)``; faces ``(F_b, 3)``.
        skinning_weights: ``(N_b, 24)`` the body's own skinning weights per canonical
            joint (rows sum to 1), or ``None`` when the body model does not expose them.
    """

    joints: np.ndarray
    distances: np.ndarray
    subset: np.ndarray
    rest_vertices: np.ndarray
    faces: np.ndarray
    skinning_weights: np.ndarray | None = None


@dataclass
class BodyMotionInputs:
    """Per (body shape, motion), ``T`` frames.

    Attributes:
        motion_features: ``(T, 75)`` joint axis-angles + root displacement.
        velocities: ``(T, N_b', 3)`` feature-subset velocities (m/s).
        joint_transforms: ``(T, 24, 4, 4)`` skinning transforms.
        vertices: ``(T, N_b, 3)`` posed body (world, metres).
        fps: frames per second.
    """

    motion_features: np.ndarray
    velocities: np.ndarray
    joint_transforms: np.ndarray
    vertices: np.ndarray
    fps: float


def body_shape_inputs(body_model: BodyModel, shape: Any, count: int) -> BodyShapeInputs:
    """Rest joints, feature ``D``, the feature-vertex subset of ``count`` vertices, the
    rest mesh and (where the body model has them) its skinning weights."""
    rest = body_model.rest(shape)
    subset = body_model.feature_vertex_indices(count)
    distances = body_model.shape_features(shape, count)
    try:
        skinning_weights: np.ndarray | None = np.asarray(body_model.skinning_weights(),
                                                         dtype=np.float32)
    except NotImplementedError:
        skinning_weights = None
    return BodyShapeInputs(joints=rest.joints.detach().cpu().numpy().astype(np.float32),
                           distances=distances.detach().cpu().numpy().astype(np.float32),
                           subset=np.asarray(subset, dtype=np.int64),
                           rest_vertices=rest.vertices.detach().cpu().numpy(),
                           faces=np.asarray(rest.faces, dtype=np.int64),
                           skinning_weights=skinning_weights)


def body_motion_inputs(body_model: BodyModel, shape: Any, motion: Motion,
                       count: int) -> BodyMotionInputs:
    """Pose the body by ``motion`` and derive the per-frame model inputs."""
    with torch.no_grad():
        posed = body_model.pose(motion, shape)
        velocities = body_model.subset_velocities(posed, motion.fps, count)
        features = motion_features(motion)
    return BodyMotionInputs(
        motion_features=features.cpu().numpy().astype(np.float32),
        velocities=velocities.cpu().numpy().astype(np.float32),
        joint_transforms=posed.joint_transforms.cpu().numpy().astype(np.float32),
        vertices=posed.vertices.cpu().numpy().astype(np.float32), fps=float(motion.fps))
