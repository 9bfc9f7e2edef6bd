"""A design fitted to a body's rest pose, before draping (:class:`GarmentDesign`), and the
vertices it pins to the body, as the cache stores them (``garments/<name>.pins.json``)."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from data_prep.bodies import anny_body_model, anny_shape
from data_prep.plan import BodyPlan, DesignPlan
from gnngarment.io.atomic import atomic_write_bytes

#: Garment types whose waist ring is pinned to the pelvis (they hang from the waist).
WAIST_SUPPORTED = ("skirt", "trousers")


def is_strapless(style: Any) -> bool:
    """Whether a sampled style has no straps or sleeves to hang from (a tube top, a
    strapless dress or jumpsuit)."""
    return "strapless" in (getattr(style, "sleeves", None), getattr(style, "kind", None))


@dataclass(frozen=True)
class GarmentDesign:
    """A design fitted to a body's rest pose, before draping.

    Attributes:
        pos: ``(N, 3)`` design positions [m]; faces ``(F, 3)``.
        pinned: ``(P,)`` vertices held by the body: the waist ring of a skirt or trousers,
            the elastic top band of a strapless design; empty otherwise.
        pin_joint: the joint whose rigid motion the pinned vertices follow (-1: none).
    """

    pos: np.ndarray
    faces: np.ndarray
    pinned: np.ndarray
    pin_joint: int


def make_garment(design: DesignPlan, body: BodyPlan) -> GarmentDesign:
    """The design fitted to the body's rest pose (undraped).

    A design is its type, a style drawn from the design's seed and a resolution: the
    same design on every body (fitted to each), as CLOTH3D refits a garment per body.
    Skirts and trousers hang from a waist ring that follows the pelvis; a strapless top,
    dress or jumpsuit has an elastic top band that follows the chest joint it sits on
    (without it, 17 of 74 benchmark sequences slid down the body).
    """
    from data_prep.garments import GARMENT_TYPES, BodyFrame
    from data_prep.garments import make_garment as build_garment

    body_model = anny_body_model()
    rest = body_model.rest(anny_shape(body))
    frame = BodyFrame(vertices=rest.vertices.numpy(), faces=rest.faces,
                      joints=rest.joints.numpy())
    style = GARMENT_TYPES[design.garment_type][0].sample(np.random.default_rng(design.seed))
    garment = build_garment(frame, design.garment_type, style,
                            target_vertices=design.vertices, seed=design.seed,
                            name=design.name)
    band = np.asarray(garment.pin_candidates, dtype=np.int64)
    if design.garment_type in WAIST_SUPPORTED:
        return GarmentDesign(garment.pos, garment.faces, band, 0)
    if is_strapless(style):
        from gnngarment.body.weight_transfer import transfer_body_weights

        weights = transfer_body_weights(garment.pos[band], rest.vertices.numpy(),
                                        body_model.skinning_weights())
        return GarmentDesign(garment.pos, garment.faces, band, int(weights.sum(0).argmax()))
    return GarmentDesign(garment.pos, garment.faces, np.zeros(0, dtype=np.int64), -1)


def write_pins(root: Path, garment: str, design: GarmentDesign) -> None:
    """Write a cache garment's pinned vertices and the joint they follow (read back by
    :func:`read_pins`)."""
    atomic_write_bytes(root / "garments" / f"{garment}.pins.json", json.dumps(
        {"vertices": design.pinned.tolist(), "joint": design.pin_joint}).encode())


def read_pins(root: Path, garment: str) -> tuple[np.ndarray, int]:
    """The pinned vertices ``(P,)`` of a cache garment and the joint they follow."""
    pins = json.loads((root / "garments" / f"{garment}.pins.json").read_text())
    return np.asarray(pins["vertices"], dtype=np.int64), int(pins["joint"])


def pin_targets(rest_pos: np.ndarray, pinned: np.ndarray, joint: int,
                joint_transforms: np.ndarray) -> np.ndarray:
    """Where the pinned vertices are every frame: a waist ring or top band follows its
    joint rigidly. Shapes: rest_pos ``(N, 3)`` [m], pinned ``(P,)``, joint_transforms
    ``(T, 24, 4, 4)`` → ``(T, P, 3)`` [m]."""
    rest = np.concatenate([rest_pos[pinned], np.ones((len(pinned), 1))], 1)
    return np.einsum("tab,pb->tpa", joint_transforms[:, joint], rest)[..., :3]
