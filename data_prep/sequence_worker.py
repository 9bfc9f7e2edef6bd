"""The sequence worker of a synthetic build: one sequence posed, simulated from its
garment's template, checked and written (in the CLOTH3D layout under ``raw/`` and as a
prepared-cache file). A module-level function: the executors send it to their workers
by name (:mod:`data_prep.executor`)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np

from data_prep.bodies import anny_body_model, anny_shape
from data_prep.build_records import crashed, left_out
from data_prep.config import DataConfig
from data_prep.garment_fitting import pin_targets, read_pins
from data_prep.left_the_body import left_the_body
from data_prep.plan import SequencePlan, planned_motion
from gnngarment.io.atomic import atomic_write_bytes
from gnngarment.threads import one_thread


@one_thread()
def simulate_sequence(task: tuple[str, SequencePlan, DataConfig, str]) -> dict[str, Any]:
    """Worker: pose, simulate, check and write one sequence. Returns a status dict
    (never raises for a failed simulation: that sequence is reported and left out)."""
    root_text, plan, config, inputs_hash = task
    root = Path(root_text)
    started = time.perf_counter()
    try:
        import torch

        from data_prep.cloth3d import write_sequence as write_cloth3d
        from data_prep.simulate import SimulationFailed, load_simulation_settings, simulate_garment
        from gnngarment.body.features import motion_features
        from gnngarment.data.cache import SequenceRecord, read_garment, write_sequence
        from gnngarment.geometry.normals import vertex_normals

        body_model = anny_body_model()
        shape = anny_shape(plan.body)
        motion = planned_motion(plan.motion, config, body_model, shape)
        with torch.no_grad():
            posed = body_model.pose(motion, shape)
        body_vertices = posed.vertices.numpy()
        transforms = posed.joint_transforms.numpy()
        garment = read_garment(root, plan.garment)
        pinned, pin_joint = read_pins(root, plan.garment)
        targets = (pin_targets(garment.rest_pos, pinned, pin_joint, transforms)
                   if len(pinned) else None)
        settings = load_simulation_settings(config.simulation)
        if config.settle_frames >= 0:
            settings.settle_frames = config.settle_frames
        result = simulate_garment(garment.rest_pos, garment.faces, body_vertices,
                                  body_model.faces, config.fps, fabric=plan.design.fabric,
                                  pinned=pinned if len(pinned) else None,
                                  pin_targets=targets, settings=settings)
        velocities = body_model.subset_velocities(posed, config.fps, config.body_vertices).numpy()
        samples = body_model.feature_vertex_indices(config.collision_points)
        normals = np.stack([vertex_normals(v, body_model.faces)[samples] for v in body_vertices])
        features = motion_features(motion).numpy()
        off = left_the_body(result.positions, body_vertices[:, samples],
                            rest=garment.rest_pos)
        if off:
            return left_out(root, plan.name, inputs_hash, off, started)
        record = SequenceRecord(
            name=plan.name, garment=plan.garment, body=plan.body.name, motion=plan.motion.name,
            fps=config.fps, positions=result.positions, joint_transforms=transforms,
            motion_features=features, velocities=velocities,
            body_points=body_vertices[:, samples], body_normals=normals)
        # Raw sequence in the CLOTH3D layout (same reader path as real CLOTH3D data).
        translation = motion.translation.astype(np.float64)
        write_cloth3d(root / "raw" / plan.name, {
            "poses": motion.rotations.reshape(len(motion), -1), "trans": translation,
            "shape": np.zeros(10), "gender": round(plan.body.shape["gender"]),
            "zrot": 0.0, "outfit": {plan.design.garment_type: {"fabric": plan.design.fabric}},
            "body_model": "anny", "anny_phenotype": plan.body.shape,
        }, {plan.design.garment_type: (garment.rest_pos, garment.faces,
                                       result.positions - translation[:, None, :])})
        path = write_sequence(root, record)
        # The input hash lives beside the file: the next build skips this sequence.
        atomic_write_bytes(path.parent / f"{plan.name}.hash", inputs_hash.encode())
        return {"name": plan.name, "ok": True, "frames": len(motion),
                "seconds": time.perf_counter() - started,
                "seconds_per_frame": result.seconds_per_frame, "attempts": result.attempts,
                "max_stretch": float(np.nanmax(result.quality.max_stretch)),
                "max_inside_pct": 100 * float(np.nanmax(result.quality.inside_fraction))}
    except SimulationFailed as error:
        return left_out(root, plan.name, inputs_hash, str(error), started)
    except Exception as error:  # a broken garment or body: report, don't kill the build
        return crashed(plan.name, error, started)
