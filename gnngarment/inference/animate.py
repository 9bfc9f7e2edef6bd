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
from gnngarment.geometry import body_collisions
from gnngarment.geometry.body_collisions import CollisionSettings, CollisionStats
from gnngarment.geometry.prepare import GarmentPreparationConfig, PreparedGarment, prepare_garment
from gnngarment.geometry.welding import weld_vertices
from gnngarment.model.deformer import GarmentDeformer


@dataclass
class Animation:
    """A garment animated on a body.

    Attributes:
        rest_pos: ``(N, 3)`` garment rest vertices (input order) as animated (moved out
            of the rest body when collisions are resolved), faces ``(F, 3)``.
        posed: ``(T, N, 3)`` animated garment (world, metres).
        weights: ``(T, N, 24)`` predicted skinning weights.
        blend_shapes: ``(T, N, 3)`` predicted blend shapes (rest frame, metres).
        joint_transforms: ``(T, 24, 4, 4)``; rest_joints ``(24, 3)``.
        body_vertices: ``(T, N_b, 3)`` posed body, body_faces ``(F_b, 3)``.
        fps: frames per second.
        seconds: wall-clock of the context (per pair), of all frames and of the
            collision resolution (``collisions``).
        raw_posed: ``(T, N, 3)`` the network's output before collision resolution
            (``posed`` itself when resolution was off); raw_rest_pos ``(N, 3)`` the rest
            garment as given, before its penetration of the rest body was removed.
            ``None`` only in an Animation built by hand.
        collisions, rest_collisions: what the resolution did per frame and to the rest
            garment (:class:`CollisionStats`), ``None`` when it was off.
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
    raw_posed: np.ndarray | None = None
    raw_rest_pos: np.ndarray | None = None
    collisions: CollisionStats | None = None
    rest_collisions: CollisionStats | None = None
    #: The input garment's texture coordinates, ``uv (K, 2)`` (OBJ convention) and per-
    #: corner ``uv_faces (F, 3)`` (:mod:`gnngarment.geometry.texture_coordinates`), or
    #: ``None``; the exporters write them (OBJ ``vt``, glb ``TEXCOORD_0``).
    uv: np.ndarray | None = None
    uv_faces: np.ndarray | None = None
    #: Input vertices merged into a coincident one for the network
    #: (:func:`~gnngarment.geometry.welding.weld_vertices`: STL exports, UV-split OBJs);
    #: every array above is in the input's vertex order, copies moving as one.
    welded: int = 0


def garment_pair(model: GarmentDeformer, pos: np.ndarray, faces: np.ndarray,
                 body: BodyShapeInputs, prepared: PreparedGarment | None = None,
                 source: str = "<garment>") -> GarmentBodyPair:
    """The model input of a garment (rest positions on the body's rest frame) on a body.

    For a model with the ``body`` weight prior, the body's skinning weights are
    transferred to the garment (:func:`transfer_body_weights`, as the cache builders do),
    and with a weight reach each joint's body-region distance is measured
    (:func:`joint_region_distances`).

    Raises:
        MeshError: the garment mesh is unusable (names ``source``).
        ValueError: the model has the ``body`` weight prior and ``body`` has no skinning
            weights.
    """
    config = model.config
    body_weights = joint_distances = None
    if config.weight_prior == "body":
        # Imported here: the evaluation package imports much of the library.
        from gnngarment.body.joint_reach import joint_region_distances
        from gnngarment.body.weight_transfer import transfer_body_weights

        if body.skinning_weights is None:
            raise ValueError(f"{source}: the model's weight_prior 'body' needs the body's "
                             "skinning weights (BodyShapeInputs.skinning_weights is None; "
                             "the body model does not expose them)")
        rest = np.asarray(pos, dtype=np.float64)
        body_weights = transfer_body_weights(rest, body.rest_vertices, body.skinning_weights)
        if config.weight_reach is not None:
            joint_distances = joint_region_distances(rest, body.rest_vertices,
                                                     body.skinning_weights)
    if prepared is None:
        prepared = prepare_garment(pos, faces, GarmentPreparationConfig(
            levels=config.levels, landmarks=config.landmarks), source=source)
    return GarmentBodyPair.from_arrays(
        pos, garment_vertex_features(pos, faces, body.joints), prepared.hierarchy,
        prepared.descriptor, body.distances, body_weights, joint_distances)


#: Garment vertices × frames per forward pass (16 frames of a 5,000-vertex garment).
#: Measured with the shipped model (docs/reliability.md, "Memory"): a pass takes
#: ~6.8 kB per vertex-frame at its peak, and per frame it gets *slower* beyond this
#: (a 78k-vertex garment: 1.2 s for 1 frame, 8.8 s for 4), so a large garment runs
#: one frame at a time in bounded memory.
MAX_VERTEX_FRAMES = 80_000
#: The most frames per pass (small garments gain nothing beyond it).
MAX_FRAMES_PER_CHUNK = 16


def frames_per_chunk(vertices: int) -> int:
    """Frames per forward pass for a garment of ``vertices`` vertices: as many as
    :data:`MAX_VERTEX_FRAMES` allows, at least 1, at most :data:`MAX_FRAMES_PER_CHUNK`."""
    return max(1, min(MAX_FRAMES_PER_CHUNK, MAX_VERTEX_FRAMES // max(vertices, 1)))


@torch.inference_mode()
def animate(model: GarmentDeformer, pos: np.ndarray, faces: np.ndarray, body: BodyShapeInputs,
            frames: BodyMotionInputs, chunk: int | None = None, source: str = "<garment>",
            progress: Callable[[int, int], None] | None = None,
            resolve_collisions: bool = True,
            collisions: CollisionSettings | None = None) -> Animation:
    """Predict the garment for every frame of a posed body.

    With ``resolve_collisions`` (the default) the output is penetration-free: the rest
    garment's penetration of the rest body is removed before the network sees it, and
    every predicted frame's vertices inside the posed body or closer than ``ε`` are
    moved out (:func:`~gnngarment.geometry.body_collisions.resolve_collisions`); the
    network's own output stays in ``Animation.raw_posed``.

    Args:
        model: a trained deformer (eval mode is set here).
        pos: ``(N, 3)`` garment rest vertices in the rest body's frame (metres, Z up).
        faces: ``(F, 3)`` triangles.
        body: body-shape inputs (:func:`body_shape_inputs`).
        frames: the posed body's per-frame inputs (:func:`body_motion_inputs`).
        chunk: frames per forward pass; ``None``: :func:`frames_per_chunk` (memory and
            time per frame grow with the chunk's vertex-frames, not only its frames).
        progress: called with (frames done, total) after each chunk.
        resolve_collisions: remove body penetrations (rest garment and every frame).
        collisions: ``ε`` and smoothing; default :class:`CollisionSettings`.

    Raises:
        MeshError: the garment mesh is unusable (names ``source``).
    """
    import time

    from gnngarment.geometry.validation import validate_mesh

    model.eval()
    settings = collisions or CollisionSettings()
    given_pos, given_faces = np.asarray(pos), np.asarray(faces, dtype=np.int64)
    validate_mesh(given_pos, given_faces, source)
    # Coincident vertices (one per triangle corner in an STL) would make the graph
    # network see triangle soup: it runs on the welded mesh, the copies follow it.
    welded = weld_vertices(given_pos, given_faces)
    pos, faces = welded.pos, welded.faces
    rest, rest_stats, collision_seconds = np.asarray(pos), None, 0.0
    if resolve_collisions:
        started = time.perf_counter()
        rest, rest_stats = body_collisions.resolve_collisions(
            rest, faces, body.rest_vertices, body.faces, settings)
        collision_seconds = time.perf_counter() - started
    started = time.perf_counter()
    pair = garment_pair(model, rest, faces, body, source=source)
    context = model.encode([pair])
    context_seconds = time.perf_counter() - started

    window = model.config.window
    total = frames.motion_features.shape[0]
    chunk = chunk or frames_per_chunk(len(pos))
    motion = torch.from_numpy(frames.motion_features)
    velocity = torch.from_numpy(frames.velocities.reshape(total, -1))
    transforms = torch.from_numpy(frames.joint_transforms)
    posed, weights, blend = [], [], []
    # The oscillators' state runs through the chunks: the same result as one pass.
    stream = model.dynamics_stream(context, frames.fps) if model.has_dynamics else None
    started = time.perf_counter()
    for start in range(0, total, chunk):
        index = np.arange(start, min(start + chunk, total))
        windows = torch.from_numpy(window_indices(index, window))
        offsets = None if stream is None else stream.advance(transforms[index]).flatten(0, 1)
        out = model(context, motion[windows][None], velocity[windows][None],
                    transforms[index][None], offsets)
        count = len(index)
        posed.append(out.posed.view(count, -1, 3))
        weights.append(out.weights.view(count, -1, 24))
        blend.append(out.blend_shapes.view(count, -1, 3))
        if progress is not None:
            progress(start + count, total)
    frames_seconds = time.perf_counter() - started
    raw_posed = torch.cat(posed).numpy()
    resolved, stats = raw_posed, None
    if resolve_collisions:
        started = time.perf_counter()
        resolved, stats = body_collisions.resolve_collisions(
            raw_posed, faces, frames.vertices, body.faces, settings)
        collision_seconds += time.perf_counter() - started
    # Back to the input's vertex order (no copy when nothing was welded, so that
    # ``posed is raw_posed`` stays true with the resolution off).
    weights_all, blend_all = torch.cat(weights).numpy(), torch.cat(blend).numpy()
    rest = np.asarray(rest, dtype=np.float32)
    if welded.merged:
        index = welded.index
        same = resolved is raw_posed
        raw_posed = raw_posed[:, index]
        resolved = raw_posed if same else resolved[:, index]
        weights_all, blend_all, rest = weights_all[:, index], blend_all[:, index], rest[index]
    return Animation(
        rest_pos=rest, faces=given_faces, posed=resolved, weights=weights_all,
        blend_shapes=blend_all,
        joint_transforms=frames.joint_transforms,
        rest_joints=body.joints, body_vertices=frames.vertices, body_faces=body.faces,
        fps=frames.fps, seconds={"context": context_seconds, "frames": frames_seconds,
                                 "collisions": collision_seconds},
        raw_posed=raw_posed, raw_rest_pos=np.asarray(given_pos, dtype=np.float32),
        collisions=stats, rest_collisions=rest_stats, welded=welded.merged)
