"""Animate a garment: one per-pair context, then the frames in chunks."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import torch

from gnngarment.data.body_inputs import BodyMotionInputs, BodyShapeInputs
from gnngarment.data.dataset import window_indices
from gnngarment.data.pair import GarmentBodyPair
from gnngarment.data.vertex_features import garment_vertex_features
from gnngarment.geometry.prepare import GarmentPreparationConfig, PreparedGarment, prepare_garment
from gnngarment.model.deformer import GarmentDeformer


@dataclass
class Animation:
    """A garment animated on a body.

    Attributes:
        rest_pos: ``(N, 3)`` garment rest vertices (input order), faces ``(F, 3)``.
        posed: ``(T, N, 3)`` animated garment (world, metres).
        weights: ``(T, N, 24)`` predicted skinning weights.
        blend_shapes: ``(T, N, 3)`` predicted blend shapes (rest frame, metres).
        joint_transforms: ``(T, 24, 4, 4)``; rest_joints ``(24, 3)``.
        body_vertices: ``(T, N_b, 3)`` posed body, body_faces ``(F_b, 3)``.
        fps: frames per second.
        seconds: wall-clock of the context (per pair) and of all frames.
    """

    rest_pos: np.ndarray
    faces: np.ndarray
    posed: np.ndarray
    weights: np.ndarray
    blend_shapes: np.ndarray
    joint_transforms: np.ndarray
    rest_joints: np.ndarray
    body_vertices: np.ndarray
    body_faces: np.ndarray
    fps: float
    seconds: dict[str, float]


def garment_pair(model: GarmentDeformer, pos: np.ndarray, faces: np.ndarray,
                 body: BodyShapeInputs, prepared: PreparedGarment | None = None,
                 source: str = "<garment>") -> GarmentBodyPair:
    """The model input of a garment (rest positions on the body's rest frame) on a body.

    Raises:
        MeshError: the garment mesh is unusable (names ``source``).
    """
    config = model.config
    if prepared is None:
        prepared = prepare_garment(pos, faces, GarmentPreparationConfig(
            levels=config.levels, landmarks=config.landmarks), source=source)
    features = garment_vertex_features(pos, faces, body.joints)
    return GarmentBodyPair(
        rest_pos=torch.tensor(pos, dtype=torch.float32),
        features=torch.from_numpy(features), hierarchy=prepared.hierarchy,
        descriptor=torch.tensor(prepared.descriptor, dtype=torch.float32),
        body_distances=torch.from_numpy(body.distances))


@torch.inference_mode()
def animate(model: GarmentDeformer, pos: np.ndarray, faces: np.ndarray, body: BodyShapeInputs,
            frames: BodyMotionInputs, chunk: int = 16, source: str = "<garment>",
            progress: Callable[[int, int], None] | None = None) -> Animation:
    """Predict the garment for every frame of a posed body.

    Args:
        model: a trained deformer (eval mode is set here).
        pos, faces: ``(N, 3)`` garment rest vertices in the rest body's frame (metres,
            Z up) and ``(F, 3)`` triangles.
        body: body-shape inputs (:func:`body_shape_inputs`).
        frames: the posed body's per-frame inputs (:func:`body_motion_inputs`).
        chunk: frames per forward pass.
        progress: called with (frames done, total) after each chunk.
    """
    import time

    model.eval()
    started = time.perf_counter()
    pair = garment_pair(model, pos, faces, body, source=source)
    context = model.prepare([pair])
    context_seconds = time.perf_counter() - started

    window = model.config.window
    total = frames.motion_features.shape[0]
    motion = torch.from_numpy(frames.motion_features)
    velocity = torch.from_numpy(frames.velocities.reshape(total, -1))
    transforms = torch.from_numpy(frames.joint_transforms)
    posed, weights, blend = [], [], []
    started = time.perf_counter()
    for start in range(0, total, chunk):
        index = np.arange(start, min(start + chunk, total))
        windows = torch.from_numpy(window_indices(index, window))
        out = model(context, motion[windows][None], velocity[windows][None],
                    transforms[index][None])
        count = len(index)
        posed.append(out.posed.view(count, -1, 3))
        weights.append(out.weights.view(count, -1, 24))
        blend.append(out.blend_shapes.view(count, -1, 3))
        if progress is not None:
            progress(start + count, total)
    return Animation(
        rest_pos=np.asarray(pos, dtype=np.float32), faces=np.asarray(faces, dtype=np.int64),
        posed=torch.cat(posed).numpy(), weights=torch.cat(weights).numpy(),
        blend_shapes=torch.cat(blend).numpy(), joint_transforms=frames.joint_transforms,
        rest_joints=body.joints, body_vertices=frames.vertices, body_faces=body.faces,
        fps=frames.fps, seconds={"context": context_seconds,
                                 "frames": time.perf_counter() - started})
