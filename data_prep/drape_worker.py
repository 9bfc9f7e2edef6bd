"""The drape worker of a synthetic build: one (design, body) garment fitted, draped on
its still rest body (the template, DESIGN.md) and written to the prepared cache with its
pins and topology. A module-level function: the executors send it to their workers by
name (:mod:`data_prep.executor`)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np

from data_prep.bodies import anny_body_model, anny_shape
from data_prep.build_records import crashed, left_out
from data_prep.config import DataConfig
from data_prep.garment_fitting import make_garment, write_pins
from data_prep.left_the_body import left_the_body
from data_prep.plan import BodyPlan, DesignPlan
from gnngarment.io.atomic import atomic_write_bytes
from gnngarment.threads import one_thread


@one_thread()
def drape_and_prepare_garment(task: tuple[str, DesignPlan, BodyPlan, DataConfig, str]
                              ) -> dict[str, Any]:
    """Worker: fit a design to a body, drape it on the still rest body (the template,
    DESIGN.md), and write ``garments/<design>_<body>.npz`` (rest_pos = the drape,
    design_pos = the design), its pins and its topology. Returns a status dict (never
    raises for a failed drape: the garment and its sequences are reported and left out).
    """
    root_text, design, body, config, inputs_hash = task
    root = Path(root_text)
    name = f"{design.name}_{body.name}"
    started = time.perf_counter()
    try:
        from data_prep.simulate import SimulationFailed, drape_garment, load_simulation_settings
        from gnngarment.body.joint_reach import joint_region_distances
        from gnngarment.body.weight_transfer import transfer_body_weights
        from gnngarment.data.cache import (
            GarmentRecord,
            topology_key,
            write_garment,
            write_topology,
        )
        from gnngarment.geometry.prepare import GarmentPreparationConfig, prepare_garment

        body_model = anny_body_model()
        rest = body_model.rest(anny_shape(body))
        body_vertices = rest.vertices.numpy()
        made = make_garment(design, body)
        try:
            drape = drape_garment(made.pos, made.faces, body_vertices, body_model.faces,
                                  config.fps, fabric=design.fabric,
                                  pinned=made.pinned if len(made.pinned) else None,
                                  settings=load_simulation_settings(config.simulation),
                                  max_frames=config.drape_frames,
                                  rest_speed=config.drape_rest_speed)
        except SimulationFailed as error:
            return left_out(root, name, inputs_hash, f"drape: {error}", started, "garments")
        samples = body_model.feature_vertex_indices(config.collision_points)
        off = left_the_body(drape.positions[None], body_vertices[samples][None],
                            rest=made.pos)
        if off:
            return left_out(root, name, inputs_hash, f"drape: {off}", started, "garments")
        pos = drape.positions.astype(np.float64)
        prepared = prepare_garment(pos, made.faces, GarmentPreparationConfig(
            levels=config.levels, landmarks=config.landmarks), source=name)
        key = topology_key(made.faces)
        if not (root / "topologies" / f"{key}.npz").is_file():
            write_topology(root, key, prepared.hierarchy)
        skinning = body_model.skinning_weights()
        weights = transfer_body_weights(pos, body_vertices, skinning)
        write_pins(root, name, made)
        write_garment(root, GarmentRecord(
            name=name, rest_pos=pos, faces=made.faces, descriptor=prepared.descriptor,
            topology=key, garment_type=design.garment_type, body=body.name,
            body_weights=weights,
            joint_distances=joint_region_distances(pos, body_vertices, skinning),
            design_pos=made.pos))
        atomic_write_bytes(root / "garments" / f"{name}.hash", inputs_hash.encode())
        return {"name": name, "ok": True, "vertices": len(pos), "faces": len(made.faces),
                "pinned": len(made.pinned), "drape_frames": drape.frames,
                "drape_settled": drape.settled,
                "drape_last_speed_mm": 1000 * drape.last_speed,
                "drape_mean_displacement_mm": 1000 * drape.mean_displacement,
                "seconds": time.perf_counter() - started}
    except Exception as error:  # a broken design on this body: report, don't kill the build
        return crashed(name, error, started)
