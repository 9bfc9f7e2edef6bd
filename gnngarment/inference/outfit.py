"""Animate an outfit: several garments on one body and motion, kept in their layers.

Each garment is animated by the model as it would be alone (its own context, the same
frames; :func:`~gnngarment.inference.animate.animate`), then, innermost first, every
garment is moved out of the body (as alone) and out of every garment beneath it by the
layer clearance (:func:`~gnngarment.geometry.garment_layers.resolve_layer_collisions`) —
at rest before the network sees it (the rest pose's layering is kept) and every frame
after. Garments that do not overlap come out exactly as when animated alone.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from gnngarment.data.body_inputs import BodyMotionInputs, BodyShapeInputs
from gnngarment.geometry import body_collisions
from gnngarment.geometry.body_collisions import CollisionSettings
from gnngarment.geometry.garment_layers import (
    LayerRelation,
    LayerSettings,
    LayerStats,
    layer_order,
    layer_penetration,
    outward_faces,
    resolve_layer_collisions,
)
from gnngarment.geometry.validation import validate_mesh
from gnngarment.geometry.welding import weld_vertices
from gnngarment.inference.animate import Animation, animate
from gnngarment.model.deformer import GarmentDeformer


@dataclass
class OutfitGarment:
    """One garment of an outfit as given: a name (file stem), rest ``pos (N, 3)`` on the
    rest body (metres, Z up) and ``faces (F, 3)``."""

    name: str
    pos: np.ndarray
    faces: np.ndarray


@dataclass
class OutfitAnimation:
    """An outfit animated on a body.

    Attributes:
        names: garment names, in the order given.
        animations: one :class:`Animation` per garment (given order); ``posed`` is
            resolved against the body and the garments beneath.
        order: garment indices, innermost first.
        relations: what the rest pose said about each overlapping pair.
        layer_stats: per garment index (not the innermost) what the layer resolution did
            every frame; rest_layer_stats the same for its rest garment.
        penetration_raw, penetration: per garment index (not the innermost), the share
            ``(T,)`` of its vertices behind the garment directly beneath, in the network's
            output and after resolution.
        seconds: wall-clock of the layer resolution (``"layers"``).
    """

    names: list[str]
    animations: list[Animation]
    order: list[int]
    relations: list[LayerRelation]
    layer_stats: dict[int, LayerStats]
    rest_layer_stats: dict[int, LayerStats]
    penetration_raw: dict[int, np.ndarray]
    penetration: dict[int, np.ndarray]
    seconds: dict[str, float]


def _welded_faces(pos: np.ndarray, faces: np.ndarray):
    """The welded mesh (copies of one point moved as one) of a garment."""
    return weld_vertices(np.asarray(pos), np.asarray(faces, dtype=np.int64))


def _resolve_outer(frames: np.ndarray, faces: np.ndarray, beneath, settings: LayerSettings
                   ) -> tuple[np.ndarray, LayerStats]:
    """:func:`resolve_layer_collisions` on the welded garment, back in its vertex order:
    coincident copies (a UV seam) get one push."""
    welded = _welded_faces(frames[0] if frames.ndim == 3 else frames, faces)
    first = np.unique(welded.index, return_index=True)[1]
    single = frames.ndim == 2
    data = frames[None] if single else frames
    resolved, stats = resolve_layer_collisions(data[:, first], welded.faces, beneath, settings)
    out = resolved[:, welded.index]
    return (out[0] if single else out), stats


def animate_outfit(model: GarmentDeformer, garments: Sequence[OutfitGarment],
                   body: BodyShapeInputs, frames: BodyMotionInputs,
                   layers: Sequence[str] | None = None, chunk: int | None = None,
                   progress: Callable[[int, int], None] | None = None,
                   resolve_collisions: bool = True,
                   collisions: CollisionSettings | None = None,
                   layer_settings: LayerSettings | None = None) -> OutfitAnimation:
    """Predict every garment of an outfit for every frame of a posed body.

    Args:
        model: a trained deformer.
        garments: the outfit (at least one garment; names unique).
        body: as :func:`~gnngarment.inference.animate.animate`.
        frames: as :func:`~gnngarment.inference.animate.animate`.
        layers: the order by name, innermost first; ``None``: inferred at rest
            (:func:`~gnngarment.geometry.garment_layers.layer_order`).
        chunk: frames per forward pass (``None``: by the garment's size).
        progress: called with (frames done, total) over all garments.
        resolve_collisions: body and layer resolution (off: the network's output).
        collisions: the body's ``ε`` (default :class:`CollisionSettings`).
        layer_settings: the layer clearance (default :class:`LayerSettings`).

    Raises:
        LayerOrderError: the order cannot be told (names the garments).
        MeshError: a garment mesh is unusable.
        ValueError: no garment, or two with one name.
    """
    import time

    if not garments:
        raise ValueError("an outfit needs at least one garment")
    names = [garment.name for garment in garments]
    if len(set(names)) != len(names):
        raise ValueError(f"garment names must differ: {', '.join(names)}")
    settings = collisions or CollisionSettings()
    layer_settings = layer_settings or LayerSettings()
    for garment in garments:
        validate_mesh(np.asarray(garment.pos), np.asarray(garment.faces), garment.name)
    # The rest garments out of the rest body first (as animate does), so that the order
    # and the layer resolution read the garments as they will be worn.
    rest = []
    for garment in garments:
        pos = np.asarray(garment.pos, dtype=np.float64)
        if resolve_collisions:
            pos, _ = body_collisions.resolve_collisions(
                pos, np.asarray(garment.faces, dtype=np.int64), body.rest_vertices,
                body.faces, settings)
        rest.append(pos)
    outward = [outward_faces(pos, garment.faces, body.rest_vertices, body.faces)
               for pos, garment in zip(rest, garments, strict=True)]
    order, relations = layer_order(list(zip(rest, outward, strict=True)), names,
                                   layer_settings, layers)
    started = time.perf_counter()
    rest_stats: dict[int, LayerStats] = {}
    if resolve_collisions:
        for place, index in enumerate(order[1:], start=1):
            beneath = [(rest[j], outward[j]) for j in order[:place]]
            rest[index], rest_stats[index] = _resolve_outer(rest[index], garments[index].faces,
                                                            beneath, layer_settings)
    layer_seconds = time.perf_counter() - started

    count = frames.motion_features.shape[0]
    done: list[Animation] = []
    for step, garment in enumerate(garments):

        def advance(frames_done: int, _: int, offset: int = step * count) -> None:
            if progress is not None:
                progress(offset + frames_done, count * len(garments))

        animation = animate(model, rest[step], garment.faces, body, frames, chunk=chunk,
                            source=garment.name, progress=advance,
                            resolve_collisions=resolve_collisions, collisions=settings)
        # The garment as given (before any resolution), as a single animation reports it.
        animation.raw_rest_pos = np.asarray(garment.pos, dtype=np.float32)
        done.append(animation)

    started = time.perf_counter()
    stats: dict[int, LayerStats] = {}
    raw_share: dict[int, np.ndarray] = {}
    share: dict[int, np.ndarray] = {}
    for place, index in enumerate(order[1:], start=1):
        below = order[place - 1]
        animation = done[index]
        raw_below = done[below].raw_posed if done[below].raw_posed is not None \
            else done[below].posed
        raw = animation.raw_posed if animation.raw_posed is not None else animation.posed
        raw_share[index] = layer_penetration(raw, raw_below, outward[below], layer_settings)
        if resolve_collisions:
            beneath = [(done[j].posed, outward[j]) for j in order[:place]]
            animation.posed, stats[index] = _resolve_outer(
                np.asarray(animation.posed), garments[index].faces, beneath, layer_settings)
        share[index] = layer_penetration(animation.posed, done[below].posed, outward[below],
                                         layer_settings)
    layer_seconds += time.perf_counter() - started
    return OutfitAnimation(names=names, animations=done, order=order, relations=relations,
                           layer_stats=stats, rest_layer_stats=rest_stats,
                           penetration_raw=raw_share, penetration=share,
                           seconds={"layers": layer_seconds})
