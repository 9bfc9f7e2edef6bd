"""The outfit worker of a synthetic build: a layered outfit (a top over a bottom, each
already draped alone on the rest body) simulated with Newton in one scene with the
simulator's cloth self-contact, on the body and motion of the bottom's test sequence,
and written to ``outfits/``. A module-level function: the executors send it to their
workers by name (:mod:`data_prep.executor`)."""

from __future__ import annotations

import time
from dataclasses import replace
from itertools import pairwise
from pathlib import Path
from typing import Any

import numpy as np

from data_prep.bodies import anny_body_model, anny_shape
from data_prep.build_records import crashed, left_out
from data_prep.config import DataConfig
from data_prep.garment_fitting import pin_targets, read_pins
from data_prep.plan import OutfitPlan, planned_motion
from gnngarment.io.atomic import atomic_write_bytes
from gnngarment.threads import one_thread

#: The outer garment starts this many self-contact distances outside the one beneath:
#: the two were draped apart, and a start inside the contact distance is an impulse
#: that failed the stretch gate within a few frames (measured, 2026-12-07: with 3 mm,
#: inside the 4 mm distance, 2 of the first 9 outfit sequences passed).
START_GAP_CONTACT_DISTANCES = 1.5


def layered_start(rests: list[np.ndarray], faces: list[np.ndarray],
                  body_rest_vertices: np.ndarray, body_faces: np.ndarray,
                  gap: float) -> list[np.ndarray]:
    """The garments' start positions, innermost first: each moved out of the ones
    beneath it by at least ``gap`` [m] (the layer resolution at rest). Shapes: rests
    and faces per garment ``(N_g, 3)`` / ``(F_g, 3)``."""
    from gnngarment.geometry.garment_layers import (
        LayerSettings,
        outward_faces,
        resolve_layer_collisions,
    )

    layers = LayerSettings()
    settings = replace(layers, clearance=max(layers.clearance, gap))
    starts: list[np.ndarray] = []
    beneath: list[tuple[np.ndarray, np.ndarray]] = []
    for rest, garment_faces in zip(rests, faces, strict=True):
        start = rest
        if beneath:
            start, _ = resolve_layer_collisions(rest, garment_faces, beneath, settings)
            start = np.asarray(start)
        starts.append(start)
        beneath.append((start, outward_faces(start, garment_faces, body_rest_vertices,
                                             body_faces)))
    return starts


def pinned_scene(root: Path, garments: list[str], starts: list[np.ndarray],
                 transforms: np.ndarray) -> tuple[np.ndarray | None, np.ndarray | None]:
    """The pins of every garment of a scene (indices into the concatenated mesh) and
    their targets per frame ``(T, P, 3)``, each following its own joint rigidly."""
    pins, targets, offset = [], [], 0
    for name, start in zip(garments, starts, strict=True):
        pinned, joint = read_pins(root, name)
        if len(pinned):
            targets.append(pin_targets(start, pinned, joint, transforms))
            pins.append(pinned + offset)
        offset += len(start)
    if not pins:
        return None, None
    return np.concatenate(pins), np.concatenate(targets, axis=1)


@one_thread()
def simulate_outfit(task: tuple[str, OutfitPlan, DataConfig, str]) -> dict[str, Any]:
    """Worker: pose, simulate every garment of an outfit in one scene, check and write
    ``outfits/<name>.npz``. Returns a status dict (never raises for a failed
    simulation: the outfit is reported and left out)."""
    root_text, plan, config, inputs_hash = task
    root = Path(root_text)
    started = time.perf_counter()
    try:
        import torch

        from data_prep.simulate import SimulationFailed, load_simulation_settings, simulate_garment
        from gnngarment.data.cache import OutfitRecord, read_garment, write_outfit

        body_model = anny_body_model()
        shape = anny_shape(plan.sequence.body)
        motion = planned_motion(plan.sequence.motion, config, body_model, shape)
        with torch.no_grad():
            posed = body_model.pose(motion, shape)
            rest_body = body_model.rest(shape).vertices.numpy()
        transforms = posed.joint_transforms.numpy()
        garments = [read_garment(root, name) for name in plan.garments]
        settings = load_simulation_settings(config.simulation)
        settings.self_contact = True
        if config.settle_frames >= 0:
            settings.settle_frames = config.settle_frames
        # The start is the scene's rest shape: settling the outfit together first, with
        # each garment keeping its own drape's edge lengths, was tried (2026-12-07) and
        # passed the gates less often (2 of 5 outfit sequences against 3).
        starts = layered_start([g.rest_pos for g in garments], [g.faces for g in garments],
                               rest_body, body_model.faces,
                               START_GAP_CONTACT_DISTANCES * settings.self_contact_distance)
        offsets = np.cumsum([0] + [len(s) for s in starts])
        faces = np.concatenate([g.faces + offset for g, offset
                                in zip(garments, offsets, strict=False)])
        pinned, targets = pinned_scene(root, list(plan.garments), starts, transforms)
        # The outer garment's fabric for the scene (the simulator takes one).
        result = simulate_garment(np.concatenate(starts), faces, posed.vertices.numpy(),
                                  body_model.faces, config.fps, fabric=plan.top.fabric,
                                  pinned=pinned, pin_targets=targets, settings=settings)
        path = write_outfit(root, OutfitRecord(
            name=plan.name, sequence=plan.sequence.name, garments=list(plan.garments),
            start_pos=starts,
            positions=[result.positions[:, a:b] for a, b in pairwise(offsets)]))
        atomic_write_bytes(path.parent / f"{plan.name}.hash", inputs_hash.encode())
        return {"name": plan.name, "ok": True, "frames": len(motion),
                "seconds": time.perf_counter() - started,
                "seconds_per_frame": result.seconds_per_frame}
    except SimulationFailed as error:
        return left_out(root, plan.name, inputs_hash, str(error), started, "outfits")
    except Exception as error:  # a broken garment or body: report, don't kill the build
        return crashed(plan.name, error, started)
